#include "task/keyframes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numbers>

#include "robot/kinematics.h"

namespace wrap {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Rotation taking unit vector a onto unit vector b.
Mat3 RotationBetween(const Vec3& a, const Vec3& b) {
  return Eigen::Quaterniond::FromTwoVectors(a, b).toRotationMatrix();
}

Mat3 RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

// Candidates tried per effort level for poses in the air.
constexpr int kAirSamples[] = {6, 16, 40};
constexpr int kAssemblySamples[] = {10, 25, 60};
constexpr int kNumericRestarts[] = {3, 10, 25};
constexpr int kMaxLeaves = 24;  // IK combinations tried per pose candidate
constexpr int kMaxSolutionsPerRobot = 8;
constexpr double kTouchTolerance = 2e-3;  // an object this close above the table rests on it
// The straight moves that the motion stage makes at a keyframe as skills (a gripper's approach
// to its grasp along its axis, a placement's descent) must be clear for at least this length
// [m], checked at kStraightSamples points.
constexpr double kStraightM = 0.02;
// A retreat needs less: a release is permanent (nothing to sample), and a gripper near the table
// still backs off a centimetre where two would hit it.
constexpr double kRetreatM = 0.01;
constexpr int kStraightSamples = 4;

}  // namespace

std::string_view GateName(Gate gate) {
  switch (gate) {
    case Gate::kNone:
      return "none";
    case Gate::kReach:
      return "out of reach";
    case Gate::kIk:
      return "IK";
    case Gate::kCollision:
      return "collision";
    case Gate::kClearance:
      return "robot clearance";
    case Gate::kApproach:
      return "insertion approach";
    case Gate::kTable:
      return "below the table";
    case Gate::kWrenchAssembly:
      return "wrench (assembly)";
    case Gate::kWrenchTransport:
      return "wrench (transport)";
    case Gate::kWrenchRelease:
      return "wrench (release)";
    case Gate::kWrenchRest:
      return "wrench (rest)";
    case Gate::kSkill:
      return "straight approach, retreat or descent";
    case Gate::kGripperTable:
      return "gripper into the table";
  }
  return "?";
}

KeyframeSolver::KeyframeSolver(const TaskWorld& world, TaskTables& tables,
                               const TaskPlannerOptions& options, Cell cell, TaskCounters& counters)
    : world_(world),
      tables_(tables),
      options_(options),
      cell_(std::move(cell)),
      counters_(counters),
      checker_(WrenchOptions{}) {
  frames_.resize(world.robots.size());
  for (size_t r = 0; r < world.robots.size(); ++r) {
    frames_[r].resize(world.robots[r].chain.links.size());
  }
  part_object_.assign(world.num_parts, -1);
  // Finger boxes as bodies of their own, so that each keyframe opens them to its grasp.
  fingers_.resize(world.robots.size());
  opening_.assign(world.robots.size(), 0.0);
  CollisionWorld& w = cell_.world();
  for (size_t r = 0; r < world.robots.size(); ++r) {
    const EndEffector& ee = world.robots[r].end_effector;
    if (ee.kind != EndEffectorKind::kTwoFinger || ee.finger_shapes[0] < 0) continue;
    const std::vector<Shape> closed = EndEffectorShapesAt(ee, 0.0);
    const std::vector<Shape> open = EndEffectorShapesAt(ee, ee.stroke_m);
    Fingers f;
    f.stroke = ee.stroke_m;
    for (int k = 0; k < 2; ++k) {
      const Shape& shape = closed[ee.finger_shapes[k]];
      f.X_FS0[k] = shape.X_LS;
      f.per_metre[k] = Vec3::Zero();
      if (ee.stroke_m > 0.0) {
        f.per_metre[k] =
            (open[ee.finger_shapes[k]].X_LS.translation() - shape.X_LS.translation()) / ee.stroke_m;
      }
      Shape box = shape;
      box.X_LS = Iso3::Identity();
      auto body = w.AddBody(BodyDef{world.robots[r].name + "/finger_" + std::to_string(k),
                                    CellEndEffectorGroup(static_cast<int>(r)),
                                    {box},
                                    Iso3::Identity()});
      if (!body) continue;
      f.body[k] = *body;
      w.SetAllowed(*body, cell_.end_effector_body(static_cast<int>(r)), true);
      const int dof = world.robots[r].chain.dof();
      w.SetAllowed(*body, cell_.link_body(static_cast<int>(r), dof), true);
    }
    if (!f.body[0].valid() || !f.body[1].valid()) continue;
    w.SetAllowed(f.body[0], f.body[1], true);
    fingers_[r] = f;
    opening_[r] = ee.stroke_m;
  }
}

bool KeyframeSolver::GripperClear(int robot, int grasp, const Iso3& X_WA, int other_node,
                                  const Iso3& X_other) {
  const TaskRobot& r = world_.robots[robot];
  const Iso3 X_WF = GraspTarget(X_WA, grasp) * r.end_effector.X_FT.inverse();
  CollisionWorld& w = cell_.world();
  const BodyId ee = cell_.end_effector_body(robot);
  w.SetPose(ee, X_WF);
  if (fingers_[robot]) {
    opening_[robot] = GraspOpening(grasp);
    PlaceFingers(robot, X_WF);
  }
  bool hit = false;
  for (int p : world_.tree->nodes[other_node].parts) {
    const BodyId part = cell_.object_body(p);
    cell_.SetObjectPose(p, X_other * world_.X_AP[p]);
    hit = hit || w.Collide(ee, part);
    if (fingers_[robot]) {
      for (int k = 0; k < 2 && !hit; ++k) hit = w.Collide(fingers_[robot]->body[k], part);
    }
  }
  // Every validation sets the robots and the scene again before it checks anything.
  return !hit;
}

bool KeyframeSolver::GrippersApart(int robot_a, int grasp_a, int robot_b, int grasp_b) {
  ++counters_.collision_checks;
  CollisionWorld& w = cell_.world();
  std::vector<BodyId> bodies[2];
  const int robots[2] = {robot_a, robot_b};
  const int grasps[2] = {grasp_a, grasp_b};
  for (int k = 0; k < 2; ++k) {
    const TaskRobot& r = world_.robots[robots[k]];
    const Iso3 X_WF = GraspTarget(Iso3::Identity(), grasps[k]) * r.end_effector.X_FT.inverse();
    bodies[k].push_back(cell_.end_effector_body(robots[k]));
    w.SetPose(bodies[k][0], X_WF);
    if (fingers_[robots[k]]) {
      opening_[robots[k]] = GraspOpening(grasps[k]);
      PlaceFingers(robots[k], X_WF);
      for (int f = 0; f < 2; ++f) bodies[k].push_back(fingers_[robots[k]]->body[f]);
    }
  }
  CollisionRequest request;
  request.margin_m = options_.min_clearance_m;
  for (BodyId a : bodies[0]) {
    for (BodyId b : bodies[1]) {
      if (w.Collide(a, b, request)) return false;
    }
  }
  // Every validation sets the robots and the scene again before it checks anything.
  return true;
}

