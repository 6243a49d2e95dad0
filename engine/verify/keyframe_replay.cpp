// The keyframe replay of a plan without motion: a Timer walks the actions in plan order and
// gives every robot a timed trajectory (see detail/keyframe_replay.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <random>

#include "robot/ik.h"
#include "robot/kinematics.h"
#include "task/plan_state.h"
#include "verify/detail/keyframe_replay.h"

namespace wrap::detail {

namespace {

class Timer {
 public:
  Timer(const CellScene& scene, const AssemblyTree& tree, Plan& plan,
        const KeyframeReplayOptions& options, std::vector<std::string>& notes)
      : scene_(scene), tree_(tree), plan_(plan), options_(options), notes_(notes) {}

  void Run() {
    const int nr = static_cast<int>(scene_.robots.size());
    q_ = plan_.initial.q;
    opening_.assign(nr, -1.0);
    lifted_.assign(nr, std::nullopt);
    state_ = InitialPlanState(plan_.initial, nr);
    plan_.trajectories.assign(nr, RobotTrajectory{});
    plan_.segments.clear();
    for (int r = 0; r < nr; ++r) {
      plan_.trajectories[r].robot = r;
      plan_.trajectories[r].knots.push_back({0.0, q_[r], Zero(r), -1.0});
    }
    for (size_t ii = 0; ii < plan_.actions.size(); ++ii) Action(static_cast<int>(ii));
    // Every robot home at the end.
    const int last = static_cast<int>(plan_.actions.size()) - 1;
    MoveAll(SegmentKind::kFree, last, plan_.initial.q);
    for (int r = 0; r < nr; ++r) Idle(r, t_);
    plan_.stats.makespan_s = t_;
    plan_.stats.makespan_sequential_s = t_;
    plan_.stats.motion_segments = static_cast<int>(plan_.segments.size());
  }

 private:
  enum class SegmentKind { kFree, kLift, kDescend, kInsert, kGrip };
  static const char* Name(SegmentKind k) {
    switch (k) {
      case SegmentKind::kFree:
        return "free";
      case SegmentKind::kLift:
        return "lift";
      case SegmentKind::kDescend:
        return "descend";
      case SegmentKind::kInsert:
        return "insert";
      case SegmentKind::kGrip:
        return "grip";
    }
    return "free";
  }

  JointVector Zero(int r) const {
    return JointVector::Zero(static_cast<int>(scene_.robots[r].chain.dof()));
  }

  Iso3 Tcp(int r, const JointVector& q) const {
    const SceneRobot& robot = scene_.robots[r];
    return TcpPose(robot.chain, robot.X_WB, q, robot.end_effector.X_FT);
  }

  // A knot at time `at` where the robot stands still, so that its trajectory holds until then.
  void Idle(int r, double at) {
    auto& knots = plan_.trajectories[r].knots;
    if (knots.back().t < at - 1e-12) knots.push_back({at, q_[r], Zero(r), opening_[r]});
    knots.back().opening_m = opening_[r];
  }

  // Robot r's joints with the TCP moved by `d_W` (world), by IK near q; nothing when out of reach.
  std::optional<JointVector> Shifted(int r, const JointVector& q, const Vec3& d_W) {
    const SceneRobot& robot = scene_.robots[r];
    Iso3 X_WT = Tcp(r, q);
    X_WT.translation() += d_W;
    NumericIkRequest req;
    req.X_BT = robot.X_WB.inverse() * X_WT;
    req.X_FT = robot.end_effector.X_FT;
    req.seeds = {q};
    req.reference = q;
    NumericIkOptions o;
    o.restarts = 4;
    auto ik = SolveNumericIk(robot.chain, req, rng_, o);
    // A solution on another branch would swing the arm (and what it holds) far: not a shift.
    if (!ik || JointDistanceMax(robot.chain, q, ik->q, false) > 1.0) return std::nullopt;
    return ik->q;
  }

