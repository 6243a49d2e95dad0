#include <optional>
#include <ostream>

#include "cli.h"
#include "grasp/preprocess.h"
#include "load.h"
#include "model/entity_path.h"
#include "task/plan_json.h"
#include "task/planner.h"

namespace wrap::cli {

namespace {

// Parts that no robot can pick where they start, by the planner's own pick checks on the
// project's grasp sets: warnings (the planner would say it only when a milestone fails).
Diagnostics StartPickWarnings(const LoadedProject& loaded, const std::string& project) {
  Diagnostics out;
  const Project& p = *loaded.project;
  PreprocessOptions options;
  options.project_file = project;
  RunContext ctx(p.planner.seed);
  auto pre = Preprocess(p, loaded.check, options, ctx);
  if (!pre) return out;  // planning will say why; validation has checked what it can
  TaskPlannerOptions task;
  task.project_file = project;
  auto unpickable = UnpickableAtStart(p, loaded.check, *pre, task);
  if (!unpickable) return out;
  for (const UnpickablePart& u : *unpickable) {
    out.Warning(project, "parts[" + std::to_string(u.part) + "].initial_pose", u.why);
  }
  return out;
}

void PrintDiagnostics(const Diagnostics& diags, const Project* project, bool errors_only,
                      std::ostream& err) {
  for (const Diagnostic& d : diags.items) {
    if (errors_only && d.severity != Severity::kError) continue;
    err << FormatNamed(d, project) << "\n";
  }
}

}  // namespace

int Validate(const std::string& project, const std::string& plan_file, bool quiet,
             std::ostream& out, std::ostream& err) {
  // The plan's own structure is checked before the project (and its meshes) is loaded.
  std::optional<Plan> plan;
  if (!plan_file.empty()) {
    auto read = ReadPlanFile(plan_file);
    if (!read) {
      err << read.error().message << "\n";
      return 2;
    }
    plan = std::move(*read);
  }
  GeometryReport geometry;
  LoadedProject loaded = LoadChecked(project, &geometry);
  if (loaded.ok()) loaded.check.diagnostics.Append(StartPickWarnings(loaded, project));
  const Diagnostics& diags = loaded.check.diagnostics;
  PrintDiagnostics(diags, loaded.project ? &*loaded.project : nullptr, quiet, err);
  if (!loaded.ok()) {
    if (!quiet) {
      err << project << ": invalid: " << diags.error_count() << " error(s), "
          << diags.warning_count() << " warning(s)\n";
    }
    return 2;
  }
  if (!quiet) {
    const Project& p = *loaded.project;
    out << project << ": valid: " << p.parts.size() << " parts, " << p.steps.size() << " steps, "
        << p.robots.size() << " robots, " << diags.warning_count() << " warning(s)\n";
  }
  if (!plan) return 0;
  if (!loaded.check.tree) {
    err << project << ": the project has no assembly DAG to replay a plan against\n";
    return 2;
  }
  if (auto ok = CheckPlanMatchesProject(*plan, *loaded.project, *loaded.check.tree, plan_file);
      !ok) {
    err << ok.error().message << "\n";
    return 2;
  }
  if (const int code = ReportPlanValidation(loaded, *plan, project, out, err); code != 0) {
    return code;
  }
  if (!plan->stats.motion) return 0;
  return ReportTrajectoryCheck(loaded, *plan, project, nullptr, out, err);
}

}  // namespace wrap::cli