bool KeyframeSolver::ClearOfHomes(int node, const Iso3& X_WA) {
  ++counters_.collision_checks;
  CollisionWorld& w = cell_.world();
  for (int p : world_.tree->nodes[node].parts) cell_.SetObjectPose(p, X_WA * world_.X_AP[p]);
  for (int r = 0; r < static_cast<int>(world_.robots.size()); ++r) {
    SetRobot(r, world_.robots[r].home);
    std::vector<BodyId> bodies = {cell_.end_effector_body(r)};
    const int links = static_cast<int>(world_.robots[r].chain.links.size());
    for (int i = 0; i < links; ++i) bodies.push_back(cell_.link_body(r, i));
    if (fingers_[r]) {
      for (int k = 0; k < 2; ++k) bodies.push_back(fingers_[r]->body[k]);
    }
    for (int p : world_.tree->nodes[node].parts) {
      for (BodyId b : bodies) {
        if (w.Collide(b, cell_.object_body(p))) return false;
      }
    }
  }
  // Every validation sets the robots and the scene again before it checks anything.
  return true;
}

double KeyframeSolver::GraspOpening(int grasp) const {
  return tables_.grasp(grasp).width_m + 0.002;
}

void KeyframeSolver::PlaceFingers(int robot, const Iso3& X_WF) {
  if (!fingers_[robot]) return;
  const Fingers& f = *fingers_[robot];
  const double o = std::clamp(opening_[robot], 0.0, f.stroke);
  for (int k = 0; k < 2; ++k) {
    Iso3 X = f.X_FS0[k];
    X.translation() += o * f.per_metre[k];
    cell_.world().SetPose(f.body[k], X_WF * X);
  }
}

Iso3 KeyframeSolver::GraspTarget(const Iso3& X_WA, int grasp_id) const {
  const GraspRef& g = tables_.grasp(grasp_id);
  return X_WA * world_.X_AP[g.part] * g.X_PG;
}

bool KeyframeSolver::InReach(int robot, const Iso3& X_WT) const {
  const TaskRobot& r = world_.robots[robot];
  return (X_WT.translation() - r.shoulder_W).norm() <= r.reach_m;
}

bool KeyframeSolver::ClearOfTable(int robot, const Iso3& X_WT, double opening_m) {
  const TaskRobot& r = world_.robots[robot];
  const Iso3 X_WF = X_WT * r.end_effector.X_FT.inverse();
  CollisionWorld& w = cell_.world();
  const BodyId ee = cell_.end_effector_body(robot);
  const Iso3 saved = w.pose(ee);
  const double saved_opening = opening_[robot];
  w.SetPose(ee, X_WF);
  bool hit = w.Collide(ee, cell_.table_body());
  if (fingers_[robot]) {
    opening_[robot] = opening_m < 0.0 ? fingers_[robot]->stroke : opening_m;
    PlaceFingers(robot, X_WF);
    for (int k = 0; k < 2 && !hit; ++k)
      hit = w.Collide(fingers_[robot]->body[k], cell_.table_body());
    opening_[robot] = saved_opening;
    PlaceFingers(robot, saved);
  }
  w.SetPose(ee, saved);
  return !hit;
}

bool KeyframeSolver::SoloReach(int robot, const std::vector<PlanObject>& objects, int grasp,
                               std::string* why) {
  const auto start = Clock::now();
  const Iso3 target = GraspTarget(objects.front().X_WA, grasp);
  std::mt19937_64 rng(HashMix(0x5010, static_cast<std::uint64_t>(grasp)));
  std::vector<JointVector> sols;
  const TaskRobot& r = world_.robots[robot];
  bool ok = SolveIk(robot, target, r.home, r.ur ? 0 : 1, rng, sols);
  if (!ok) {
    if (why)
      *why = "no IK solution for '" + r.name + "' at grasp " +
             std::to_string(tables_.grasp(grasp).index);
  } else {
    SetScene(objects, {{robot, grasp}}, objects.size() > 1 ? objects[0].node : -1,
             objects.size() > 1 ? objects[1].node : -1);
    for (int q = 0; q < static_cast<int>(world_.robots.size()); ++q) EnableRobot(q, q == robot);
    ok = false;
    for (const JointVector& q : sols) {
      SetRobot(robot, q);
      if (!Collides()) {
        ok = true;
        break;
      }
    }
    for (int q = 0; q < static_cast<int>(world_.robots.size()); ++q) EnableRobot(q, true);
    if (!ok && why) {
      *why = "every IK solution of '" + r.name + "' at grasp " +
             std::to_string(tables_.grasp(grasp).index) + " collides (with the table or the part)";
    }
  }
  counters_.t_ik_s += Seconds(start);
  return ok;
}

Result<WrenchCheck> KeyframeSolver::CountedCheck(WrenchGate gate, std::uint64_t key,
                                                 const StepConfiguration& config) {
  ++counters_.lp_checks;
  const auto start = Clock::now();
  WrenchQuery query;
  query.gate = gate;
  query.mode = options_.wrench_mode;
  query.lambda = options_.force_scale;
  const std::uint64_t hits = checker_.cache_hits();
  const std::uint64_t solves = checker_.lp_solves();
  const std::uint64_t pivots = checker_.lp_pivots();
  auto result =
      key != 0 ? checker_.CheckCached(key, config, query) : checker_.CheckCached(config, query);
  counters_.t_lp_s += Seconds(start);
  counters_.lp_cache_hits += static_cast<long long>(checker_.cache_hits() - hits);
  counters_.lp_solves += static_cast<long long>(checker_.lp_solves() - solves);
  counters_.lp_pivots += static_cast<long long>(checker_.lp_pivots() - pivots);
  return result;
}

bool KeyframeSolver::Wrench(WrenchGate gate, std::span<const WrenchObject> objects, int mating_step,
                            std::uint64_t key, std::string* reason) {
  if (options_.wrench_mode == MatingWrenchMode::kNone) return true;
  const StepConfiguration config = BuildWrenchConfig(world_, tables_, objects, mating_step);
  auto result = CountedCheck(gate, key, config);
  if (!result) {
    if (reason) *reason = result.error().message;
    return false;
  }
  if (!result->feasible && reason) *reason = result->reason;
  return result->feasible;
}

std::vector<Mat3> KeyframeSolver::AxisOrientations(const Vec3& axis_A) {
  std::vector<Mat3> out;
  const Vec3 dirs[] = {-Vec3::UnitZ(), Vec3::UnitX(),  -Vec3::UnitX(),
                       Vec3::UnitY(),  -Vec3::UnitY(), Vec3::UnitZ()};
  for (const Vec3& d : dirs) {
    const Mat3 align = RotationBetween(axis_A.normalized(), d);
    for (int k = 0; k < 4; ++k) {
      out.push_back(Eigen::AngleAxisd(k * std::numbers::pi / 2, d).toRotationMatrix() * align);
    }
  }
  return out;
}

