// The independent check of a plan's timed trajectories (paper §IV-F): it reads only the plan
// (keyframes, action times, the declared skill windows, the trajectories) and the robot and part
// models, replays who holds what over time with its own code (not the motion planner's scene), and
// samples the trajectories densely. Tests and `wrap plan --validate` use it.
#pragma once

#include <string>
#include <vector>

#include "core/result.h"
#include "core/run_context.h"
#include "task/plan.h"
#include "task/world.h"

namespace wrap {

/// Options of CheckTrajectories.
struct TrajectoryCheckOptions {
  /// Collisions are checked at states no farther apart than this in any joint of any robot
  /// [rad]: the joint-space resolution of the dense check.
  double resolution_rad = 0.02;
  /// Relative slack on the velocity and acceleration limits (rounding).
  double limit_slack = 1e-6;
  /// A robot at an event is at its keyframe joints within this [rad].
  double joint_tolerance = 1e-6;
  /// A co-holder's TCP stays this close to its grasp on the object the carrier moves [m, rad].
  double grasp_tolerance_m = 3e-3;
  double grasp_tolerance_rad = 3e-2;
  /// An object may touch the table top from above within this [m].
  double table_tolerance_m = 2e-3;
  bool check_collisions = true;  ///< Run the dense collision check (the expensive part).
  /// Gets, under "motion", the objects' state at each collision found (null: nowhere).
  const RunContext* log = nullptr;
};

/// One thing wrong with the trajectories.
struct TrajectoryIssue {
  double t = 0.0;  ///< When [s] (-1: not tied to a moment).
  int robot = -1;  ///< Robot concerned, or -1.
  /// "format" (knots), "limits" (position, velocity, acceleration), "continuity" (knots that do
  /// not join), "start", "end", "event" (a robot away from its keyframe at its action's moment,
  /// events out of order), "grasp" (a co-holder away from its grasp), "collision".
  std::string check;
  std::string message;  ///< In words, with names.
};

/// What CheckTrajectories found.
struct TrajectoryCheck {
  bool valid = false;                   ///< No issue.
  std::vector<TrajectoryIssue> issues;  ///< Every issue (collisions: the first per pair of bodies).
  int samples = 0;                      ///< Moments checked for collisions.
  long long collision_checks = 0;       ///< Cell collision queries.
  double max_velocity_ratio = 0.0;      ///< Largest |qd| / limit over all joints and knots.
  double max_acceleration_ratio = 0.0;  ///< Largest |qdd| / limit.
  double makespan_s = 0.0;              ///< End of the trajectories [s].
};

/// One line: "t=3.20 s: ur5e_a: collision: ...".
std::string FormatTrajectoryIssue(const Plan& plan, const TrajectoryIssue& issue);

/// Checks `plan.trajectories` against the plan and the models of `world`: one trajectory per
/// robot, knots in time order from 0 to one common end; every stretch of constant acceleration
/// consistent with its ends; joint positions (at knots and at turning points), velocities and
/// accelerations within the chain's limits; each robot starts at the initial keyframe and ends at
/// rest there (home); at each action's end_s its robots are at its keyframe joints, and each
/// robot's and object's events happen in plan order; while an object is held by several robots
/// their TCPs keep their grasps; and, sampled at the resolution, nothing collides (allowed: a
/// held part and its holders' grippers, the parts of one object, an object touching the table
/// from above, the two inputs of an insertion during its insert window, a gripper and the object
/// of its approach or retreat window). Fails with kInvalidInput when the plan has no trajectories
/// or names robots or nodes the world lacks.
[[nodiscard]] Result<TrajectoryCheck> CheckTrajectories(const TaskWorld& world, const Plan& plan,
                                                        const TrajectoryCheckOptions& options = {});

}  // namespace wrap
