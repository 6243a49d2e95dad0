#include "model/project_io.h"

#include <cmath>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/file_io.h"

namespace wrap {

namespace {

using json = nlohmann::json;
using ojson = nlohmann::ordered_json;

constexpr std::string_view kFormatName = "wrap-project";

std::string TypeName(const json& j) {
  switch (j.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return "a number";
    default:
      return "an unsupported value";
  }
}

std::string Join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string Index(const std::string& path, size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// Reads JSON values into plain structs, recording every problem with its JSON path and going on
// with the defaults, so that one pass reports all problems.
class Reader {
 public:
  Reader(const std::string& file, Diagnostics& diags) : file_(file), diags_(diags) {}

  void Error(const std::string& path, const std::string& message) {
    diags_.Error(file_, path, message);
  }
  void Warning(const std::string& path, const std::string& message) {
    diags_.Warning(file_, path, message);
  }

  // Warns about keys of `obj` that are not in `known` (probably a typo).
  void CheckKeys(const json& obj, const std::string& path,
                 std::initializer_list<std::string_view> known) {
    for (const auto& [key, value] : obj.items()) {
      bool found = false;
      for (std::string_view k : known) found = found || key == k;
      if (!found) {
        std::string list;
        for (std::string_view k : known) list += (list.empty() ? "" : ", ") + std::string(k);
        Warning(Join(path, key), "unknown field, ignored (known here: " + list + ")");
      }
    }
  }

  // The member `key` of `obj`, or nullptr when absent (error when `required`).
  const json* Member(const json& obj, const std::string& path, const char* key, bool required) {
    auto it = obj.find(key);
    if (it == obj.end()) {
      if (required) Error(Join(path, key), "required field is missing");
      return nullptr;
    }
    return &*it;
  }

  bool Object(const json& j, const std::string& path) {
    if (j.is_object()) return true;
    Error(path, "expected an object, found " + TypeName(j));
    return false;
  }

  bool Array(const json& j, const std::string& path) {
    if (j.is_array()) return true;
    Error(path, "expected an array, found " + TypeName(j));
    return false;
  }

  void Number(const json& obj, const std::string& path, const char* key, double& out,
              bool required = false) {
    const json* j = Member(obj, path, key, required);
    if (!j) return;
    if (!j->is_number()) {
      Error(Join(path, key), "expected a number, found " + TypeName(*j));
      return;
    }
    out = j->get<double>();
  }

  void Integer(const json& obj, const std::string& path, const char* key, long long& out) {
    const json* j = Member(obj, path, key, false);
    if (!j) return;
    if (!j->is_number_integer()) {
      Error(Join(path, key),
            "expected an integer, found " + (j->is_number() ? std::string("a "
                                                                          "fraction")
                                                            : TypeName(*j)));
      return;
    }
    out = j->get<long long>();
  }

  void Bool(const json& obj, const std::string& path, const char* key, bool& out) {
    const json* j = Member(obj, path, key, false);
    if (!j) return;
    if (!j->is_boolean()) {
      Error(Join(path, key), "expected true or false, found " + TypeName(*j));
      return;
    }
    out = j->get<bool>();
  }

  void String(const json& obj, const std::string& path, const char* key, std::string& out,
              bool required = false) {
    const json* j = Member(obj, path, key, required);
    if (!j) return;
    if (!j->is_string()) {
      Error(Join(path, key), "expected a string, found " + TypeName(*j));
      return;
    }
    out = j->get<std::string>();
  }

  void Strings(const json& obj, const std::string& path, const char* key,
               std::vector<std::string>& out, bool required = false) {
    const json* j = Member(obj, path, key, required);
    if (!j || !Array(*j, Join(path, key))) return;
    out.clear();
    for (size_t i = 0; i < j->size(); ++i) {
      const json& e = (*j)[i];
      if (!e.is_string()) {
        Error(Index(Join(path, key), i), "expected a string, found " + TypeName(e));
        continue;
      }
      out.push_back(e.get<std::string>());
    }
  }

  // A fixed-length array of numbers.
  bool Numbers(const json& j, const std::string& path, double* out, size_t n) {
    if (!j.is_array() || j.size() != n) {
      Error(path, "expected an array of " + std::to_string(n) + " numbers, found " +
                      (j.is_array() ? "an array of " + std::to_string(j.size()) : TypeName(j)));
      return false;
    }
    bool ok = true;
    for (size_t i = 0; i < n; ++i) {
      if (!j[i].is_number()) {
        Error(Index(path, i), "expected a number, found " + TypeName(j[i]));
        ok = false;
        continue;
      }
      out[i] = j[i].get<double>();
    }
    return ok;
  }

  void Vector3(const json& obj, const std::string& path, const char* key, Vec3& out,
               bool required = false) {
    const json* j = Member(obj, path, key, required);
    if (!j) return;
    double v[3];
    if (Numbers(*j, Join(path, key), v, 3)) out = Vec3(v[0], v[1], v[2]);
  }

  void PoseValue(const json& j, const std::string& path, Pose& out) {
    if (!Object(j, path)) return;
    CheckKeys(j, path, {"xyz", "rpy", "rpy_deg"});
    Vector3(j, path, "xyz", out.xyz);
    if (j.contains("rpy") && j.contains("rpy_deg")) {
      Error(Join(path, "rpy_deg"), "give either rpy (rad) or rpy_deg, not both");
      return;
    }
    Vector3(j, path, "rpy", out.rpy);
    Vec3 deg = Vec3::Zero();
    if (j.contains("rpy_deg")) {
      Vector3(j, path, "rpy_deg", deg);
      out.rpy = deg * (std::numbers::pi / 180.0);
    }
  }

  void PoseMember(const json& obj, const std::string& path, const char* key, Pose& out,
                  bool required = false) {
    const json* j = Member(obj, path, key, required);
    if (j) PoseValue(*j, Join(path, key), out);
  }

  void WrenchBoxValue(const json& j, const std::string& path, WrenchBox& out) {
    if (!Object(j, path)) return;
    CheckKeys(j, path, {"force_N", "torque_Nm"});
    Vector3(j, path, "force_N", out.force_N, true);
    Vector3(j, path, "torque_Nm", out.torque_Nm, true);
  }

  void ColorMember(const json& obj, const std::string& path, const char* key, Rgba& out) {
    const json* j = Member(obj, path, key, false);
    if (!j) return;
    const std::string p = Join(path, key);
    if (!j->is_array() || (j->size() != 3 && j->size() != 4)) {
      Error(p, "expected [r, g, b] or [r, g, b, a] in [0, 1], found " + TypeName(*j));
      return;
    }
    Rgba c = {0, 0, 0, 1};
    if (Numbers(*j, p, c.data(), j->size())) out = c;
  }

 private:
  const std::string& file_;
  Diagnostics& diags_;
};

void ReadPart(Reader& r, const json& j, const std::string& path, Part& part) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path,
              {"name", "mesh", "solid", "scale", "mass_kg", "density_kg_m3", "assembled_pose",
               "initial_pose", "color"});
  r.String(j, path, "name", part.name, true);
  r.String(j, path, "mesh", part.mesh, true);
  r.String(j, path, "solid", part.solid);
  r.Number(j, path, "scale", part.scale);
  if (j.contains("mass_kg")) {
    double m = 0.0;
    r.Number(j, path, "mass_kg", m);
    part.mass_kg = m;
  }
  r.Number(j, path, "density_kg_m3", part.density_kg_m3);
  r.PoseMember(j, path, "assembled_pose", part.assembled_pose);
  r.PoseMember(j, path, "initial_pose", part.initial_pose, true);
  r.ColorMember(j, path, "color", part.color);
}

void ReadMating(Reader& r, const json& j, const std::string& path, Mating& m) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path,
              {"moved", "base", "final_poses", "axis", "force_N", "torque_Nm",
               "transverse_fraction", "offset_m", "approach_m", "interference_travel_m",
               "interference_depth_m", "connection_limits"});
  r.String(j, path, "moved", m.moved, true);
  r.String(j, path, "base", m.base, true);
  if (const json* fp = r.Member(j, path, "final_poses", false)) {
    const std::string p = Join(path, "final_poses");
    if (r.Array(*fp, p)) {
      for (size_t i = 0; i < fp->size(); ++i) {
        Pose pose;
        r.PoseValue((*fp)[i], Index(p, i), pose);
        m.final_poses.push_back(pose);
      }
    }
  }
  r.Vector3(j, path, "axis", m.axis);
  r.Number(j, path, "force_N", m.force_N);
  r.Number(j, path, "torque_Nm", m.torque_Nm);
  r.Number(j, path, "transverse_fraction", m.transverse_fraction);
  r.Number(j, path, "offset_m", m.offset_m);
  r.Number(j, path, "approach_m", m.approach_m);
  r.Number(j, path, "interference_travel_m", m.interference_travel_m);
  r.Number(j, path, "interference_depth_m", m.interference_depth_m);
  if (const json* cl = r.Member(j, path, "connection_limits", false)) {
    WrenchBox box;
    r.WrenchBoxValue(*cl, Join(path, "connection_limits"), box);
    m.connection_limits = box;
  }
}