bool KeyframeSolver::MatingIncrementFits(int step,
                                         const std::vector<std::pair<int, int>>& moved_holders,
                                         const std::vector<std::pair<int, int>>& base_holders,
                                         std::uint64_t key) {
  if (options_.wrench_mode != MatingWrenchMode::kFull) return true;
  const StepInterface& s = world_.interface(step);
  const WrenchObject objs[2] = {{s.moved, Iso3::Identity(), false, moved_holders},
                                {s.base, Iso3::Identity(), false, base_holders}};
  const StepConfiguration config = BuildWrenchConfig(world_, tables_, objs, step);
  if (!HeldThenMated(config)) return true;  // A relaxation of that check only.
  auto result = CountedCheck(WrenchGate::kAssembly, HashMix(key, 0x6d6174696e67ULL),
                             MatingIncrementRelaxation(config));
  return !result || result->feasible;  // An error: no conclusion from the relaxation.
}

bool KeyframeSolver::AirAssemblyPossible(int step,
                                         const std::vector<std::pair<int, int>>& moved_holders,
                                         const std::vector<std::pair<int, int>>& base_holders,
                                         std::uint64_t key, std::string* reason) {
  const StepInterface& s = world_.interface(step);
  std::vector<Mat3> orientations = AxisOrientations(s.axis_A);
  if (!MatingIncrementFits(step, moved_holders, base_holders, key)) {
    // No orientation holds: orientation 0's full check gives the reason.
    orientations.resize(1);
  }
  for (size_t k = 0; k < orientations.size(); ++k) {
    Iso3 X = Iso3::Identity();
    X.linear() = orientations[k];
    X.translation() = Vec3(0, 0, world_.table_top + 0.3);
    const WrenchObject objs[2] = {{s.moved, X, false, moved_holders},
                                  {s.base, X, false, base_holders}};
    if (Wrench(WrenchGate::kAssembly, objs, step, HashMix(key, k + 1), reason)) return true;
  }
  return false;
}

bool KeyframeSolver::SolveIk(int robot, const Iso3& X_WT, const JointVector& reference, int effort,
                             std::mt19937_64& rng, std::vector<JointVector>& out) {
  out.clear();
  ++counters_.ik_calls;
  if (!InReach(robot, X_WT)) return false;
  const TaskRobot& r = world_.robots[robot];
  const Iso3 X_BT = r.X_BW * X_WT;
  if (r.ur) {
    const UrIkSolutions sols = r.ur->SolveTcp(X_BT, r.end_effector.X_FT);
    for (int i = 0; i < sols.count; ++i) {
      out.push_back(NearestEquivalent(r.chain, sols.q[i], reference));
    }
  } else {
    NumericIkRequest request;
    request.X_BT = X_BT;
    request.X_FT = r.end_effector.X_FT;
    request.seeds = {reference, r.home};
    request.reference = reference;
    NumericIkOptions o;
    o.restarts = kNumericRestarts[std::clamp(effort, 0, 2)];
    o.all_branches = effort > 0;
    o.max_branches = kMaxSolutionsPerRobot;
    o.position_tolerance_m = 1e-4;
    o.rotation_tolerance_rad = 1e-3;
    auto result = SolveNumericIk(r.chain, request, rng, o);
    if (result) out = result->branches;
  }
  std::stable_sort(out.begin(), out.end(), [&](const JointVector& a, const JointVector& b) {
    return (a - reference).squaredNorm() < (b - reference).squaredNorm();
  });
  if (out.size() > kMaxSolutionsPerRobot) out.resize(kMaxSolutionsPerRobot);
  return !out.empty();
}

void KeyframeSolver::SetRobot(int robot, const JointVector& q) {
  if (explain_) {
    if (q_now_.size() != world_.robots.size()) q_now_.resize(world_.robots.size());
    q_now_[robot] = q;
  }
  ForwardKinematics(world_.robots[robot].chain, world_.robots[robot].X_WB, q, frames_[robot]);
  cell_.SetConfiguration(robot, std::span<const double>(q.data(), q.size()), frames_[robot]);
  PlaceFingers(robot, cell_.X_WF(robot));
}

void KeyframeSolver::EnableRobot(int robot, bool on) {
  CollisionWorld& w = cell_.world();
  const int links = static_cast<int>(world_.robots[robot].chain.links.size());
  for (int i = 0; i < links; ++i) w.SetEnabled(cell_.link_body(robot, i), on);
  w.SetEnabled(cell_.end_effector_body(robot), on);
  if (fingers_[robot]) {
    for (int k = 0; k < 2; ++k) w.SetEnabled(fingers_[robot]->body[k], on);
  }
}

bool KeyframeSolver::Collides() {
  ++counters_.collision_checks;
  if (!trace_collisions_ && !explain_) return cell_.InCollision();
  CollisionResult result;
  const bool hit = cell_.InCollision(&result);
  if (hit && trace_collisions_) {
    log_->Log("task", "    collision: " + cell_.Describe(result.first), LogLevel::kTrace);
  }
  if (hit && explain_) {
    // The failure record's picture of it: every robot's joints, every part's pose, the bodies.
    const CollisionWorld& w = cell_.world();
    hit_.q = q_now_;
    hit_.X_WP.resize(world_.num_parts);
    for (int p = 0; p < world_.num_parts; ++p) hit_.X_WP[p] = cell_.object_pose(p);
    hit_.bodies = {w.body_name(result.first.body_a), w.body_name(result.first.body_b)};
  }
  return hit;
}

void KeyframeSolver::SetScene(const std::vector<PlanObject>& objects,
                              const std::vector<std::pair<int, int>>& holds, int allow_a,
                              int allow_b) {
  CollisionWorld& w = cell_.world();
  std::fill(part_object_.begin(), part_object_.end(), -1);
  for (size_t i = 0; i < objects.size(); ++i) {
    for (int p : world_.tree->nodes[objects[i].node].parts) {
      part_object_[p] = static_cast<int>(i);
      cell_.SetObjectPose(p, objects[i].X_WA * world_.X_AP[p]);
    }
  }
  const BodyId table = cell_.table_body();
  std::vector<char> touching(objects.size(), 0);
  for (size_t i = 0; i < objects.size(); ++i) {
    touching[i] =
        !objects[i].resting && std::abs(LowestPoint(world_, objects[i].node, objects[i].X_WA) -
                                        world_.table_top) <= kTouchTolerance;
  }
  for (int p = 0; p < world_.num_parts; ++p) {
    const BodyId body = cell_.object_body(p);
    const int op = part_object_[p];
    w.SetEnabled(body, op >= 0);
    if (op < 0) continue;
    // Resting objects touch the table, and so does one just picked, still where it rested.
    w.SetAllowed(body, table, objects[op].resting || touching[op]);
    for (int q = p + 1; q < world_.num_parts; ++q) {
      const int oq = part_object_[q];
      if (oq < 0) continue;
      const int na = objects[op].node, nb = objects[oq].node;
      const bool mated = (na == allow_a && nb == allow_b) || (na == allow_b && nb == allow_a);
      w.SetAllowed(body, cell_.object_body(q), op == oq || mated);
    }
    for (int r = 0; r < static_cast<int>(world_.robots.size()); ++r) {
      w.SetAllowed(cell_.end_effector_body(r), body, false);
      if (fingers_[r]) {
        for (int k = 0; k < 2; ++k) w.SetAllowed(fingers_[r]->body[k], body, false);
      }
    }
  }
  // Free grippers wait open; holding ones close to their grasp.
  for (int r = 0; r < static_cast<int>(world_.robots.size()); ++r) {
    if (fingers_[r]) opening_[r] = fingers_[r]->stroke;
  }
  for (const auto& [robot, grasp] : holds) {
    const BodyId part = cell_.object_body(tables_.grasp(grasp).part);
    w.SetAllowed(cell_.end_effector_body(robot), part, true);
    if (fingers_[robot]) {
      opening_[robot] = GraspOpening(grasp);
      for (int k = 0; k < 2; ++k) w.SetAllowed(fingers_[robot]->body[k], part, true);
    }
  }
  for (int r = 0; r < static_cast<int>(world_.robots.size()); ++r) {
    if (fingers_[r]) PlaceFingers(r, cell_.X_WF(r));
  }
}

