// The plan state before and after an action (see plan_state.h).
#include "task/plan_state.h"

#include <algorithm>

namespace wrap {

namespace {

// Robot k of `action` when the action names it and it is a robot of `state`, else -1.
int RobotOf(const PlanState& state, const PlanAction& action, size_t k) {
  if (k >= action.robots.size()) return -1;
  const int r = action.robots[k];
  return r >= 0 && r < static_cast<int>(state.held.size()) ? r : -1;
}

// Robot k of `action` closes its listed grasp on the action's object.
void Close(PlanState& state, const PlanAction& action, size_t k) {
  const int r = RobotOf(state, action, k);
  if (r < 0 || k >= action.grasps.size() || action.objects.empty()) return;
  state.held[r] = action.objects[0];
  state.grasp[r] = action.grasps[k].grasp;
}

// Robot k of `action` lets go of what it holds.
void LetGo(PlanState& state, const PlanAction& action, size_t k) {
  if (const int r = RobotOf(state, action, k); r >= 0) state.held[r] = -1;
}

void SetResting(PlanState& state, const PlanAction& action, bool resting) {
  if (action.objects.empty()) return;
  if (auto it = state.objects.find(action.objects[0]); it != state.objects.end()) {
    it->second.resting = resting;
  }
}

// Assemble (M, B -> S): S takes B's place, and the holders of M and B hold S.
void Join(PlanState& state, const PlanAction& action) {
  if (action.objects.size() < 3) return;
  const int m = action.objects[0];
  const int b = action.objects[1];
  const int result = action.objects[2];
  PlanObject merged;
  if (auto it = state.objects.find(b); it != state.objects.end()) merged = it->second;
  merged.node = result;
  for (int& h : state.held) {
    if (h == m || h == b) h = result;
  }
  state.objects.erase(m);
  state.objects.erase(b);
  state.objects[result] = merged;
}

}  // namespace

std::vector<int> PlanState::Holders(int node) const {
  std::vector<int> out;
  for (size_t r = 0; r < held.size(); ++r) {
    if (held[r] == node) out.push_back(static_cast<int>(r));
  }
  return out;
}

PlanState InitialPlanState(const Keyframe& initial, int n_robots) {
  PlanState s;
  s.held.assign(std::max(0, n_robots), -1);
  s.grasp.assign(std::max(0, n_robots), PlanGrasp{});
  for (const PlanObject& o : initial.objects) s.objects[o.node] = o;
  return s;
}

PlanState StateAtKeyframe(const PlanState& before, const PlanAction& action) {
  PlanState s = before;
  // The objects it acts on where its keyframe has them.
  for (const PlanObject& o : action.keyframe.objects) {
    if (std::find(action.objects.begin(), action.objects.end(), o.node) == action.objects.end()) {
      continue;
    }
    if (auto it = s.objects.find(o.node); it != s.objects.end()) it->second.X_WA = o.X_WA;
  }
  // Every robot it names with the grasp it lists for it.
  for (size_t k = 0; k < action.grasps.size(); ++k) {
    if (const int r = RobotOf(s, action, k); r >= 0) s.grasp[r] = action.grasps[k].grasp;
  }
  switch (action.type) {
    case ActionType::kPick:
    case ActionType::kAddGrasp:
      Close(s, action, 0);
      break;
    case ActionType::kHandover:
      Close(s, action, 1);
      break;
    case ActionType::kPlace:
    case ActionType::kRelease:
    case ActionType::kAssemble:
      break;
  }
  return s;
}

PlanState ApplyAction(const PlanState& before, const PlanAction& action) {
  PlanState s = StateAtKeyframe(before, action);
  switch (action.type) {
    case ActionType::kPick:
      SetResting(s, action, false);
      break;
    case ActionType::kPlace:
      LetGo(s, action, 0);
      SetResting(s, action, true);
      break;
    case ActionType::kRelease:
    case ActionType::kHandover:
      LetGo(s, action, 0);
      break;
    case ActionType::kAddGrasp:
      break;
    case ActionType::kAssemble:
      Join(s, action);
      break;
  }
  return s;
}

std::vector<PlanState> ReplayPlanStates(const Plan& plan) {
  std::vector<PlanState> out;
  out.reserve(plan.actions.size() + 1);
  out.push_back(InitialPlanState(plan.initial, static_cast<int>(plan.robots.size())));
  for (const PlanAction& a : plan.actions) out.push_back(ApplyAction(out.back(), a));
  return out;
}

}  // namespace wrap