void ReadStep(Reader& r, const json& j, const std::string& path, Step& step) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path, {"name", "inputs", "parts", "mating"});
  r.String(j, path, "name", step.name, true);
  r.Strings(j, path, "inputs", step.inputs, true);
  r.Strings(j, path, "parts", step.parts);
  if (const json* m = r.Member(j, path, "mating", true)) {
    ReadMating(r, *m, Join(path, "mating"), step.mating);
  }
}

void ReadWrenchLimits(Reader& r, const json& j, const std::string& path, WrenchLimits& wl) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path, {"two_finger", "vacuum_assembly", "vacuum_transport"});
  if (const json* v = r.Member(j, path, "two_finger", false)) {
    r.WrenchBoxValue(*v, Join(path, "two_finger"), wl.two_finger);
  }
  if (const json* v = r.Member(j, path, "vacuum_assembly", false)) {
    r.WrenchBoxValue(*v, Join(path, "vacuum_assembly"), wl.vacuum_assembly);
  }
  if (const json* v = r.Member(j, path, "vacuum_transport", false)) {
    r.WrenchBoxValue(*v, Join(path, "vacuum_transport"), wl.vacuum_transport);
  }
}

void ReadRobot(Reader& r, const json& j, const std::string& path, Robot& robot) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path,
              {"name", "model", "urdf", "urdf_root", "urdf_tip", "end_effector", "mounted_on",
               "mount", "base_pose", "wrench_limits"});
  r.String(j, path, "name", robot.name, true);
  r.String(j, path, "model", robot.model);
  r.String(j, path, "urdf", robot.urdf);
  r.String(j, path, "urdf_root", robot.urdf_root);
  r.String(j, path, "urdf_tip", robot.urdf_tip);
  r.String(j, path, "end_effector", robot.end_effector, true);
  r.String(j, path, "mounted_on", robot.mounted_on);
  r.String(j, path, "mount", robot.mount);
  r.PoseMember(j, path, "base_pose", robot.base_pose);
  if (const json* wl = r.Member(j, path, "wrench_limits", false)) {
    WrenchLimits limits;
    ReadWrenchLimits(r, *wl, Join(path, "wrench_limits"), limits);
    robot.wrench_limits = limits;
  }
}

