// Two-handed carries: the holders of one object move it to its pose at the keyframe along a
// straight, rotate-first, rotate-last or over-the-top path, each tracked by the holders' IK; else
// (effort 1 and more) along a path found by a search over the object's poses.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "motion/segments_internal.h"
#include "robot/kinematics.h"

namespace wrap::detail {

bool SegmentBuilder::Carry(int action, int node, const std::vector<int>& holders,
                           const Iso3& X_goal, std::vector<JointVector> goal_q,
                           const Keyframe& target, bool approach) {
  // The object's pose now, from its first holder's TCP.
  const PlanGrasp& g0 = state_.grasp[holders[0]];
  const Iso3 X_AT0 = w_.X_AP[g0.part] * g0.X_PG;
  const Iso3 X_start = Tcp(holders[0], cur_[holders[0]]) * X_AT0.inverse();
  const double dist = (X_goal.translation() - X_start.translation()).norm();
  const Eigen::Quaterniond qa(X_start.linear());
  const Eigen::Quaterniond qb(X_goal.linear());
  const double angle = qa.angularDistance(qb);
  const Vec3 pa = X_start.translation();
  const Vec3 pb = X_goal.translation();
  // Object paths tried in turn: straight; rotate, then translate; translate, then rotate; up
  // 10 cm, across, down.
  auto pose = [&](int variant, double s) {
    double sr = s, st = s;
    Vec3 lift = Vec3::Zero();
    if (variant == 1) {
      sr = std::min(1.0, 2 * s);
      st = std::max(0.0, 2 * s - 1);
    } else if (variant == 2) {
      st = std::min(1.0, 2 * s);
      sr = std::max(0.0, 2 * s - 1);
    } else if (variant == 3) {
      lift.z() = 0.10 * std::min(1.0, std::min(4 * s, 4 * (1 - s)));
      st = std::clamp(2 * s - 0.5, 0.0, 1.0);
    }
    Iso3 X = Iso3::Identity();
    X.linear() = qa.slerp(sr, qb).toRotationMatrix();
    X.translation() = (1 - st) * pa + st * pb + lift;
    return X;
  };
  const double length = dist + 0.2 + angle * 0.1;
  const int steps = std::max(
      2, static_cast<int>(std::ceil(std::max(length / opt_.cartesian_step_m, 2 * angle / 0.02))));
  std::string why;
  for (int variant = 0; variant < 4; ++variant) {
    std::vector<JointVector> q0;
    std::vector<std::function<Iso3(double)>> targets;
    for (int r : holders) {
      q0.push_back(cur_[r]);
      const PlanGrasp& g = state_.grasp[r];
      const Iso3 X_AT = w_.X_AP[g.part] * g.X_PG;
      targets.push_back([&pose, variant, X_AT](double s) { return pose(variant, s) * X_AT; });
    }
    auto path = Track(holders, q0, targets, steps, &goal_q);
    std::vector<std::pair<size_t, JointVector>> rebranch;
    why.clear();
    if (path.empty()) {
      why = "an arm cannot follow the object (no IK solution near the last one)";
      continue;
    }
    if (!CarryEnd(holders, goal_q, target, path.back(), rebranch, why)) continue;
    if (!SetScene(opening_)) return false;
    if (!PathClear(holders, path)) {
      why = "on the way " + last_hit_;
      continue;
    }
    for (const auto& [i, q] : rebranch) Rebranch(holders[i], action, approach, goal_q[i], q);
    PushSkill(SegmentKind::kCarry, action, true, holders, {node}, std::move(path),
              variant == 3 ? dist + 0.2 : std::max(dist, angle * 0.1), opt_.carry_speed_mps);
    return true;
  }
  // Neither of the straight variants: search the object's poses (at effort 1 and more; at
  // effort 0 the plan is suspended so that other task plans get their turn first).
  if (effort_ >= 1 && !ctx_.ShouldStop()) {
    std::vector<std::pair<size_t, JointVector>> rebranch;
    double carry_length = 0.0;
    std::string search_why;
    if (!SetScene(opening_)) return false;
    auto path =
        CarrySearch(holders, X_start, X_goal, goal_q, target, rebranch, &carry_length, search_why);
    if (!path.empty()) {
      for (const auto& [i, q] : rebranch) Rebranch(holders[i], action, approach, goal_q[i], q);
      PushSkill(SegmentKind::kCarry, action, true, holders, {node}, std::move(path), carry_length,
                opt_.carry_speed_mps);
      return true;
    }
    why += "; searched over the object's poses: " + search_why;
  }
  return Fail(action, SegmentKind::kCarry, !ctx_.ShouldStop(),
              "the robots holding " + NodeName(node) +
                  " cannot carry it together to its keyframe pose (straight, rotating first or "
                  "last, or over the top" +
                  (effort_ >= 1 ? ", or by a search over its poses" : "") + "): " + why);
}

bool SegmentBuilder::CarryEnd(const std::vector<int>& holders,
                              const std::vector<JointVector>& goal_q, const Keyframe& target,
                              std::vector<JointVector>& last,
                              std::vector<std::pair<size_t, JointVector>>& rebranch,
                              std::string& why) {
  for (size_t i = 0; i < holders.size(); ++i) {
    const double off = (last[i] - goal_q[i]).cwiseAbs().maxCoeff();
    const JointVector same_pose =
        NearestEquivalent(w_.robots[holders[i]].chain, goal_q[i], last[i]);
    if (off > kMaxSnap && hover_) {
      why = Name(holders[i]) + " ends " + std::to_string(off).substr(0, 4) +
            " rad away from its joints above the insertion's start";
      return false;
    } else if (off > kMaxSnap && (same_pose - last[i]).cwiseAbs().maxCoeff() <= kMaxSnap) {
      // The keyframe's joints up to turns of 2 pi: the same configuration.
      rebranch.push_back({i, same_pose});
      last[i] = same_pose;
    } else if (off > kMaxSnap) {
      if (KeyframeAccepts(holders[i], last[i], target, {})) {
        rebranch.push_back({i, last[i]});
      } else {
        why = Name(holders[i]) + " ends " + std::to_string(off).substr(0, 4) +
              " rad away from its keyframe joints, on another IK solution that does not fit "
              "the keyframe";
        return false;
      }
    } else {
      last[i] = goal_q[i];
    }
  }
  return true;
}

std::vector<std::vector<JointVector>> SegmentBuilder::CarryEdge(const std::vector<int>& holders,
                                                                const std::vector<JointVector>& q0,
                                                                const Iso3& X_a, const Iso3& X_b) {
  const Eigen::Quaterniond qa(X_a.linear());
  const Eigen::Quaterniond qb(X_b.linear());
  const double angle = qa.angularDistance(qb);
  const double dist = (X_b.translation() - X_a.translation()).norm();
  const int steps = std::max(
      2, static_cast<int>(std::ceil(std::max(dist / opt_.cartesian_step_m, 2 * angle / 0.02))));
  std::vector<std::function<Iso3(double)>> targets;
  for (int r : holders) {
    const PlanGrasp& g = state_.grasp[r];
    const Iso3 X_AT = w_.X_AP[g.part] * g.X_PG;
    targets.push_back([&, X_AT](double s) {
      Iso3 X = Iso3::Identity();
      X.linear() = qa.slerp(s, qb).toRotationMatrix();
      X.translation() = (1 - s) * X_a.translation() + s * X_b.translation();
      return X * X_AT;
    });
  }
  auto path = Track(holders, q0, targets, steps, nullptr);
  if (path.empty() || !PathClear(holders, path)) return {};
  return path;
}

std::vector<std::vector<JointVector>> SegmentBuilder::CarrySearch(
    const std::vector<int>& holders, const Iso3& X_start, const Iso3& X_goal,
    const std::vector<JointVector>& goal_q, const Keyframe& target,
    std::vector<std::pair<size_t, JointVector>>& rebranch, double* length, std::string& why) {
  struct Node {
    Iso3 X;
    std::vector<JointVector> q;
    int parent = -1;
  };
  auto metric = [](const Iso3& a, const Iso3& b) {
    return (a.translation() - b.translation()).norm() +
           0.15 * Eigen::Quaterniond(a.linear()).angularDistance(Eigen::Quaterniond(b.linear()));
  };
  std::vector<JointVector> q0;
  for (int r : holders) q0.push_back(cur_[r]);
  std::vector<Node> tree = {{X_start, q0, -1}};
  const Vec3 lo = X_start.translation().cwiseMin(X_goal.translation()) - Vec3(0.25, 0.25, 0.05);
  const Vec3 hi = X_start.translation().cwiseMax(X_goal.translation()) + Vec3(0.25, 0.25, 0.30);
  const Eigen::Quaterniond qs(X_start.linear());
  const Eigen::Quaterniond qg(X_goal.linear());
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n01(0.0, 1.0);
  const int budget = opt_.carry_edges << std::max(0, effort_ - 1);  // edges tried
  const auto t0 = std::chrono::steady_clock::now();
  constexpr double kStepM = 0.08;  // longest edge in the metric [m]
  constexpr int kMaxNodes = 4000;
  int goal_node = -1;
  std::vector<JointVector> goal_last;
  int edges = 0;
  std::string end_why;
  while (goal_node < 0 && static_cast<int>(tree.size()) < kMaxNodes && !ctx_.ShouldStop() &&
         edges < budget) {
    const bool to_goal = u(rng_) < 0.2;
    Iso3 X_rand = X_goal;
    if (!to_goal) {
      X_rand.translation() = lo + (hi - lo).cwiseProduct(Vec3(u(rng_), u(rng_), u(rng_)));
      // Orientations between the start's and the goal's, turned by up to ~0.6 rad.
      const Vec3 axis = Vec3(n01(rng_), n01(rng_), n01(rng_)).normalized();
      const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.6 * u(rng_), axis));
      X_rand.linear() = (turn * qs.slerp(u(rng_), qg)).toRotationMatrix();
    }
    int nearest = 0;
    double best = metric(tree[0].X, X_rand);
    for (size_t k = 1; k < tree.size(); ++k) {
      const double d = metric(tree[k].X, X_rand);
      if (d < best) {
        best = d;
        nearest = static_cast<int>(k);
      }
    }
    const bool reaches = best <= kStepM;
    Iso3 X_new = X_rand;
    if (!reaches) {
      const double f = kStepM / best;
      const Iso3& X_n = tree[nearest].X;
      X_new.translation() = X_n.translation() + f * (X_rand.translation() - X_n.translation());
      X_new.linear() = Eigen::Quaterniond(X_n.linear())
                           .slerp(f, Eigen::Quaterniond(X_rand.linear()))
                           .toRotationMatrix();
    }
    ++edges;
    auto edge = CarryEdge(holders, tree[nearest].q, tree[nearest].X, X_new);
    if (edge.empty()) continue;
    tree.push_back({X_new, edge.back(), nearest});
    if (to_goal && reaches) {
      std::vector<JointVector> last = edge.back();
      std::vector<std::pair<size_t, JointVector>> rb;
      if (CarryEnd(holders, goal_q, target, last, rb, end_why)) {
        goal_node = static_cast<int>(tree.size()) - 1;
      }
    }
  }
  if (ctx_.Logs("motion")) {
    ctx_.Log("motion",
             StrFormat("carry: search: %zu poses, %d edges tried, %.2f s, %s", tree.size(), edges,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                       goal_node >= 0 ? "reached" : "not reached"));
  }
  if (goal_node < 0) {
    why = "the goal pose was not reached from " + std::to_string(tree.size()) + " poses" +
          (end_why.empty() ? "" : " (" + end_why + ")");
    return {};
  }
  std::vector<int> chain;
  for (int k = goal_node; k >= 0; k = tree[k].parent) chain.push_back(k);
  std::reverse(chain.begin(), chain.end());
  // Shortcut greedily: from each pose, the farthest one along the chain it reaches directly.
  std::vector<std::vector<JointVector>> path = {q0};
  double total = 0.0;
  size_t at = 0;
  std::vector<JointVector> q = q0;
  while (at + 1 < chain.size()) {
    bool moved = false;
    for (size_t j = chain.size() - 1; j > at && !moved; --j) {
      auto edge = CarryEdge(holders, q, tree[chain[at]].X, tree[chain[j]].X);
      if (edge.empty()) continue;
      if (j + 1 == chain.size()) {
        std::vector<std::pair<size_t, JointVector>> rb;
        std::string w;
        if (!CarryEnd(holders, goal_q, target, edge.back(), rb, w)) continue;
        rebranch = std::move(rb);
      }
      total += metric(tree[chain[at]].X, tree[chain[j]].X);
      path.insert(path.end(), edge.begin() + 1, edge.end());
      q = path.back();
      at = j;
      moved = true;
    }
    if (!moved) {
      why = "the found path could not be retraced";
      return {};
    }
  }
  *length = total;
  return path;
}

}  // namespace wrap::detail
