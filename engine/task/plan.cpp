#include "task/plan.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <utility>

namespace wrap {

namespace {

constexpr std::array<std::pair<ActionType, std::string_view>, 6> kActionNames = {{
    {ActionType::kPick, "pick"},
    {ActionType::kPlace, "place"},
    {ActionType::kHandover, "handover"},
    {ActionType::kAddGrasp, "add_grasp"},
    {ActionType::kRelease, "release"},
    {ActionType::kAssemble, "assemble"},
}};

// A name from one of the plan's lists, or a placeholder that shows the bad index (the words of
// a broken plan must still be printable).
std::string NameAt(const std::vector<std::string>& names, int i, const char* what) {
  if (i >= 0 && static_cast<size_t>(i) < names.size()) return names[i];
  return std::string(what) + " #" + std::to_string(i);
}

std::string Robot(const Plan& plan, int r) { return NameAt(plan.robots, r, "robot"); }

std::string Object(const Plan& plan, int node) {
  return "'" + NameAt(plan.nodes, node, "node") + "'";
}

std::string RobotAt(const Plan& plan, const PlanAction& a, size_t k) {
  return k < a.robots.size() ? Robot(plan, a.robots[k]) : std::string("?");
}

std::string ObjectAt(const Plan& plan, const PlanAction& a, size_t k) {
  return k < a.objects.size() ? Object(plan, a.objects[k]) : std::string("'?'");
}

// "grasp 7", or "grasp 7 of 'leg1'" when the grasp was drawn from another subassembly's set
// than that of the object it holds.
std::string GraspWords(const Plan& plan, const PlanAction& a, size_t k, int object) {
  if (k >= a.grasps.size()) return "grasp ?";
  const PlanGrasp& g = a.grasps[k].grasp;
  std::string words = "grasp " + std::to_string(g.index);
  if (g.subassembly != object) words += " of " + Object(plan, g.subassembly);
  return words;
}

// Whether `node` rests on the table at `keyframe`.
bool RestsAt(const Keyframe& keyframe, int node) {
  for (const PlanObject& o : keyframe.objects) {
    if (o.node == node) return o.resting;
  }
  return false;
}

}  // namespace

std::string_view ToString(ActionType type) {
  for (const auto& [t, name] : kActionNames) {
    if (t == type) return name;
  }
  return "unknown";
}

std::optional<ActionType> ActionTypeFromString(std::string_view word) {
  for (const auto& [t, name] : kActionNames) {
    if (name == word) return t;
  }
  return std::nullopt;
}

std::string DescribeAction(const Plan& plan, const PlanAction& action) {
  const int object = action.objects.empty() ? -1 : action.objects.front();
  const std::string r0 = RobotAt(plan, action, 0);
  const std::string o = ObjectAt(plan, action, 0);
  switch (action.type) {
    case ActionType::kPick:
      return r0 + " picks " + o + " (" + GraspWords(plan, action, 0, object) + ")";
    case ActionType::kPlace: {
      std::string words = r0 + " places " + o + " on the table";
      if (action.placement) {
        const PlanPlacement& p = *action.placement;
        words += " (placement " + std::to_string(p.placement) + ", slot " + std::to_string(p.slot) +
                 ", yaw " + std::to_string(p.yaw) + ")";
      }
      return words;
    }
    case ActionType::kHandover:
      return r0 + " hands " + o + " over to " + RobotAt(plan, action, 1) + " (" +
             GraspWords(plan, action, 0, object) + " -> " + GraspWords(plan, action, 1, object) +
             ")";
    case ActionType::kAddGrasp:
      return r0 + " adds " + GraspWords(plan, action, 0, object) + " on " + o +
             (RestsAt(action.keyframe, object) ? " (brace)" : "");
    case ActionType::kRelease:
      return r0 + " releases " + o;
    case ActionType::kAssemble: {
      std::string holders;
      for (size_t k = 0; k < action.robots.size(); ++k) {
        holders += (k ? ", " : "") + Robot(plan, action.robots[k]);
      }
      return "assembles " + o + " onto " + ObjectAt(plan, action, 1) + " -> " +
             ObjectAt(plan, action, 2) + " (held by " + (holders.empty() ? "nobody" : holders) +
             ")";
    }
  }
  return "unknown action";
}

namespace {
// Index of the last knot at or before t (0 when t is before the first).
size_t KnotBefore(const RobotTrajectory& trajectory, double t) {
  const auto& k = trajectory.knots;
  auto it = std::upper_bound(k.begin(), k.end(), t,
                             [](double v, const TrajectoryKnot& knot) { return v < knot.t; });
  return it == k.begin() ? 0 : static_cast<size_t>(it - k.begin()) - 1;
}
}  // namespace

JointVector SampleTrajectory(const RobotTrajectory& trajectory, double t, JointVector* qd) {
  const auto& k = trajectory.knots;
  assert(!k.empty());
  if (t <= k.front().t || k.size() == 1) {
    if (qd) *qd = JointVector::Zero(k.front().q.size());
    return k.front().q;
  }
  if (t >= k.back().t) {
    if (qd) *qd = JointVector::Zero(k.back().q.size());
    return k.back().q;
  }
  const size_t i = KnotBefore(trajectory, t);
  const TrajectoryKnot& a = k[i];
  const TrajectoryKnot& b = k[i + 1];
  const double span = b.t - a.t;
  const double tau = t - a.t;
  if (span <= 0.0) {
    if (qd) *qd = b.qd;
    return b.q;
  }
  const JointVector acc = (b.qd - a.qd) / span;
  if (qd) *qd = a.qd + acc * tau;
  return a.q + a.qd * tau + 0.5 * acc * tau * tau;
}

double OpeningAt(const RobotTrajectory& trajectory, double t) {
  if (trajectory.knots.empty()) return -1.0;
  return trajectory.knots[KnotBefore(trajectory, t)].opening_m;
}

}  // namespace wrap
