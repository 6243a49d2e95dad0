// The renderer in this process (EGL): frames follow the scene state, text strips, and the rule
// of one GL platform library per process. Fails where EGL cannot make a context.
#include <gtest/gtest.h>

#include <filesystem>

#include "render/gl_context.h"
#include "render/renderer.h"
#include "sim/mjcf.h"
#include "sim/mujoco_model.h"
#include "sim/scene.h"

namespace wrap::render {
namespace {

namespace fs = std::filesystem;

struct Cell {
  LoadedProject project;
  CellScene scene;
  std::optional<CellModel> model;
};

Cell Load(const std::string& name, int width, int height) {
  const fs::path file = fs::path(WRAP_SOURCE_DIR) / "projects" / (name + ".json");
  Cell c;
  c.project = LoadProject(file);
  EXPECT_TRUE(c.project.ok());
  auto scene = BuildCellScene(*c.project.project, c.project.check, file);
  EXPECT_TRUE(scene.has_value());
  c.scene = *scene;
  MjcfOptions options;
  options.offscreen_width = width;
  options.offscreen_height = height;
  auto doc = BuildCellMjcf(c.scene, InitialState(c.scene), options);
  EXPECT_TRUE(doc.has_value());
  auto model = CellModel::Compile(*doc);
  EXPECT_TRUE(model.has_value());
  c.model = std::move(*model);
  return c;
}

TEST(OffscreenRenderer, FramesFollowTheState) {
  Cell c = Load("stool", 160, 120);
  RendererOptions options;
  options.width = 160;
  options.height = 120;
  auto renderer = OffscreenRenderer::Create(*c.model, options);
  ASSERT_TRUE(renderer) << "no EGL here (scripts/install_deps.sh installs it): "
                        << renderer.error().message;
  const SceneState home = InitialState(c.scene);
  const CameraView camera = FrameBox(SceneBounds(c.scene, home), 150, -40, 40, 160.0 / 120.0);
  auto a = (*renderer)->Render(home, camera);
  auto b = (*renderer)->Render(home, camera);
  ASSERT_TRUE(a && b) << (a ? b.error().message : a.error().message);
  EXPECT_EQ(a->width, 160);
  EXPECT_EQ(a->rgb, b->rgb) << "deterministic";
  SceneState moved = home;
  moved.q[0][0] += 1.0;
  auto m = (*renderer)->Render(moved, camera);
  ASSERT_TRUE(m.has_value());
  EXPECT_NE(m->rgb, a->rgb);
  // The wrong number of robots is an error, not a crash.
  SceneState bad = home;
  bad.q.pop_back();
  EXPECT_FALSE((*renderer)->Render(bad, camera).has_value());

  auto text = (*renderer)->RenderText("t = 1.5 s: a very long caption that cannot fit", 120, 20);
  ASSERT_TRUE(text.has_value());
  EXPECT_EQ(text->width, 120);
  int dark = 0;
  for (size_t i = 0; i < text->rgb.size(); i += 3) dark += text->rgb[i] < 128;
  EXPECT_GT(dark, 20) << "text was drawn";
  EXPECT_NE((*renderer)->gl_description().find("EGL"), std::string::npos);
}

TEST(OffscreenRenderer, SizeBeyondTheModelBufferIsRejected) {
  Cell c = Load("stool", 160, 120);
  RendererOptions options;
  options.width = 320;
  options.height = 240;
  auto renderer = OffscreenRenderer::Create(*c.model, options);
  ASSERT_FALSE(renderer.has_value());
  EXPECT_EQ(renderer.error().code, ErrorCode::kInvalidInput);
}

TEST(GlContext, OneGlPlatformLibraryPerProcess) {
  auto egl = GlContext::Create(GlBackend::kEgl);
  ASSERT_TRUE(egl) << "no EGL here (scripts/install_deps.sh installs it): " << egl.error().message;
  auto osmesa = GlContext::Create(GlBackend::kOsmesa);
  ASSERT_FALSE(osmesa.has_value());
  EXPECT_EQ(osmesa.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(osmesa.error().message.find("already loaded"), std::string::npos)
      << osmesa.error().message;
}

}  // namespace
}  // namespace wrap::render
