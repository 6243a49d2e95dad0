#include "render/renderer.h"

#include <algorithm>
#include <cmath>

namespace wrap::render {

namespace {

// Room in MuJoCo's abstract scene for geoms beyond the model's own [count].
constexpr int kExtraGeoms = 1000;

// MuJoCo's font scale for an image: larger text for larger images.
int FontScale(int width, int height) {
  const int size = std::min(width, height * 4 / 3);
  if (size < 900) return mjFONTSCALE_100;
  if (size < 1500) return mjFONTSCALE_150;
  return mjFONTSCALE_200;
}

}  // namespace

OffscreenRenderer::OffscreenRenderer(const CellModel& model, const RendererOptions& options)
    : model_(model), options_(options), data_(nullptr, [](mjData*) {}) {}

OffscreenRenderer::~OffscreenRenderer() {
  // Free GPU resources with the context current; then the context goes.
  if (gl_ && gl_->MakeCurrent()) {
    if (context_made_) mjr_freeContext(&context_);
  }
  if (scene_made_) mjv_freeScene(&scene_);
}

Result<std::unique_ptr<OffscreenRenderer>> OffscreenRenderer::Create(
    const CellModel& model, const RendererOptions& options) {
  const mjModel* m = model.model();
  if (!m) return Fail(ErrorCode::kInternal, "renderer: no model");
  if (options.width < 1 || options.height < 1 || options.width > m->vis.global.offwidth ||
      options.height > m->vis.global.offheight) {
    return Fail(ErrorCode::kInvalidInput, "renderer: image " + std::to_string(options.width) + "x" +
                                              std::to_string(options.height) +
                                              " does not fit the model's offscreen buffer " +
                                              std::to_string(m->vis.global.offwidth) + "x" +
                                              std::to_string(m->vis.global.offheight));
  }
  std::unique_ptr<OffscreenRenderer> r(new OffscreenRenderer(model, options));
  auto gl = GlContext::Create(options.backend);
  if (!gl) return std::unexpected(gl.error());
  r->gl_ = std::move(*gl);
  r->data_ = model.MakeData();
  if (!r->data_) return Fail(ErrorCode::kInternal, "renderer: MuJoCo could not allocate data");

  OffscreenRenderer* self = r.get();
  auto made = RunGuarded("making the render context", [&] {
    mjv_defaultOption(&self->option_);
    mjv_defaultScene(&self->scene_);
    mjv_makeScene(m, &self->scene_, m->ngeom + kExtraGeoms);
    self->scene_made_ = true;
    mjr_defaultContext(&self->context_);
    mjr_makeContext(m, &self->context_, FontScale(options.width, options.height));
    self->context_made_ = true;
    // Always select the offscreen buffer: the context may have no window buffer at all.
    mjr_setBuffer(mjFB_OFFSCREEN, &self->context_);
  });
  if (!made) {
    return Fail(ErrorCode::kInternal, made.error().message + " (GL: " + r->gl_description() + ")");
  }
  if (r->context_.currentBuffer != mjFB_OFFSCREEN) {
    return Fail(ErrorCode::kInternal,
                "renderer: MuJoCo has no offscreen buffer (GL: " + r->gl_description() + ")");
  }
  r->scene_.flags[mjRND_SHADOW] = options.shadows ? 1 : 0;
  r->scene_.flags[mjRND_REFLECTION] = 0;
  r->scene_.flags[mjRND_SKYBOX] = 1;
  r->scene_.flags[mjRND_HAZE] = 1;
  return r;
}

Result<Image> OffscreenRenderer::ReadPixels(const mjrRect& rect) {
  Image image = Image::Filled(rect.width, rect.height, {0, 0, 0});
  std::vector<std::uint8_t> rows(image.rgb.size());
  auto read =
      RunGuarded("reading pixels", [&] { mjr_readPixels(rows.data(), nullptr, rect, &context_); });
  if (!read) return std::unexpected(read.error());
  // GL's origin is the bottom-left corner; images start at the top.
  const size_t stride = 3 * static_cast<size_t>(rect.width);
  for (int y = 0; y < rect.height; ++y) {
    std::copy_n(rows.data() + (rect.height - 1 - y) * stride, stride,
                image.rgb.data() + y * stride);
  }
  return image;
}

Result<Image> OffscreenRenderer::Render(const SceneState& state, const CameraView& camera) {
  if (auto ok = gl_->MakeCurrent(); !ok) return std::unexpected(ok.error());
  if (auto ok = model_.Apply(state, data_.get()); !ok) return std::unexpected(ok.error());
  mjvCamera cam;
  mjv_defaultCamera(&cam);
  cam.type = mjCAMERA_FREE;
  for (int k = 0; k < 3; ++k) cam.lookat[k] = camera.lookat[k];
  cam.azimuth = camera.azimuth_deg;
  cam.elevation = camera.elevation_deg;
  cam.distance = camera.distance_m;
  const mjrRect viewport = {0, 0, options_.width, options_.height};
  auto drawn = RunGuarded("rendering", [&] {
    mjv_updateScene(model_.model(), data_.get(), &option_, nullptr, &cam, mjCAT_ALL, &scene_);
    mjr_setBuffer(mjFB_OFFSCREEN, &context_);
    mjr_render(viewport, &scene_, &context_);
  });
  if (!drawn) return std::unexpected(drawn.error());
  return ReadPixels(viewport);
}

int OffscreenRenderer::text_height(bool big) const {
  return big ? context_.charHeightBig : context_.charHeight;
}

Result<Image> OffscreenRenderer::RenderText(const std::string& text, int width, int height,
                                            bool big) {
  width = std::clamp(width, 1, options_.width);
  height = std::clamp(height, 1, options_.height);
  if (auto ok = gl_->MakeCurrent(); !ok) return std::unexpected(ok.error());
  const int font = big ? mjFONT_BIG : mjFONT_NORMAL;
  const int* advance = big ? context_.charWidthBig : context_.charWidth;
  auto width_of = [&](const std::string& s) {
    int w = 0;
    for (unsigned char c : s) w += advance[c < 127 && c >= 32 ? c : '?'];
    return w;
  };
  // Keep printable ASCII (MuJoCo's fonts have no more); shorten with "..." to fit.
  std::string line;
  for (unsigned char c : text) line += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
  const int room = width - 8;
  if (width_of(line) > room) {
    while (!line.empty() && width_of(line + "...") > room) line.pop_back();
    line += "...";
  }
  const mjrRect rect = {0, 0, width, height};
  const int w = width_of(line);
  const int h = text_height(big);
  auto drawn = RunGuarded("drawing text", [&] {
    mjr_setBuffer(mjFB_OFFSCREEN, &context_);
    mjr_rectangle(rect, 1.0f, 1.0f, 1.0f, 1.0f);
    // mjr_text places the baseline-left corner in coordinates relative to the last viewport.
    const float x = static_cast<float>(std::max(0, (width - w) / 2)) / width;
    const float y = static_cast<float>(std::max(0, (height - h) / 2) + h / 5) / height;
    mjr_text(font, line.c_str(), &context_, x, y, 0.22f, 0.22f, 0.24f);
  });
  if (!drawn) return std::unexpected(drawn.error());
  return ReadPixels(rect);
}

}  // namespace wrap::render
