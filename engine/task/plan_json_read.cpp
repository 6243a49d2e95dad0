// Reading the plan file (task/plan_json.h): ParsePlan and ReadPlanFile. The document is parsed
// whole (duplicate keys refused), then read into a Plan by PlanReader, which checks every field
// and throws the first problem as a BadField (plan_json_internal.h) that ParsePlan turns into
// the Error.
#include <algorithm>
#include <climits>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "core/file_io.h"
#include "task/plan_json.h"
#include "task/plan_json_internal.h"

namespace wrap::plan_json_internal {

namespace {

// The plan's name lists as lookups, and the joint-vector size of each robot (from `initial`).
class PlanReader {
 public:
  explicit PlanReader(Plan& plan) : plan_(plan) {}

  void IndexNames() {
    for (size_t i = 0; i < plan_.robots.size(); ++i) robots_[plan_.robots[i]] = int(i);
    for (size_t i = 0; i < plan_.parts.size(); ++i) parts_[plan_.parts[i]] = int(i);
    for (size_t i = 0; i < plan_.nodes.size(); ++i) nodes_[plan_.nodes[i]] = int(i);
  }

  int RobotValue(const json& j, const std::string& path) const {
    return Lookup(robots_, StringValue(j, path), path, "robot", "robots");
  }
  int NodeValue(const json& j, const std::string& path) const {
    return Lookup(nodes_, StringValue(j, path), path, "node", "nodes");
  }
  int PartValue(const json& j, const std::string& path) const {
    return Lookup(parts_, StringValue(j, path), path, "part", "parts");
  }

  Keyframe ReadKeyframe(const json& obj, const std::string& path, std::string_view key) {
    const std::string at = Join(path, key);
    const json& j = ExpectObject(Member(obj, path, key), at);
    CheckKeys(j, at, {"q", "objects"});
    Keyframe k;
    const std::string q_at = Join(at, "q");
    const json& q = ExpectObject(Member(j, at, "q"), q_at);
    for (const auto& [name, value] : q.items()) {
      if (!robots_.contains(name)) Bad(Join(q_at, name), "unknown robot (not in \"robots\")");
    }
    const bool first = dof_.empty();
    for (size_t r = 0; r < plan_.robots.size(); ++r) {
      const std::string& name = plan_.robots[r];
      const std::string r_at = Join(q_at, name);
      const json* values = Find(q, name);
      if (!values) Bad(r_at, "joint values of robot '" + name + "' are missing");
      if (!values->is_array() || values->empty() || values->size() > size_t(kMaxDof)) {
        Bad(r_at, "expected an array of 1 to " + std::to_string(kMaxDof) + " numbers, found " +
                      (values->is_array() ? "an array of " + std::to_string(values->size())
                                          : TypeName(*values)));
      }
      if (first) dof_.push_back(values->size());
      if (values->size() != dof_[r]) {
        Bad(r_at, "expected " + std::to_string(dof_[r]) + " numbers (as in initial.q." + name +
                      "), found " + std::to_string(values->size()));
      }
      JointVector v(static_cast<Eigen::Index>(values->size()));
      for (size_t i = 0; i < values->size(); ++i) {
        v[static_cast<Eigen::Index>(i)] = NumberValue((*values)[i], Index(r_at, i));
      }
      k.q.push_back(v);
    }
    const std::string o_at = Join(at, "objects");
    const json& objects = ExpectArray(Member(j, at, "objects"), o_at);
    std::set<int> seen;
    for (size_t i = 0; i < objects.size(); ++i) {
      const std::string e_at = Index(o_at, i);
      const json& e = ExpectObject(objects[i], e_at);
      CheckKeys(e, e_at, {"name", "X_WA", "resting"});
      PlanObject o;
      o.node = NodeValue(Member(e, e_at, "name"), Join(e_at, "name"));
      if (!seen.insert(o.node).second) {
        Bad(Join(e_at, "name"), "object '" + plan_.nodes[o.node] + "' is listed twice");
      }
      o.X_WA = PoseValue(e, e_at, "X_WA");
      o.resting = Bool(e, e_at, "resting");
      k.objects.push_back(o);
    }
    return k;
  }

