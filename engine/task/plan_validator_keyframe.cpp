// The plan validator's keyframe checks: what one keyframe must show given the replayed state
// before its action (the object list and the poses of objects that may not move, resting objects
// on the table top, joint limits and robots that may not move, FK of every grasp, collisions and
// the robots' clearance in the validator's own cells), the insertion path of an assemble, and the
// wrench gates re-solved from scratch. The replay (plan_validator_replay.cpp) says per action
// which checks a keyframe gets (a Moment).
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include "geometry/convex_hull.h"
#include "grasp/grasp.h"
#include "mating/insertion.h"
#include "task/plan_validator_internal.h"

namespace wrap::plan_validator_internal {

namespace {

// The part of the convex counter-clockwise polygon `poly` inside the rectangle [lo, hi]
// (Sutherland-Hodgman, one rectangle side at a time).
std::vector<Eigen::Vector2d> ClipToRectangle(std::vector<Eigen::Vector2d> poly,
                                             const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  for (int side = 0; side < 4 && !poly.empty(); ++side) {
    const int axis = side % 2;
    const double bound = side < 2 ? lo[axis] : hi[axis];
    const double sign = side < 2 ? 1.0 : -1.0;  // inside: sign * (x - bound) >= 0
    auto inside = [&](const Eigen::Vector2d& v) { return sign * (v[axis] - bound) >= 0.0; };
    std::vector<Eigen::Vector2d> out;
    for (size_t k = 0; k < poly.size(); ++k) {
      const Eigen::Vector2d& a = poly[k];
      const Eigen::Vector2d& b = poly[(k + 1) % poly.size()];
      if (inside(a)) out.push_back(a);
      if (inside(a) != inside(b)) {
        const double t = (bound - a[axis]) / (b[axis] - a[axis]);
        out.push_back(a + t * (b - a));
      }
    }
    poly = std::move(out);
  }
  return poly;
}

}  // namespace

std::map<int, Iso3> Validator::CheckKeyframe(int index, const std::string& label,
                                             const Keyframe& kf, const Moment& m) {
  ++out_.keyframes;
  std::map<int, Iso3> X_WA = CheckObjects(index, label, kf, m);
  CheckJoints(index, label, kf, m);
  const std::vector<std::pair<int, PlanHold>> holds = CheckGrasps(index, label, kf, m, X_WA);
  if (options_.check_collisions) CheckCollisions(index, label, kf, m, X_WA, holds);
  return X_WA;
}

std::map<int, Iso3> Validator::CheckObjects(int index, const std::string& label, const Keyframe& kf,
                                            const Moment& m) {
  const bool initial = index < 0;
  // The object list: exactly the objects that exist at this moment.
  std::map<int, const PlanObject*> listed;
  for (const PlanObject& o : kf.objects) {
    if (!listed.emplace(o.node, &o).second) {
      Issue(index, "pose", label + "the keyframe lists " + Quote(NodeName(o.node)) + " twice");
    } else if (!objects_.count(o.node)) {
      Issue(index, "pose",
            label + "the keyframe lists " + Quote(NodeName(o.node)) +
                ", which does not exist as an object at this moment");
    }
  }
  std::map<int, Iso3> X_WA;
  for (const auto& [node, state] : objects_) {
    auto it = listed.find(node);
    if (it == listed.end()) {
      Issue(index, "pose",
            label + "the keyframe does not list the object " + Quote(NodeName(node)));
      X_WA[node] = state.X_WA;
      continue;
    }
    const PlanObject& o = *it->second;
    X_WA[node] = o.X_WA;
    if (auto req = m.required.find(node); req != m.required.end()) {
      const PoseError e = Difference(req->second.first, o.X_WA);
      if (e.position_m > options_.position_tolerance_m ||
          e.rotation_rad > options_.rotation_tolerance_rad) {
        Issue(index, "pose",
              label + Quote(NodeName(node)) + " is " + Mm(e.position_m) + " / " +
                  Deg(e.rotation_rad) + " away from " + req->second.second);
      }
    } else if (!m.moving.count(node)) {
      const PoseError e = Difference(state.X_WA, o.X_WA);
      if (e.position_m > options_.position_tolerance_m ||
          e.rotation_rad > options_.rotation_tolerance_rad) {
        Issue(index, "pose",
              label + Quote(NodeName(node)) + " is " + Mm(e.position_m) + " / " +
                  Deg(e.rotation_rad) +
                  (initial ? " away from its initial pose in the project"
                           : " away from where it was, but the action "
                             "may not move it"));
      }
      // Keep the state's pose: small drifts must not add up over the plan.
      X_WA[node] = state.X_WA;
    }
    if (!m.acted.count(node) && o.resting != state.resting) {
      Issue(index, "pose",
            label + Quote(NodeName(node)) + " is marked " + (o.resting ? "resting" : "in the air") +
                ", but it is " + (state.resting ? "resting" : "in the air"));
    }
  }
  for (int node : m.rest_check) {
    if (X_WA.count(node)) CheckRest(index, label, node, X_WA.at(node));
  }
  return X_WA;
}

void Validator::CheckJoints(int index, const std::string& label, const Keyframe& kf,
                            const Moment& m) {
  const bool initial = index < 0;
  const int n_robots = static_cast<int>(robots_.size());
  for (int r = 0; r < n_robots; ++r) {
    const RobotModel& robot = robots_[r];
    const JointVector& q = kf.q[r];
    if (!WithinLimits(robot.chain, q, 1e-9)) {
      for (int j = 0; j < robot.chain.dof(); ++j) {
        const Joint& joint = robot.chain.joints[j];
        if (q[j] < joint.lower - 1e-9 || q[j] > joint.upper + 1e-9) {
          Issue(index, "joint_limits",
                label + "robot " + Quote(robot.name) + " joint " + Quote(joint.name) + " at " +
                    Num(q[j]) + " is outside [" + Num(joint.lower) + ", " + Num(joint.upper) + "]");
        }
      }
    }
    if (initial) continue;
    const double moved = JointDistanceMax(robot.chain, q, q_[r], false);
    if (moved <= options_.joint_tolerance) continue;
    const int held = holding_[r];
    if (held >= 0) {
      if (!m.moving.count(held)) {
        Issue(index, "joints",
              label + "robot " + Quote(robot.name) + " holds " + Quote(NodeName(held)) +
                  ", which does not move, yet its joints changed by up to " + Num(moved));
      }
      continue;
    }
    const bool grasps_now = std::any_of(m.new_holds.begin(), m.new_holds.end(),
                                        [&](const auto& nh) { return nh.second.robot == r; });
    const bool at_home =
        JointDistanceMax(robot.chain, q, plan_.initial.q[r], false) <= options_.joint_tolerance;
    if (!grasps_now && !may_move_[r] && !at_home) {
      Issue(index, "joints",
            label + "robot " + Quote(robot.name) +
                " is free and does not act, yet its joints changed by up to " + Num(moved) +
                " and it is not at its home configuration");
    }
  }
}

std::vector<std::pair<int, PlanHold>> Validator::CheckGrasps(int index, const std::string& label,
                                                             const Keyframe& kf, const Moment& m,
                                                             const std::map<int, Iso3>& X_WA) {
  std::vector<std::pair<int, PlanHold>> holds;
  for (const auto& [node, state] : objects_) {
    for (const PlanHold& h : state.holders) holds.emplace_back(node, h);
  }
  holds.insert(holds.end(), m.new_holds.begin(), m.new_holds.end());
  for (const auto& [node, h] : holds) {
    if (!NodeHasPart(node, h.grasp.part)) continue;  // reported as a precondition
    const RobotModel& robot = robots_[h.robot];
    const Iso3 X_WG = X_WA.at(node) * X_AP_[h.grasp.part] * h.grasp.X_PG;
    const Iso3 X_WT = TcpPose(robot.chain, robot.X_WB, kf.q[h.robot], robot.ee.X_FT);
    const PoseError e = Difference(X_WG, X_WT);
    if (e.position_m > options_.position_tolerance_m ||
        e.rotation_rad > options_.rotation_tolerance_rad) {
      const std::string of = node == h.grasp.part ? "" : " of " + Quote(NodeName(node));
      Issue(index, "fk",
            label + "robot " + Quote(robot.name) + ": the TCP is " + Mm(e.position_m) + " / " +
                Deg(e.rotation_rad) + " away from its grasp on " + Quote(PartName(h.grasp.part)) +
                of + " (allowed " + Mm(options_.position_tolerance_m) + " / " +
                Deg(options_.rotation_tolerance_rad) + ")");
    }
  }
  return holds;
}

std::vector<Eigen::Vector2d> Validator::SupportPolygon(int part, const Iso3& X_WP) const {
  const Table& t = project_.table;
  std::vector<Eigen::Vector2d> xy;
  for (const Vec3& v : hull_P_[part]) {
    const Vec3 p_W = X_WP * v;
    if (std::abs(p_W.z() - t.height) <= options_.table_tolerance_m) xy.push_back(p_W.head<2>());
  }
  if (xy.empty()) return {};
  std::vector<Eigen::Vector2d> hull;
  for (int k : ConvexHull2d(xy)) hull.push_back(xy[k]);
  const Eigen::Vector2d half = 0.5 * t.size.head<2>();
  return ClipToRectangle(std::move(hull), t.center_xy.head<2>() - half,
                         t.center_xy.head<2>() + half);
}

void Validator::CheckRest(int index, const std::string& label, int node, const Iso3& X_WA) {
  const Table& t = project_.table;
  double lowest = std::numeric_limits<double>::infinity();
  bool supported = false;
  for (int p : tree_.nodes[node].parts) {
    const Iso3 X_WP = X_WA * X_AP_[p];
    for (const Vec3& v : hull_P_[p]) lowest = std::min(lowest, (X_WP * v).z());
    supported = supported || !SupportPolygon(p, X_WP).empty();
  }
  const double gap = lowest - t.height;
  if (std::abs(gap) > options_.table_tolerance_m) {
    Issue(index, "pose",
          label + Quote(NodeName(node)) + " should rest on the table, but its lowest point is " +
              Mm(std::abs(gap)) + (gap > 0 ? " above" : " below") + " the table top");
  } else if (!supported) {
    Issue(index, "pose",
          label + Quote(NodeName(node)) + " should rest on the table, but it is beside it");
  }
}

Cell* Validator::CellFor(const std::vector<double>& openings) {
  std::vector<long long> key;
  for (double o : openings) key.push_back(o < 0.0 ? -1 : std::llround(o * 1e5));
  if (auto it = cells_.find(key); it != cells_.end()) return &it->second;
  CellDef def;
  for (size_t r = 0; r < robots_.size(); ++r) {
    const RobotModel& m = robots_[r];
    CellRobot robot;
    robot.name = m.name;
    robot.chain = m.chain;
    robot.X_WB = m.X_WB;
    robot.end_effector.name = m.ee.name;
    robot.end_effector.X_FT = m.ee.X_FT;
    robot.end_effector.collision =
        openings[r] < 0.0 ? m.ee.collision : EndEffectorShapesAt(m.ee, openings[r]);
    robot.reference_link_frames = m.reference_frames;
    def.robots.push_back(std::move(robot));
  }
  for (size_t p = 0; p < project_.parts.size(); ++p) {
    def.objects.push_back({project_.parts[p].name, check_.parts[p].mesh, Iso3::Identity()});
  }
  def.table.present = true;
  def.table.size = project_.table.size;
  def.table.top_center =
      Vec3(project_.table.center_xy.x(), project_.table.center_xy.y(), project_.table.height);
  CellOptions options;
  options.objects_touch_table = false;  // decided per keyframe
  auto cell = Cell::Build(def, options);
  if (!cell) {
    if (!cells_failed_) {
      Issue(-1, "collision", "the collision cell could not be built: " + cell.error().message);
    }
    cells_failed_ = true;
    return nullptr;
  }
  return &cells_.emplace(std::move(key), std::move(*cell)).first->second;
}

void Validator::CheckCollisions(int index, const std::string& label, const Keyframe& kf,
                                const Moment& m, const std::map<int, Iso3>& X_WA,
                                const std::vector<std::pair<int, PlanHold>>& holds) {
  const int n_robots = static_cast<int>(robots_.size());
  std::vector<double> openings(n_robots, -1.0);
  std::vector<int> held_part(n_robots, -1);
  for (const auto& [node, h] : holds) {
    held_part[h.robot] = h.grasp.part;
    if (robots_[h.robot].ee.kind == EndEffectorKind::kTwoFinger) {
      openings[h.robot] = h.grasp.width_m + 2.0 * kFingerClearanceM;
    }
  }
  Cell* cell = CellFor(openings);
  if (cell == nullptr) return;
  PoseCell(*cell, kf, m, X_WA, held_part);
  ++out_.collision_checks;
  ReportCollisions(index, label, *cell);
  if (n_robots >= 2) CheckClearance(index, label, *cell);
}

void Validator::PoseCell(Cell& cell, const Keyframe& kf, const Moment& m,
                         const std::map<int, Iso3>& X_WA, const std::vector<int>& held_part) {
  const int n_robots = static_cast<int>(robots_.size());
  const int n_parts = static_cast<int>(project_.parts.size());
  std::vector<Iso3> frames;
  for (int r = 0; r < n_robots; ++r) {
    frames.resize(robots_[r].chain.links.size());
    ForwardKinematics(robots_[r].chain, robots_[r].X_WB, kf.q[r], frames);
    cell.SetConfiguration(r, std::span<const double>(kf.q[r].data(), kf.q[r].size()), frames);
  }
  // Each part belongs to one object at this moment.
  std::vector<int> object_of(n_parts, -1);
  for (const auto& [node, X] : X_WA) {
    for (int p : tree_.nodes[node].parts) {
      object_of[p] = node;
      cell.SetObjectPose(p, X * X_AP_[p]);
    }
  }
  auto pair_allowed = [&](int a, int b) {
    if (a == b) return true;
    return std::any_of(m.allowed_pairs.begin(), m.allowed_pairs.end(), [&](const auto& pr) {
      return (pr.first == a && pr.second == b) || (pr.first == b && pr.second == a);
    });
  };
  CollisionWorld& world = cell.world();
  for (int p = 0; p < n_parts; ++p) {
    cell.SetObjectEnabled(p, object_of[p] >= 0);
    for (int s = p + 1; s < n_parts; ++s) {
      cell.SetObjectPairAllowed(
          p, s, object_of[p] >= 0 && object_of[s] >= 0 && pair_allowed(object_of[p], object_of[s]));
    }
    for (int r = 0; r < n_robots; ++r) {
      world.SetAllowed(cell.object_body(p), cell.end_effector_body(r), held_part[r] == p);
    }
    bool touches = false;
    if (object_of[p] >= 0) {
      const int node = object_of[p];
      touches = m.rest_check.count(node) > 0;
      // Any object may touch the table top from above (e.g. a moved input that slides along the
      // table into a resting base, or reaches down to the top when mated), never sink into it.
      double lowest = std::numeric_limits<double>::infinity();
      for (int q : tree_.nodes[node].parts) {
        const Iso3 X_WP = X_WA.at(node) * X_AP_[q];
        for (const Vec3& v : hull_P_[q]) lowest = std::min(lowest, (X_WP * v).z());
      }
      touches = touches || std::abs(lowest - project_.table.height) <= options_.table_tolerance_m;
      if (auto it = objects_.find(node); it != objects_.end() && it->second.at_rest_pose) {
        const PoseError e = Difference(it->second.X_WA, X_WA.at(node));
        touches = touches || (e.position_m <= options_.position_tolerance_m &&
                              e.rotation_rad <= options_.rotation_tolerance_rad);
      }
    }
    world.SetAllowed(cell.object_body(p), cell.table_body(), touches);
  }
}

void Validator::ReportCollisions(int index, const std::string& label, Cell& cell) {
  CollisionWorld& world = cell.world();
  CollisionRequest request;
  request.all_pairs = true;
  request.max_pairs = 64;
  CollisionResult result;
  if (cell.InCollision(&result, request)) {
    std::set<std::pair<int, int>> seen;
    int reported = 0;
    int more = 0;
    const std::vector<ShapePair>& pairs =
        result.pairs.empty() ? std::vector<ShapePair>{result.first} : result.pairs;
    for (const ShapePair& pair : pairs) {
      const auto key = std::minmax(pair.body_a.value, pair.body_b.value);
      if (!seen.insert(key).second) continue;
      if (reported == kMaxCollisionPairsReported) {
        ++more;
        continue;
      }
      ++reported;
      Issue(index, "collision",
            label + Quote(world.body_name(pair.body_a)) + " collides with " +
                Quote(world.body_name(pair.body_b)) + " (" + cell.Describe(pair) + ")");
    }
    if (more > 0) {
      Issue(index, "collision",
            label + "and " + std::to_string(more) + " more colliding pairs of bodies");
    }
  }
}

void Validator::CheckClearance(int index, const std::string& label, Cell& cell) {
  CollisionWorld& world = cell.world();
  DistanceRequest request_d;
  request_d.nearest_points = false;
  request_d.upper_bound_m = options_.min_clearance_m + 1e-3;
  const DistanceResult d = cell.MinRobotClearance(request_d);
  if (d.distance < options_.min_clearance_m) {
    std::string who;
    if (d.has_pair()) {
      who = " between " + Quote(world.body_name(d.pair.body_a)) + " and " +
            Quote(world.body_name(d.pair.body_b));
    }
    Issue(index, "clearance",
          label + "robots come " + Mm(d.distance) + " close" + who + ", less than the " +
              Mm(options_.min_clearance_m) + " clearance");
  }
}

void Validator::CheckInsertionPath(int index, const Interface& f, const Iso3& X_WB) {
  const Mating& mating = f.step->mating;
  const std::vector<int>& moved = tree_.nodes[f.moved_node].parts;
  const std::vector<int>& base = tree_.nodes[f.base_node].parts;
  std::vector<Iso3> X(project_.parts.size(), Iso3::Identity());
  for (int p : base) X[p] = X_WB * X_AP_[p];
  const Vec3 axis_W = X_WB.linear() * f.axis_A;
  const int steps = static_cast<int>(std::ceil(mating.approach_m / kInsertionStep_m));
  for (int k = steps; k >= 0; --k) {
    const double s = steps > 0 ? mating.approach_m * k / steps : 0.0;
    for (int p : moved) {
      X[p] = X_WB * X_AP_[p];
      X[p].translation() -= s * axis_W;
    }
    const double allowed =
        s <= mating.interference_travel_m + 1e-12
            ? std::max(mating.interference_depth_m, project_.geometry.touch_depth_m)
            : project_.geometry.touch_depth_m;
    if (const auto o = OverlapBeyond(*geometry_, moved, base, X, allowed)) {
      Issue(index, "insertion",
            "assemble: on its way into its mating pose " + Quote(NodeName(f.moved_node)) +
                " (part " + Quote(PartName(o->part_a)) + ") cuts " + Mm(s) + " before it into " +
                Quote(NodeName(f.base_node)) + " (part " + Quote(PartName(o->part_b)) +
                ") deeper than the " + Mm(allowed) + " allowed");
      return;
    }
  }
}

void Validator::AddObject(int node, const Iso3& X_WA, const std::vector<PlanHold>& holders,
                          bool on_table, StepConfiguration& config,
                          std::vector<int>& body_of_part) const {
  const Table& t = project_.table;
  for (int p : tree_.nodes[node].parts) {
    const Iso3 X_WP = X_WA * X_AP_[p];
    body_of_part[p] = static_cast<int>(config.bodies.size());
    config.bodies.push_back(
        {PartName(p), check_.parts[p].mass_kg, X_WP * check_.parts[p].mass_properties.com});
    if (!on_table) continue;
    const std::vector<Eigen::Vector2d> polygon = SupportPolygon(p, X_WP);
    if (polygon.empty()) continue;
    WrenchTableSupport support;
    support.body = body_of_part[p];
    support.friction = t.friction;
    for (const Eigen::Vector2d& v : polygon) support.p_WV.emplace_back(v.x(), v.y(), t.height);
    config.tables.push_back(std::move(support));
  }
  // Connections made by the steps inside the object.
  std::vector<int> stack = {node};
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    const AssemblyNode& an = tree_.nodes[n];
    if (an.step < 0) continue;
    const Interface& f = interfaces_[n];
    if (f.step != nullptr && f.moved_part >= 0) {
      WrenchConnection c;
      c.body_a = body_of_part[f.base_part];
      c.body_b = body_of_part[f.moved_part];
      c.X_WC = X_WA * f.X_AC;
      c.limits = f.limits;
      c.name = an.name;
      config.connections.push_back(c);
    }
    for (int input : an.inputs) stack.push_back(input);
  }
  for (const PlanHold& h : holders) {
    if (!NodeHasPart(node, h.grasp.part)) continue;
    const RobotModel& robot = robots_[h.robot];
    config.grippers.push_back(MakeGripper(robot.name, body_of_part[h.grasp.part],
                                          X_WA * X_AP_[h.grasp.part] * h.grasp.X_PG, robot.ee.kind,
                                          GraspLimits(robot.limits, h.grasp.torque_scale)));
  }
}