  // Robots `robots` move from where they are to `target` (per robot, same order) along straight
  // lines in joint space, in step: s(t) from 0 to 1 with one trapezoid whose speed and
  // acceleration keep every joint within its limits (and the TCPs within `speed_mps` when > 0).
  void Move(SegmentKind kind, int action, const std::vector<int>& robots,
            const std::vector<JointVector>& target, std::vector<int> objects,
            double speed_mps = 0.0) {
    double V = std::numeric_limits<double>::infinity();
    double A = std::numeric_limits<double>::infinity();
    double tcp_length = 0.0;
    bool moves = false;
    for (size_t k = 0; k < robots.size(); ++k) {
      const int r = robots[k];
      const Chain& chain = scene_.robots[r].chain;
      const JointVector d = target[k] - q_[r];
      for (int j = 0; j < chain.dof(); ++j) {
        const double dj = std::abs(d[j]);
        if (dj < 1e-12) continue;
        moves = true;
        V = std::min(V, chain.joints[j].max_velocity / dj);
        A = std::min(A, chain.joints[j].max_acceleration / dj);
      }
      tcp_length = std::max(tcp_length,
                            (Tcp(r, target[k]).translation() - Tcp(r, q_[r]).translation()).norm());
    }
    if (!moves) return;
    if (speed_mps > 0.0 && tcp_length > 1e-9) V = std::min(V, speed_mps / tcp_length);
    // The profile: accelerate, cruise, decelerate (triangular when it never reaches V).
    std::vector<std::pair<double, double>> s_sd;  // (s, ds/dt) at the knots after the start
    std::vector<double> at;
    const double t0 = t_;
    if (V * V / A >= 1.0) {
      const double ta = std::sqrt(1.0 / A);
      at = {t0 + ta, t0 + 2.0 * ta};
      s_sd = {{0.5, A * ta}, {1.0, 0.0}};
    } else {
      const double ta = V / A;
      const double sa = 0.5 * V * ta;
      const double tc = (1.0 - 2.0 * sa) / V;
      at = {t0 + ta, t0 + ta + tc, t0 + 2.0 * ta + tc};
      s_sd = {{sa, V}, {1.0 - sa, V}, {1.0, 0.0}};
    }
    for (size_t k = 0; k < robots.size(); ++k) {
      const int r = robots[k];
      Idle(r, t0);
      const JointVector q0 = q_[r];
      const JointVector d = target[k] - q0;
      for (size_t n = 0; n < at.size(); ++n) {
        const JointVector q = n + 1 == at.size() ? target[k] : JointVector(q0 + s_sd[n].first * d);
        plan_.trajectories[r].knots.push_back({at[n], q, s_sd[n].second * d, opening_[r]});
      }
      q_[r] = target[k];
    }
    t_ = at.back();
    std::vector<int> rs = robots;
    std::sort(rs.begin(), rs.end());
    plan_.segments.push_back({Name(kind), action, rs, std::move(objects), t0, t_});
  }

  // Lowest world z of what robot r holds when at q (+inf when it holds nothing).
  double LowestHeld(int r, const JointVector& q) const {
    if (state_.held[r] < 0) return std::numeric_limits<double>::infinity();
    const PlanGrasp& g = state_.grasp[r];
    const Iso3 X_WA = Tcp(r, q) * (scene_.parts[g.part].X_AP * g.X_PG).inverse();
    double lowest = std::numeric_limits<double>::infinity();
    for (int p : tree_.nodes[state_.held[r]].parts) {
      const Iso3 X_WP = X_WA * scene_.parts[p].X_AP;
      const auto& v = scene_.parts[p].mesh->vertices;
      const size_t step = std::max<size_t>(1, v.size() / 400);
      for (size_t k = 0; k < v.size(); k += step) lowest = std::min(lowest, (X_WP * v[k]).z());
    }
    return lowest;
  }

  // True when the held objects of `robots` stay clear of the table top along the straight
  // joint-space move from `from` to `to` (sampled).
  bool ClearOfTable(const std::vector<int>& robots, const std::vector<JointVector>& from,
                    const std::vector<JointVector>& to) const {
    const double top = scene_.table.top_center.z() + 0.005;
    for (int n = 0; n <= 24; ++n) {
      for (size_t k = 0; k < robots.size(); ++k) {
        const JointVector q = from[k] + (n / 24.0) * (to[k] - from[k]);
        if (LowestHeld(robots[k], q) < top) return false;
      }
    }
    return true;
  }