  PlanAction ReadAction(const json& j, const std::string& at, size_t index) {
    ExpectObject(j, at);
    CheckKeys(j, at,
              {"index", "type", "robots", "objects", "grasps", "placement", "milestone", "start_s",
               "end_s", "keyframe", "approach", "utilisation", "description"});
    PlanAction a;
    const int i = Int(j, at, "index");
    if (i != static_cast<int>(index)) {
      Bad(Join(at, "index"), "expected " + std::to_string(index) + " (the action's position), " +
                                 "found " + std::to_string(i));
    }
    const std::string type = String(j, at, "type");
    const auto t = ActionTypeFromString(type);
    if (!t) {
      Bad(Join(at, "type"), "unknown action type '" + type +
                                "' (known: pick, place, handover, add_grasp, release, assemble)");
    }
    a.type = *t;

    const std::string r_at = Join(at, "robots");
    const json& robots = ExpectArray(Member(j, at, "robots"), r_at);
    for (size_t k = 0; k < robots.size(); ++k) {
      const int r = RobotValue(robots[k], Index(r_at, k));
      for (int prev : a.robots) {
        if (prev == r) Bad(Index(r_at, k), "robot '" + plan_.robots[r] + "' is listed twice");
      }
      a.robots.push_back(r);
    }
    const std::string o_at = Join(at, "objects");
    const json& objects = ExpectArray(Member(j, at, "objects"), o_at);
    for (size_t k = 0; k < objects.size(); ++k) {
      const int o = NodeValue(objects[k], Index(o_at, k));
      for (int prev : a.objects) {
        if (prev == o) Bad(Index(o_at, k), "object '" + plan_.nodes[o] + "' is listed twice");
      }
      a.objects.push_back(o);
    }
    CheckArity(a, type, at);

    const std::string g_at = Join(at, "grasps");
    const json& grasps = ExpectArray(Member(j, at, "grasps"), g_at);
    if (grasps.size() != a.robots.size()) {
      Bad(g_at, "expected one grasp per robot (" + std::to_string(a.robots.size()) + "), found " +
                    std::to_string(grasps.size()));
    }
    for (size_t k = 0; k < grasps.size(); ++k) {
      a.grasps.push_back(ReadHold(grasps[k], Index(g_at, k), a.robots[k]));
    }

    if (const json* p = Find(j, "placement")) {
      const std::string p_at = Join(at, "placement");
      if (a.type != ActionType::kPlace) Bad(p_at, "only a place action has a placement");
      ExpectObject(*p, p_at);
      CheckKeys(*p, p_at, {"placement", "slot", "yaw"});
      a.placement = PlanPlacement{Int(*p, p_at, "placement", 0), Int(*p, p_at, "slot", 0),
                                  Int(*p, p_at, "yaw", 0)};
    }
    if (Find(j, "milestone")) {
      a.milestone = Int(j, at, "milestone", -1, static_cast<int>(plan_.milestone_steps.size()) - 1);
    }
    if (Find(j, "start_s")) a.start_s = NonNegative(j, at, "start_s");
    if (Find(j, "end_s")) a.end_s = NonNegative(j, at, "end_s");
    if (a.start_s >= 0.0 && a.end_s >= 0.0 && a.end_s < a.start_s) {
      Bad(Join(at, "end_s"), "ends before it starts (start_s " + std::to_string(a.start_s) + ")");
    }
    a.keyframe = ReadKeyframe(j, at, "keyframe");
    if (Find(j, "approach")) {
      if (a.type != ActionType::kAssemble) {
        Bad(Join(at, "approach"), "only an assemble action has an approach keyframe");
      }
      a.approach = ReadKeyframe(j, at, "approach");
    }
    if (const json* u = Find(j, "utilisation")) {
      const std::string u_at = Join(at, "utilisation");
      ExpectObject(*u, u_at);
      for (const auto& [name, value] : u->items()) {
        const std::string v_at = Join(u_at, name);
        const auto it = std::find(plan_.robots.begin(), plan_.robots.end(), name);
        if (it == plan_.robots.end()) Bad(v_at, "no robot '" + name + "' in the plan");
        if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0) {
          Bad(v_at, "expected a non-negative number (a gripper's utilisation)");
        }
        a.utilisation[static_cast<int>(it - plan_.robots.begin())] = value.get<double>();
      }
    }
    if (const json* d = Find(j, "description")) StringValue(*d, Join(at, "description"));
    return a;
  }

