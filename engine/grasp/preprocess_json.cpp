#include "grasp/preprocess_json.h"

#include <array>

#include <nlohmann/json.hpp>

#include "model/catalog.h"

namespace wrap {

namespace {

using json = nlohmann::ordered_json;

json Vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

json PoseJson(const Iso3& X) {
  const Pose p = FromIsometry(X);
  return json{{"xyz", Vec(p.xyz)}, {"rpy", Vec(p.rpy)}};
}

json PlacementJson(const StablePlacement& s) {
  json support_A = json::array(), support_T = json::array();
  for (const Vec3& p : s.support_A) support_A.push_back(Vec(p));
  for (const Eigen::Vector2d& p : s.support_T) support_T.push_back(json::array({p.x(), p.y()}));
  return json{{"facet", s.facet},
              {"normal_A", Vec(s.normal_A)},
              {"X_TA", PoseJson(s.X_TA)},
              {"support_A", support_A},
              {"support_T", support_T},
              {"area_m2", s.area_m2},
              {"margin_m", s.margin_m},
              {"com_height_m", s.com_height_m},
              {"tip_angle_rad", s.tip_angle_rad},
              {"equivalent_facets", s.equivalent_facets}};
}

json BoxJson(const WrenchBox& box) {
  return json{{"force_N", Vec(box.force_N)}, {"torque_Nm", Vec(box.torque_Nm)}};
}

json GraspJson(const Project& project, const Subassembly& sub, const Grasp& g) {
  Iso3 X_AP = Iso3::Identity();
  for (size_t k = 0; k < sub.parts.size(); ++k) {
    if (sub.parts[k] == g.part) X_AP = sub.X_AP[k];
  }
  return json{{"end_effector", g.end_effector},
              {"kind", std::string(ToString(g.kind))},
              {"part", project.parts[g.part].name},
              {"X_PG", PoseJson(g.X_PG)},
              {"X_AG", PoseJson(X_AP * g.X_PG)},
              {"quality", g.quality},
              {"width_m", g.width_m},
              {"contacts_P", json::array({Vec(g.contacts_P[0]), Vec(g.contacts_P[1])})},
              {"contact_area_m2", g.contact_area_m2},
              {"type", std::string(ToString(g.type))},
              {"torque_scale", Vec(g.torque_scale)},
              {"wrench_limits", BoxJson(g.kind == EndEffectorKind::kVacuum
                                            ? project.wrench_limits.vacuum_transport
                                            : GraspLimits(project.wrench_limits, g).two_finger)}};
}

// Per grasp type, the count of `items` of that type.
template <class Items, class TypeOf>
json ByType(const Items& items, TypeOf type_of) {
  std::array<int, kGraspTypes> n{};
  for (const auto& item : items) ++n[static_cast<int>(type_of(item))];
  json out = json::object();
  for (int t = 0; t < kGraspTypes; ++t)
    out[std::string(ToString(static_cast<GraspType>(t)))] = n[t];
  return out;
}

}  // namespace

std::string PreprocessedToJson(const Project& project, const Preprocessed& result) {
  json doc;
  doc["format"] = "wrap-preprocess";
  doc["version"] = 1;
  doc["project"] = project.name;
  doc["seed"] = result.seed;
  doc["grasps_per_set"] = result.grasps_per_set;
  doc["friction"] = result.friction;
  json times = json::object();
  for (const auto& [key, seconds] : result.times) times[key] = seconds;
  doc["timings_s"] = times;
  doc["t_grasp_s"] = result.times.contains("total") ? result.times.at("total") : 0.0;
  json ees = json::array();
  for (const std::string& name : result.end_effectors) {
    const EndEffectorInfo* info = FindEndEffector(name);
    ees.push_back(
        json{{"name", name},
             {"kind", info ? std::string(ToString(info->kind)) : std::string("unknown")}});
  }
  doc["end_effectors"] = ees;

  json slots = json::array();
  for (const TableSlot& slot : result.table_slots.slots) {
    json robots = json::array();
    for (int r : slot.robots) robots.push_back(project.robots[r].name);
    slots.push_back(json{{"xyz", Vec(slot.p_W)}, {"robots", robots}});
  }
  doc["table_slots"] = json{{"yaws_rad", result.table_slots.yaws_rad},
                            {"slots", slots},
                            {"candidates", result.table_slots.candidates},
                            {"reachable", result.table_slots.reachable}};

  json subs = json::array();
  for (const Subassembly& sub : result.subassemblies) {
    json parts = json::array(), poses = json::array();
    for (size_t k = 0; k < sub.parts.size(); ++k) {
      parts.push_back(project.parts[sub.parts[k]].name);
      poses.push_back(
          json{{"part", project.parts[sub.parts[k]].name}, {"X_AP", PoseJson(sub.X_AP[k])}});
    }
    json placements = json::array();
    for (const StablePlacement& s : sub.placements) placements.push_back(PlacementJson(s));
    json grasps = json::array();
    json counts = json::object(), by_type = json::object(), candidates = json::object();
    json assembly = json::object();
    for (const GraspSet& set : sub.grasp_sets) {
      counts[set.end_effector] = set.grasps.size();
      by_type[set.end_effector] = ByType(set.grasps, [](const Grasp& g) { return g.type; });
      json c = json::object();
      for (int t = 0; t < kGraspTypes; ++t) {
        c[std::string(ToString(static_cast<GraspType>(t)))] = set.candidates_by_type[t];
      }
      candidates[set.end_effector] = c;
      json a = json::object();
      for (int t = 0; t < kGraspTypes; ++t) {
        a[std::string(ToString(static_cast<GraspType>(t)))] = set.assembly_candidates_by_type[t];
      }
      assembly[set.end_effector] = a;
      for (const Grasp& g : set.grasps) grasps.push_back(GraspJson(project, sub, g));
    }
    subs.push_back(json{{"name", sub.name},
                        {"parts", parts},
                        {"part_poses", poses},
                        {"mass_kg", sub.mass_kg},
                        {"com_A", Vec(sub.com_A)},
                        {"hull", json{{"vertices", sub.hull.mesh.vertices.size()},
                                      {"facets", sub.hull.facets.size()},
                                      {"volume_m3", sub.hull.volume_m3}}},
                        {"placements", placements},
                        {"grasp_counts", counts},
                        {"grasp_counts_by_type", by_type},
                        {"candidates_by_type", candidates},
                        {"assembly_candidates_by_type", assembly},
                        {"grasps", grasps}});
  }
  doc["subassemblies"] = subs;
  doc["warnings"] = result.warnings;
  return doc.dump(1) + "\n";
}

}  // namespace wrap
