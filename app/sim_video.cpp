#include "sim_video.h"

#include <cstdio>
#include <filesystem>
#include <random>
#include <system_error>

#include "render/render_job.h"
#include "render/video.h"

namespace wrap::cli {

namespace fs = std::filesystem;

Result<void> CheckSimVideo() { return render::CheckVideoEncoder(); }

Result<void> WriteSimVideo(const CellScene& scene, const std::vector<SimFrame>& frames,
                           const std::string& file) {
  if (frames.empty()) return Fail(ErrorCode::kInternal, "--video: no frames were recorded");
  const fs::path out = fs::absolute(file);
  std::random_device rd;
  const std::string tag = std::to_string(rd());
  // Hidden names beside the video; ffmpeg picks the container from the extension.
  const fs::path dir = out.parent_path() / ("." + out.filename().string() + ".frames." + tag);
  const fs::path partial = out.parent_path() / ("." + out.stem().string() + "." + tag + ".mp4");
  render::RenderJob job;
  job.out_dir = dir;
  job.width = 640;
  job.height = 480;
  job.shadows = false;
  job.contact_sheet = false;
  job.video = partial;
  for (size_t i = 0; i < frames.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05zu.png", i);
    job.shots.push_back({frames[i].state, "", name, frames[i].duration_s});
  }
  auto rendered = render::RunRenderJob(scene, job);
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (!rendered) {
    fs::remove(partial, ec);
    Error e = rendered.error();
    e.message = "--video " + file + ": " + e.message;
    return std::unexpected(e);
  }
  fs::rename(partial, out, ec);
  if (ec) {
    fs::remove(partial, ec);
    return Fail(ErrorCode::kIo, "--video " + file + ": cannot write it: " + ec.message());
  }
  return {};
}

}  // namespace wrap::cli
