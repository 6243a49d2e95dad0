// Writing the plan file (task/plan_json.h): SerializePlan and SavePlan. Keys keep the order
// written here, so the same plan always gives the same bytes.
#include <utility>

#include "core/file_io.h"
#include "task/plan_json.h"
#include "task/plan_json_internal.h"

namespace wrap {

namespace {

using plan_json_internal::kFormatName;
using plan_json_internal::kFormatVersion;
using plan_json_internal::ojson;

// A name from one of the plan's lists; "#i" for an index outside it (never thrown away).
std::string NameOr(const std::vector<std::string>& names, int i) {
  if (i >= 0 && static_cast<size_t>(i) < names.size()) return names[i];
  return "#" + std::to_string(i);
}

ojson Vec3Json(const Vec3& v) { return ojson::array({v.x(), v.y(), v.z()}); }

ojson PoseJson(const Iso3& X) {
  const Pose p = FromIsometry(X);
  return ojson{{"xyz", Vec3Json(p.xyz)}, {"rpy", Vec3Json(p.rpy)}};
}

ojson KeyframeJson(const Plan& plan, const Keyframe& k) {
  ojson q = ojson::object();
  for (size_t r = 0; r < k.q.size(); ++r) {
    ojson values = ojson::array();
    for (Eigen::Index i = 0; i < k.q[r].size(); ++i) values.push_back(k.q[r][i]);
    q[NameOr(plan.robots, static_cast<int>(r))] = values;
  }
  ojson objects = ojson::array();
  for (const PlanObject& o : k.objects) {
    objects.push_back(ojson{
        {"name", NameOr(plan.nodes, o.node)}, {"X_WA", PoseJson(o.X_WA)}, {"resting", o.resting}});
  }
  return ojson{{"q", q}, {"objects", objects}};
}

// [[seconds, cost], ...]
ojson CostHistoryJson(const std::vector<std::pair<double, int>>& history) {
  ojson out = ojson::array();
  for (const auto& [t, cost] : history) out.push_back(ojson::array({t, cost}));
  return out;
}

ojson StatsJson(const PlanStats& s) {
  return ojson{{"solved", s.solved},
               {"cost", s.cost},
               {"t_init_s", s.t_init_s},
               {"planner", s.planner},
               {"objective", s.objective},
               {"makespan_est_s", s.makespan_est_s},
               {"seed", s.seed},
               {"t_grasp_s", s.t_grasp_s},
               {"t_bwd_s", s.t_bwd_s},
               {"t_lp_s", s.t_lp_s},
               {"t_fwd_s", s.t_fwd_s},
               {"t_ik_s", s.t_ik_s},
               {"wrench_mode", s.wrench_mode},
               {"force_scale", s.force_scale},
               {"grasps", s.grasps},
               {"expansions", s.expansions},
               {"validations", s.validations},
               {"validation_failures", s.validation_failures},
               {"lp_checks", s.lp_checks},
               {"lp_cache_hits", s.lp_cache_hits},
               {"lp_solves", s.lp_solves},
               {"lp_pivots", s.lp_pivots},
               {"ik_calls", s.ik_calls},
               {"collision_checks", s.collision_checks},
               {"milestones", s.milestones},
               {"backtracks", s.backtracks},
               {"widenings", s.widenings},
               {"out_of_memory", s.out_of_memory},
               {"first_cost", s.first_cost},
               {"t_opt_s", s.t_opt_s},
               {"cost_history", CostHistoryJson(s.cost_history)},
               {"motion", s.motion},
               {"t_kf_s", s.t_kf_s},
               {"t_mp_s", s.t_mp_s},
               {"t_retime_s", s.t_retime_s},
               {"makespan_s", s.makespan_s},
               {"makespan_sequential_s", s.makespan_sequential_s},
               {"motion_segments", s.motion_segments},
               {"motion_suspensions", s.motion_suspensions},
               {"task_plans", s.task_plans},
               {"failure", s.failure}};
}

ojson NumbersJson(const JointVector& v) {
  ojson out = ojson::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v[i]);
  return out;
}

// One robot's trajectory as columns: t, q, qd, opening_m (one entry per knot each).
ojson TrajectoryJson(const Plan& plan, const RobotTrajectory& tr) {
  ojson t = ojson::array(), q = ojson::array(), qd = ojson::array(), opening = ojson::array();
  for (const TrajectoryKnot& k : tr.knots) {
    t.push_back(k.t);
    q.push_back(NumbersJson(k.q));
    qd.push_back(NumbersJson(k.qd));
    opening.push_back(k.opening_m);
  }
  return ojson{{"robot", NameOr(plan.robots, tr.robot)},
               {"t", t},
               {"q", q},
               {"qd", qd},
               {"opening_m", opening}};
}

ojson SegmentJson(const Plan& plan, const MotionSegment& m) {
  ojson robots = ojson::array(), objects = ojson::array();
  for (int r : m.robots) robots.push_back(NameOr(plan.robots, r));
  for (int o : m.objects) objects.push_back(NameOr(plan.nodes, o));
  ojson j{{"kind", m.kind},     {"action", m.action},   {"robots", robots},
          {"objects", objects}, {"start_s", m.start_s}, {"end_s", m.end_s}};
  if (!m.wait.empty()) {
    j["wait"] = m.wait;
    j["wait_segment"] = m.wait_segment;
  }
  return j;
}

ojson ActionJson(const Plan& plan, const PlanAction& a, size_t index) {
  ojson robots = ojson::array(), objects = ojson::array(), grasps = ojson::array();
  for (int r : a.robots) robots.push_back(NameOr(plan.robots, r));
  for (int o : a.objects) objects.push_back(NameOr(plan.nodes, o));
  for (const PlanHold& h : a.grasps) {
    ojson g{{"robot", NameOr(plan.robots, h.robot)},
            {"subassembly", NameOr(plan.nodes, h.grasp.subassembly)},
            {"index", h.grasp.index},
            {"part", NameOr(plan.parts, h.grasp.part)},
            {"X_PG", PoseJson(h.grasp.X_PG)},
            {"width_m", h.grasp.width_m}};
    // Reduced grasps only: a full-pad grasp's file reads as it did before grasp types existed.
    if (h.grasp.type != GraspType::kFullPad) {
      g["grasp_type"] = std::string(ToString(h.grasp.type));
      const Vec3& s = h.grasp.torque_scale;
      g["torque_scale"] = ojson::array({s.x(), s.y(), s.z()});
    }
    grasps.push_back(std::move(g));
  }
  ojson j{{"index", index},
          {"type", std::string(ToString(a.type))},
          {"robots", robots},
          {"objects", objects},
          {"grasps", grasps}};
  if (a.placement) {
    j["placement"] = ojson{{"placement", a.placement->placement},
                           {"slot", a.placement->slot},
                           {"yaw", a.placement->yaw}};
  }
  j["milestone"] = a.milestone;
  if (a.start_s != -1.0) j["start_s"] = a.start_s;
  if (a.end_s != -1.0) j["end_s"] = a.end_s;
  j["keyframe"] = KeyframeJson(plan, a.keyframe);
  if (a.approach) j["approach"] = KeyframeJson(plan, *a.approach);
  if (!a.utilisation.empty()) {
    ojson u = ojson::object();
    for (const auto& [r, value] : a.utilisation) u[NameOr(plan.robots, r)] = value;
    j["utilisation"] = u;
  }
  j["description"] = DescribeAction(plan, a);
  return j;
}

ojson ContactJson(const Plan& plan, const PlanContact& c) {
  ojson normals = ojson::array();
  for (const auto& [n, area] : c.normals) {
    normals.push_back(ojson{{"n", Vec3Json(n)}, {"area_m2", area}});
  }
  return ojson{
      {"parts", {NameOr(plan.parts, c.part_a), NameOr(plan.parts, c.part_b)}},
      {"distance_m", c.distance_m},
      {"area_m2", c.area_m2},
      {"centroid", Vec3Json(c.centroid_A)},
      {"extent", ojson{{"min", Vec3Json(c.extent_min_A)}, {"max", Vec3Json(c.extent_max_A)}}},
      {"normals", normals}};
}

}  // namespace

