// The checks of a keyframe candidate once every acting robot has its joints: the robots keep
// their clearance, each skill at the keyframe (a grasp's straight approach, a release's retreat,
// a placement's descent) has room, a two-handed carry gets there, the freed robots can go home or
// stay open, and an assembly's insertion approach is clear; with the straight-line and carry
// checks they use.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "robot/kinematics.h"
#include "task/keyframes.h"
#include "task/keyframes_internal.h"

namespace wrap {
namespace {

// The straight moves that the motion stage makes at a keyframe as skills (a gripper's approach
// to its grasp along its axis, a placement's descent, a freed gripper's retreat) are checked
// clear for their least lengths (TaskPlannerOptions::skills) at this many points.
constexpr int kStraightSamples = 4;

}  // namespace

bool KeyframeSolver::ApproachClear(int robot, int grasp, const Iso3& X_WA,
                                   std::span<const std::pair<int, Iso3>> others, int* hit_node) {
  // The end effector alone along the line StraightClear follows with the whole arm: a hit here
  // is a hit there, whatever the arm's IK.
  ++counters_.collision_checks;
  const TaskRobot& r = world_.robots[robot];
  const Iso3 X_WT = GraspTarget(X_WA, grasp);
  const Vec3 back = -X_WT.linear().col(2);
  CollisionWorld& w = cell_.world();
  const BodyId ee = cell_.end_effector_body(robot);
  if (fingers_[robot]) opening_[robot] = GraspOpening(grasp);
  for (const auto& [node, X] : others) {
    for (int p : world_.tree->nodes[node].parts) cell_.SetObjectPose(p, X * world_.X_AP[p]);
  }
  for (int k = 0; k <= kStraightSamples; ++k) {
    Iso3 X_T = X_WT;
    X_T.translation() += (options_.skills.min_straight_m * k / kStraightSamples) * back;
    const Iso3 X_WF = X_T * r.end_effector.X_FT.inverse();
    w.SetPose(ee, X_WF);
    if (fingers_[robot]) PlaceFingers(robot, X_WF);
    for (const auto& [node, X] : others) {
      for (int p : world_.tree->nodes[node].parts) {
        const BodyId part = cell_.object_body(p);
        bool hit = w.Collide(ee, part);
        for (int f = 0; f < 2 && !hit && fingers_[robot]; ++f) {
          hit = w.Collide(fingers_[robot]->body[f], part);
        }
        if (hit) {
          if (hit_node) *hit_node = node;
          return false;  // every validation sets the robots and the scene again
        }
      }
    }
  }
  return true;
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

bool KeyframeSolver::RobotsTooClose() {
  DistanceRequest request;
  request.upper_bound_m = options_.skills.robot_clearance_m * 2 + 0.01;
  return cell_.MinRobotClearance(request).distance < options_.skills.robot_clearance_m;
}

bool KeyframeSolver::KeyframeClear(Edge& e, const Problem& p, Attempt& t,
                                   const std::vector<JointVector>& q) {
  if (e.n_robots >= 2 && RobotsTooClose()) {
    t.gate = Gate::kClearance;
    t.message = "robots closer than " +
                std::to_string(options_.skills.robot_clearance_m * 1000).substr(0, 4) + " mm";
    return false;
  }
  if (!SkillsClear(e, p, t, q)) return false;
  if (!CarriesClear(e, p, t, q)) return false;
  if (!p.freed.empty() && !FreedRobotsClear(e, p, t, q)) return false;
  if (e.a.type != ActionType::kAssemble) return true;
  return InsertionClear(e, p, t, q);
}

bool KeyframeSolver::SkillsClear(const Edge& e, const Problem& p, Attempt& t,
                                 const std::vector<JointVector>& q) {
  // The skills at this keyframe: each new grasp's straight approach along the gripper axis, each
  // freed gripper's retreat, a placement's descent (motion makes them straight; a keyframe that
  // leaves no room for them has no motion).
  const TaskAction& a = e.a;
  const std::vector<Mover>& movers = p.movers;
  std::string why_straight;
  for (size_t i = 0; i < movers.size(); ++i) {
    const int r = movers[i].robot;
    const bool grasps =
        (r == a.r1 && (a.type == ActionType::kPick || a.type == ActionType::kAddGrasp)) ||
        (r == a.r2 && a.type == ActionType::kHandover);
    if (!grasps) continue;
    const TaskRobot& R = world_.robots[r];
    const Vec3 back = -TcpPose(R.chain, R.X_WB, q[i], R.end_effector.X_FT).linear().col(2);
    if (!StraightClear(r, q[i], back, options_.skills.min_straight_m, &why_straight)) {
      t.gate = Gate::kSkill;
      t.message = "'" + R.name + "' cannot approach its grasp straight along the " +
                  "gripper axis: " + why_straight;
      return false;
    }
  }
  for (int r : p.freed) {
    JointVector qr = e.c.q[r];
    for (size_t i = 0; i < movers.size(); ++i) {
      if (movers[i].robot == r) qr = q[i];
    }
    const TaskRobot& R = world_.robots[r];
    const Iso3 X_WT = TcpPose(R.chain, R.X_WB, qr, R.end_effector.X_FT);
    if (a.type == ActionType::kPlace) {
      // The descent onto the table, seen from the bottom: the object rides along.
      const auto& parts = world_.tree->nodes[a.obj].parts;
      for (int part : parts) cell_.Attach(part, r);
      const bool down =
          StraightClear(r, qr, Vec3::UnitZ(), options_.skills.min_straight_m, &why_straight);
      for (int part : parts) {
        cell_.Detach(part, r);
        cell_.world().SetAllowed(cell_.object_body(part), cell_.end_effector_body(r), true);
      }
      if (!down) {
        t.gate = Gate::kSkill;
        t.message = "'" + R.name + "' cannot set its object down straight: " + why_straight;
        return false;
      }
    }
    if (!StraightClear(r, qr, -X_WT.linear().col(2), options_.skills.min_retreat_m,
                       &why_straight)) {
      t.gate = Gate::kSkill;
      t.message = "'" + R.name + "' cannot back its gripper away straight after " +
                  "letting go: " + why_straight;
      return false;
    }
  }
  return true;
}

bool KeyframeSolver::CarriesClear(const Edge& e, const Problem& p, Attempt& t,
                                  const std::vector<JointVector>& q) {
  // A two-handed carry: an object that robots already hold together and whose pose is sampled
  // must be carried there along one of the motion stage's straight variants, the rest of the
  // cell as it was (the carry comes before the other robots move).
  const SymState& s = e.s;
  const ContState& c = e.c;
  const std::vector<Mover>& movers = p.movers;
  for (int node : p.reposed) {
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
    for (int n2 : p.keyframe_nodes) before.push_back({n2, c.X_WA[n2], s.loc[n2] >= 0});
    for (int r = 0; r < e.n_robots; ++r) {
      if (s.held[r] >= 0) holds_before.push_back({r, s.grasp[r]});
    }
    SetScene(before, holds_before, -1, -1);
    for (int r = 0; r < e.n_robots; ++r) SetRobot(r, c.q[r]);
    std::string why_carry;
    const bool carried = CarryClear(node, holders, grasps, q0, c.X_WA[node], t.X[node], &why_carry);
    SetScene(t.objects, p.holds_at_keyframe, p.allow_a, p.allow_b);
    for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, q[i]);
    if (!carried) {
      t.gate = Gate::kSkill;
      t.message = "the robots holding '" + world_.tree->nodes[node].name +
                  "' cannot carry it there together: " + why_carry;
      return false;
    }
  }
  return true;
}

bool KeyframeSolver::FreedRobotsClear(const Edge& e, const Problem& p, Attempt& t,
                                      const std::vector<JointVector>& q) {
  // The robots this action frees go home, or, when home is blocked, open their grippers and
  // stay where they are: either must be clear of everything that stays.
  const std::vector<Mover>& movers = p.movers;
  const std::vector<int>& freed = p.freed;
  std::vector<std::pair<int, int>> holds_after;
  for (const auto& h : p.holds_at_keyframe) {
    if (std::find(freed.begin(), freed.end(), h.first) == freed.end()) holds_after.push_back(h);
  }
  auto at_keyframe = [&](int r) -> JointVector {
    for (size_t i = 0; i < movers.size(); ++i) {
      if (movers[i].robot == r) return q[i];
    }
    return e.c.q[r];
  };
  bool hit = true;
  for (int option = 0; option < 2 && hit; ++option) {
    SetScene(t.objects, holds_after, p.allow_a, p.allow_b);
    for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, q[i]);
    for (int r : freed) SetRobot(r, option == 0 ? world_.robots[r].home : at_keyframe(r));
    hit = Collides();
    t.park_home = option == 0;
  }
  SetScene(t.objects, p.holds_at_keyframe, p.allow_a, p.allow_b);
  for (int r : freed) SetRobot(r, at_keyframe(r));
  for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, q[i]);
  if (hit) {
    t.gate = Gate::kCollision;
    t.message = "'" + world_.robots[freed.front()].name +
                "' can neither go home nor stay with its gripper open afterwards";
    return false;
  }
  return true;
}