void Validator::RunGate(int index, WrenchGate gate, const StepConfiguration& config,
                        std::string what) {
  if (!options_.check_wrench || options_.wrench_mode == MatingWrenchMode::kNone) return;
  WrenchQuery query;
  query.gate = gate;
  query.mode = options_.wrench_mode;
  query.lambda = options_.force_scale;
  ++out_.wrench_checks;
  const std::string name = "wrench_" + std::string(ToString(gate));
  auto check = checker_->Check(config, query);
  if (!check) {
    Issue(index, name, what + ": the wrench check could not run: " + check.error().message);
    return;
  }
  if (!check->feasible) Issue(index, name, what + ": " + check->reason);
  if (index < 0) return;
  if (out_.utilisation.size() <= static_cast<size_t>(index)) out_.utilisation.resize(index + 1);
  for (const SupportLoad& load : check->supports) {
    if (load.kind != SupportKind::kGripper || !std::isfinite(load.utilisation)) continue;
    const std::string& who = config.grippers[static_cast<size_t>(load.index)].name;
    for (size_t r = 0; r < robots_.size(); ++r) {
      if (robots_[r].name != who) continue;
      double& u = out_.utilisation[static_cast<size_t>(index)][static_cast<int>(r)];
      u = std::max(u, load.utilisation);
    }
  }
}

}  // namespace wrap::plan_validator_internal
