// The task plan's makespan estimate (makespan_estimate.h).
#include "task/makespan_estimate.h"

#include <algorithm>

namespace wrap {

double EstimatedDuration(ActionType type) {
  // Rounded means of the seconds the motion stage's segments of each action took (2026-12-03);
  // a release is short because the robot's way home belongs to its next action's free path.
  switch (type) {
    case ActionType::kPick:
      return 3.5;
    case ActionType::kPlace:
      return 5.0;
    case ActionType::kHandover:
      return 5.5;
    case ActionType::kAddGrasp:
      return 5.0;
    case ActionType::kRelease:
      return 1.0;
    case ActionType::kAssemble:
      return 7.0;
  }
  return 0.0;
}

double EstimatedInsertion() { return 2.0; }

TaskClock::TaskClock(int robots, int nodes)
    : robots_(robots),
      free_s_(static_cast<size_t>(robots + nodes), 0.0f),
      held_(static_cast<size_t>(robots), -1) {}

double TaskClock::Advance(ActionType type, std::span<const int> robots,
                          std::span<const int> objects) {
  float end = 0.0f;
  if (type == ActionType::kAssemble && objects.size() == 3) {
    // The moved input's holders bring it to the approach pose, whatever the base does; the
    // insertion then waits for the base and the base's holders.
    const int moved = objects[0], base = objects[1];
    float start = free_s_[robots_ + moved];
    for (int r : robots) {
      if (held_[r] == moved) start = std::max(start, free_s_[r]);
    }
    float insert = start + static_cast<float>(EstimatedDuration(type) - EstimatedInsertion());
    insert = std::max(insert, free_s_[robots_ + base]);
    for (int r : robots) {
      if (held_[r] != moved) insert = std::max(insert, free_s_[r]);
    }
    end = insert + static_cast<float>(EstimatedInsertion());
  } else {
    float start = 0.0f;
    for (int r : robots) start = std::max(start, free_s_[r]);
    for (int o : objects) start = std::max(start, free_s_[robots_ + o]);
    end = start + static_cast<float>(EstimatedDuration(type));
  }
  for (int r : robots) free_s_[r] = end;
  for (int o : objects) free_s_[robots_ + o] = end;
  // Who holds what afterwards (plan.h's semantics of each action).
  const int object = objects.empty() ? -1 : objects.back();
  switch (type) {
    case ActionType::kPick:
    case ActionType::kAddGrasp:
      for (int r : robots) held_[r] = object;
      break;
    case ActionType::kHandover:
      if (robots.size() == 2) {
        held_[robots[0]] = -1;
        held_[robots[1]] = object;
      }
      break;
    case ActionType::kPlace:
    case ActionType::kRelease:
      for (int r : robots) held_[r] = -1;
      break;
    case ActionType::kAssemble:
      for (int r : robots) held_[r] = object;
      break;
  }
  makespan_s_ = std::max(makespan_s_, static_cast<double>(end));
  completion_sum_s_ += end;
  return end;
}

TaskClock ClockAfter(std::span<const PlanAction> actions, int robots, int nodes) {
  TaskClock clock(robots, nodes);
  for (const PlanAction& a : actions) clock.Advance(a);
  return clock;
}

double EstimateMakespan(const Plan& plan) {
  return ClockAfter(plan.actions, static_cast<int>(plan.robots.size()),
                    static_cast<int>(plan.nodes.size()))
      .makespan_s();
}

}  // namespace wrap