void ReadMobileBase(Reader& r, const json& j, const std::string& path, MobileBase& base) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path, {"name", "model", "pose"});
  r.String(j, path, "name", base.name, true);
  r.String(j, path, "model", base.model, true);
  r.PoseMember(j, path, "pose", base.pose);
}

void ReadTable(Reader& r, const json& j, const std::string& path, Table& t) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path, {"size", "center_xy", "height", "friction"});
  r.Vector3(j, path, "size", t.size);
  if (const json* c = r.Member(j, path, "center_xy", false)) {
    double xy[2] = {0, 0};
    if (r.Numbers(*c, Join(path, "center_xy"), xy, 2)) t.center_xy = Vec3(xy[0], xy[1], 0.0);
  }
  r.Number(j, path, "height", t.height);
  r.Number(j, path, "friction", t.friction);
}

void ReadGeometry(Reader& r, const json& j, const std::string& path, GeometryTolerances& g) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path, {"contact_m", "touch_depth_m"});
  r.Number(j, path, "contact_m", g.contact_m);
  r.Number(j, path, "touch_depth_m", g.touch_depth_m);
}

void ReadTessellation(Reader& r, const json& j, const std::string& path, StepTessellation& t) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path, {"linear_deflection_m", "angular_deflection_deg"});
  r.Number(j, path, "linear_deflection_m", t.linear_deflection_m);
  double degrees = t.angular_deflection_rad * 180.0 / std::numbers::pi;
  r.Number(j, path, "angular_deflection_deg", degrees);
  t.angular_deflection_rad = degrees * std::numbers::pi / 180.0;
}

