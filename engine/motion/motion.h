// Motion of one task plan (paper §IV-E, §IV-F): the geometric motion (free paths and skills) at
// an effort level, then retiming into per-robot trajectories that run concurrently where the
// robots do not depend on each other. The front door of the motion stage (its options, request,
// failure record and path cache are in motion_options.h, included here).
#pragma once

#include <optional>

#include "core/result.h"
#include "core/run_context.h"
#include "motion/motion_options.h"
#include "motion/scene.h"
#include "task/plan.h"
#include "task/world.h"

namespace wrap {

/// What one motion attempt gave.
struct MotionAttempt {
  bool solved = false;    ///< Trajectories were made (plan updated).
  MotionFailure failure;  ///< Otherwise which segment failed and whether to retry with more effort.
  double t_mp_s = 0.0;    ///< Geometric motion [s].
  double t_retime_s = 0.0;  ///< Retiming [s].
};

/// Plans the motion of `plan` at effort level request.effort (the searches' work budgets,
/// options.segment_checks and carry_edges, double per level) with the path searches seeded by
/// request.seed; `cache` keeps the paths solved by earlier attempts on the same plan. On success
/// fills plan.trajectories, plan.segments, every action's start_s and end_s, and the stats'
/// makespan_s, makespan_sequential_s, motion_segments and motion = true.
///
/// With options.self_check, timed trajectories that fail the independent check are not kept:
/// the attempt fails (segment "timed", not to be retried) naming the first issue.
///
/// `scene` (may be null) keeps the motion scene of `world` between attempts: built by the first
/// (when empty), its collision cells are not built again.
///
/// Fails with kCancelled when ctx is cancelled, kInvalidInput when the plan does not fit the world.
[[nodiscard]] Result<MotionAttempt> PlanMotion(const TaskWorld& world, Plan& plan,
                                               const MotionOptions& options,
                                               const MotionRequest& request, MotionCache& cache,
                                               RunContext& ctx,
                                               std::optional<MotionScene>* scene = nullptr);

}  // namespace wrap
