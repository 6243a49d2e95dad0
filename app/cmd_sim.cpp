#include <cstdio>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>

#include "cli.h"
#include "core/file_io.h"
#include "core/run_context.h"
#include "load.h"
#include "sim/scene.h"
#include "sim_video.h"
#include "task/plan_json.h"
#include "verify/simulate.h"

namespace wrap::cli {

namespace {

int Report(const Error& e, std::ostream& err) {
  err << "wrap sim: " << e.message << "\n";
  return ExitCodeFor(e.code);
}

std::string Percent(double u) {
  if (u < 0.0) return "--";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f%%", 100.0 * u);
  return buf;
}

}  // namespace

int Sim(const SimArgs& args, std::ostream& out, std::ostream& err) {
  // A video that cannot be made is said before anything runs.
  if (!args.video.empty()) {
    if (auto ok = CheckSimVideo(); !ok) return Report(ok.error(), err);
    const std::filesystem::path parent = std::filesystem::absolute(args.video).parent_path();
    std::error_code ec;
    if (!std::filesystem::is_directory(parent, ec)) {
      return Report({ErrorCode::kInvalidInput,
                     "--video " + args.video + ": the folder " + parent.string() +
                         " does not exist"},
                    err);
    }
  }
  // The plan's own structure first: it is cheap and names the field at fault.
  auto plan = ReadPlanFile(args.plan);
  if (!plan) return Report(plan.error(), err);
  GeometryReport geometry;
  const LoadedProject loaded = LoadChecked(args.project, &geometry);
  if (!ReportLoad(loaded, args.project, err, /*warnings=*/false)) return 2;
  if (!loaded.check.tree) {
    return Report({ErrorCode::kInternal, "the project's assembly tree is missing"}, err);
  }
  if (auto ok = CheckPlanMatchesProject(*plan, *loaded.project, *loaded.check.tree, args.plan);
      !ok) {
    return Report(ok.error(), err);
  }
  SimOptions options;
  options.force_scale = args.force_scale;
  options.mjcf_dir = args.mjcf_dir;
  std::vector<SimFrame> frames;
  if (!args.video.empty()) {
    options.frame_interval_s = 0.1;
    options.on_frame = [&frames](double t, const SceneState& state) {
      frames.push_back({t, state, 0.1});
    };
  }
  RunContext ctx;
  UseLog(ctx, err);
  auto report = SimulatePlan(*loaded.project, loaded.check, args.project, *plan, options, ctx);
  if (!report) {
    Error e = report.error();
    if (e.code == ErrorCode::kInvalidInput) e.message = args.plan + ": " + e.message;
    return Report(e, err);
  }
  if (!args.output.empty()) {
    if (auto ok = WriteFileAtomic(args.output, SerializeSimReport(*report)); !ok) {
      return Report(ok.error(), err);
    }
  }
  for (const std::string& w : report->warnings) err << "wrap sim: warning: " << w << "\n";
  const SimUtilisation& u = report->peak;
  out << (report->success ? "holds" : "fails") << ": " << report->tasks_completed << "/"
      << report->tasks_total << " actions, " << Fmt("%.2f", report->simulated_s) << " s simulated\n"
      << "peak utilisation: transport 2F " << Percent(u.two_finger_transport) << ", vacuum "
      << Percent(u.vacuum_transport) << "; insertion 2F " << Percent(u.two_finger_insertion)
      << ", vacuum " << Percent(u.vacuum_insertion) << "; connections " << Percent(u.connection)
      << "; table friction " << Percent(u.table_friction) << "\n";
  if (report->failure) {
    const SimFailure& f = *report->failure;
    out << "failure: action " << f.action;
    if (f.action >= 0 && f.action < static_cast<int>(plan->actions.size())) {
      out << " (" << DescribeAction(*plan, plan->actions[f.action]) << ")";
    }
    out << ": " << f.reason << " at t = " << Fmt("%.3f", f.t_s) << " s: " << f.detail << "\n";
  }
  for (const std::string& n : report->notes) out << "note: " << n << "\n";
  if (!args.output.empty()) out << "wrote " << args.output << "\n";
  if (!args.video.empty()) {
    auto scene = BuildCellScene(*loaded.project, loaded.check, args.project);
    if (!scene) return Report(scene.error(), err);
    if (auto ok = WriteSimVideo(*scene, frames, args.video); !ok) return Report(ok.error(), err);
    out << "wrote " << args.video << " (" << frames.size() << " frames)\n";
  }
  return report->success ? 0 : 1;
}

}  // namespace wrap::cli
