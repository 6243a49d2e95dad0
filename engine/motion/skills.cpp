// The skills: straight moves at contacts. A gripper's approach to its grasp and retreat from what
// it let go (along the gripper axis), the lift of an object off the table and its descent onto
// it. The insertion is in insertion_skill.cpp.

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "motion/segments_internal.h"
#include "robot/ik.h"
#include "robot/kinematics.h"

namespace wrap::detail {

std::vector<JointVector> SegmentBuilder::BackOff(
    int robot, const JointVector& q, double* length,
    const std::function<bool(const JointVector&)>& end_clear) {
  const Iso3 X0 = Tcp(robot, q);
  const Vec3 axis = X0.linear().col(2);
  // The straight move back by d, collision-free, or empty (last_hit_ says why).
  auto straight = [&](double d) {
    const int steps = std::max(2, static_cast<int>(std::ceil(d / opt_.cartesian_step_m)));
    auto target = [X0, axis, d](double s) {
      Iso3 X = X0;
      X.translation() -= s * d * axis;
      return X;
    };
    auto path = Track({robot}, {q}, {target}, steps, nullptr, kLooseTrackTolerance);
    std::vector<JointVector> out;
    if (path.empty()) {
      last_hit_ = "no IK solution along the line";
    } else if (PathClear({robot}, path)) {
      // The move may graze what the gripper let go of (or is about to hold) on its way; where it
      // ends, a free path starts or ends, and there it must touch nothing.
      if (end_clear && !end_clear(path.back()[0])) {
        last_hit_ = StrFormat("%.1f mm back the gripper still touches the object", d * 1e3);
        return out;
      }
      for (auto& wp : path) out.push_back(wp[0]);
    }
    return out;
  };
  // Longer first where the end of the usual length is in a tight pocket (free path searches
  // hardly leave one); then the usual length and shorter ones.
  std::vector<std::vector<JointVector>> longer;
  for (double d :
       {opt_.skills.approach_m, 2 * opt_.skills.approach_m, 3 * opt_.skills.approach_m}) {
    std::vector<JointVector> out = straight(d);
    if (out.empty()) break;
    *length = d;
    if (!Tight(robot, out.back()) || d > 2.5 * opt_.skills.approach_m) return out;
    longer.push_back(std::move(out));
  }
  if (!longer.empty()) {
    *length = opt_.skills.approach_m * static_cast<double>(longer.size());
    return longer.back();
  }
  for (double d :
       {opt_.skills.approach_m / 2, opt_.skills.approach_m / 4, opt_.skills.approach_m / 8}) {
    std::vector<JointVector> out = straight(d);
    if (out.empty()) continue;
    *length = d;
    return out;
  }
  return {};
}

bool SegmentBuilder::EndClear(int robot, const JointVector& q_end,
                              const std::vector<double>& openings,
                              const std::vector<std::pair<int, int>>& gripper_ok) {
  const JointVector start = cur_[robot];
  cur_[robot] = q_end;
  const bool clear =
      SetScene(openings).has_value() && !scene_->Collides(std::span<const int>(&robot, 1));
  cur_[robot] = start;
  // Back to the scene the straight move is checked in.
  return SetScene(openings, {}, {}, gripper_ok).has_value() && clear;
}

bool SegmentBuilder::Retreat(int action, int robot) {
  const int node = released_[robot];
  if (node < 0) return true;
  if (!SetScene(opening_, {}, {}, {{robot, node}})) return false;
  auto end_clear = [&](const JointVector& q_end) {
    return EndClear(robot, q_end, opening_, {{robot, node}});
  };
  double length = 0.0;
  std::vector<JointVector> back = BackOff(robot, cur_[robot], &length, end_clear);
  if (back.empty()) {
    return Fail(action, SegmentKind::kRetreat, false,
                Name(robot) + " cannot back its gripper away from " + NodeName(node) +
                    " along the gripper axis: " + last_hit_,
                released_at_[robot]);
  }
  if (ctx_.Logs("motion") && length < opt_.skills.approach_m) {
    ctx_.Log("motion", StrFormat("retreat: action %d %s backs only %.1f mm", action + 1,
                                 Name(robot).c_str(), length * 1e3));
  }
  PushSkill(SegmentKind::kRetreat, action, false, robot, node, back, length, opt_.skill_speed_mps);
  released_[robot] = -1;
  return true;
}

bool SegmentBuilder::Lift(int action, int node, const std::vector<int>& holders) {
  if (!SetScene(opening_, {}, {node})) return false;
  // Straight up; else back along the first holder's approach axis when that leaves the table
  // upward; else up and sideways; else a shorter lift.
  const Vec3 back = -Tcp(holders[0], cur_[holders[0]]).linear().col(2);
  std::vector<std::pair<Vec3, double>> moves = {{Vec3::UnitZ(), opt_.skills.lift_m}};
  if (back.z() > 0.3) moves.push_back({back, opt_.skills.lift_m / back.z()});
  for (const Vec3& side :
       std::array<Vec3, 4>{Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0)}) {
    moves.push_back({(side + Vec3::UnitZ()).normalized(), opt_.skills.lift_m * std::sqrt(2.0)});
  }
  moves.push_back({Vec3::UnitZ(), opt_.skills.lift_m / 2});
  std::string why;
  for (const auto& [dir, d] : moves) {
    std::vector<JointVector> q0;
    for (int r : holders) q0.push_back(cur_[r]);
    const auto targets = ShiftedTcps(holders, q0, d * dir);
    const int steps = std::max(2, static_cast<int>(std::ceil(d / opt_.cartesian_step_m)));
    auto path = Track(holders, q0, targets, steps);
    if (path.empty()) {
      why = "no IK solution along the line";
      continue;
    }
    if (!PathClear(holders, path)) {
      why = last_hit_;
      continue;
    }
    PushSkill(SegmentKind::kLift, action, true, holders, {node}, std::move(path), d,
              opt_.skill_speed_mps);
    grounded_.erase(node);
    return true;
  }
  return Fail(action, SegmentKind::kLift, false,
              "the holders of " + NodeName(node) + " cannot lift it off the table: " + why);
}