  // Every robot whose joints differ from `target` (all robots) moves there. A robot that lifted
  // what it picked stays lifted while the keyframes keep it at the pick. A free move that carries
  // an object whose straight joint-space path would sweep it through the table rises first,
  // moves at a height, and comes down straight.
  void MoveAll(SegmentKind kind, int action, std::vector<JointVector> target,
               std::vector<int> objects = {}, double speed_mps = 0.0) {
    std::vector<int> robots;
    std::vector<JointVector> goals, starts;
    bool carries = false;
    for (size_t r = 0; r < target.size(); ++r) {
      if (lifted_[r] && (target[r] - lifted_[r]->first).cwiseAbs().maxCoeff() < 1e-9) {
        target[r] = lifted_[r]->second;
      } else {
        lifted_[r].reset();
      }
      if ((target[r] - q_[r]).cwiseAbs().maxCoeff() > 1e-12) {
        robots.push_back(static_cast<int>(r));
        goals.push_back(target[r]);
        starts.push_back(q_[r]);
        carries = carries || state_.held[r] >= 0;
      }
    }
    if (robots.empty()) return;
    if (kind == SegmentKind::kFree && carries && !ClearOfTable(robots, starts, goals)) {
      for (double h : {0.1, 0.2, 0.4}) {
        std::vector<JointVector> up0, up1;
        for (size_t k = 0; k < robots.size(); ++k) {
          auto a = Shifted(robots[k], starts[k], Vec3(0, 0, h));
          auto b = Shifted(robots[k], goals[k], Vec3(0, 0, h));
          if (!a || !b) break;
          up0.push_back(*a);
          up1.push_back(*b);
        }
        if (up1.size() != robots.size()) continue;
        if (!ClearOfTable(robots, up0, up1)) continue;  // higher, or the note below
        Move(SegmentKind::kFree, action, robots, up0, objects, kRaiseSpeed_mps);
        Move(SegmentKind::kFree, action, robots, up1, objects);
        Move(SegmentKind::kFree, action, robots, goals, std::move(objects), kRaiseSpeed_mps);
        return;
      }
      notes_.push_back("actions[" + std::to_string(action) +
                       "]: a carried object may sweep the table on the way (no raised route)");
    }
    Move(kind, action, robots, goals, std::move(objects), speed_mps);
  }

  void Action(int i) {
    PlanAction& a = plan_.actions[i];
    const std::vector<JointVector>& K = a.keyframe.q;
    const double start = t_;
    const Vec3 up(0.0, 0.0, options_.lift_m);
    if (a.type == ActionType::kAssemble && a.approach) {
      MoveAll(SegmentKind::kFree, i, a.approach->q);
      MoveAll(SegmentKind::kInsert, i, K, {a.objects[0], a.objects[1]}, options_.insert_speed_mps);
    } else if (a.type == ActionType::kPlace) {
      const int r = a.robots[0];
      std::vector<JointVector> above = K;
      if (auto q = Shifted(r, K[r], up)) {
        above[r] = *q;
      } else {
        notes_.push_back("actions[" + std::to_string(i) +
                         "]: no IK above the place keyframe; set down without a descent");
      }
      MoveAll(SegmentKind::kFree, i, above, {a.objects[0]});
      MoveAll(SegmentKind::kDescend, i, K, {a.objects[0]}, options_.skill_speed_mps);
    } else {
      if (a.type == ActionType::kHandover || a.type == ActionType::kAddGrasp) {
        // Another gripper takes hold where the keyframe has the object: lifted robots that stay
        // at their pick set it back down first, straight.
        for (size_t r = 0; r < K.size(); ++r) {
          if (lifted_[r] && (K[r] - lifted_[r]->first).cwiseAbs().maxCoeff() < 1e-9) {
            const JointVector down = lifted_[r]->first;
            lifted_[r].reset();
            Move(SegmentKind::kDescend, i, {static_cast<int>(r)}, {down}, {},
                 options_.skill_speed_mps);
          }
        }
      }
      MoveAll(SegmentKind::kFree, i, K);
    }
    // Hold still, then the action happens.
    const double dwell0 = t_;
    t_ += options_.grip_s;
    plan_.segments.push_back({Name(SegmentKind::kGrip), i, a.robots, {a.objects[0]}, dwell0, t_});
    std::sort(plan_.segments.back().robots.begin(), plan_.segments.back().robots.end());
    a.start_s = start;
    a.end_s = t_;
    auto width = [&](size_t k) {
      const EndEffector& ee = scene_.robots[a.robots[k]].end_effector;
      return ee.kind == EndEffectorKind::kVacuum ? -1.0 : a.grasps[k].grasp.width_m;
    };
    switch (a.type) {
      case ActionType::kPick:
      case ActionType::kAddGrasp:
        opening_[a.robots[0]] = width(0);
        break;
      case ActionType::kHandover:
        opening_[a.robots[0]] = -1.0;
        opening_[a.robots[1]] = width(1);
        break;
      case ActionType::kPlace:
      case ActionType::kRelease:
        opening_[a.robots[0]] = -1.0;
        break;
      case ActionType::kAssemble:
        break;
    }
    for (int r : a.robots) Idle(r, t_);
    state_ = ApplyAction(state_, a);  // who holds what from now on
    if (a.type == ActionType::kPick) {
      const int r = a.robots[0];
      if (auto q = Shifted(r, q_[r], up)) {
        lifted_[r] = {q_[r], *q};
        Move(SegmentKind::kLift, i, {r}, {*q}, {a.objects[0]}, options_.skill_speed_mps);
      } else {
        notes_.push_back("actions[" + std::to_string(i) +
                         "]: no IK above the pick keyframe; lifted by the next move");
      }
    }
  }

