// `wrap sim --video`: the simulated run drawn by the offscreen renderer (ui/render) and encoded
// by ffmpeg. The engine never draws: it hands the cell's states to the CLI (SimOptions::on_frame),
// which draws them here once the run is over. Builds without ui/ link sim_video_unavailable.cpp.
#pragma once

#include <string>
#include <vector>

#include "core/result.h"
#include "sim/scene.h"

namespace wrap::cli {

/// One recorded moment of a simulated run.
struct SimFrame {
  double t_s = 0.0;    ///< Simulated time [s].
  SceneState state;    ///< Robots as driven, parts where MuJoCo had them.
  double duration_s = 0.1;  ///< How long the video shows it [s].
};

/// Fails with kInvalidInput saying why when this build or machine cannot record a video: built
/// without the renderer (WRAP_BUILD_UI=OFF) or no ffmpeg on PATH. Cheap: call it before a run.
Result<void> CheckSimVideo();

/// Draws `frames` of `scene` offscreen (640x480, one camera framing them all) into a temporary
/// folder beside `file`, encodes them as the MP4 `file` through ffmpeg (written under a
/// temporary name and renamed, so a failure leaves no partial file) and removes the folder.
/// Fails with kInvalidInput (no renderer, GL backend or ffmpeg), kIo (cannot write, ffmpeg
/// failed) or kInternal (MuJoCo or GL).
Result<void> WriteSimVideo(const CellScene& scene, const std::vector<SimFrame>& frames,
                           const std::string& file);

}  // namespace wrap::cli
