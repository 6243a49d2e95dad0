// The task plan's makespan estimate (issue 33): each action lasts an estimated time by its type
// and starts as soon as its robots and its objects are done with their previous actions, so
// actions of different robots on different objects overlap, as the motion stage's schedule lets
// them. An assembly has two phases: the moved input's holders bring it to the approach pose
// (waiting only for the moved input), then the insertion (waiting for the base too), so the next
// part comes close while the previous insertion runs. Plans report it beside their action count
// (PlanStats::makespan_est_s); `--objective makespan` makes the task planner minimise it.
#pragma once

#include <span>
#include <vector>

#include "task/plan.h"

namespace wrap {

/// Estimated duration of an action of `type` [s]: the mean of the motion stage's segments per
/// action type (free paths, approaches, skills) over the stool, chair, cross, cube and Fabrica
/// beam plans of seed 0. An assembly's is both its phases.
double EstimatedDuration(ActionType type);

/// Estimated duration of an assembly's insertion phase [s] (the insertion and the grasps
/// closing); the rest of EstimatedDuration(kAssemble) brings the moved input to the approach.
double EstimatedInsertion();

/// When each robot and each object of a task plan is next free, were its actions run as early as
/// their robots and objects allow (their order kept per robot and per object).
class TaskClock {
 public:
  TaskClock() = default;
  /// Everything free at time 0: `robots` robots, `nodes` objects (the assembly tree's nodes).
  TaskClock(int robots, int nodes);

  /// Runs an action of `type` by `robots` on `objects` (PlanAction's: node ids, an assembly's
  /// moved, base, result) from the latest of their free times; returns its end [s]. The clock
  /// follows who holds what, to tell an assembly's moved input's holders from the base's.
  double Advance(ActionType type, std::span<const int> robots, std::span<const int> objects);
  /// Advance with a plan's action.
  double Advance(const PlanAction& action) {
    return Advance(action.type, action.robots, action.objects);
  }

  /// The end of the last action [s]: the estimated makespan.
  double makespan_s() const { return makespan_s_; }
  /// The sum of the actions' ends [s]: smaller when work runs at once (the search's tie-break
  /// among plans of one makespan).
  double completion_sum_s() const { return completion_sum_s_; }
  /// When robot `r` is free [s].
  double robot_free_s(int r) const { return free_s_[r]; }

 private:
  int robots_ = 0;
  std::vector<float> free_s_;  ///< Robots first, then objects [s].
  std::vector<int> held_;      ///< Per robot the object it holds, -1: none.
  double makespan_s_ = 0.0;
  double completion_sum_s_ = 0.0;
};

/// The clock after `actions` of a plan with `robots` robots and `nodes` objects.
TaskClock ClockAfter(std::span<const PlanAction> actions, int robots, int nodes);

/// The estimated makespan of `plan`'s actions [s] (0 without actions).
double EstimateMakespan(const Plan& plan);

}  // namespace wrap