 private:
  static int Lookup(const std::map<std::string, int>& names, const std::string& name,
                    const std::string& path, const char* what, const char* list) {
    auto it = names.find(name);
    if (it == names.end()) {
      Bad(path, "unknown " + std::string(what) + " '" + name + "' (not in \"" + list + "\")");
    }
    return it->second;
  }

  // The robot and object counts each action type has (plan.h, PlanAction).
  static void CheckArity(const PlanAction& a, const std::string& type, const std::string& at) {
    const std::string an = std::string(type[0] == 'a' ? "an " : "a ") + type;
    size_t robots = 1, objects = 1;
    if (a.type == ActionType::kHandover) robots = 2;
    if (a.type == ActionType::kAssemble) objects = 3;
    if (a.type == ActionType::kAssemble ? a.robots.empty() : a.robots.size() != robots) {
      Bad(Join(at, "robots"), an + " action has " +
                                  (a.type == ActionType::kAssemble ? std::string("at least 1")
                                                                   : std::to_string(robots)) +
                                  " robot(s), found " + std::to_string(a.robots.size()));
    }
    if (a.objects.size() != objects) {
      Bad(Join(at, "objects"), an + " action has " + std::to_string(objects) + " object(s)" +
                                   (objects == 3 ? " (moved, base, result)" : "") + ", found " +
                                   std::to_string(a.objects.size()));
    }
  }

  PlanHold ReadHold(const json& j, const std::string& at, int robot) const {
    ExpectObject(j, at);
    CheckKeys(
        j, at,
        {"robot", "subassembly", "index", "part", "X_PG", "width_m", "grasp_type", "torque_scale"});
    PlanHold h;
    h.robot = RobotValue(Member(j, at, "robot"), Join(at, "robot"));
    if (h.robot != robot) {
      Bad(Join(at, "robot"), "expected '" + plan_.robots[robot] +
                                 "' (grasps follow the action's robots), found '" +
                                 plan_.robots[h.robot] + "'");
    }
    h.grasp.subassembly = NodeValue(Member(j, at, "subassembly"), Join(at, "subassembly"));
    h.grasp.index = Int(j, at, "index", 0);
    h.grasp.part = PartValue(Member(j, at, "part"), Join(at, "part"));
    h.grasp.X_PG = PoseValue(j, at, "X_PG");
    h.grasp.width_m = NonNegative(j, at, "width_m");
    if (Find(j, "grasp_type")) {
      const std::string type = String(j, at, "grasp_type");
      bool known = false;
      for (int t = 0; t < kGraspTypes; ++t) {
        if (type == ToString(static_cast<GraspType>(t))) {
          h.grasp.type = static_cast<GraspType>(t);
          known = true;
        }
      }
      if (!known) Bad(Join(at, "grasp_type"), "expected full_pad, partial_pad or fingertip");
    }
    if (Find(j, "torque_scale")) {
      h.grasp.torque_scale = Vector3(j, at, "torque_scale");
      for (int i = 0; i < 3; ++i) {
        if (!(h.grasp.torque_scale[i] >= 0.0 && h.grasp.torque_scale[i] <= 1.0)) {
          Bad(Join(at, "torque_scale"), "expected fractions in [0, 1]");
        }
      }
    }
    return h;
  }