bool SegmentBuilder::PlanApproaches(int i, ActionWork& w) {
  w.approaches.assign(w.graspers.size(), {});
  w.approach_len.assign(w.graspers.size(), 0.0);
  // Other IK solutions of each grasper's grasp (UR arms, at higher effort): where they fit the
  // keyframe and can approach straight, the free path may end at any of them.
  w.alternatives.assign(w.graspers.size(), {});
  for (size_t k = 0; k < w.graspers.size(); ++k) {
    const int r = w.graspers[k];
    const std::vector<JointVector> options = GraspSolutions(i, r);
    for (size_t o = 0; o < options.size(); ++o) {
      double len = 0.0;
      std::vector<JointVector> back;
      if (!BackOffGrasp(i, w, r, options[o], back, len)) return false;
      if (o > 0) {
        if (!back.empty()) {
          std::reverse(back.begin(), back.end());
          w.alternatives[k].push_back({options[o], std::move(back), len});
        }
        continue;
      }
      if (back.empty()) {
        return Fail(i, SegmentKind::kApproach, false,
                    Name(r) + " cannot approach its grasp on " + NodeName(w.grasped) +
                        " straight along the gripper axis: " + last_hit_);
      }
      std::reverse(back.begin(), back.end());
      w.approaches[k] = std::move(back);
      w.approach_len[k] = len;
    }
  }
  return true;
}

std::vector<JointVector> SegmentBuilder::GraspSolutions(int i, int r) {
  const Keyframe& K = plan_.actions[i].keyframe;
  std::vector<JointVector> options = {K.q[r]};
  const TaskRobot& tr = w_.robots[r];
  if (effort_ >= 1 && tr.ur) {
    const UrIkSolutions sols = tr.ur->SolveTcp(tr.X_BW * Tcp(r, K.q[r]), tr.end_effector.X_FT);
    for (int c = 0; c < sols.count; ++c) {
      const JointVector q = NearestEquivalent(tr.chain, sols.q[c], cur_[r]);
      if ((NearestEquivalent(tr.chain, q, K.q[r]) - K.q[r]).cwiseAbs().maxCoeff() < 1e-6) {
        continue;
      }
      if (StageAccepts(r, i, false, K.q[r], q)) options.push_back(q);
    }
    if (ctx_.Logs("motion")) {
      ctx_.Log("motion", StrFormat("alternatives: action %d %s: %d IK solutions, %zu fit", i + 1,
                                   Name(r).c_str(), sols.count, options.size() - 1));
    }
  }
  return options;
}

bool SegmentBuilder::BackOffGrasp(int i, const ActionWork& w, int r, const JointVector& q,
                                  std::vector<JointVector>& back, double& length) {
  const Keyframe& K = plan_.actions[i].keyframe;
  std::vector<double> openings = opening_;
  openings[r] = GraspOpening(w_.robots[r], w.new_grasp);
  const JointVector saved = cur_[r];
  cur_[r] = K.q[r];
  // The scene at the keyframe's object poses: the object to grasp where it will be.
  PlanState at = state_;
  for (const PlanObject& ob : K.objects) {
    if (auto it = at.objects.find(ob.node); it != at.objects.end()) it->second.X_WA = ob.X_WA;
  }
  std::swap(state_, at);
  std::vector<int> carriers_now;
  for (const MovingObject& m : w.moving) {
    for (int h : m.holders) {
      carriers_now.push_back(h);
    }
  }
  std::vector<JointVector> saved_carriers;
  for (int h : carriers_now) {
    saved_carriers.push_back(cur_[h]);
    cur_[h] = K.q[h];
  }
  auto set = SetScene(openings, {}, {}, {{r, w.grasped}});
  if (!set) return false;
  auto end_clear = [&](const JointVector& q_end) {
    return EndClear(r, q_end, openings, {{r, w.grasped}});
  };
  back = BackOff(r, q, &length, end_clear);
  for (size_t c = 0; c < carriers_now.size(); ++c) cur_[carriers_now[c]] = saved_carriers[c];
  std::swap(state_, at);
  cur_[r] = saved;
  return true;
}

bool SegmentBuilder::PlanPlaceDescent(int i, ActionWork& w) {
  const PlanAction& a = plan_.actions[i];
  const Keyframe& K = a.keyframe;
  const int r = a.robots[0];
  const JointVector saved = cur_[r];
  cur_[r] = K.q[r];
  if (!SetScene(opening_, {}, {w.grasped})) return false;
  const Iso3 X0 = Tcp(r, K.q[r]);
  const double d = opt_.skills.lift_m;
  auto path = Track({r}, {K.q[r]}, {[X0, d](double s) {
                      Iso3 X = X0;
                      X.translation().z() += s * d;
                      return X;
                    }},
                    std::max(2, static_cast<int>(std::ceil(d / opt_.cartesian_step_m))));
  const bool ok = !path.empty() && PathClear({r}, path);
  cur_[r] = saved;
  if (!ok) {
    return Fail(i, SegmentKind::kDescend, false,
                Name(r) + " cannot set " + NodeName(w.grasped) +
                    " down straight onto the table at its placement: " + last_hit_);
  }
  for (auto it = path.rbegin(); it != path.rend(); ++it) w.descend.push_back((*it)[0]);
  return true;
}
}  // namespace wrap::detail
