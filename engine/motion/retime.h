// Retiming (paper §IV-F): every segment is timed along its own geometric path within the joint
// velocity and acceleration limits of its robots (a trapezoidal profile per straight piece, the
// robots of one segment in step; skills no faster than their TCP speed), then the segments are
// scheduled in plan order, each as early as its robots, its objects and its real timed conflicts
// allow: it waits for the previous segment of each of its robots, for earlier segments that
// touch one of its objects (events on one object keep their order), and, beyond that, only as
// long as its timed motion, or its robots' rest at its end, would collide with the timed motion
// of what was placed before it (other robots, what they carry, objects where the schedule has
// them at that moment). Robots therefore synchronise only at the events that involve them (a
// handover, an insertion, a brace) and where their motions would collide; unrelated robots keep
// moving.
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
  /// Per input segment: 1 when it starts before everything scheduled before it has ended.
  std::vector<char> segment_concurrent;
  double makespan_s = 0.0;             ///< Everything done, robots moving concurrently.
  double makespan_sequential_s = 0.0;  ///< Same segments one at a time.
  int dependencies = 0;                ///< Segments whose start waited for another.
  int collision_waits = 0;             ///< ... for a timed conflict with another.
  int candidates = 0;                  ///< Start times the schedule tried.
  int checked_candidates = 0;          ///< ... that needed the timed collision test.
  long long check_samples = 0;         ///< Moments that test posed.
};

/// Times the geometric motion `segments` of `plan` (from PlanGeometricMotion, in its order) and
/// schedules it with `options`; `log` (may be null) gets, under "motion", what each segment
/// waits for; `scene` (may be null: Retime builds one) is a motion scene of `world` to pose the
/// timeline in, kept by callers that retime the same world again (its cells are built once). The
/// segments' sweeps (GeoSegment::sweep) only spare the collision test where they never meet; a
/// segment without one is tested wherever it overlaps another in time. Deterministic. Fails with
/// kInvalidInput when a segment's robots or waypoints do not fit the world or the motion scene does
/// not build.
[[nodiscard]] Result<Timing> Retime(const TaskWorld& world, const Plan& plan,
                                    const std::vector<GeoSegment>& segments,
                                    const RetimeOptions& options = {},
                                    const RunContext* log = nullptr, MotionScene* scene = nullptr);

}  // namespace wrap