bool KeyframeSolver::StraightClear(int robot, const JointVector& q, const Vec3& dir_W,
                                   double length_m, std::string* why) {
  const TaskRobot& r = world_.robots[robot];
  const Iso3 X0 = TcpPose(r.chain, r.X_WB, q, r.end_effector.X_FT);
  const int branch = r.ur ? r.ur->BranchOf(r.chain, q) : -1;
  JointVector prev = q;
  bool ok = true;
  for (int k = 1; k <= kStraightSamples && ok; ++k) {
    Iso3 X = X0;
    X.translation() += (length_m * k / kStraightSamples) * dir_W;
    const Iso3 X_BT = r.X_BW * X;
    JointVector next;
    ++counters_.ik_calls;
    if (r.ur) {
      UrIkOptions options;
      options.q6_if_singular = prev[5];
      const UrIkSolutions sols = r.ur->SolveTcp(X_BT, r.end_effector.X_FT, options);
      for (int c = 0; c < sols.count; ++c) {
        if (sols.branch[c] == branch) next = NearestEquivalent(r.chain, sols.q[c], prev);
      }
    } else {
      NumericIkRequest request;
      request.X_BT = X_BT;
      request.X_FT = r.end_effector.X_FT;
      request.seeds = {prev};
      request.reference = prev;
      NumericIkOptions o;
      o.restarts = 0;
      o.position_tolerance_m = 5e-4;
      o.rotation_tolerance_rad = 5e-3;
      std::mt19937_64 rng(static_cast<std::uint64_t>(k));
      auto result = SolveNumericIk(r.chain, request, rng, o);
      if (result) next = result->q;
    }
    // The motion stage tracks the line on this branch with steps of at most 0.25 rad.
    if (next.size() == 0 || (next - prev).cwiseAbs().maxCoeff() > 0.25) {
      if (why) *why = "no IK solution along the line";
      ok = false;
      break;
    }
    SetRobot(robot, next);
    if (Collides()) {
      if (why) {
        CollisionResult hit;
        cell_.InCollision(&hit);
        const CollisionWorld& w = cell_.world();
        *why = hit.collision ? "'" + w.body_name(hit.first.body_a) + "' hits '" +
                                   w.body_name(hit.first.body_b) + "'"
                             : "a collision";
      }
      ok = false;
    }
    prev = next;
  }
  SetRobot(robot, q);
  return ok;
}

bool KeyframeSolver::CarryClear(int node, const std::vector<int>& holders,
                                const std::vector<int>& grasps, const std::vector<JointVector>& q0,
                                const Iso3& X_a, const Iso3& X_b, std::string* why) {
  const Eigen::Quaterniond qa(X_a.linear());
  const Eigen::Quaterniond qb(X_b.linear());
  const double dist = (X_b.translation() - X_a.translation()).norm();
  const double angle = qa.angularDistance(qb);
  const int n = std::clamp(static_cast<int>(std::ceil(std::max(dist / 0.03, angle / 0.1))), 8, 40);
  std::vector<Iso3> X_AT;
  for (int g : grasps) {
    const GraspRef& ref = tables_.grasp(g);
    X_AT.push_back(world_.X_AP[ref.part] * ref.X_PG);
  }
  const auto& parts = world_.tree->nodes[node].parts;
  std::string last = "no IK solution near the last one for an arm";
  for (int variant = 0; variant < 2; ++variant) {
    std::vector<JointVector> prev = q0;
    bool ok = true;
    for (int k = 1; k <= n && ok; ++k) {
      const double s = static_cast<double>(k) / n;
      double st = s;
      Vec3 lift = Vec3::Zero();
      if (variant == 1) {
        lift.z() = 0.10 * std::min(1.0, std::min(4 * s, 4 * (1 - s)));
        st = std::clamp(2 * s - 0.5, 0.0, 1.0);
      }
      Iso3 X = Iso3::Identity();
      X.linear() = qa.slerp(s, qb).toRotationMatrix();
      X.translation() = (1 - st) * X_a.translation() + st * X_b.translation() + lift;
      for (size_t i = 0; i < holders.size() && ok; ++i) {
        const TaskRobot& r = world_.robots[holders[i]];
        const Iso3 X_BT = r.X_BW * X * X_AT[i];
        JointVector next;
        ++counters_.ik_calls;
        if (r.ur) {
          const int branch = r.ur->BranchOf(r.chain, prev[i]);
          UrIkOptions options;
          options.q6_if_singular = prev[i][5];
          const UrIkSolutions sols = r.ur->SolveTcp(X_BT, r.end_effector.X_FT, options);
          for (int c = 0; c < sols.count; ++c) {
            if (sols.branch[c] == branch) next = NearestEquivalent(r.chain, sols.q[c], prev[i]);
          }
        } else {
          NumericIkRequest request;
          request.X_BT = X_BT;
          request.X_FT = r.end_effector.X_FT;
          request.seeds = {prev[i]};
          request.reference = prev[i];
          NumericIkOptions o;
          o.restarts = 0;
          o.position_tolerance_m = 5e-4;
          o.rotation_tolerance_rad = 5e-3;
          std::mt19937_64 rng(static_cast<std::uint64_t>(k));
          auto result = SolveNumericIk(r.chain, request, rng, o);
          if (result) next = result->q;
        }
        // The motion stage tracks in steps of millimetres and refuses jumps of 0.25 rad; a
        // sample here stands for several of them.
        if (next.size() == 0 || (next - prev[i]).cwiseAbs().maxCoeff() > 0.6) {
          last = "'" + r.name + "' cannot follow it on its IK branch";
          ok = false;
          break;
        }
        prev[i] = next;
        SetRobot(holders[i], next);
      }
      if (!ok) break;
      for (int p : parts) cell_.SetObjectPose(p, X * world_.X_AP[p]);
      if (Collides()) {
        CollisionResult hit;
        cell_.InCollision(&hit);
        const CollisionWorld& w = cell_.world();
        last = hit.collision ? "on the way '" + w.body_name(hit.first.body_a) + "' hits '" +
                                   w.body_name(hit.first.body_b) + "'"
                             : "a collision on the way";
        ok = false;
      }
    }
    if (ok) return true;
  }
  if (why) *why = last;
  return false;
}

