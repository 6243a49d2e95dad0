#include "render/render_job.h"

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "render/contact_sheet.h"
#include "render/renderer.h"
#include "render/video.h"
#include "sim/mujoco_model.h"

namespace wrap::render {

namespace fs = std::filesystem;

namespace {

constexpr int kMinSize = 16;
constexpr int kMaxSize = 8192;

Aabb Union(const Aabb& a, const Aabb& b) {
  Aabb u;
  u.min = a.min.cwiseMin(b.min);
  u.max = a.max.cwiseMax(b.max);
  return u;
}

bool PlainFileName(const std::string& name) {
  return !name.empty() && name.find('/') == std::string::npos && name != "." && name != "..";
}

}  // namespace

Result<void> CheckRenderOptions(const RenderJob& job) {
  auto bad = [](const std::string& m) { return Fail(ErrorCode::kInvalidInput, m); };
  if (job.width < kMinSize || job.width > kMaxSize || job.height < kMinSize ||
      job.height > kMaxSize) {
    return bad("--size " + std::to_string(job.width) + "x" + std::to_string(job.height) +
               ": width and height must be between " + std::to_string(kMinSize) + " and " +
               std::to_string(kMaxSize) + " pixels");
  }
  const CameraRequest& c = job.camera;
  if (c.azimuth_deg && !std::isfinite(*c.azimuth_deg)) {
    return bad("--camera: azimuth is not a number");
  }
  if (c.elevation_deg && !(std::abs(*c.elevation_deg) <= 90.0)) {
    return bad("--camera: elevation must be in [-90, 90] degrees");
  }
  if (c.distance_m && !(std::isfinite(*c.distance_m) && *c.distance_m > 0.0)) {
    return bad("--camera: distance must be a positive number of metres");
  }
  if (job.contact_sheet && !PlainFileName(job.sheet_file)) {
    return bad("render: bad contact sheet name '" + job.sheet_file + "'");
  }
  return {};
}

Result<void> CheckRenderJob(const RenderJob& job) {
  if (auto ok = CheckRenderOptions(job); !ok) return ok;
  if (job.shots.empty())
    return Fail(ErrorCode::kInvalidInput, "render: nothing to draw (no shots)");
  for (const Shot& s : job.shots) {
    if (!PlainFileName(s.file_name)) {
      return Fail(ErrorCode::kInvalidInput, "render: bad file name '" + s.file_name + "'");
    }
  }
  return {};
}

Result<void> PrepareOutputDirectory(const fs::path& dir) {
  if (dir.empty()) return Fail(ErrorCode::kIo, "output folder: no path given");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    return Fail(ErrorCode::kIo, "output folder '" + dir.string() +
                                    "' cannot be created: " + (ec ? ec.message() : "not a folder"));
  }
  const fs::path probe = dir / ".wrap_write_probe";
  {
    std::ofstream out(probe);
    if (!out || !(out << "probe") || !out.flush()) {
      return Fail(ErrorCode::kIo,
                  "output folder '" + dir.string() + "' is not writable: " + std::strerror(errno));
    }
  }
  fs::remove(probe, ec);
  return {};
}