  // The motion part of a plan.
 public:
  RobotTrajectory ReadTrajectory(const json& e, const std::string& at) {
    ExpectObject(e, at);
    CheckKeys(e, at, {"robot", "t", "q", "qd", "opening_m"});
    RobotTrajectory tr;
    tr.robot = RobotValue(Member(e, at, "robot"), Join(at, "robot"));
    const size_t dof = tr.robot < static_cast<int>(dof_.size()) ? dof_[tr.robot] : 0;
    const json& t = ExpectArray(Member(e, at, "t"), Join(at, "t"));
    const json& q = ExpectArray(Member(e, at, "q"), Join(at, "q"));
    const json& qd = ExpectArray(Member(e, at, "qd"), Join(at, "qd"));
    const json& opening = ExpectArray(Member(e, at, "opening_m"), Join(at, "opening_m"));
    if (t.empty()) Bad(Join(at, "t"), "expected at least one knot");
    for (const char* key : {"q", "qd", "opening_m"}) {
      if (Member(e, at, key).size() != t.size()) {
        Bad(Join(at, key), "expected " + std::to_string(t.size()) + " entries (one per time in " +
                               "\"t\"), found " + std::to_string(Member(e, at, key).size()));
      }
    }
    auto vector = [&](const json& values, const std::string& path) {
      if (!values.is_array() || values.size() != dof) {
        Bad(path, "expected an array of " + std::to_string(dof) + " numbers (the robot's joints)");
      }
      JointVector v(static_cast<Eigen::Index>(dof));
      for (size_t k = 0; k < dof; ++k)
        v[static_cast<Eigen::Index>(k)] = NumberValue(values[k], Index(path, k));
      return v;
    };
    for (size_t k = 0; k < t.size(); ++k) {
      TrajectoryKnot knot;
      knot.t = NumberValue(t[k], Index(Join(at, "t"), k));
      if (k == 0 && knot.t != 0.0) Bad(Index(Join(at, "t"), k), "the first knot must be at 0 s");
      if (k > 0 && !(knot.t >= tr.knots.back().t)) {
        Bad(Index(Join(at, "t"), k),
            "times must not decrease (previous " + std::to_string(tr.knots.back().t) + ")");
      }
      knot.q = vector(q[k], Index(Join(at, "q"), k));
      knot.qd = vector(qd[k], Index(Join(at, "qd"), k));
      knot.opening_m = NumberValue(opening[k], Index(Join(at, "opening_m"), k));
      tr.knots.push_back(std::move(knot));
    }
    return tr;
  }
  // A segment of `count` (its wait names one of them).
  MotionSegment ReadSegment(const json& e, const std::string& at, size_t count) {
    ExpectObject(e, at);
    CheckKeys(e, at,
              {"kind", "action", "robots", "objects", "start_s", "end_s", "wait", "wait_segment"});
    MotionSegment m;
    m.kind = String(e, at, "kind");
    m.action = Int(e, at, "action", -1, static_cast<int>(plan_.actions.size()) - 1);
    const json& robots = ExpectArray(Member(e, at, "robots"), Join(at, "robots"));
    for (size_t k = 0; k < robots.size(); ++k) {
      m.robots.push_back(RobotValue(robots[k], Index(Join(at, "robots"), k)));
    }
    const json& objects = ExpectArray(Member(e, at, "objects"), Join(at, "objects"));
    for (size_t k = 0; k < objects.size(); ++k) {
      m.objects.push_back(NodeValue(objects[k], Index(Join(at, "objects"), k)));
    }
    m.start_s = NonNegative(e, at, "start_s");
    m.end_s = NonNegative(e, at, "end_s");
    if (m.end_s < m.start_s) Bad(Join(at, "end_s"), "ends before it starts");
    // Absent in plans written before the schedule recorded its waits.
    if (Find(e, "wait")) {
      m.wait = String(e, at, "wait");
      if (m.wait != "none" && m.wait != "robot" && m.wait != "object" && m.wait != "collision") {
        Bad(Join(at, "wait"),
            "unknown wait '" + m.wait + "' (known: none, robot, object, collision)");
      }
      m.wait_segment = Int(e, at, "wait_segment", -1, static_cast<int>(count) - 1);
    }
    return m;
  }