bool KeyframeSolver::Search(const std::vector<Mover>& movers,
                            const std::vector<std::vector<JointVector>>& sols, size_t depth,
                            std::vector<JointVector>& chosen, int& leaves, Gate& gate,
                            const std::function<bool(std::vector<JointVector>&)>& leaf) {
  if (depth == movers.size()) {
    ++leaves;
    return leaf(chosen);
  }
  const int r = movers[depth].robot;
  EnableRobot(r, true);
  for (const JointVector& q : sols[depth]) {
    SetRobot(r, q);
    if (Collides()) {
      if (gate == Gate::kNone || gate == Gate::kIk) gate = Gate::kCollision;
      continue;
    }
    chosen[depth] = q;
    if (Search(movers, sols, depth + 1, chosen, leaves, gate, leaf)) return true;
    if (leaves >= kMaxLeaves) break;
  }
  EnableRobot(r, false);
  return false;
}

EdgeOutcome KeyframeSolver::Validate(const SymState& s, const ContState& c, const TaskAction& a,
                                     const SymState& next, int effort, std::uint64_t seed) {
  ++counters_.validations;
  const auto start = Clock::now();
  const double lp_before = counters_.t_lp_s;
  hit_ = FailureScene{};
  if (explain_) {
    q_now_ = c.q;  // robots not set below stay where the state has them
  }
  std::mt19937_64 rng(HashMix(seed, static_cast<std::uint64_t>(effort) + 11));
  effort = std::clamp(effort, 0, 2);
  const int n_robots = static_cast<int>(world_.robots.size());

  auto holders_of = [&](const SymState& st, int node) {
    std::vector<std::pair<int, int>> h;
    for (int r = 0; r < n_robots; ++r) {
      if (st.held[r] == node) h.push_back({r, st.grasp[r]});
    }
    return h;
  };
  // Workspace centre of some robots: their shoulders' mean, pulled toward the table centre.
  auto workspace_centre = [&](const std::vector<int>& robots) {
    Vec3 m = Vec3::Zero();
    for (int r : robots) m += world_.robots[r].shoulder_W;
    m /= std::max<size_t>(1, robots.size());
    Vec3 p = m + 0.4 * (world_.table_center - m);
    p.z() = world_.table_top + 0.28;
    return p;
  };

  // The problem, filled per action type.
  std::vector<Mover> movers;
  std::vector<int> reposed;  // nodes whose pose is sampled
  int n_candidates = 1;
  std::function<bool(int, std::vector<Iso3>&)> make;  // candidate poses (node-indexed)
  std::function<bool(const std::vector<Iso3>&, Gate&, std::string&)> gates;
  std::vector<int> keyframe_nodes;  // objects listed in the keyframe
  std::vector<bool> keyframe_resting(world_.num_nodes, false);
  int allow_a = -1, allow_b = -1;  // mated pair at the keyframe (assemble)
  std::vector<int> freed;          // robots that go home after the action
  std::vector<std::pair<int, int>> holds_at_keyframe;
  for (int r = 0; r < n_robots; ++r) {
    if (s.held[r] >= 0) holds_at_keyframe.push_back({r, s.grasp[r]});
  }
  for (int node = 0; node < world_.num_nodes; ++node) {
    if (s.loc[node] != kInactive) {
      keyframe_nodes.push_back(node);
      keyframe_resting[node] = s.loc[node] >= 0;
    }
  }
  const bool fixed_ik_complete = true;  // UR closed form: all solutions
  bool numeric = false;
  auto add_mover = [&](int robot, int node, int grasp) {
    movers.push_back({robot, node, grasp});
    if (!world_.robots[robot].ur) numeric = true;
  };
  // Random pose of `node` around `centre`, orientation R.
  auto air_pose = [&](int node, const Mat3& R, const Vec3& centre, bool jitter) {
    Vec3 p = centre;
    if (jitter) {
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      p += Vec3(0.08 * u(rng), 0.08 * u(rng), 0.06 + 0.08 * u(rng));
    }
    Iso3 X = Iso3::Identity();
    X.linear() = R;
    X.translation() = p - R * world_.pre->subassemblies[node].com_A;
    return X;
  };
  auto above_table = [&](int node, const Iso3& X) {
    return LowestPoint(world_, node, X) >= world_.table_top + 0.01;
  };

  const int o = a.obj;
  switch (a.type) {
    case ActionType::kPick: {
      add_mover(a.r1, o, a.grasp);
      holds_at_keyframe.push_back({a.r1, a.grasp});
      make = [&](int, std::vector<Iso3>&) { return true; };
      gates = [&](const std::vector<Iso3>& X, Gate& g, std::string& why) {
        const WrenchObject obj{o, X[o], false, {{a.r1, a.grasp}}};
        const std::uint64_t key =
            HashMix(HashMix(HashMix(1, static_cast<std::uint64_t>(s.loc[o]) + 100), a.r1),
                    static_cast<std::uint64_t>(a.grasp));
        if (!Wrench(WrenchGate::kTransport, {&obj, 1}, -1, key, &why)) {
          g = Gate::kWrenchTransport;
          return false;
        }
        return true;
      };
      break;
    }
    case ActionType::kPlace: {
      add_mover(a.r1, o, s.grasp[a.r1]);
      keyframe_resting[o] = true;
      freed.push_back(a.r1);
      make = [&](int, std::vector<Iso3>& X) {
        X[o] = tables_.location(a.loc).X_WA;
        return true;
      };
      gates = [&](const std::vector<Iso3>& X, Gate& g, std::string& why) {
        const WrenchObject obj{o, X[o], true, {}};
        if (!Wrench(WrenchGate::kRest, {&obj, 1}, -1, HashMix(2, a.loc + 1), &why)) {
          g = Gate::kWrenchRest;
          return false;
        }
        // Brought down to that pose by its holder alone (the same problem as a pick from it).
        const WrenchObject carried{o, X[o], false, {{a.r1, s.grasp[a.r1]}}};
        const std::uint64_t key =
            HashMix(HashMix(HashMix(1, static_cast<std::uint64_t>(a.loc) + 100), a.r1),
                    static_cast<std::uint64_t>(s.grasp[a.r1]));
        if (!Wrench(WrenchGate::kTransport, {&carried, 1}, -1, key, &why)) {
          g = Gate::kWrenchTransport;
          return false;
        }
        return true;
      };
      break;
    }
    case ActionType::kHandover: {
      add_mover(a.r1, o, s.grasp[a.r1]);
      add_mover(a.r2, o, a.grasp);
      holds_at_keyframe.push_back({a.r2, a.grasp});
      freed.push_back(a.r1);
      reposed.push_back(o);
      n_candidates = kAirSamples[effort];
      const Vec3 centre = workspace_centre({a.r1, a.r2});
      make = [&, centre](int k, std::vector<Iso3>& X) {
        const Mat3 R = k < n_candidates / 3 ? Mat3(c.X_WA[o].linear()) : RandomRotation(rng);
        X[o] = air_pose(o, R, centre, k > 0);
        return above_table(o, X[o]);
      };
      gates = [&](const std::vector<Iso3>& X, Gate& g, std::string& why) {
        // The giver brings it there alone; the receiver holds it alone afterwards.
        const WrenchObject giver{o, X[o], false, {{a.r1, s.grasp[a.r1]}}};
        const WrenchObject obj{o, X[o], false, {{a.r2, a.grasp}}};
        if (!Wrench(WrenchGate::kTransport, {&giver, 1}, -1, 0, &why) ||
            !Wrench(WrenchGate::kTransport, {&obj, 1}, -1, 0, &why)) {
          g = Gate::kWrenchTransport;
          return false;
        }
        return true;
      };
      break;
    }
    case ActionType::kAddGrasp: {
      const auto holders = holders_of(s, o);
      const bool resting = s.loc[o] >= 0;
      if (!resting) {
        for (const auto& [r, g] : holders) add_mover(r, o, g);
        reposed.push_back(o);
      }
      add_mover(a.r1, o, a.grasp);
      holds_at_keyframe.push_back({a.r1, a.grasp});
      std::vector<int> robots;
      for (const Mover& m : movers) robots.push_back(m.robot);
      const Vec3 centre = workspace_centre(robots);
      n_candidates = resting ? 1 : kAirSamples[effort];
      make = [&, centre, resting](int k, std::vector<Iso3>& X) {
        if (resting || k == 0) return true;
        const Mat3 R = k < n_candidates / 2 ? Mat3(c.X_WA[o].linear()) : RandomRotation(rng);
        X[o] = air_pose(o, R, centre, true);
        return above_table(o, X[o]);
      };
      gates = [&, holders, resting](const std::vector<Iso3>& X, Gate& g, std::string& why) {
        // In the air its holders bring it there before the new hand takes it.
        if (!resting) {
          const WrenchObject before{o, X[o], false, holders};
          if (!Wrench(WrenchGate::kTransport, {&before, 1}, -1, 0, &why)) {
            g = Gate::kWrenchTransport;
            return false;
          }
        }
        WrenchObject obj{o, X[o], resting, holders};
        obj.holders.push_back({a.r1, a.grasp});
        if (!Wrench(WrenchGate::kRelease, {&obj, 1}, -1, 0, &why)) {
          g = Gate::kWrenchRelease;
          return false;
        }
        return true;
      };
      break;
    }
    case ActionType::kRelease: {
      freed.push_back(a.r1);
      make = [&](int, std::vector<Iso3>&) { return true; };
      gates = [&](const std::vector<Iso3>& X, Gate& g, std::string& why) {
        auto remaining = holders_of(next, o);
        const bool resting = s.loc[o] >= 0;
        const WrenchObject obj{o, X[o], resting, remaining};
        const WrenchGate gate = remaining.empty() ? WrenchGate::kRest : WrenchGate::kRelease;
        if (!Wrench(gate, {&obj, 1}, -1, 0, &why)) {
          g = remaining.empty() ? Gate::kWrenchRest : Gate::kWrenchRelease;
          return false;
        }
        return true;
      };
      break;
    }
    case ActionType::kAssemble: {
      const StepInterface& st = world_.interface(o);
      const int M = st.moved, B = st.base;
      const auto m_holders = holders_of(s, M);
      const auto b_holders = holders_of(s, B);
      const bool b_rests = s.loc[B] >= 0;
      for (const auto& [r, g] : m_holders) add_mover(r, M, g);
      std::vector<int> robots;
      for (const auto& [r, g] : m_holders) robots.push_back(r);
      if (!b_rests) {
        for (const auto& [r, g] : b_holders) {
          add_mover(r, B, g);
          robots.push_back(r);
        }
        reposed.push_back(B);
        n_candidates = kAssemblySamples[effort];
      }
      allow_a = M;
      allow_b = B;
      const Vec3 centre = workspace_centre(robots);
      auto orientations = std::make_shared<std::vector<Mat3>>(AxisOrientations(st.axis_A));
      make = [&, centre, orientations, b_rests, M, B](int k, std::vector<Iso3>& X) {
        if (!b_rests) {
          Mat3 R;
          if (k == 0) {
            R = c.X_WA[B].linear();
          } else if (k <= static_cast<int>(orientations->size())) {
            R = (*orientations)[k - 1];
          } else {
            R = (*orientations)[rng() % orientations->size()];
          }
          X[B] = air_pose(B, R, centre, k > static_cast<int>(orientations->size()));
        }
        X[M] = X[B];
        // A moved input that reaches down to the table top slides along it into a resting base.
        keyframe_resting[M] =
            b_rests && std::abs(LowestPoint(world_, M, X[M]) - world_.table_top) <= kTouchTolerance;
        if (!b_rests && !above_table(B, X[B])) return false;
        // The moved input must not reach under the table top.
        return LowestPoint(world_, M, X[M]) >= world_.table_top - 1e-3;
      };
      gates = [&, m_holders, b_holders, b_rests, M, B](const std::vector<Iso3>& X, Gate& g,
                                                       std::string& why) {
        // Each input is brought to the mating pose by its own holders, alone: the base in the
        // air, the moved input (oriented as at its approach).
        const WrenchObject m_alone{M, X[M], false, m_holders};
        const WrenchObject b_alone{B, X[B], false, b_holders};
        if ((!m_holders.empty() && !Wrench(WrenchGate::kTransport, {&m_alone, 1}, -1, 0, &why)) ||
            (!b_rests && !Wrench(WrenchGate::kTransport, {&b_alone, 1}, -1, 0, &why))) {
          g = Gate::kWrenchTransport;
          return false;
        }
        const WrenchObject objs[2] = {{M, X[M], keyframe_resting[M], m_holders},
                                      {B, X[B], b_rests, b_holders}};
        std::uint64_t key = 0;
        if (b_rests) {
          key = AssemblyLpKey(o, s.loc[B], m_holders, b_holders);
        }
        if (!Wrench(WrenchGate::kAssembly, objs, o, key, &why)) {
          g = Gate::kWrenchAssembly;
          return false;
        }
        return true;
      };
      break;
    }
  }

  std::vector<Iso3> X = c.X_WA;
  EdgeOutcome out;
  Gate worst = Gate::kNone;
  std::string why;
  auto note = [&](Gate g, const std::string& message) {
    // Keep the most advanced failure: wrench < IK < collision < clearance < approach.
    auto rank = [](Gate x) {
      switch (x) {
        case Gate::kNone:
          return 0;
        case Gate::kTable:
          return 1;
        case Gate::kWrenchTransport:
        case Gate::kWrenchRelease:
        case Gate::kWrenchRest:
        case Gate::kWrenchAssembly:
          return 2;
        case Gate::kReach:
          return 3;
        case Gate::kIk:
          return 4;
        case Gate::kCollision:
        case Gate::kGripperTable:
          return 5;
        case Gate::kClearance:
          return 6;
        case Gate::kApproach:
        case Gate::kSkill:
          return 7;
      }
      return 0;
    };
    if (rank(g) >= rank(worst)) {
      worst = g;
      why = message;
    }
  };

  for (int r = 0; r < n_robots; ++r) {
    EnableRobot(r, true);
    SetRobot(r, c.q[r]);
  }
  bool success = false;
  std::vector<JointVector> chosen(movers.size());
  std::optional<Keyframe> approach;
  bool park_home = true;  // freed robots go home (else they stay, gripper open)
  // Candidate poses. When poses are sampled, draw a larger pool and try first those where
  // every acting gripper approaches its grasp from its own robot's side (the approach axis
  // pointing away from the robot's shoulder): arms then reach without crossing each other.
  std::vector<std::vector<Iso3>> candidates;
  {
    const int pool = reposed.empty() ? n_candidates : 4 * n_candidates;
    std::vector<std::pair<double, int>> scored;
    for (int k = 0; k < pool; ++k) {
      std::vector<Iso3> Xk = c.X_WA;
      if (!make(k, Xk)) {
        note(Gate::kTable, "the object would be below the table top");
        continue;
      }
      double score = 1.0;
      for (const Mover& m : movers) {
        const Iso3 T = GraspTarget(Xk[m.node], m.grasp);
        const Vec3 from = (T.translation() - world_.robots[m.robot].shoulder_W).normalized();
        score = std::min(score, T.linear().col(2).dot(from));
      }
      // Keep the first candidate (the current pose) first: it needs no carrying.
      scored.push_back({k == 0 ? 2.0 : score, static_cast<int>(candidates.size())});
      candidates.push_back(std::move(Xk));
    }
    std::stable_sort(scored.begin(), scored.end(),
                     [](const auto& x, const auto& y) { return x.first > y.first; });
    std::vector<std::vector<Iso3>> ordered;
    for (int i = 0; i < static_cast<int>(scored.size()) && i < n_candidates; ++i) {
      ordered.push_back(std::move(candidates[scored[i].second]));
    }
    candidates = std::move(ordered);
  }
  for (size_t k = 0; k < candidates.size() && !success; ++k) {
    X = candidates[k];
    Gate g = Gate::kNone;
    std::string message;
    if (!gates(X, g, message)) {
      note(g, message);
      continue;
    }
    if (movers.empty() && freed.empty()) {
      success = true;
      break;
    }
    // IK of every mover.
    std::vector<std::vector<JointVector>> sols(movers.size());
    bool all = true;
    for (size_t i = 0; i < movers.size() && all; ++i) {
      const Mover& m = movers[i];
      const Iso3 target = GraspTarget(X[m.node], m.grasp);
      if (!InReach(m.robot, target)) {
        note(Gate::kReach, "'" + world_.robots[m.robot].name + "' cannot reach grasp " +
                               std::to_string(tables_.grasp(m.grasp).index) + " there");
        all = false;
        break;
      }
      if (!ClearOfTable(m.robot, target, GraspOpening(m.grasp))) {
        note(Gate::kCollision, "the gripper of '" + world_.robots[m.robot].name +
                                   "' would be in the table at grasp " +
                                   std::to_string(tables_.grasp(m.grasp).index));
        all = false;
        break;
      }
      if (!SolveIk(m.robot, target, c.q[m.robot], effort, rng, sols[i])) {
        note(Gate::kIk, "no IK solution for '" + world_.robots[m.robot].name + "' at grasp " +
                            std::to_string(tables_.grasp(m.grasp).index));
        all = false;
        continue;
      }
      // Two or more robots carrying one object move it as a rigid chain: a UR arm can only
      // follow on its current IK branch (another one is behind a singularity).
      if (s.held[m.robot] == m.node && world_.robots[m.robot].ur &&
          std::count_if(movers.begin(), movers.end(), [&](const Mover& x) {
            return x.node == m.node && s.held[x.robot] == x.node;
          }) >= 2) {
        const TaskRobot& rr = world_.robots[m.robot];
        const int branch = rr.ur->BranchOf(rr.chain, c.q[m.robot]);
        std::erase_if(sols[i],
                      [&](const JointVector& q) { return rr.ur->BranchOf(rr.chain, q) != branch; });
        if (sols[i].empty()) {
          note(Gate::kIk, "'" + world_.robots[m.robot].name +
                              "' cannot carry its object there with the others on its IK branch");
          all = false;
        }
      }
    }
    if (!all) continue;
    // Scene at the keyframe.
    std::vector<PlanObject> objects;
    for (int node : keyframe_nodes) objects.push_back({node, X[node], keyframe_resting[node]});
    SetScene(objects, holds_at_keyframe, allow_a, allow_b);
    for (const Mover& m : movers) EnableRobot(m.robot, false);
    int leaves = 0;
    Gate search_gate = Gate::kNone;
    std::string leaf_message;
    auto leaf = [&](std::vector<JointVector>& q) {
      if (n_robots >= 2) {
        DistanceRequest request;
        request.upper_bound_m = options_.min_clearance_m * 2 + 0.01;
        const DistanceResult d = cell_.MinRobotClearance(request);
        if (d.distance < options_.min_clearance_m) {
          search_gate = Gate::kClearance;
          leaf_message = "robots closer than " +
                         std::to_string(options_.min_clearance_m * 1000).substr(0, 4) + " mm";
          return false;
        }
      }
      {
        // The skills at this keyframe: each new grasp's straight approach along the gripper
        // axis, each freed gripper's retreat, a placement's descent (motion makes them straight;
        // a keyframe that leaves no room for them has no motion).
        std::string why_straight;
        for (size_t i = 0; i < movers.size(); ++i) {
          const int r = movers[i].robot;
          const bool grasps =
              (r == a.r1 && (a.type == ActionType::kPick || a.type == ActionType::kAddGrasp)) ||
              (r == a.r2 && a.type == ActionType::kHandover);
          if (!grasps) continue;
          const TaskRobot& R = world_.robots[r];
          const Vec3 back = -TcpPose(R.chain, R.X_WB, q[i], R.end_effector.X_FT).linear().col(2);
          if (!StraightClear(r, q[i], back, kStraightM, &why_straight)) {
            search_gate = Gate::kSkill;
            leaf_message = "'" + R.name + "' cannot approach its grasp straight along the " +
                           "gripper axis: " + why_straight;
            return false;
          }
        }
        for (int r : freed) {
          JointVector qr = c.q[r];
          for (size_t i = 0; i < movers.size(); ++i) {
            if (movers[i].robot == r) qr = q[i];
          }
          const TaskRobot& R = world_.robots[r];
          const Iso3 X_WT = TcpPose(R.chain, R.X_WB, qr, R.end_effector.X_FT);
          if (a.type == ActionType::kPlace) {
            // The descent onto the table, seen from the bottom: the object rides along.
            const auto& parts = world_.tree->nodes[o].parts;
            for (int p : parts) cell_.Attach(p, r);
            const bool down = StraightClear(r, qr, Vec3::UnitZ(), kStraightM, &why_straight);
            for (int p : parts) {
              cell_.Detach(p, r);
              cell_.world().SetAllowed(cell_.object_body(p), cell_.end_effector_body(r), true);
            }
            if (!down) {
              search_gate = Gate::kSkill;
              leaf_message =
                  "'" + R.name + "' cannot set its object down straight: " + why_straight;
              return false;
            }
          }
          if (!StraightClear(r, qr, -X_WT.linear().col(2), kRetreatM, &why_straight)) {
            search_gate = Gate::kSkill;
            leaf_message = "'" + R.name + "' cannot back its gripper away straight after " +
                           "letting go: " + why_straight;
            return false;
          }
        }
      }
      // A two-handed carry: an object that robots already hold together and whose pose is
      // sampled must be carried there along one of the motion stage's straight variants, the
      // rest of the cell as it was (the carry comes before the other robots move).
      for (int node : reposed) {
        std::vector<int> holders, grasps;
        std::vector<JointVector> q0;
        for (const Mover& m : movers) {
          if (m.node == node && s.held[m.robot] == node) {
            holders.push_back(m.robot);
            grasps.push_back(m.grasp);
            q0.push_back(c.q[m.robot]);
          }
        }
        if (holders.size() < 2) continue;
        std::vector<PlanObject> before;
        std::vector<std::pair<int, int>> holds_before;
        for (int n2 : keyframe_nodes) before.push_back({n2, c.X_WA[n2], s.loc[n2] >= 0});
        for (int r = 0; r < n_robots; ++r) {
          if (s.held[r] >= 0) holds_before.push_back({r, s.grasp[r]});
        }
        SetScene(before, holds_before, -1, -1);
        for (int r = 0; r < n_robots; ++r) SetRobot(r, c.q[r]);
        std::string why_carry;
        const bool carried =
            CarryClear(node, holders, grasps, q0, c.X_WA[node], X[node], &why_carry);
        SetScene(objects, holds_at_keyframe, allow_a, allow_b);
        for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, q[i]);
        if (!carried) {
          search_gate = Gate::kSkill;
          leaf_message = "the robots holding '" + world_.tree->nodes[node].name +
                         "' cannot carry it there together: " + why_carry;
          return false;
        }
      }
      if (!freed.empty()) {
        // The robots this action frees go home, or, when home is blocked, open their grippers
        // and stay where they are: either must be clear of everything that stays.
        std::vector<std::pair<int, int>> holds_after;
        for (const auto& h : holds_at_keyframe) {
          if (std::find(freed.begin(), freed.end(), h.first) == freed.end())
            holds_after.push_back(h);
        }
        auto at_keyframe = [&](int r) -> JointVector {
          for (size_t i = 0; i < movers.size(); ++i) {
            if (movers[i].robot == r) return q[i];
          }
          return c.q[r];
        };
        bool hit = true;
        for (int option = 0; option < 2 && hit; ++option) {
          SetScene(objects, holds_after, allow_a, allow_b);
          for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, q[i]);
          for (int r : freed) SetRobot(r, option == 0 ? world_.robots[r].home : at_keyframe(r));
          hit = Collides();
          park_home = option == 0;
        }
        SetScene(objects, holds_at_keyframe, allow_a, allow_b);
        for (int r : freed) SetRobot(r, at_keyframe(r));
        for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, q[i]);
        if (hit) {
          search_gate = Gate::kCollision;
          leaf_message = "'" + world_.robots[freed.front()].name +
                         "' can neither go home nor stay with its gripper open afterwards";
          return false;
        }
      }
      if (a.type != ActionType::kAssemble) return true;
      // The insertion: the moved input `approach_m` back along the axis, reachable near the
      // mated joints, and collision-free without the mated contact.
      const StepInterface& st = world_.interface(o);
      const Vec3 axis_W = X[st.base].linear() * st.axis_A;
      std::vector<Iso3> Xa = X;
      Xa[st.moved].translation() -= st.approach_m * axis_W;
      std::vector<JointVector> qa = q;
      for (size_t i = 0; i < movers.size(); ++i) {
        if (movers[i].node != st.moved) continue;
        const int r = movers[i].robot;
        // Halfway and at the approach: the nearest solution must stay on the same branch.
        JointVector ref = q[i];
        for (double f : {0.5, 1.0}) {
          std::vector<Iso3> Xf = X;
          Xf[st.moved].translation() -= f * st.approach_m * axis_W;
          std::vector<JointVector> s2;
          if (!SolveIk(r, GraspTarget(Xf[st.moved], movers[i].grasp), ref, effort, rng, s2) ||
              JointDistanceMax(world_.robots[r].chain, s2.front(), ref, false) > 0.5) {
            search_gate = Gate::kApproach;
            leaf_message = "'" + world_.robots[r].name +
                           "' cannot make the straight insertion from the approach pose";
            return false;
          }
          ref = s2.front();
        }
        qa[i] = ref;
      }
      std::vector<PlanObject> objs_a;
      for (int node : keyframe_nodes) objs_a.push_back({node, Xa[node], keyframe_resting[node]});
      // The moved input may touch the base along its insertion (faces that slide along each
      // other, as in a stack of cubes); everything else must be clear.
      SetScene(objs_a, holds_at_keyframe, st.moved, st.base);
      for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, qa[i]);
      bool hit = Collides();
      if (!hit && n_robots >= 2) {  // The robots' clearance holds at the approach too.
        DistanceRequest request;
        request.upper_bound_m = options_.min_clearance_m * 2 + 0.01;
        hit = cell_.MinRobotClearance(request).distance < options_.min_clearance_m;
      }
      // Restore the mated scene for the search to go on.
      SetScene(objects, holds_at_keyframe, allow_a, allow_b);
      for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, q[i]);
      if (hit) {
        search_gate = Gate::kApproach;
        leaf_message = "the insertion approach collides or brings robots within the clearance";
        return false;
      }
      Keyframe kf;
      kf.q = c.q;
      for (size_t i = 0; i < movers.size(); ++i) kf.q[movers[i].robot] = qa[i];
      kf.objects = std::move(objs_a);
      approach = std::move(kf);
      return true;
    };
    if (Search(movers, sols, 0, chosen, leaves, search_gate, leaf)) {
      success = true;
      break;
    }
    for (const Mover& m : movers) EnableRobot(m.robot, true);
    std::string who;
    for (const Mover& m : movers)
      who += (who.empty() ? "'" : ", '") + world_.robots[m.robot].name + "'";
    note(search_gate == Gate::kNone ? Gate::kCollision : search_gate,
         leaf_message.empty() ? "every IK solution of " + who + " collides" : leaf_message);
  }
  for (int r = 0; r < n_robots; ++r) EnableRobot(r, true);
  counters_.t_ik_s += Seconds(start) - (counters_.t_lp_s - lp_before);

  if (!success) {
    ++counters_.validation_failures;
    out.ok = false;
    out.gate = worst;
    out.message = why;
    if (worst == Gate::kCollision || worst == Gate::kSkill || worst == Gate::kApproach) {
      out.scene = std::move(hit_);
    }
    // Closed-form IK at a fixed pose (nothing sampled) or a wrench failure: effort cannot help.
    const bool wrench_only = worst == Gate::kWrenchAssembly || worst == Gate::kWrenchRest ||
                             worst == Gate::kWrenchRelease ||
                             (worst == Gate::kWrenchTransport && reposed.empty());
    out.permanent = wrench_only || (reposed.empty() && !numeric && fixed_ik_complete);
    return out;
  }
  out.ok = true;
  ContState& nc = out.next;
  nc.q = c.q;
  for (size_t i = 0; i < movers.size(); ++i) nc.q[movers[i].robot] = chosen[i];
  nc.X_WA = X;
  Keyframe& kf = out.keyframe;
  kf.q = nc.q;
  for (int node : keyframe_nodes) kf.objects.push_back({node, X[node], keyframe_resting[node]});
  if (park_home) {
    for (int r : freed) nc.q[r] = world_.robots[r].home;
  }
  if (a.type == ActionType::kAssemble) {
    const StepInterface& st = world_.interface(o);
    nc.X_WA[o] = X[st.base];
    out.approach = std::move(approach);
  }
  return out;
}

}  // namespace wrap