void ReadPlanner(Reader& r, const json& j, const std::string& path, PlannerDefaults& p) {
  if (!r.Object(j, path)) return;
  r.CheckKeys(j, path, {"grasps", "widen_grasps", "time_limit_s", "seed"});
  long long grasps = p.grasps;
  r.Integer(j, path, "grasps", grasps);
  if (grasps < 1 || grasps > 100000) {
    r.Error(Join(path, "grasps"), "must be between 1 and 100000, found " + std::to_string(grasps));
  } else {
    p.grasps = static_cast<int>(grasps);
  }
  r.Bool(j, path, "widen_grasps", p.widen_grasps);
  r.Number(j, path, "time_limit_s", p.time_limit_s);
  if (const json* s = r.Member(j, path, "seed", false)) {
    if (s->is_number_unsigned() || (s->is_number_integer() && s->get<long long>() >= 0)) {
      p.seed = s->get<std::uint64_t>();
    } else {
      r.Error(Join(path, "seed"), "expected a non-negative integer, found " + TypeName(*s));
    }
  }
}

void ReadPaths(Reader& r, const json& j, const std::string& path,
               std::map<std::string, PathVariable>& out) {
  if (!r.Object(j, path)) return;
  for (const auto& [name, value] : j.items()) {
    const std::string p = Join(path, name);
    if (!r.Object(value, p)) continue;
    r.CheckKeys(value, p, {"default", "env", "hint"});
    PathVariable var;
    r.String(value, p, "default", var.default_value, true);
    r.String(value, p, "env", var.env);
    r.String(value, p, "hint", var.hint);
    out[name] = var;
  }
}

template <typename T, typename Fn>
void ReadList(Reader& r, const json& root, const char* key, bool required, std::vector<T>& out,
              Fn read_one) {
  const json* j = r.Member(root, "", key, required);
  if (!j || !r.Array(*j, key)) return;
  for (size_t i = 0; i < j->size(); ++i) {
    T item;
    read_one(r, (*j)[i], Index(key, i), item);
    out.push_back(std::move(item));
  }
}

// Strips nlohmann's "[json.exception.parse_error.101] " prefix.
std::string CleanJsonMessage(const std::string& what) {
  const auto pos = what.find("] ");
  return pos == std::string::npos ? what : what.substr(pos + 2);
}

ojson PoseJson(const Pose& p) {
  return ojson{{"xyz", {p.xyz.x(), p.xyz.y(), p.xyz.z()}},
               {"rpy", {p.rpy.x(), p.rpy.y(), p.rpy.z()}}};
}

ojson Vec3Json(const Vec3& v) { return ojson::array({v.x(), v.y(), v.z()}); }

ojson WrenchBoxJson(const WrenchBox& b) {
  return ojson{{"force_N", Vec3Json(b.force_N)}, {"torque_Nm", Vec3Json(b.torque_Nm)}};
}

ojson WrenchLimitsJson(const WrenchLimits& w) {
  return ojson{{"two_finger", WrenchBoxJson(w.two_finger)},
               {"vacuum_assembly", WrenchBoxJson(w.vacuum_assembly)},
               {"vacuum_transport", WrenchBoxJson(w.vacuum_transport)}};
}

}  // namespace

