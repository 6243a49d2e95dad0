// The keyframe solver itself: its copy of the cell (robots, finger bodies, the scene of a
// keyframe), its IK, its wrench gates with their counters and cache, and the cheap checks the
// search makes while expanding. Edge validation is in keyframe_validate.cpp, the problem of each
// action type in keyframe_actions.cpp, the checks of a keyframe candidate in keyframe_checks.cpp.
#include "task/keyframes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <tuple>

#include "robot/kinematics.h"
#include "task/keyframes_internal.h"

namespace wrap {
namespace {

using detail::Clock;
using detail::Seconds;

// Rotation taking unit vector a onto unit vector b.
Mat3 RotationBetween(const Vec3& a, const Vec3& b) {
  return Eigen::Quaterniond::FromTwoVectors(a, b).toRotationMatrix();
}

// Numeric IK restarts per effort level.
constexpr int kNumericRestarts[] = {3, 10, 25};
constexpr int kMaxSolutionsPerRobot = 8;
// A numeric IK whose first five starts all end over 2 cm (give_up_residual_m) from the target
// gives up on it: on cross_openarm's task plans fewer than 4% of such targets converged in the
// remaining starts of effort levels 1 and 2, which took most of the planner's IK time.
constexpr int kIkGiveUpAfter = 5;

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
      checker_(WrenchOptions{.first_failure_suffices = true,
                             .on_question = options.wrench_question_observer}) {
  frames_.resize(world.robots.size());
  for (size_t r = 0; r < world.robots.size(); ++r) {
    frames_[r].resize(world.robots[r].chain.links.size());
  }
  for (size_t r = 0; r < world.robots.size(); ++r) {
    const TaskRobot& a = world.robots[r];
    int q = 0;
    while (q < static_cast<int>(r) &&
           !(world.robots[q].grasp_set == a.grasp_set && world.robots[q].limits == a.limits &&
             world.robots[q].end_effector.kind == a.end_effector.kind)) {
      ++q;
    }
    wrench_class_.push_back(q);
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
  request.margin_m = options_.skills.robot_clearance_m;
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
                                                 const StepConfiguration& config, bool uncached) {
  ++counters_.lp_checks;
  const auto start = Clock::now();
  WrenchQuery query;
  query.gate = gate;
  query.mode = options_.wrench_mode;
  query.lambda = options_.force_scale;
  const std::uint64_t hits = checker_.cache_hits();
  const std::uint64_t solves = checker_.lp_solves();
  const std::uint64_t pivots = checker_.lp_pivots();
  auto result = uncached   ? checker_.Check(config, query)
                : key != 0 ? checker_.CheckCached(key, config, query)
                           : checker_.CheckCached(config, query);
  counters_.t_lp_s += Seconds(start);
  counters_.lp_cache_hits += static_cast<long long>(checker_.cache_hits() - hits);
  counters_.lp_solves += static_cast<long long>(checker_.lp_solves() - solves);
  counters_.lp_pivots += static_cast<long long>(checker_.lp_pivots() - pivots);
  return result;
}

std::vector<std::pair<int, int>> KeyframeSolver::ClassHolders(
    std::vector<std::pair<int, int>> holders) const {
  for (auto& [robot, grasp] : holders) robot = wrench_class_[robot];
  std::sort(holders.begin(), holders.end());
  return holders;
}

namespace {

// The robots holding `objects`, object by object, each object's in the order of (wrench class,
// grasp): the order in which two questions of one class key name their robots alike.
std::vector<int> RobotsInClassOrder(std::span<const WrenchObject> objects,
                                    const std::vector<int>& wrench_class) {
  std::vector<int> robots;
  for (const WrenchObject& o : objects) {
    std::vector<std::tuple<int, int, int>> held;
    for (const auto& [robot, grasp] : o.holders)
      held.emplace_back(wrench_class[robot], grasp, robot);
    std::sort(held.begin(), held.end());
    for (const auto& h : held) robots.push_back(std::get<2>(h));
  }
  return robots;
}

// `text` with each quoted name of robots[i] replaced by that of to[i] (at once: names may swap).
std::string Renamed(std::string text, const std::vector<int>& from, const std::vector<int>& to,
                    const std::vector<TaskRobot>& robots) {
  auto replace_all = [&text](const std::string& a, const std::string& b) {
    for (std::size_t at = text.find(a); at != std::string::npos; at = text.find(a, at + b.size())) {
      text.replace(at, a.size(), b);
    }
  };
  for (std::size_t i = 0; i < from.size() && i < to.size(); ++i) {
    if (from[i] != to[i])
      replace_all("'" + robots[from[i]].name + "'", "'\x01" + std::to_string(i) + "'");
  }
  for (std::size_t i = 0; i < from.size() && i < to.size(); ++i) {
    if (from[i] != to[i])
      replace_all("'\x01" + std::to_string(i) + "'", "'" + robots[to[i]].name + "'");
  }
  return text;
}

}  // namespace

bool KeyframeSolver::Wrench(WrenchGate gate, std::span<const WrenchObject> objects, int mating_step,
                            std::uint64_t key, std::string* reason) {
  if (options_.wrench_mode == MatingWrenchMode::kNone) return true;
  if (key != 0) {
    if (auto it = class_answers_.find(key); it != class_answers_.end()) {
      ++counters_.lp_checks;
      ++counters_.lp_cache_hits;
      if (!it->second.feasible && reason) {
        *reason = Renamed(it->second.reason, it->second.robots,
                          RobotsInClassOrder(objects, wrench_class_), world_.robots);
      }
      return it->second.feasible;
    }
  }
  const StepConfiguration config = BuildWrenchConfig(world_, tables_, objects, mating_step);
  // A keyed answer is kept in class_answers_ alone.
  auto result = CountedCheck(gate, key, config, /*uncached=*/key != 0);
  if (!result) {
    if (reason) *reason = result.error().message;
    return false;
  }
  if (!result->feasible && reason) *reason = result->reason;
  if (key != 0) {
    if (class_answers_.size() >= (1u << 20)) class_answers_.clear();
    ClassAnswer& answer = class_answers_[key];
    answer.feasible = result->feasible;
    if (!answer.feasible) {
      answer.reason = result->reason;
      answer.robots = RobotsInClassOrder(objects, wrench_class_);
    }
  }
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
    o.give_up_after = kIkGiveUpAfter;
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
                                        world_.table_top) <= detail::kTouchTolerance;
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

}  // namespace wrap
