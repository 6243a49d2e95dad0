// Helpers of the task planner's tests: example project files, preprocessing, a plan replayed by
// the independent validator.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "grasp/preprocess.h"
#include "model/validate.h"
#include "task/plan_validator.h"
#include "task/planner.h"

namespace wrap {

namespace fs = std::filesystem;

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
  ctx.set_time_limit_s(time_limit_s);
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

}  // namespace wrap
