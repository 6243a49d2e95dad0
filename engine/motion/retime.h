// Retiming (paper §IV-F): every segment is timed along its own geometric path within the joint
// velocity and acceleration limits of its robots (a trapezoidal profile per straight piece, the
// robots of one segment in step; skills no faster than their TCP speed), then segments are
// scheduled as early as their dependencies allow: a segment waits for the previous segment of each
// of its robots, for earlier segments that touch one of its objects, and for earlier segments
// whose swept boxes meet its own. Robots therefore synchronise only at the events that involve
// them (a handover, an insertion, a brace) and where their motions could collide; unrelated robots
// keep moving.
#pragma once

#include <vector>

#include "core/result.h"
#include "core/run_context.h"
#include "motion/segments.h"
#include "task/plan.h"
#include "task/world.h"

namespace wrap {

/// What Retime gives.
struct Timing {
  std::vector<RobotTrajectory> trajectories;  ///< One per robot, from t = 0 to the makespan.
  std::vector<MotionSegment> segments;        ///< The segments with their times, by start.
  std::vector<double> action_start_s;         ///< Per action: first motion toward it [s].
  std::vector<double> action_end_s;           ///< Per action: its keyframe moment [s].
  /// Per input segment (the order of `segments` given to Retime): its start and end [s].
  std::vector<double> segment_start_s, segment_end_s;
  /// Per input segment: how much slower than its fastest timing it runs (skill speed, slow).
  std::vector<double> segment_stretch;
  double makespan_s = 0.0;             ///< Everything done, robots moving concurrently.
  double makespan_sequential_s = 0.0;  ///< Same segments one at a time.
  int dependencies = 0;                ///< Ordering constraints the schedule kept.
};

/// Times the geometric motion `segments` of `plan` (from PlanGeometricMotion); `log` (may be
/// null) gets, under "motion", what each segment waits for. Fails with kInvalidInput when a
/// segment's robots or waypoints do not fit the world.
[[nodiscard]] Result<Timing> Retime(const TaskWorld& world, const Plan& plan,
                                    const std::vector<GeoSegment>& segments,
                                    const RunContext* log = nullptr);

}  // namespace wrap
