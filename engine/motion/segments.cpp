// The geometric motion of a plan (segments.h): the segment builder walks the plan's actions in
// order. Each action's steps (robots freed earlier return, retreats and lifts, the graspers'
// approaches, carries and free moves to the target keyframe, the final skills, the grip, the
// action's effects) call the free paths, skills and carries of the other files of
// segments_internal.h. Where a motion reaches a keyframe's TCP pose on another IK solution, the
// keyframes follow it (Rebranch).
#include "motion/segments.h"

#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "grasp/grasp.h"
#include "motion/segments_internal.h"
#include "robot/kinematics.h"

namespace wrap {
namespace detail {

Result<std::vector<GeoSegment>> SegmentBuilder::Run() {
  // The caller's scene when it keeps one (cells built once for all its calls), else our own.
  std::optional<MotionScene>& slot = scene_holder_ ? *scene_holder_ : own_scene_;
  if (!slot) {
    auto scene = MotionScene::Build(w_);
    if (!scene) return std::unexpected(scene.error());
    slot = std::move(*scene);
  }
  scene_ = &*slot;
  rng_.seed(Mix(seed_, 0x6d6f74));
  const int n_robots = static_cast<int>(w_.robots.size());
  if (static_cast<int>(plan_.initial.q.size()) != n_robots) {
    return wrap::Fail(ErrorCode::kInvalidInput, "the plan's robots do not match the project's");
  }
  states_ = ReplayPlanStates(plan_);
  cur_ = plan_.initial.q;
  opening_.assign(n_robots, -1.0);
  released_.assign(n_robots, -1);
  released_at_.assign(n_robots, -1);
  for (const PlanObject& o : plan_.initial.objects) {
    if (o.resting) grounded_.insert(o.node);
  }
  for (size_t i = 0; i < plan_.actions.size(); ++i) {
    if (ctx_.cancelled()) return wrap::Fail(ErrorCode::kCancelled, "motion planning cancelled");
    ctx_.Progress("motion", static_cast<double>(i) / plan_.actions.size(),
                  "action " + std::to_string(i + 1) + "/" + std::to_string(plan_.actions.size()) +
                      ": " + DescribeAction(plan_, plan_.actions[i]));
    if (!Action(static_cast<int>(i)) || jump_) {
      if (cancelled_ || ctx_.cancelled()) {
        return wrap::Fail(ErrorCode::kCancelled, "motion planning cancelled");
      }
      return std::vector<GeoSegment>{};
    }
  }
  // Everyone home at the end.
  const int last = static_cast<int>(plan_.actions.size()) - 1;
  state_ = states_.back();
  for (int r = 0; r < n_robots; ++r) {
    if (!Return(std::max(last, 0), r, plan_.initial.q[r], false) || jump_) {
      if (cancelled_ || ctx_.cancelled()) {
        return wrap::Fail(ErrorCode::kCancelled, "motion planning cancelled");
      }
      return std::vector<GeoSegment>{};
    }
  }
  return std::move(out_);
}

bool SegmentBuilder::Action(int i) {
  const PlanAction& a = plan_.actions[i];
  state_ = states_[i];
  if (!ReturnFreed(i)) return false;
  ActionWork w;
  FindGraspers(i, w);
  if (!PrepareTarget(i, w)) return false;
  FindMoving(i, w);
  if (!RetreatAndLift(i, w)) return false;
  if (!PlanApproaches(i, w)) return false;
  // Where the carriers go before their final skill: the descent's top for a place.
  if (a.type == ActionType::kPlace && !PlanPlaceDescent(i, w)) return false;
  SortMovers(i, w);
  // Two-handed carries first: the object reaches its pose, then the others come to it.
  for (const MovingObject* m : w.carries) {
    std::vector<JointVector> goal_q;
    for (int r : m->holders) goal_q.push_back(w.target_kf.q[r]);
    if (!Carry(i, m->node, m->holders, m->X_goal, goal_q, w.target_kf, w.assemble && a.approach))
      return false;
  }
  if (!FreeMoves(i, w)) return false;
  hover_ = false;
  if (!FinalSkills(i, w)) return false;
  if (!ArriveAtKeyframe(i)) return false;
  PushGrip(i);
  ApplyEffects(i, w.grasped);
  return true;
}

bool SegmentBuilder::ReturnFreed(int i) {
  const PlanAction& a = plan_.actions[i];
  const Keyframe& K = a.keyframe;
  const int n_robots = static_cast<int>(w_.robots.size());
  auto in_action = [&](int r) {
    return std::find(a.robots.begin(), a.robots.end(), r) != a.robots.end();
  };
  // Robots freed earlier go where the keyframe has them (home).
  for (int r = 0; r < n_robots; ++r) {
    if (in_action(r) || state_.held[r] >= 0) continue;
    if (!Return(i, r, K.q[r], false)) return false;
  }
  return true;
}

void SegmentBuilder::FindGraspers(int i, ActionWork& w) {
  const PlanAction& a = plan_.actions[i];
  w.grasped = a.objects.empty() ? -1 : a.objects[0];
  if (a.type == ActionType::kPick || a.type == ActionType::kAddGrasp) {
    w.graspers.push_back(a.robots[0]);
    w.new_grasp = a.grasps[0].grasp;
  } else if (a.type == ActionType::kHandover) {
    w.graspers.push_back(a.robots[1]);
    w.new_grasp = a.grasps[1].grasp;
  }
  w.assemble = a.type == ActionType::kAssemble;
}

bool SegmentBuilder::PrepareTarget(int i, ActionWork& w) {
  const PlanAction& a = plan_.actions[i];
  // Where the movers go before the final skill: the approach keyframe of an insertion (or the
  // start of its slide), else the keyframe.
  w.target_kf = w.assemble && a.approach ? *a.approach : a.keyframe;
  if (w.assemble && a.approach) SlideStart(i, w.target_kf);
  if (w.assemble && a.approach &&
      !HoverAbove(i, w.target_kf, w.hover_holders, w.hover_descent, &w.hover_length)) {
    return false;
  }
  hover_ = !w.hover_descent.empty();
  return true;
}

void SegmentBuilder::FindMoving(int i, ActionWork& w) {
  const PlanAction& a = plan_.actions[i];
  for (const auto& [node, o] : state_.objects) {
    const std::vector<int> holders = state_.Holders(node);
    if (holders.empty()) continue;
    const PlanObject* goal = FindObject(w.target_kf, node);
    if (goal == nullptr) continue;
    // A placement moves its object even to where it was (its carrier comes to the descent).
    if (!SamePose(goal->X_WA, o.X_WA) || (a.type == ActionType::kPlace && node == w.grasped)) {
      w.moving.push_back({node, holders, goal->X_WA});
    }
  }
}

bool SegmentBuilder::RetreatAndLift(int i, ActionWork& w) {
  const PlanAction& a = plan_.actions[i];
  // Robots that let go and stayed back off first.
  for (int r : a.robots) {
    if (released_[r] >= 0 && !Retreat(i, r)) return false;
  }
  for (const MovingObject& m : w.moving) {
    for (int r : m.holders) {
      if (released_[r] >= 0 && !Retreat(i, r)) return false;
    }
  }
  // Lift what moves off the table.
  for (const MovingObject& m : w.moving) {
    if (grounded_.count(m.node) && !Lift(i, m.node, m.holders)) return false;
  }
  return true;
}

void SegmentBuilder::SortMovers(int i, ActionWork& w) {
  const PlanAction& a = plan_.actions[i];
  // Free motion of the graspers and of single-handed carriers; two-handed carries apart.
  for (size_t k = 0; k < w.graspers.size(); ++k) {
    w.free_robots.push_back(w.graspers[k]);
    w.free_goals.push_back(w.approaches[k].front());
  }
  for (const MovingObject& m : w.moving) {
    if (m.holders.size() > 1) {
      w.carries.push_back(&m);
      continue;
    }
    const int r = m.holders[0];
    w.free_robots.push_back(r);
    w.free_goals.push_back(a.type == ActionType::kPlace ? w.descend.front() : w.target_kf.q[r]);
    w.free_objects.push_back(m.node);
  }
  if (w.grasped >= 0 && !w.graspers.empty()) w.free_objects.push_back(w.grasped);
}

bool SegmentBuilder::FreeMoves(int i, ActionWork& w) {
  // One robot after another (prioritised): the carriers bring their objects, then the
  // graspers come to them. Each search is in one arm's space; the schedule lets the moves
  // overlap in time where their sweeps allow. When that fails, all of them at once in their
  // composite space.
  const size_t n_graspers = w.graspers.size();
  const BuilderCheckpoint saved = Save();
  // Carriers first; when that fails, the graspers first (a carrier's goal may be where a
  // grasper stands now).
  const int n_orders = n_graspers > 0 && w.free_robots.size() > n_graspers ? 2 : 1;
  bool ok = false;
  for (int order = 0; order < n_orders && !ok; ++order) {
    if (order > 0) {
      if (cancelled_ || ctx_.cancelled()) return false;
      Restore(saved);
      free_index_ = saved.free_index + static_cast<int>(w.free_robots.size());
    }
    ok = true;
    for (size_t pass = 0; pass < 2 && ok; ++pass) {
      for (size_t k = 0; k < w.free_robots.size() && ok; ++k) {
        const bool is_grasper = k < n_graspers;
        if (is_grasper != ((pass == 1) != (order == 1))) continue;
        if (!FreeMoveOne(i, w, k, ok)) return false;
      }
    }
  }
  if (!ok && w.free_robots.size() > 1) {
    if (cancelled_ || ctx_.cancelled()) return false;
    if (!FreeTogether(i, w, saved, n_orders, ok)) return false;
  }
  return ok;
}

bool SegmentBuilder::FreeMoveOne(int i, ActionWork& w, size_t k, bool& ok) {
  const Keyframe& K = plan_.actions[i].keyframe;
  const bool is_grasper = k < w.graspers.size();
  const int robot = w.free_robots[k];
  std::vector<int> objects;
  if (is_grasper && w.grasped >= 0) objects.push_back(w.grasped);
  if (!is_grasper) {
    for (const MovingObject& m : w.moving) {
      if (m.holders.size() == 1 && m.holders[0] == robot) objects.push_back(m.node);
    }
  }
  std::vector<JointVector> others;
  if (is_grasper) {
    for (const GraspAlternative& alt : w.alternatives[k]) others.push_back(alt.approach.front());
  }
  // A grasper opens to its grasp as it moves in (not before: robots moving earlier pass its
  // fingers as they are); where its fingers at that width would hit something where it stands
  // (open fingers straddling a part), it moves as it is and sets them at the start of its
  // approach.
  double grasp_opening = 0.0;
  if (is_grasper) {
    grasp_opening = GraspOpening(w_.robots[robot], w.new_grasp);
    if (!MoveOpening(robot, grasp_opening)) return false;
  }
  int reached = 0;
  ok = Free(i, true, {robot}, {w.free_goals[k]}, objects, &others, &reached);
  if (is_grasper) opening_[robot] = grasp_opening;
  if (ok && reached > 0) {
    // It reached another IK solution of the grasp: the keyframe follows.
    GraspAlternative& alt = w.alternatives[k][reached - 1];
    // The old solution stays an alternative (Rebranch overwrites K.q[robot]).
    const JointVector old_q = K.q[robot];
    Rebranch(robot, i, false, old_q, alt.q);
    std::swap(w.approaches[k], alt.approach);
    std::swap(w.approach_len[k], alt.length);
    alt.q = old_q;
    w.free_goals[k] = w.approaches[k].front();
  }
  return true;
}

bool SegmentBuilder::FreeTogether(int i, ActionWork& w, const BuilderCheckpoint& saved,
                                  int n_orders, bool& ok) {
  Restore(saved);
  for (int r : w.graspers) {
    if (!MoveOpening(r, GraspOpening(w_.robots[r], w.new_grasp))) return false;
  }
  free_index_ = saved.free_index + n_orders * static_cast<int>(w.free_robots.size());
  std::vector<size_t> order(w.free_robots.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](size_t x, size_t y) { return w.free_robots[x] < w.free_robots[y]; });
  std::vector<int> robots;
  std::vector<JointVector> goals;
  for (size_t k : order) {
    robots.push_back(w.free_robots[k]);
    goals.push_back(w.free_goals[k]);
  }
  ok = Free(i, true, robots, goals, w.free_objects);
  for (int r : w.graspers) opening_[r] = GraspOpening(w_.robots[r], w.new_grasp);
  return true;
}

bool SegmentBuilder::FinalSkills(int i, ActionWork& w) {
  const PlanAction& a = plan_.actions[i];
  if (!w.hover_descent.empty()) {
    PushSkill(SegmentKind::kDescend, i, true, w.hover_holders, {a.objects[0]},
              std::move(w.hover_descent), w.hover_length, opt_.skill_speed_mps);
  }
  if (a.type == ActionType::kPlace) {
    PushSkill(SegmentKind::kDescend, i, true, a.robots[0], w.grasped, w.descend, opt_.skills.lift_m,
              opt_.skill_speed_mps);
  }
  if (w.assemble && a.approach && !Insert(i)) return false;
  for (size_t k = 0; k < w.graspers.size(); ++k) {
    PushSkill(SegmentKind::kApproach, i, true, w.graspers[k], w.grasped, w.approaches[k],
              w.approach_len[k], opt_.skill_speed_mps);
  }
  return true;
}

bool SegmentBuilder::ArriveAtKeyframe(int i) {
  const PlanAction& a = plan_.actions[i];
  const Keyframe& K = a.keyframe;
  const int n_robots = static_cast<int>(w_.robots.size());
  // Every robot is now at the keyframe (a robot whose keyframe joints differ from where it is by
  // whole turns only is where the keyframe wants it: the keyframes follow it).
  for (int r = 0; r < n_robots; ++r) {
    if ((cur_[r] - K.q[r]).cwiseAbs().maxCoeff() > 1e-6 &&
        (NearestEquivalent(w_.robots[r].chain, K.q[r], cur_[r]) - cur_[r]).cwiseAbs().maxCoeff() <=
            1e-6) {
      Rebranch(r, i, a.approach.has_value(), K.q[r], cur_[r]);
    }
    if ((cur_[r] - K.q[r]).cwiseAbs().maxCoeff() > 1e-6) {
      return Fail(i, SegmentKind::kFree, false,
                  Name(r) + " would have to change its joints at the keyframe of action " +
                      std::to_string(i + 1) + " while it holds an object that stays put");
    }
    cur_[r] = K.q[r];
  }
  return true;
}

void SegmentBuilder::PushGrip(int i) {
  const PlanAction& a = plan_.actions[i];
  GeoSegment grip;
  grip.kind = SegmentKind::kGrip;
  grip.action = i;
  grip.main = true;
  grip.robots = a.robots;
  std::sort(grip.robots.begin(), grip.robots.end());
  grip.objects = a.objects;
  grip.waypoints.push_back({});
  for (int r : grip.robots) grip.waypoints[0].push_back(a.keyframe.q[r]);
  grip.hold_s = a.type == ActionType::kAssemble || a.type == ActionType::kRelease ? opt_.grip_s / 2
                                                                                  : opt_.grip_s;
  Push(std::move(grip));
}

void SegmentBuilder::ApplyEffects(int i, int grasped) {
  const PlanAction& a = plan_.actions[i];
  switch (a.type) {
    case ActionType::kPick:
    case ActionType::kAddGrasp:
      break;
    case ActionType::kPlace:
      grounded_.insert(grasped);
      released_[a.robots[0]] = grasped;
      released_at_[a.robots[0]] = i;
      break;
    case ActionType::kRelease:
      released_[a.robots[0]] = grasped;
      released_at_[a.robots[0]] = i;
      break;
    case ActionType::kHandover:
      released_[a.robots[0]] = grasped;
      released_at_[a.robots[0]] = i;
      break;
    case ActionType::kAssemble: {
      const bool base_grounded = grounded_.count(a.objects[1]) > 0;
      grounded_.erase(a.objects[0]);
      grounded_.erase(a.objects[1]);
      if (base_grounded) grounded_.insert(a.objects[2]);
      break;
    }
  }
}

bool SegmentBuilder::KeyframeAccepts(int robot, const JointVector& q, const Keyframe& kf,
                                     const std::vector<std::pair<int, int>>& mating) {
  PlanState at = state_;
  for (const PlanObject& o : kf.objects) {
    if (auto it = at.objects.find(o.node); it != at.objects.end()) it->second.X_WA = o.X_WA;
  }
  std::vector<JointVector> qs = kf.q;
  qs[robot] = q;
  if (!scene_->Set(at, opening_, qs, mating)) return false;
  CollisionResult hit;
  if (scene_->cell().InCollision(&hit)) {
    if (ctx_.Logs("motion")) {
      ctx_.Log("motion", StrFormat("keyframe: %s", scene_->cell().Describe(hit.first).c_str()));
    }
    return false;
  }
  DistanceRequest request;
  request.upper_bound_m = 0.02;
  return scene_->cell().MinRobotClearance(request).distance >= opt_.skills.robot_clearance_m;
}

bool SegmentBuilder::StageAccepts(int robot, int action, bool from_approach,
                                  const JointVector& old_q, const JointVector& new_q) {
  const PlanState saved = state_;
  bool ok = true;
  for (size_t j = static_cast<size_t>(action); ok && j < plan_.actions.size(); ++j) {
    const PlanAction& b = plan_.actions[j];
    state_ = states_[j];
    if (b.approach && (from_approach || j > static_cast<size_t>(action))) {
      if (!Same(b.approach->q[robot], old_q)) break;
      ok = KeyframeAccepts(robot, new_q, *b.approach, {});
    }
    if (!ok || !Same(b.keyframe.q[robot], old_q)) break;
    std::vector<std::pair<int, int>> mating;
    if (b.type == ActionType::kAssemble) mating.push_back({b.objects[0], b.objects[1]});
    ok = KeyframeAccepts(robot, new_q, b.keyframe, mating);
  }
  state_ = saved;
  return ok;
}

void SegmentBuilder::Rebranch(int robot, int action, bool from_approach, JointVector old_q,
                              JointVector new_q) {
  // By value: old_q may be a keyframe's own joints, which this overwrites.
  for (size_t j = static_cast<size_t>(action); j < plan_.actions.size(); ++j) {
    PlanAction& b = plan_.actions[j];
    if (b.approach && (from_approach || j > static_cast<size_t>(action))) {
      if (!Same(b.approach->q[robot], old_q)) return;
      b.approach->q[robot] = new_q;
    }
    if (!Same(b.keyframe.q[robot], old_q)) return;
    b.keyframe.q[robot] = new_q;
  }
}

bool SegmentBuilder::Return(int action, int robot, const JointVector& goal, bool main) {
  if (Same(cur_[robot], goal)) return true;
  if (!Retreat(action, robot)) return false;
  // Fingers open fully on the way, unless that hits something where the robot is.
  const double saved = opening_[robot];
  opening_[robot] = -1.0;
  if (!SetScene(opening_)) return false;
  if (scene_->Collides(std::vector<int>{robot})) opening_[robot] = saved;
  return Free(action, main, {robot}, {goal}, {});
}

}  // namespace detail