Result<RenderReport> RunRenderJob(const CellScene& scene, const RenderJob& job) {
  if (auto ok = CheckRenderJob(job); !ok) return std::unexpected(ok.error());
  if (!job.video.empty()) {
    if (auto ok = CheckVideoEncoder(); !ok) return std::unexpected(ok.error());
  }
  if (auto ok = PrepareOutputDirectory(job.out_dir); !ok) return std::unexpected(ok.error());

  RenderReport report;
  MjcfOptions mjcf;
  mjcf.offscreen_width = job.width;
  mjcf.offscreen_height = job.height;
  mjcf.shadows = job.shadows;

  // One camera for every shot, framing all of them.
  Aabb bounds = SceneBounds(scene, job.shots.front().state);
  for (const Shot& s : job.shots) bounds = Union(bounds, SceneBounds(scene, s.state));
  const double aspect = double(job.width) / double(job.height);
  CameraView camera =
      FrameBox(bounds, job.camera.azimuth_deg.value_or(kDefaultAzimuthDeg),
               job.camera.elevation_deg.value_or(kDefaultElevationDeg), mjcf.fovy_deg, aspect);
  if (job.camera.distance_m) camera.distance_m = *job.camera.distance_m;
  mjcf.camera = camera;
  report.camera = camera;

  auto doc = BuildCellMjcf(scene, job.shots.front().state, mjcf);
  if (!doc) return std::unexpected(doc.error());
  report.warnings = doc->warnings;
  auto model = CellModel::Compile(*doc);
  if (!model) return std::unexpected(model.error());

  RendererOptions ro;
  ro.width = job.width;
  ro.height = job.height;
  ro.backend = job.backend;
  ro.shadows = job.shadows;
  auto renderer = OffscreenRenderer::Create(*model, ro);
  if (!renderer) return std::unexpected(renderer.error());
  OffscreenRenderer& r = **renderer;
  report.gl = r.gl_description();

  // The sheet's layout first: it keeps only the shrunk snapshots, not every full frame.
  const int caption_h = r.text_height() * 2;
  const int title_h = job.title.empty() ? 0 : r.text_height(true) * 2;
  const SheetLayout layout = PlanContactSheet(static_cast<int>(job.shots.size()), job.width,
                                              job.height, caption_h, title_h);
  std::vector<Image> cells;
  std::vector<fs::path> files;
  double total_ms = 0.0;
  for (const Shot& shot : job.shots) {
    const auto start = std::chrono::steady_clock::now();
    auto image = r.Render(shot.state, camera);
    if (!image) return std::unexpected(image.error());
    total_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const fs::path file = job.out_dir / shot.file_name;
    if (auto ok = WritePng(*image, file); !ok) return std::unexpected(ok.error());
    report.written.push_back(file);
    files.push_back(file);
    if (job.contact_sheet) cells.push_back(Downscale(*image, layout.shrink));
  }
  report.mean_frame_ms = total_ms / double(job.shots.size());

  if (job.contact_sheet) {
    std::vector<Image> captions;
    for (const Shot& shot : job.shots) {
      auto caption = r.RenderText(shot.caption, layout.cell_width, caption_h);
      if (!caption) return std::unexpected(caption.error());
      captions.push_back(std::move(*caption));
    }
    Image title;
    if (!job.title.empty()) {
      auto t = r.RenderText(job.title, std::min(layout.width, job.width), title_h, true);
      if (!t) return std::unexpected(t.error());
      title = std::move(*t);
    }
    const fs::path file = job.out_dir / job.sheet_file;
    if (auto ok = WritePng(ComposeContactSheet(layout, cells, captions, title), file); !ok) {
      return std::unexpected(ok.error());
    }
    report.written.push_back(file);
  }

  if (!job.video.empty()) {
    std::vector<double> durations;
    for (const Shot& s : job.shots) durations.push_back(s.duration_s);
    if (auto ok = EncodeVideo(files, durations, job.video); !ok) return std::unexpected(ok.error());
    report.written.push_back(job.video);
  }
  for (std::string& w : TakeMujocoWarnings()) report.warnings.push_back("MuJoCo: " + w);
  return report;
}

Result<std::vector<Shot>> StillShots(const CellScene& scene, const StillShotOptions& options) {
  std::vector<Shot> shots;
  if (options.initial) shots.push_back({InitialState(scene), "initial scene", "initial.png"});
  if (options.goal) {
    auto goal = GoalState(scene);
    if (!goal) return std::unexpected(goal.error());
    shots.push_back({std::move(*goal), "assembled goal", "goal.png"});
  }
  if (options.explode != 0.0) {
    auto exploded = GoalState(scene, GoalOptions{options.explode});
    if (!exploded) return std::unexpected(exploded.error());
    char caption[64];
    std::snprintf(caption, sizeof caption, "goal, exploded x%.2g", options.explode);
    shots.push_back({std::move(*exploded), caption, "goal_exploded.png"});
  }
  if (shots.empty()) return Fail(ErrorCode::kInvalidInput, "render: no shot selected");
  return shots;
}

Result<std::vector<double>> FrameTimes(double duration_s, int frames,
                                       const std::vector<double>& at_s) {
  if (!std::isfinite(duration_s) || duration_s < 0.0) {
    return Fail(ErrorCode::kInvalidInput, "timeline duration must be a finite number >= 0");
  }
  if (!at_s.empty()) {
    for (double t : at_s) {
      if (!std::isfinite(t) || t < 0.0 || t > duration_s + 1e-9) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "--at: time %g s is outside the timeline [0, %g] s", t,
                      duration_s);
        return Fail(ErrorCode::kInvalidInput, buf);
      }
    }
    return at_s;
  }
  if (frames < 1) {
    return Fail(ErrorCode::kInvalidInput,
                "--frames " + std::to_string(frames) + ": need at least 1 frame");
  }
  std::vector<double> times;
  for (int i = 0; i < frames; ++i) {
    times.push_back(frames == 1 ? 0.0 : duration_s * double(i) / double(frames - 1));
  }
  return times;
}

}  // namespace wrap::render
