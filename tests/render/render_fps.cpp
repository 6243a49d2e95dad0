// wrap_render_fps: frames per second of the offscreen renderer (a benchmark, not a test).
//
//   wrap_render_fps [--backend egl|osmesa] [--size WxH] [--frames N] [--no-shadows]
//                   [--samples N] [--shadow-map PX] [PROJECT]
//
// Times N frames of the project's cell (default: projects/stool.json) after 5 warm-up frames
// (the first compiles shaders), each frame with the robots at a new configuration: writing the
// state, mjv_updateScene, mjr_render and reading the pixels back (no PNG encoding). Prints one
// line with the frames per second. One backend per process: run it once per backend.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "render/gl_context.h"
#include "render/render_job.h"
#include "render/renderer.h"
#include "sim/mjcf.h"
#include "sim/mujoco_model.h"
#include "sim/scene.h"

namespace {

int Usage(const char* why) {
  std::fprintf(stderr,
               "wrap_render_fps: %s\nusage: wrap_render_fps [--backend egl|osmesa] "
               "[--size WxH] [--frames N] [--no-shadows] [--samples N] [--shadow-map PX] "
               "[PROJECT]\n",
               why);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace wrap;
  std::string backend_name = "egl";
  std::string project = std::string(WRAP_SOURCE_DIR) + "/projects/stool.json";
  int width = 640, height = 480, frames = 60;
  bool shadows = true;
  int samples = MjcfOptions{}.offscreen_samples;
  int shadow_map = MjcfOptions{}.shadow_map_px;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--backend" && i + 1 < argc) {
      backend_name = argv[++i];
    } else if (a == "--size" && i + 1 < argc) {
      if (std::sscanf(argv[++i], "%dx%d", &width, &height) != 2) return Usage("bad --size");
    } else if (a == "--frames" && i + 1 < argc) {
      frames = std::atoi(argv[++i]);
    } else if (a == "--samples" && i + 1 < argc) {
      samples = std::atoi(argv[++i]);
    } else if (a == "--shadow-map" && i + 1 < argc) {
      shadow_map = std::atoi(argv[++i]);
    } else if (a == "--no-shadows") {
      shadows = false;
    } else if (!a.empty() && a[0] != '-') {
      project = a;
    } else {
      return Usage(("unknown option " + a).c_str());
    }
  }
  auto backend = render::ParseGlBackend(backend_name);
  if (!backend) return Usage(backend.error().message.c_str());
  if (frames < 1 || width < 16 || height < 16) return Usage("bad numbers");

  const LoadedProject loaded = LoadProject(project);
  if (!loaded.ok()) return Usage(("invalid project " + project).c_str());
  auto scene = BuildCellScene(*loaded.project, loaded.check, project);
  if (!scene) return Usage(scene.error().message.c_str());
  MjcfOptions mjcf;
  mjcf.offscreen_width = width;
  mjcf.offscreen_height = height;
  mjcf.shadows = shadows;
  mjcf.offscreen_samples = samples;
  mjcf.shadow_map_px = shadow_map;
  const SceneState home = InitialState(*scene);
  const CameraView camera =
      FrameBox(SceneBounds(*scene, home), render::kDefaultAzimuthDeg, render::kDefaultElevationDeg,
               mjcf.fovy_deg, double(width) / height);
  auto doc = BuildCellMjcf(*scene, home, mjcf);
  if (!doc) return Usage(doc.error().message.c_str());
  auto model = CellModel::Compile(*doc);
  if (!model) return Usage(model.error().message.c_str());
  render::RendererOptions options;
  options.width = width;
  options.height = height;
  options.backend = *backend;
  options.shadows = shadows;
  auto renderer = render::OffscreenRenderer::Create(*model, options);
  if (!renderer) return Usage(renderer.error().message.c_str());

  SceneState state = home;
  auto frame = [&](int k) {
    for (size_t r = 0; r < state.q.size(); ++r) state.q[r][0] = home.q[r][0] + 0.01 * k;
    return (*renderer)->Render(state, camera).has_value();
  };
  for (int k = 0; k < 5; ++k) {
    if (!frame(k)) return Usage("render failed");
  }
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < frames; ++k) {
    if (!frame(k)) return Usage("render failed");
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s %dx%d shadows=%s (map %d) samples=%d frames=%d: %.1f fps (%.2f ms/frame) [%s]\n",
              backend_name.c_str(), width, height, shadows ? "on" : "off", shadow_map, samples,
              frames, frames / s, 1000.0 * s / frames, (*renderer)->gl_description().c_str());
  return 0;
}