  PlanContact ReadContact(const json& e, const std::string& at) const {
    ExpectObject(e, at);
    CheckKeys(e, at, {"parts", "distance_m", "area_m2", "centroid", "extent", "normals"});
    PlanContact c;
    const json& parts = ExpectArray(Member(e, at, "parts"), Join(at, "parts"));
    if (parts.size() != 2) Bad(Join(at, "parts"), "expected two part names");
    c.part_a = PartValue(parts[0], Index(Join(at, "parts"), 0));
    c.part_b = PartValue(parts[1], Index(Join(at, "parts"), 1));
    c.distance_m = NonNegative(e, at, "distance_m");
    c.area_m2 = NonNegative(e, at, "area_m2");
    c.centroid_A = Vector3(e, at, "centroid");
    const std::string ext = Join(at, "extent");
    const json& extent = ExpectObject(Member(e, at, "extent"), ext);
    CheckKeys(extent, ext, {"min", "max"});
    c.extent_min_A = Vector3(extent, ext, "min");
    c.extent_max_A = Vector3(extent, ext, "max");
    const json& normals = ExpectArray(Member(e, at, "normals"), Join(at, "normals"));
    for (size_t k = 0; k < normals.size(); ++k) {
      const std::string n = Index(Join(at, "normals"), k);
      ExpectObject(normals[k], n);
      CheckKeys(normals[k], n, {"n", "area_m2"});
      c.normals.emplace_back(Vector3(normals[k], n, "n"), NonNegative(normals[k], n, "area_m2"));
    }
    return c;
  }

