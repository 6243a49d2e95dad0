// Helpers of the task planner's tests: example project files, preprocessing, a plan replayed by
// the independent validator.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "grasp/preprocess.h"
#include "model/validate.h"
#include "robot/cell.h"
#include "task/keyframes.h"
#include "task/plan_validator.h"
#include "task/planner.h"
#include "task/world.h"

namespace wrap {

namespace fs = std::filesystem;

// How much longer the tests' time limits and search budgets are in an AddressSanitizer build,
// which runs the planner several times slower: the limits are there to bound a hang, not to
// measure speed (BENCHMARKS.md does that).
#if defined(__SANITIZE_ADDRESS__)
inline constexpr double kTimeScale = 5.0;
#else
inline constexpr double kTimeScale = 1.0;
#endif

// No wall-clock limit: the task planner's searches are bounded by work (nodes, effort levels,
// IK restarts), so a test's outcome does not depend on the machine's load; ctest's timeout
// catches a hang. (Tests of the time limit itself, and --optimize, which improves until its time
// limit, set one.)
inline constexpr double kNoTimeLimit = 0.0;

inline fs::path ProjectFile(const std::string& name) {
  return fs::path(WRAP_SOURCE_DIR) / "projects" / (name + ".json");
}

// Preprocesses `lp`'s project with the default options (seed 0).
inline Result<Preprocessed> PreprocessProject(const LoadedProject& lp, const fs::path& file) {
  RunContext ctx(0);
  PreprocessOptions options;
  options.project_file = file;
  return Preprocess(*lp.project, lp.check, options, ctx);
}

struct PlanRun {
  Result<Plan> plan = Fail(ErrorCode::kInternal, "not run");
  std::optional<PlanValidation> validation;
};

// Preprocesses and plans `project` (already loaded and checked), then validates the plan.
inline PlanRun PlanAndValidate(const Project& project, const ProjectCheck& check,
                               const fs::path& file, std::uint64_t seed, double time_limit_s,
                               const TaskPlannerOptions& base_options = {}) {
  PlanRun run;
  RunContext ctx(seed);
  ctx.set_time_limit_s(time_limit_s * kTimeScale);
  PreprocessOptions pre_options;
  pre_options.project_file = file;
  auto pre = Preprocess(project, check, pre_options, ctx);
  if (!pre) {
    run.plan = std::unexpected(pre.error());
    return run;
  }
  TaskPlannerOptions options = base_options;
  options.project_file = file;
  run.plan = PlanTask(project, check, *pre, options, ctx);
  if (run.plan && run.plan->stats.solved) {
    PlanValidationOptions v;
    v.wrench_mode = options.wrench_mode;
    v.force_scale = options.force_scale;
    auto validation = ValidatePlan(project, check, *run.plan, v, file);
    if (validation) run.validation = *validation;
  }
  return run;
}

inline std::string Issues(const PlanValidation& v) {
  std::string out;
  for (const PlanIssue& i : v.issues) out += FormatIssue(i) + "\n";
  return out;
}

// The planner's pieces for one example project as PlanTask sets them up: the task world, the
// tables and the keyframe solver (which keeps references to the rig's members: do not move it).
struct SolverRig {
  LoadedProject lp;
  std::optional<Preprocessed> pre;
  std::optional<TaskWorld> world;
  TaskTables tables;
  TaskCounters counters;
  TaskPlannerOptions options;
  std::optional<KeyframeSolver> solver;

  // Empty when built, else what failed.
  std::string Build(const std::string& project) {
    const fs::path file = ProjectFile(project);
    lp = LoadProject(file);
    if (!lp.ok()) return project + ": does not load";
    auto p = PreprocessProject(lp, file);
    if (!p) return p.error().message;
    pre = std::move(*p);
    auto w = BuildTaskWorld(*lp.project, lp.check, *pre, file);
    if (!w) return w.error().message;
    world = std::move(*w);
    CellOptions cell_options;
    cell_options.objects_touch_table = false;
    auto cell = Cell::Build(world->cell_def, cell_options);
    if (!cell) return cell.error().message;
    options.project_file = file;
    solver.emplace(*world, tables, options, std::move(*cell), counters);
    return {};
  }
};

}  // namespace wrap
