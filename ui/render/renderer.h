// The offscreen renderer: MuJoCo's mjv (abstract scene) and mjr (OpenGL) drawing a compiled cell
// into a pixel buffer, through an EGL or OSMesa context (render/gl_context.h).
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <string>

#include "core/result.h"
#include "render/gl_context.h"
#include "render/image.h"
#include "sim/mjcf.h"
#include "sim/mujoco_model.h"
#include "sim/scene.h"

namespace wrap::render {

/// Options of OffscreenRenderer::Create.
struct RendererOptions {
  int width = 640;                      ///< Image width [px]; at most the model's offwidth.
  int height = 480;                     ///< Image height [px]; at most the model's offheight.
  GlBackend backend = GlBackend::kEgl;  ///< Offscreen GL platform.
  bool shadows = true;                  ///< Draw shadows (about twice the cost on llvmpipe).
};

/// Draws one compiled cell, frame after frame, on the thread that created it. The CellModel
/// must outlive the renderer.
class OffscreenRenderer {
 public:
  /// Makes the GL context, MuJoCo's GPU resources and its abstract scene for `model`. Fails with
  /// kInvalidInput when the backend is unavailable or the size exceeds the model's offscreen
  /// buffer, kInternal when MuJoCo cannot make its context (the message says why).
  static Result<std::unique_ptr<OffscreenRenderer>> Create(const CellModel& model,
                                                           const RendererOptions& options);
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  /// Draws the cell at `state` seen from `camera`. Fails with kInvalidInput when the state does
  /// not match the model, kInternal on a MuJoCo error.
  Result<Image> Render(const SceneState& state, const CameraView& camera);

  /// A caption strip: `text` centred in dark grey on white, in MuJoCo's font (`big`: the large
  /// one), truncated with "..." to fit `width` x `height` pixels (at most the image size).
  Result<Image> RenderText(const std::string& text, int width, int height, bool big = false);

  /// Height of a line of text in the normal or big font [px].
  int text_height(bool big = false) const;

  int width() const { return options_.width; }    ///< [px].
  int height() const { return options_.height; }  ///< [px].
  /// The GL context, e.g. "EGL 1.5, surfaceless platform; GL 4.5 (...) Mesa 22.3.6, llvmpipe".
  const std::string& gl_description() const { return gl_->description(); }

 private:
  OffscreenRenderer(const CellModel& model, const RendererOptions& options);
  Result<Image> ReadPixels(const mjrRect& rect);

  const CellModel& model_;
  RendererOptions options_;
  std::unique_ptr<GlContext> gl_;
  std::unique_ptr<mjData, void (*)(mjData*)> data_;
  mjvScene scene_;
  mjvOption option_;
  mjrContext context_;
  bool scene_made_ = false;
  bool context_made_ = false;
};

}  // namespace wrap::render