  static constexpr double kRaiseSpeed_mps = 0.2;  // TCP speed rising and coming down

  const CellScene& scene_;
  const AssemblyTree& tree_;
  Plan& plan_;
  const KeyframeReplayOptions& options_;
  std::vector<std::string>& notes_;
  std::vector<JointVector> q_;   // per robot, where it is at t_
  std::vector<double> opening_;  // per robot, its finger opening from t_ on
  // Per robot after a lift: its joints at the pick and lifted, until a keyframe moves it.
  std::vector<std::optional<std::pair<JointVector, JointVector>>> lifted_;
  PlanState state_;  // who holds what from t_ on
  double t_ = 0.0;
  std::mt19937_64 rng_{1};
};

}  // namespace

Result<void> TimeKeyframes(const CellScene& scene, const AssemblyTree& tree, Plan& plan,
                           const KeyframeReplayOptions& options, std::vector<std::string>& notes) {
  const size_t nr = scene.robots.size();
  auto fits = [&](const Keyframe& k, const std::string& where) -> Result<void> {
    if (k.q.size() != nr) {
      return Fail(ErrorCode::kInvalidInput, where + ".q: joints of " + std::to_string(k.q.size()) +
                                                " robots, the cell has " + std::to_string(nr));
    }
    for (size_t r = 0; r < nr; ++r) {
      if (k.q[r].size() != scene.robots[r].chain.dof()) {
        return Fail(ErrorCode::kInvalidInput,
                    where + ".q: robot '" + scene.robots[r].name + "' has " +
                        std::to_string(scene.robots[r].chain.dof()) + " joints, the plan gives " +
                        std::to_string(k.q[r].size()));
      }
    }
    return {};
  };
  if (auto ok = fits(plan.initial, "initial"); !ok) return ok;
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    const std::string where = "actions[" + std::to_string(i) + "]";
    if (auto ok = fits(plan.actions[i].keyframe, where + ".keyframe"); !ok) return ok;
    if (plan.actions[i].approach) {
      if (auto ok = fits(*plan.actions[i].approach, where + ".approach"); !ok) return ok;
    }
    const PlanAction& a = plan.actions[i];
    const size_t n_robots = a.type == ActionType::kHandover ? 2 : 1;
    if (a.robots.size() < n_robots || a.grasps.size() < a.robots.size() || a.objects.empty()) {
      return Fail(ErrorCode::kInvalidInput,
                  where + ": expected " + std::to_string(n_robots) + " robots with grasps");
    }
    for (int r : a.robots) {
      if (r < 0 || r >= static_cast<int>(nr)) {
        return Fail(ErrorCode::kInvalidInput, where + ": bad robot " + std::to_string(r));
      }
    }
    if (a.type == ActionType::kAssemble && a.objects.size() < 3) {
      return Fail(ErrorCode::kInvalidInput, where + ": too few objects");
    }
    for (int o : a.objects) {
      if (o < 0 || o >= static_cast<int>(tree.nodes.size())) {
        return Fail(ErrorCode::kInvalidInput, where + ": object is not a node of the assembly");
      }
    }
    for (const PlanHold& h : a.grasps) {
      if (h.grasp.part < 0 || h.grasp.part >= static_cast<int>(scene.parts.size())) {
        return Fail(ErrorCode::kInvalidInput, where + ": a grasp names no part of the cell");
      }
    }
  }
  Timer(scene, tree, plan, options, notes).Run();
  return {};
}

}  // namespace wrap::detail