 private:
  Plan& plan_;
  std::map<std::string, int> robots_, parts_, nodes_;
  std::vector<size_t> dof_;  // Joint-vector size per robot, from the first keyframe read.
};

PlanStats ReadStats(const json& root, const std::string& at) {
  const json& j = ExpectObject(Member(root, "", "stats"), at);
  CheckKeys(j, at,
            {"solved",
             "cost",
             "t_init_s",
             "planner",
             "objective",
             "makespan_est_s",
             "seed",
             "t_grasp_s",
             "t_bwd_s",
             "t_lp_s",
             "t_fwd_s",
             "t_ik_s",
             "wrench_mode",
             "force_scale",
             "grasps",
             "expansions",
             "validations",
             "validation_failures",
             "lp_checks",
             "lp_cache_hits",
             "lp_solves",
             "lp_pivots",
             "ik_calls",
             "collision_checks",
             "milestones",
             "backtracks",
             "widenings",
             "out_of_memory",
             "first_cost",
             "t_opt_s",
             "cost_history",
             "failure",
             "motion",
             "t_kf_s",
             "t_mp_s",
             "t_retime_s",
             "makespan_s",
             "makespan_sequential_s",
             "motion_segments",
             "motion_suspensions",
             "task_plans"});
  PlanStats s;
  // Required: what DESIGN.md promises every plan file holds.
  s.solved = Bool(j, at, "solved");
  s.cost = Int(j, at, "cost", 0);
  s.t_init_s = NonNegative(j, at, "t_init_s");
  s.planner = String(j, at, "planner");
  {
    const json& seed = Member(j, at, "seed");
    if (!seed.is_number_integer() || (!seed.is_number_unsigned() && seed.get<long long>() < 0)) {
      Bad(Join(at, "seed"), "expected an integer >= 0, found " + TypeName(seed));
    }
    s.seed = seed.get<std::uint64_t>();
  }
  // Optional: the breakdown and counters.
  auto time = [&](const char* key, double& out) {
    if (Find(j, key)) out = NonNegative(j, at, key);
  };
  auto count = [&](const char* key, long long& out) {
    if (Find(j, key)) out = Count(j, at, key);
  };
  auto small = [&](const char* key, int& out) {
    if (Find(j, key)) out = Int(j, at, key, 0);
  };
  time("t_grasp_s", s.t_grasp_s);
  time("t_bwd_s", s.t_bwd_s);
  time("t_lp_s", s.t_lp_s);
  time("t_fwd_s", s.t_fwd_s);
  time("t_ik_s", s.t_ik_s);
  if (Find(j, "objective")) s.objective = String(j, at, "objective");
  time("makespan_est_s", s.makespan_est_s);
  if (Find(j, "wrench_mode")) s.wrench_mode = String(j, at, "wrench_mode");
  if (Find(j, "force_scale")) s.force_scale = Number(j, at, "force_scale");
  small("grasps", s.grasps);
  count("expansions", s.expansions);
  count("validations", s.validations);
  count("validation_failures", s.validation_failures);
  count("lp_checks", s.lp_checks);
  count("lp_cache_hits", s.lp_cache_hits);
  count("lp_solves", s.lp_solves);
  count("lp_pivots", s.lp_pivots);
  count("ik_calls", s.ik_calls);
  count("collision_checks", s.collision_checks);
  small("milestones", s.milestones);
  small("backtracks", s.backtracks);
  small("widenings", s.widenings);
  if (Find(j, "out_of_memory")) s.out_of_memory = Bool(j, at, "out_of_memory");
  small("first_cost", s.first_cost);
  time("t_opt_s", s.t_opt_s);
  if (const json* history = Find(j, "cost_history")) {
    const std::string path = Join(at, "cost_history");
    ExpectArray(*history, path);
    for (size_t i = 0; i < history->size(); ++i) {
      const std::string item = path + "[" + std::to_string(i) + "]";
      const json& e = ExpectArray((*history)[i], item);
      if (e.size() != 2) Bad(item, "expected [seconds, cost]");
      const double t = NumberValue(e[0], item + "[0]");
      if (t < 0.0) Bad(item + "[0]", "expected seconds >= 0");
      s.cost_history.push_back({t, static_cast<int>(IntegerValue(e[1], item + "[1]", 0, INT_MAX))});
    }
  }
  if (Find(j, "failure")) s.failure = String(j, at, "failure");
  if (Find(j, "motion")) s.motion = Bool(j, at, "motion");
  time("t_kf_s", s.t_kf_s);
  time("t_mp_s", s.t_mp_s);
  time("t_retime_s", s.t_retime_s);
  time("makespan_s", s.makespan_s);
  time("makespan_sequential_s", s.makespan_sequential_s);
  small("motion_segments", s.motion_segments);
  small("motion_suspensions", s.motion_suspensions);
  small("task_plans", s.task_plans);
  return s;
}

Plan ReadPlan(const json& root) {
  if (!root.is_object())
    Bad("", "expected a JSON object at the top level, found " + TypeName(root));
  CheckKeys(root, "",
            {"format", "version", "project", "robots", "parts", "nodes", "milestones", "stats",
             "initial", "actions", "trajectories", "segments", "contacts"});
  const std::string format = String(root, "", "format");
  if (format != kFormatName) {
    Bad("format", "expected \"" + std::string(kFormatName) + "\", found \"" + format + "\"");
  }
  const json& version = Member(root, "", "version");
  if (!version.is_number_integer() || version.get<long long>() != kFormatVersion) {
    // Not dump(): the value may be nested arbitrarily deep.
    Bad("version", "expected " + std::to_string(kFormatVersion) + " (the version this build " +
                       "reads), found " +
                       (version.is_number_integer() ? std::to_string(version.get<long long>())
                                                    : TypeName(version)));
  }

  Plan plan;
  plan.project = String(root, "", "project");
  plan.robots = Names(root, "", "robots", false);
  plan.parts = Names(root, "", "parts", false);
  plan.nodes = Names(root, "", "nodes", false);
  if (plan.nodes.size() < plan.parts.size()) {
    Bad("nodes", "expected the parts first, then the steps: " + std::to_string(plan.parts.size()) +
                     " parts but only " + std::to_string(plan.nodes.size()) + " nodes");
  }
  for (size_t i = 0; i < plan.parts.size(); ++i) {
    if (plan.nodes[i] != plan.parts[i]) {
      Bad(Index("nodes", i), "expected part '" + plan.parts[i] + "' (nodes list the parts " +
                                 "first, in \"parts\" order), found '" + plan.nodes[i] + "'");
    }
  }
  PlanReader reader(plan);
  reader.IndexNames();
  const json& milestones = ExpectArray(Member(root, "", "milestones"), "milestones");
  for (size_t i = 0; i < milestones.size(); ++i) {
    const std::string at = Index("milestones", i);
    const int node = reader.NodeValue(milestones[i], at);
    if (node < static_cast<int>(plan.parts.size())) {
      Bad(at, "'" + plan.nodes[node] + "' is a part, not an assembly step");
    }
    for (int prev : plan.milestone_steps) {
      if (prev == node) Bad(at, "step '" + plan.nodes[node] + "' is listed twice");
    }
    plan.milestone_steps.push_back(node);
  }
  plan.stats = ReadStats(root, "stats");
  plan.initial = reader.ReadKeyframe(root, "", "initial");
  const json& actions = ExpectArray(Member(root, "", "actions"), "actions");
  for (size_t i = 0; i < actions.size(); ++i) {
    plan.actions.push_back(reader.ReadAction(actions[i], Index("actions", i), i));
  }
  if (const json* trajectories = Find(root, "trajectories")) {
    ExpectArray(*trajectories, "trajectories");
    std::set<int> seen;
    for (size_t i = 0; i < trajectories->size(); ++i) {
      RobotTrajectory tr = reader.ReadTrajectory((*trajectories)[i], Index("trajectories", i));
      if (!seen.insert(tr.robot).second) {
        Bad(Join(Index("trajectories", i), "robot"),
            "robot '" + plan.robots[tr.robot] + "' has two trajectories");
      }
      plan.trajectories.push_back(std::move(tr));
    }
    if (!plan.trajectories.empty() && plan.trajectories.size() != plan.robots.size()) {
      Bad("trajectories", "expected one trajectory per robot (" +
                              std::to_string(plan.robots.size()) + "), found " +
                              std::to_string(plan.trajectories.size()));
    }
    std::sort(plan.trajectories.begin(), plan.trajectories.end(),
              [](const RobotTrajectory& a, const RobotTrajectory& b) { return a.robot < b.robot; });
  }
  if (const json* segments = Find(root, "segments")) {
    ExpectArray(*segments, "segments");
    for (size_t i = 0; i < segments->size(); ++i) {
      plan.segments.push_back(
          reader.ReadSegment((*segments)[i], Index("segments", i), segments->size()));
    }
  }
  if (const json* contacts = Find(root, "contacts")) {
    ExpectArray(*contacts, "contacts");
    for (size_t i = 0; i < contacts->size(); ++i) {
      plan.contacts.push_back(reader.ReadContact((*contacts)[i], Index("contacts", i)));
    }
  }
  return plan;
}

// Strips nlohmann's "[json.exception.parse_error.101] " prefix.
std::string CleanJsonMessage(const std::string& what) {
  const auto pos = what.find("] ");
  return pos == std::string::npos ? what : what.substr(pos + 2);
}

}  // namespace

}  // namespace wrap::plan_json_internal

