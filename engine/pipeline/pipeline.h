// The planner as one call (paper Algorithm 1, "High level search of WRAP"): task plans from the
// task planner (NextTaskPlan), each with its keyframes optimised jointly, queued with an effort
// level; the motion planner takes the queued plan with the least effort (SelectFairly), and a plan
// whose free path search spends its work budget is suspended and retried later with twice it,
// while further task plans join the queue. The first plan with motion is returned. PlanProject
// adds the preprocessing in front: the one call of the CLI's `wrap plan` and the GUI's planner job.
#pragma once

#include <cstdint>
#include <expected>
#include <functional>

#include "core/result.h"
#include "core/run_context.h"
#include "grasp/preprocess.h"
#include "model/project.h"
#include "model/validate.h"
#include "motion/keyframe_opt.h"
#include "motion/motion.h"
#include "task/plan.h"
#include "task/planner.h"

namespace wrap {

/// Options of PlanAssembly.
struct PipelineOptions {
  TaskPlannerOptions task;         ///< The task planner's.
  MotionOptions motion;            ///< The motion planner's.
  KeyframeOptOptions keyframes;    ///< Joint keyframe optimisation's.
  bool task_only = false;          ///< Stop after the task plan (no keyframe optimisation, motion).
  bool optimize_keyframes = true;  ///< Run the joint keyframe optimisation before motion.
  int max_task_plans = 32;  ///< Task plans the loop may ask for (the first with ctx's generator).
  /// Scale of the motion searches' work budgets (MotionOptions::segment_checks, carry_edges):
  /// 2 searches twice as long before a plan is suspended or given up. The run's time limit
  /// (ctx's deadline) stays wall-clock, an outer bound; the budgets decide the plan.
  double budget = 1.0;
  /// The run's seed (ctx's): recorded in the stats; further task plans and the motion planner's
  /// sampling derive their seeds from it.
  std::uint64_t seed = 0;
};

/// Plans `project` end to end. The plan's stats say whether it was solved; when the task plan was
/// found but no motion, solved is false and stats.failure names the action and segment that could
/// not be planned and why (the plan keeps its keyframes). Stage times: the task planner's, "kf",
/// "mp", "retime". Fails like PlanTask (kInvalidInput, kCancelled).
[[nodiscard]] Result<Plan> PlanAssembly(const Project& project, const ProjectCheck& check,
                                        const Preprocessed& pre, const PipelineOptions& options,
                                        RunContext& ctx);

/// Options of PlanProject: preprocessing's, the pipeline's, and a hook between the two.
struct ProjectPlanOptions {
  PreprocessOptions preprocess;  ///< Preprocess's.
  PipelineOptions pipeline;      ///< PlanAssembly's.
  /// Called with preprocessing's result before planning starts (e.g. to show its warnings while
  /// the planner runs); may be empty.
  std::function<void(const Preprocessed&)> on_preprocessed;
};

/// What PlanProject made.
struct ProjectPlan {
  Preprocessed pre;       ///< Preprocessing's result (a trajectory check can reuse it).
  Plan plan;              ///< PlanAssembly's plan (solved or not: see its stats).
  double t_plan_s = 0.0;  ///< Wall-clock time of PlanAssembly alone [s].
};

/// A failure of PlanProject, with the stage it came from.
struct ProjectPlanError {
  /// Where the run failed.
  enum class Stage {
    kPreprocess,  ///< Preprocess failed.
    kPlan,        ///< PlanAssembly failed, or the run was cancelled before it started.
  };
  Stage stage = Stage::kPlan;  ///< Where.
  Error error;                 ///< The stage's error.
};

/// Preprocesses and plans `project` (`check` from its validation) in one call: reports the
/// progress stage "preprocess", runs Preprocess, stops with kCancelled if ctx is cancelled by
/// then, calls on_preprocessed, reports the stage "task" and runs PlanAssembly, with ctx
/// throughout. Fails like Preprocess (stage kPreprocess) and PlanAssembly (stage kPlan).
[[nodiscard]] std::expected<ProjectPlan, ProjectPlanError> PlanProject(
    const Project& project, const ProjectCheck& check, const ProjectPlanOptions& options,
    RunContext& ctx);

}  // namespace wrap
