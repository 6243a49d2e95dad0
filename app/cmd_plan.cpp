#include <chrono>
#include <cstdio>
#include <optional>
#include <ostream>

#include "cli.h"
#include "core/run_context.h"
#include "grasp/preprocess.h"
#include "load.h"
#include "motion/trajectory_check.h"
#include "pipeline/pipeline.h"
#include "task/plan_json.h"
#include "task/plan_validator.h"
#include "task/planner.h"
#include "task/world.h"

namespace wrap::cli {

int ReportPlanValidation(const LoadedProject& loaded, const Plan& plan, const std::string& project,
                         std::ostream& out, std::ostream& err) {
  PlanValidationOptions vopt;
  if (plan.stats.wrench_mode == "gravity") {
    vopt.wrench_mode = MatingWrenchMode::kGravityOnly;
  } else if (plan.stats.wrench_mode == "none") {
    vopt.wrench_mode = MatingWrenchMode::kNone;
  }
  vopt.force_scale = plan.stats.force_scale;
  auto v = ValidatePlan(*loaded.project, loaded.check, plan, vopt, project);
  if (!v) {
    err << "validation: " << v.error().message << "\n";
    return ExitCodeFor(v.error().code);
  }
  if (!v->valid) {
    err << "Validation FAILED: " << v->issues.size() << " issue(s)\n";
    for (const PlanIssue& issue : v->issues) err << "  " << FormatIssue(issue) << "\n";
    return 1;
  }
  out << "Validated: " << v->actions << " actions, " << v->keyframes << " keyframes, "
      << v->collision_checks << " collision queries, " << v->wrench_checks
      << " wrench gates re-solved\n";
  return 0;
}

int ReportTrajectoryCheck(const LoadedProject& loaded, const Plan& plan, const std::string& project,
                          const Preprocessed* pre, std::ostream& out, std::ostream& err) {
  std::optional<Preprocessed> own;
  if (pre == nullptr) {
    RunContext ctx(plan.stats.seed);
    PreprocessOptions pre_options;
    pre_options.project_file = project;
    auto made = wrap::Preprocess(*loaded.project, loaded.check, pre_options, ctx);
    if (!made) {
      err << project << ": " << made.error().message << "\n";
      return ExitCodeFor(made.error().code);
    }
    own = std::move(*made);
    pre = &*own;
  }
  auto world = BuildTaskWorld(*loaded.project, loaded.check, *pre, project);
  if (!world) {
    err << project << ": " << world.error().message << "\n";
    return ExitCodeFor(world.error().code);
  }
  TrajectoryCheckOptions topt;
  auto check = CheckTrajectories(*world, plan, topt);
  if (!check) {
    err << "trajectory check: " << check.error().message << "\n";
    return ExitCodeFor(check.error().code);
  }
  if (!check->valid) {
    err << "Trajectory check FAILED: " << check->issues.size() << " issue(s)\n";
    for (const TrajectoryIssue& issue : check->issues) {
      err << "  " << FormatTrajectoryIssue(plan, issue) << "\n";
    }
    return 1;
  }
  out << "Trajectories checked: " << check->samples << " moments at "
      << Fmt("%g", topt.resolution_rad) << " rad joint resolution, limits (peak "
      << Fmt("%.0f", 100 * check->max_velocity_ratio) << "% of velocity, "
      << Fmt("%.0f", 100 * check->max_acceleration_ratio)
      << "% of acceleration), events and grasps: no issue\n";
  return 0;
}

int PlanCommand(const PlanArgs& args, std::ostream& out, std::ostream& err) {
  TaskPlannerOptions options;
  options.project_file = args.project;
  const Result<PlannerVariant> variant = ParsePlannerVariant(args.planner);
  if (!variant) {
    err << variant.error().message << "\n";
    return ExitCodeFor(variant.error().code);
  }
  options.planner = *variant;
  options.optimize = args.optimize;
  const Result<PlanObjective> objective = ParsePlanObjective(args.objective);
  if (!objective) {
    err << "--objective: " << objective.error().message << "\n";
    return ExitCodeFor(objective.error().code);
  }
  options.objective = *objective;
  options.memory_limit_mb = args.memory_limit_mb;
  if (args.wrench == "full") {
    options.wrench_mode = MatingWrenchMode::kFull;
  } else if (args.wrench == "gravity") {
    options.wrench_mode = MatingWrenchMode::kGravityOnly;
  } else if (args.wrench == "none") {
    options.wrench_mode = MatingWrenchMode::kNone;
  } else {
    err << "--wrench: '" << args.wrench << "' is not one of full, gravity, none\n";
    return 2;
  }
  if (!(args.force_scale >= 0.0) || args.force_scale > 1e6) {
    err << "--force-scale: must be a number in [0, 1e6], got " << args.force_scale << "\n";
    return 2;
  }
  options.force_scale = args.force_scale;
  if (args.time_limit && !(*args.time_limit > 0.0)) {
    err << "--time-limit: must be positive seconds\n";
    return 2;
  }

  GeometryReport geometry;
  const LoadedProject loaded = LoadChecked(args.project, &geometry);
  if (!ReportLoad(loaded, args.project, err)) return 2;
  const Project& p = *loaded.project;
  const std::uint64_t seed = args.seed.value_or(p.planner.seed);
  const double time_limit = args.time_limit.value_or(p.planner.time_limit_s);
  RunContext ctx(seed);
  ctx.set_time_limit_s(time_limit);
  UseLog(ctx, err);

  out << "Planning '" << p.name << "' (" << ToString(options.planner) << ", seed " << seed
      << ", wrench " << args.wrench << ", lambda " << Fmt("%g", options.force_scale)
      << ", time limit " << Fmt("%g", time_limit) << " s"
      << (args.budget != 1.0 ? ", budget x" + Fmt("%g", args.budget) : std::string()) << ")\n";
  ProjectPlanOptions run;
  run.preprocess.project_file = args.project;
  run.preprocess.grasps = args.grasps;
  run.pipeline.task = options;
  run.pipeline.task_only = args.task_only;
  run.pipeline.seed = seed;
  run.pipeline.budget = args.budget;
  run.pipeline.optimize_keyframes = !args.no_keyframe_opt;
  run.pipeline.motion.dump_refused_dir = args.dump_refused;
  run.on_preprocessed = [&](const Preprocessed& pre) {
    for (const std::string& w : pre.warnings) err << args.project << ": warning: " << w << "\n";
  };
  auto made = PlanProject(p, loaded.check, run, ctx);
  if (!made) {
    const Error& e = made.error().error;
    err << args.project << ": " << e.message << "\n";
    if (made.error().stage == ProjectPlanError::Stage::kPreprocess &&
        e.code == ErrorCode::kTimeout) {
      err << "no plan: the time limit ran out during preprocessing\n";
      return 1;
    }
    return ExitCodeFor(e.code);
  }
  const double t_planning = made->t_plan_s;
  Plan& plan = made->plan;
  plan.stats.seed = seed;
  plan.contacts = ToPlanContacts(geometry.contacts);
  const PlanStats& st = plan.stats;
  out << "Preprocessing (t_grasp) " << Fmt("%.2f", st.t_grasp_s) << " s\n";
  if (st.solved) {
    if (args.optimize) {
      out << "Improved: cost " << st.first_cost << " -> " << st.cost << " in "
          << Fmt("%.2f", st.t_opt_s) << " s (" << st.cost_history.size() - 1
          << " improvements, objective " << st.objective << ")\n";
    }
    out << "Solved: cost " << st.cost << ", estimated makespan " << Fmt("%.1f", st.makespan_est_s)
        << " s, time to first plan " << Fmt("%.2f", st.t_init_s) << " s (t_fwd "
        << Fmt("%.2f", st.t_fwd_s) << ", t_ik " << Fmt("%.2f", st.t_ik_s) << ", t_lp "
        << Fmt("%.2f", st.t_lp_s) << "; " << st.expansions << " nodes, " << st.validations
        << " edges validated, " << st.validation_failures << " failed)\n";
    for (size_t i = 0; i < plan.actions.size(); ++i) {
      out << "  " << (i + 1) << ". " << DescribeAction(plan, plan.actions[i]) << "\n";
    }
    if (st.motion) {
      out << "Motion: makespan " << Fmt("%.1f", st.makespan_s) << " s (one segment at a time "
          << Fmt("%.1f", st.makespan_sequential_s) << " s), " << st.motion_segments
          << " segments; t_kf " << Fmt("%.2f", st.t_kf_s) << " s, t_mp " << Fmt("%.2f", st.t_mp_s)
          << " s, t_retime " << Fmt("%.2f", st.t_retime_s) << " s";
      if (st.motion_suspensions > 0 || st.task_plans > 1) {
        out << " (" << st.motion_suspensions << " suspensions, " << st.task_plans << " task plans)";
      }
      out << "\n";
    }
  } else {
    err << "No plan found in " << Fmt("%.1f", t_planning) << " s: " << st.failure << "\n";
  }

  if (!args.output.empty()) {
    if (auto saved = SavePlan(plan, args.output); !saved) {
      err << args.output << ": " << saved.error().message << "\n";
      return ExitCodeFor(saved.error().code);
    }
    out << "Wrote " << args.output << "\n";
  }
  if (!st.solved) return 1;
  if (!args.validate) return 0;
  if (const int code = ReportPlanValidation(loaded, plan, args.project, out, err); code != 0) {
    return code;
  }
  if (!st.motion) return 0;
  return ReportTrajectoryCheck(loaded, plan, args.project, &made->pre, out, err);
}

}  // namespace wrap::cli