std::string SerializePlan(const Plan& plan) {
  ojson doc;
  doc["format"] = kFormatName;
  doc["version"] = kFormatVersion;
  doc["project"] = plan.project;
  doc["robots"] = plan.robots;
  doc["parts"] = plan.parts;
  doc["nodes"] = plan.nodes;
  ojson milestones = ojson::array();
  for (int s : plan.milestone_steps) milestones.push_back(NameOr(plan.nodes, s));
  doc["milestones"] = milestones;
  doc["stats"] = StatsJson(plan.stats);
  doc["initial"] = KeyframeJson(plan, plan.initial);
  ojson actions = ojson::array();
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    actions.push_back(ActionJson(plan, plan.actions[i], i));
  }
  doc["actions"] = actions;
  if (!plan.trajectories.empty()) {
    ojson trajectories = ojson::array();
    for (const RobotTrajectory& tr : plan.trajectories)
      trajectories.push_back(TrajectoryJson(plan, tr));
    doc["trajectories"] = trajectories;
    ojson segments = ojson::array();
    for (const MotionSegment& m : plan.segments) segments.push_back(SegmentJson(plan, m));
    doc["segments"] = segments;
  }
  if (!plan.contacts.empty()) {
    ojson contacts = ojson::array();
    for (const PlanContact& c : plan.contacts) contacts.push_back(ContactJson(plan, c));
    doc["contacts"] = contacts;
  }
  // Keys keep the order written here (ordered_json); invalid UTF-8 in names is replaced, never
  // thrown.
  return doc.dump(2, ' ', false, ojson::error_handler_t::replace) + "\n";
}

Result<void> SavePlan(const Plan& plan, const std::filesystem::path& path) {
  return WriteFileAtomic(path, SerializePlan(plan));
}

}  // namespace wrap
