#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "cli.h"
#include "load.h"
#include "render/render_job.h"
#include "render/video.h"
#include "sim/scene.h"
#include "task/plan_json.h"

namespace wrap::cli {

namespace {

// Parses a finite number that spans all of `text`.
bool ParseNumber(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(value);
}

std::vector<std::string> Split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (true) {
    const size_t end = text.find(sep, start);
    parts.push_back(text.substr(start, end == std::string::npos ? end : end - start));
    if (end == std::string::npos) return parts;
    start = end + 1;
  }
}

Result<std::pair<int, int>> ParseSize(const std::string& text) {
  const auto bad = [&] {
    return Fail(ErrorCode::kInvalidInput,
                "--size '" + text + "': expected WIDTHxHEIGHT in pixels, e.g. 960x720");
  };
  const std::vector<std::string> wh = Split(text, 'x');
  if (wh.size() != 2) return bad();
  double w = 0, h = 0;
  if (!ParseNumber(wh[0], w) || !ParseNumber(wh[1], h) || w != std::floor(w) ||
      h != std::floor(h) || std::abs(w) > 1e6 || std::abs(h) > 1e6) {
    return bad();
  }
  return std::pair<int, int>(static_cast<int>(w), static_cast<int>(h));
}

Result<render::CameraRequest> ParseCamera(const std::string& text) {
  render::CameraRequest camera;
  if (text.empty()) return camera;
  const auto bad = [&] {
    return Fail(ErrorCode::kInvalidInput,
                "--camera '" + text +
                    "': expected AZIMUTH,ELEVATION[,DISTANCE] in degrees and metres, e.g. "
                    "150,-32 or 150,-32,2.5");
  };
  std::vector<double> v;
  for (const std::string& p : Split(text, ',')) {
    double x = 0;
    if (!ParseNumber(p, x)) return bad();
    v.push_back(x);
  }
  if (v.size() != 2 && v.size() != 3) return bad();
  camera.azimuth_deg = v[0];
  camera.elevation_deg = v[1];
  if (v.size() == 3) camera.distance_m = v[2];
  return camera;
}

Result<std::vector<double>> ParseTimes(const std::string& text) {
  std::vector<double> times;
  for (const std::string& p : Split(text, ',')) {
    double t = 0;
    if (!ParseNumber(p, t)) {
      return Fail(ErrorCode::kInvalidInput,
                  "--at '" + text +
                      "': expected keyframe indices of the plan separated by commas, e.g. 0,3,7");
    }
    times.push_back(t);
  }
  return times;
}

int Report(const Error& e, std::ostream& err) {
  err << "wrap render: " << e.message << "\n";
  return ExitCodeFor(e.code);
}

}  // namespace

int Render(const RenderArgs& args, std::ostream& out, std::ostream& err) {
  // Options first: they are cheap to check and name the flag at fault.
  auto backend = render::ParseGlBackend(args.backend);
  if (!backend) return Report(backend.error(), err);
  auto size = ParseSize(args.size);
  if (!size) return Report(size.error(), err);
  auto camera = ParseCamera(args.camera);
  if (!camera) return Report(camera.error(), err);
  std::vector<double> at;
  if (!args.at.empty()) {
    auto times = ParseTimes(args.at);
    if (!times) return Report(times.error(), err);
    at = *times;
  }
  if (!(std::isfinite(args.explode) && args.explode >= 0.0)) {
    return Report({ErrorCode::kInvalidInput,
                   "--explode must be a number >= 0 (a fraction of the assembly's size)"},
                  err);
  }
  const bool with_plan = !args.plan.empty();
  if (args.frames == 0 || args.frames < -1) {
    return Report({ErrorCode::kInvalidInput,
                   "--frames " + std::to_string(args.frames) + ": need at least 1 frame"},
                  err);
  }
  if (!with_plan && (args.frames >= 0 || !at.empty())) {
    return Report({ErrorCode::kInvalidInput,
                   "--frames and --at pick keyframes along a plan, and need --plan; without a "
                   "plan the render shows the initial scene and the goal"},
                  err);
  }
  if (with_plan && (args.goal || args.explode != 0.0)) {
    return Report({ErrorCode::kInvalidInput,
                   "--goal and --explode draw the goal without a plan; with --plan the render "
                   "shows the plan's keyframes (leave them out, or render the goal separately)"},
                  err);
  }
  // The plan's own structure is checked before the project (and its meshes) is loaded.
  std::optional<Plan> plan;
  if (with_plan) {
    auto read = ReadPlanFile(args.plan);
    if (!read) return Report(read.error(), err);
    plan = std::move(*read);
  }

  render::RenderJob job;
  job.out_dir = args.output;
  job.width = size->first;
  job.height = size->second;
  job.backend = *backend;
  job.camera = *camera;
  job.shadows = !args.no_shadows;
  job.video = args.video;
  // Check everything that does not need the project before loading it (meshes take a while).
  if (auto ok = render::CheckRenderOptions(job); !ok) return Report(ok.error(), err);
  if (!job.video.empty()) {
    if (auto ok = render::CheckVideoEncoder(); !ok) return Report(ok.error(), err);
  }
  if (auto ok = render::PrepareOutputDirectory(job.out_dir); !ok) return Report(ok.error(), err);

  const LoadedProject loaded = LoadChecked(args.project);
  if (!ReportLoad(loaded, args.project, err, /*warnings=*/false)) return 2;
  auto scene = BuildCellScene(*loaded.project, loaded.check, args.project);
  if (!scene) return Report(scene.error(), err);

  if (plan && !loaded.check.tree) {
    return Report({ErrorCode::kInternal, "the project's assembly tree is missing"}, err);
  }
  if (plan) {
    // A plan as a timeline of keyframes (index = time until plans are retimed).
    if (auto ok = CheckPlanMatchesProject(*plan, *loaded.project, *loaded.check.tree, args.plan);
        !ok) {
      return Report(ok.error(), err);
    }
    render::PlanShotOptions options;
    options.frames = args.frames;
    options.at = at;
    auto shots = render::PlanShots(*scene, *loaded.check.tree, *plan, options);
    if (!shots) return Report(shots.error(), err);
    job.shots = std::move(*shots);
    const size_t n = plan->actions.size();
    job.title = scene->name + ": " + std::to_string(n) + (n == 1 ? " action" : " actions");
  } else {
    render::StillShotOptions still;
    still.initial = !args.goal;
    still.explode = args.explode;
    auto shots = render::StillShots(*scene, still);
    if (!shots) return Report(shots.error(), err);
    job.shots = std::move(*shots);
    job.title = scene->name + ": " + std::to_string(scene->robots.size()) + " robots, " +
                std::to_string(scene->parts.size()) + " parts";
  }

  auto report = render::RunRenderJob(*scene, job);
  if (!report) return Report(report.error(), err);
  for (const std::string& w : report->warnings) err << "wrap render: warning: " << w << "\n";
  const CameraView& c = report->camera;
  char line[256];
  std::snprintf(line, sizeof line,
                "camera: --camera %.1f,%.1f,%.3f (looking at %.3f, %.3f, %.3f m)\n", c.azimuth_deg,
                c.elevation_deg, c.distance_m, c.lookat.x(), c.lookat.y(), c.lookat.z());
  out << "GL: " << report->gl << "\n" << line;
  for (const auto& file : report->written) out << "wrote " << file.string() << "\n";
  return 0;
}

}  // namespace wrap::cli