namespace {

constexpr std::array<std::string_view, 8> kKindNames = {"free",    "approach", "retreat", "lift",
                                                        "descend", "insert",   "carry",   "grip"};

}  // namespace

std::string_view ToString(SegmentKind kind) { return kKindNames[static_cast<int>(kind)]; }

Result<std::vector<GeoSegment>> PlanGeometricMotion(const TaskWorld& world, Plan& plan,
                                                    const MotionOptions& options,
                                                    const MotionRequest& request,
                                                    MotionCache& cache, RunContext& ctx,
                                                    MotionFailure* failure,
                                                    std::optional<MotionScene>* scene) {
  detail::SegmentBuilder builder(world, plan, options, request, cache, ctx, failure, scene);
  return builder.Run();
}

std::optional<SoleLoad> SoleLoadOf(const TaskWorld& world, const PlanState& state, int robot) {
  const int node = state.held[robot];
  if (node < 0 || state.Holders(node).size() != 1) return std::nullopt;
  SoleLoad l;
  l.robot = robot;
  Vec3 com_A = Vec3::Zero();
  for (int p : world.tree->nodes[node].parts) {
    l.mass += world.part_mass[p];
    com_A += world.part_mass[p] * world.part_com_A[p];
  }
  if (!(l.mass > 0.0)) return std::nullopt;
  com_A /= l.mass;
  const PlanGrasp& g = state.grasp[robot];
  l.com_G = (world.X_AP[g.part] * g.X_PG).inverse() * com_A;
  const TaskRobot& tr = world.robots[robot];
  l.box = tr.end_effector.kind == EndEffectorKind::kVacuum
              ? tr.limits.vacuum_transport
              : GraspLimits(tr.limits, g.torque_scale).two_finger;
  return l;
}

double LoadRatio(const SoleLoad& load, const Mat3& R_WG, const Vec3& accel_W) {
  constexpr double kG = 9.81;
  // What the gripper applies on the object, and its moment about the grasp point, in the grasp
  // frame.
  const Vec3 f_G = R_WG.transpose() * (load.mass * (accel_W + Vec3(0.0, 0.0, kG)));
  const Vec3 tau_G = load.com_G.cross(f_G);
  double u = 0.0;
  for (int i = 0; i < 3; ++i) {
    u = std::max(u, std::abs(f_G[i]) / std::max(load.box.force_N[i], 1e-9));
    u = std::max(u, std::abs(tau_G[i]) / std::max(load.box.torque_Nm[i], 1e-9));
  }
  return u;
}

}  // namespace wrap