ProjectParse ParseProject(std::string_view json_text, const std::string& file_label) {
  ProjectParse out;
  json root;
  try {
    root = json::parse(json_text.begin(), json_text.end());
  } catch (const json::parse_error& e) {
    out.diagnostics.Error(file_label, "", "malformed JSON: " + CleanJsonMessage(e.what()));
    return out;
  } catch (const std::exception& e) {
    out.diagnostics.Error(file_label, "", std::string("malformed JSON: ") + e.what());
    return out;
  }

  Reader r(file_label, out.diagnostics);
  if (!root.is_object()) {
    r.Error("", "expected a JSON object at the top level, found " + TypeName(root));
    return out;
  }
  std::string format;
  r.String(root, "", "format", format, true);
  if (root.contains("format") && root["format"].is_string() && format != kFormatName) {
    r.Error("format", "expected \"" + std::string(kFormatName) + "\", found \"" + format + "\"");
    return out;
  }
  long long version = 0;
  if (!root.contains("version")) {
    r.Error("version", "required field is missing (this build reads version " +
                           std::to_string(Project::kFormatVersion) + ")");
    return out;
  }
  r.Integer(root, "", "version", version);
  if (version != Project::kFormatVersion) {
    r.Error("version", "unsupported version " + std::to_string(version) +
                           (version > Project::kFormatVersion
                                ? " (written by a newer Wrap; this build reads version "
                                : " (this build reads version ") +
                           std::to_string(Project::kFormatVersion) + ")");
    return out;
  }

  r.CheckKeys(root, "",
              {"format", "version", "name", "description", "paths", "table", "parts", "steps",
               "connection_limits", "wrench_limits", "mobile_bases", "robots", "geometry",
               "planner", "tessellation"});
  Project p;
  // Every error above inside a field is recorded and parsing goes on; the project is returned
  // so that validation can report the rest.
  try {
    r.String(root, "", "name", p.name);
    r.String(root, "", "description", p.description);
    if (const json* j = r.Member(root, "", "paths", false)) ReadPaths(r, *j, "paths", p.paths);
    if (const json* j = r.Member(root, "", "table", false)) ReadTable(r, *j, "table", p.table);
    ReadList(r, root, "parts", true, p.parts, ReadPart);
    ReadList(r, root, "steps", false, p.steps, ReadStep);
    if (const json* j = r.Member(root, "", "connection_limits", false)) {
      r.WrenchBoxValue(*j, "connection_limits", p.connection_limits);
    }
    if (const json* j = r.Member(root, "", "wrench_limits", false)) {
      ReadWrenchLimits(r, *j, "wrench_limits", p.wrench_limits);
    }
    ReadList(r, root, "mobile_bases", false, p.mobile_bases, ReadMobileBase);
    ReadList(r, root, "robots", true, p.robots, ReadRobot);
    if (const json* j = r.Member(root, "", "geometry", false)) {
      ReadGeometry(r, *j, "geometry", p.geometry);
    }
    if (const json* j = r.Member(root, "", "planner", false)) {
      ReadPlanner(r, *j, "planner", p.planner);
    }
    if (const json* j = r.Member(root, "", "tessellation", false)) {
      ReadTessellation(r, *j, "tessellation", p.tessellation);
    }
  } catch (const std::exception& e) {
    // A json accessor can still throw on a shape we did not anticipate: report, do not crash.
    r.Error("", std::string("unreadable project structure: ") + e.what());
    return out;
  }
  out.project = std::move(p);
  return out;
}

ProjectParse ReadProjectFile(const std::filesystem::path& path) {
  auto text = ReadFile(path);
  if (!text) {
    ProjectParse out;
    out.diagnostics.Error(path.string(), "", text.error().message);
    return out;
  }
  return ParseProject(*text, path.string());
}