bool KeyframeSolver::InsertionClear(Edge& e, const Problem& p, Attempt& t,
                                    const std::vector<JointVector>& q) {
  // The insertion: the moved input `approach_m` back along the axis, reachable near the mated
  // joints, and collision-free without the mated contact.
  const std::vector<Mover>& movers = p.movers;
  const std::vector<Iso3>& X = t.X;
  const StepInterface& st = world_.interface(e.a.obj);
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
      if (!SolveIk(r, GraspTarget(Xf[st.moved], movers[i].grasp), ref, e.effort, e.rng, s2) ||
          JointDistanceMax(world_.robots[r].chain, s2.front(), ref, false) > 0.5) {
        t.gate = Gate::kApproach;
        t.message = "'" + world_.robots[r].name +
                    "' cannot make the straight insertion from the approach pose";
        return false;
      }
      ref = s2.front();
    }
    qa[i] = ref;
  }
  std::vector<PlanObject> objs_a;
  for (int node : p.keyframe_nodes) objs_a.push_back({node, Xa[node], p.keyframe_resting[node]});
  // The moved input may touch the base along its insertion (faces that slide along each other,
  // as in a stack of cubes); everything else must be clear.
  SetScene(objs_a, p.holds_at_keyframe, st.moved, st.base);
  for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, qa[i]);
  bool hit = Collides();
  if (!hit && e.n_robots >= 2) hit = RobotsTooClose();  // The clearance holds at the approach too.
  // Restore the mated scene for the search to go on.
  SetScene(t.objects, p.holds_at_keyframe, p.allow_a, p.allow_b);
  for (size_t i = 0; i < movers.size(); ++i) SetRobot(movers[i].robot, q[i]);
  if (hit) {
    t.gate = Gate::kApproach;
    t.message = "the insertion approach collides or brings robots within the clearance";
    return false;
  }
  Keyframe kf;
  kf.q = e.c.q;
  for (size_t i = 0; i < movers.size(); ++i) kf.q[movers[i].robot] = qa[i];
  kf.objects = std::move(objs_a);
  t.approach = std::move(kf);
  return true;
}

}  // namespace wrap