namespace wrap {

Result<Plan> ParsePlan(std::string_view text, const std::string& origin) {
  using plan_json_internal::BadField;
  using plan_json_internal::json;
  // Duplicate keys would silently keep one value: refuse them while parsing.
  std::vector<std::set<std::string>> keys;
  std::string duplicate;
  const json::parser_callback_t on_event = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) {
      keys.emplace_back();
    } else if (event == json::parse_event_t::object_end) {
      if (!keys.empty()) keys.pop_back();
    } else if (event == json::parse_event_t::key && !keys.empty() && duplicate.empty()) {
      const std::string key = parsed.get<std::string>();
      if (!keys.back().insert(key).second) duplicate = key;
    }
    return true;
  };
  json root;
  try {
    root = json::parse(text.begin(), text.end(), on_event);
  } catch (const json::exception& e) {
    return Fail(ErrorCode::kInvalidInput,
                origin + ": malformed JSON: " + plan_json_internal::CleanJsonMessage(e.what()));
  } catch (const std::exception& e) {
    return Fail(ErrorCode::kInvalidInput, origin + ": malformed JSON: " + e.what());
  }
  if (!duplicate.empty()) {
    return Fail(ErrorCode::kInvalidInput,
                origin + ": duplicate key \"" + duplicate + "\" in one object");
  }
  try {
    return plan_json_internal::ReadPlan(root);
  } catch (const BadField& e) {
    return Fail(ErrorCode::kInvalidInput,
                origin + ": " + (e.path.empty() ? "" : e.path + ": ") + e.message);
  } catch (const std::exception& e) {
    return Fail(ErrorCode::kInvalidInput, origin + ": unreadable plan: " + e.what());
  }
}

Result<Plan> ReadPlanFile(const std::filesystem::path& path) {
  auto text = ReadFile(path);
  if (!text) return std::unexpected(text.error());
  return ParsePlan(*text, path.string());
}

}  // namespace wrap