std::string SerializeProject(const Project& p) {
  ojson root = ojson::object();
  root["format"] = kFormatName;
  root["version"] = Project::kFormatVersion;
  root["name"] = p.name;
  root["description"] = p.description;
  if (!p.paths.empty()) {
    ojson paths = ojson::object();
    for (const auto& [name, var] : p.paths) {
      ojson v{{"default", var.default_value}};
      if (!var.env.empty()) v["env"] = var.env;
      if (!var.hint.empty()) v["hint"] = var.hint;
      paths[name] = v;
    }
    root["paths"] = paths;
  }
  root["table"] = ojson{{"size", Vec3Json(p.table.size)},
                        {"center_xy", {p.table.center_xy.x(), p.table.center_xy.y()}},
                        {"height", p.table.height},
                        {"friction", p.table.friction}};
  ojson parts = ojson::array();
  for (const Part& part : p.parts) {
    ojson j{{"name", part.name}, {"mesh", part.mesh}};
    if (!part.solid.empty()) j["solid"] = part.solid;
    j["scale"] = part.scale;
    if (part.mass_kg) j["mass_kg"] = *part.mass_kg;
    j["density_kg_m3"] = part.density_kg_m3;
    j["assembled_pose"] = PoseJson(part.assembled_pose);
    j["initial_pose"] = PoseJson(part.initial_pose);
    j["color"] = part.color;
    parts.push_back(j);
  }
  root["parts"] = parts;
  ojson steps = ojson::array();
  for (const Step& s : p.steps) {
    const Mating& m = s.mating;
    ojson mj{{"moved", m.moved},         {"base", m.base},
             {"axis", Vec3Json(m.axis)}, {"force_N", m.force_N},
             {"torque_Nm", m.torque_Nm}, {"transverse_fraction", m.transverse_fraction},
             {"offset_m", m.offset_m},   {"approach_m", m.approach_m}};
    const Mating defaults;
    if (m.interference_travel_m != defaults.interference_travel_m ||
        m.interference_depth_m != defaults.interference_depth_m) {
      mj["interference_travel_m"] = m.interference_travel_m;
      mj["interference_depth_m"] = m.interference_depth_m;
    }
    if (!m.final_poses.empty()) {
      ojson fp = ojson::array();
      for (const Pose& pose : m.final_poses) fp.push_back(PoseJson(pose));
      mj["final_poses"] = fp;
    }
    if (m.connection_limits) mj["connection_limits"] = WrenchBoxJson(*m.connection_limits);
    ojson sj{{"name", s.name}, {"inputs", s.inputs}};
    if (!s.parts.empty()) sj["parts"] = s.parts;
    sj["mating"] = mj;
    steps.push_back(sj);
  }
  root["steps"] = steps;
  root["connection_limits"] = WrenchBoxJson(p.connection_limits);
  root["wrench_limits"] = WrenchLimitsJson(p.wrench_limits);
  if (!p.mobile_bases.empty()) {
    ojson bases = ojson::array();
    for (const MobileBase& b : p.mobile_bases) {
      bases.push_back(ojson{{"name", b.name}, {"model", b.model}, {"pose", PoseJson(b.pose)}});
    }
    root["mobile_bases"] = bases;
  }
  ojson robots = ojson::array();
  for (const Robot& rb : p.robots) {
    ojson j{{"name", rb.name}};
    if (!rb.model.empty()) j["model"] = rb.model;
    if (!rb.urdf.empty()) j["urdf"] = rb.urdf;
    if (!rb.urdf_root.empty()) j["urdf_root"] = rb.urdf_root;
    if (!rb.urdf_tip.empty()) j["urdf_tip"] = rb.urdf_tip;
    j["end_effector"] = rb.end_effector;
    if (!rb.mounted_on.empty()) j["mounted_on"] = rb.mounted_on;
    if (!rb.mount.empty()) j["mount"] = rb.mount;
    j["base_pose"] = PoseJson(rb.base_pose);
    if (rb.wrench_limits) j["wrench_limits"] = WrenchLimitsJson(*rb.wrench_limits);
    robots.push_back(j);
  }
  root["robots"] = robots;
  if (p.geometry != GeometryTolerances{}) {
    root["geometry"] = ojson{{"contact_m", p.geometry.contact_m},
                             {"touch_depth_m", p.geometry.touch_depth_m}};
  }
  root["planner"] = ojson{{"grasps", p.planner.grasps},
                          {"widen_grasps", p.planner.widen_grasps},
                          {"time_limit_s", p.planner.time_limit_s},
                          {"seed", p.planner.seed}};
  if (p.tessellation != StepTessellation{}) {
    root["tessellation"] = ojson{{"linear_deflection_m", p.tessellation.linear_deflection_m},
                                 {"angular_deflection_deg", p.tessellation.angular_deflection_rad *
                                                                180.0 / std::numbers::pi}};
  }
  // Keys keep the order written here (ordered_json): format and version first.
  return root.dump(2) + "\n";
}

Result<void> SaveProject(const Project& project, const std::filesystem::path& path) {
  return WriteFileAtomic(path, SerializeProject(project));
}

}  // namespace wrap
