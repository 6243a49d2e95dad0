// Pixel work without GL: PNG round trips, image comparison, contact-sheet layout, frame times.
#include <gtest/gtest.h>

#include <filesystem>

#include "render/contact_sheet.h"
#include "render/gl_context.h"
#include "render/image.h"
#include "render/render_job.h"

namespace wrap::render {
namespace {

namespace fs = std::filesystem;

Image Gradient(int w, int h) {
  Image image = Image::Filled(w, h, {0, 0, 0});
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = image.at(x, y);
      p[0] = static_cast<std::uint8_t>(x * 255 / std::max(1, w - 1));
      p[1] = static_cast<std::uint8_t>(y * 255 / std::max(1, h - 1));
      p[2] = 77;
    }
  }
  return image;
}

TEST(Image, PngRoundTrip) {
  const fs::path dir = fs::path(WRAP_TEST_OUT_DIR) / "image_test";
  fs::create_directories(dir);
  const Image image = Gradient(37, 21);
  ASSERT_TRUE(WritePng(image, dir / "gradient.png").has_value());
  auto back = ReadPng(dir / "gradient.png");
  ASSERT_TRUE(back.has_value()) << back.error().message;
  EXPECT_EQ(back->width, 37);
  EXPECT_EQ(back->height, 21);
  EXPECT_EQ(back->rgb, image.rgb);
  auto missing = ReadPng(dir / "missing.png");
  ASSERT_FALSE(missing.has_value());
  EXPECT_EQ(missing.error().code, ErrorCode::kIo);
  EXPECT_FALSE(WritePng(image, dir / "no_such_folder" / "x.png").has_value());
}

TEST(Image, CompareWithinTolerance) {
  const Image a = Gradient(20, 10);
  Image b = a;
  b.rgb[0] = static_cast<std::uint8_t>(b.rgb[0] + 3);
  b.rgb[1] = static_cast<std::uint8_t>(b.rgb[1] + 50);
  const ImageDifference d = CompareImages(b, a, 3);
  EXPECT_TRUE(d.same_size);
  EXPECT_EQ(d.max_difference, 50);
  EXPECT_NEAR(d.fraction_within, 1.0 - 1.0 / 600.0, 1e-12);
  const Image diff = DifferenceImage(b, a, 3);
  ASSERT_EQ(diff.width, 20);
  EXPECT_GT(diff.at(0, 0)[0], 200);  // red where they differ
  EXPECT_EQ(diff.at(0, 0)[1], 0);
  EXPECT_EQ(diff.at(5, 5)[0], diff.at(5, 5)[1]);  // grey where they agree
  EXPECT_FALSE(CompareImages(a, Gradient(10, 10), 3).same_size);
}

TEST(Image, DownscaleAndBlit) {
  Image big = Image::Filled(8, 4, {10, 20, 30});
  big.at(0, 0)[0] = 50;  // one pixel of the first 2x2 block
  const Image small = Downscale(big, 2);
  EXPECT_EQ(small.width, 4);
  EXPECT_EQ(small.height, 2);
  EXPECT_EQ(small.at(0, 0)[0], 20);  // (50 + 3 * 10) / 4
  Image canvas = Image::Filled(5, 5, {255, 255, 255});
  Blit(small, canvas, 3, -1);  // clipped on two sides
  EXPECT_EQ(canvas.at(3, 0)[2], 30);
  EXPECT_EQ(canvas.at(2, 0)[2], 255);
}

TEST(ContactSheet, LayoutAndComposition) {
  const SheetLayout l = PlanContactSheet(6, 640, 480, 20, 30);
  EXPECT_EQ(l.columns, 4);
  EXPECT_EQ(l.rows, 2);
  EXPECT_EQ(l.shrink, 1);
  EXPECT_EQ(l.width, 4 * 640 + 5 * l.gap);
  const SheetLayout wide = PlanContactSheet(4, 1920, 1080, 20, 0);
  EXPECT_EQ(wide.shrink, 3);
  EXPECT_LE(wide.width, 2560 + 5 * wide.gap);
  const SheetLayout two = PlanContactSheet(2, 100, 50, 10, 0);
  EXPECT_EQ(two.columns, 2);
  const std::vector<Image> frames(2, Image::Filled(100, 50, {200, 0, 0}));
  const std::vector<Image> captions(2, Image::Filled(100, 10, {0, 0, 200}));
  const Image sheet = ComposeContactSheet(two, frames, captions, {});
  EXPECT_EQ(sheet.width, two.width);
  EXPECT_EQ(sheet.height, two.height);
  EXPECT_EQ(sheet.at(two.gap + 5, two.gap + 5)[0], 200);       // first frame
  EXPECT_EQ(sheet.at(two.gap + 5, two.gap + 50 + 5)[2], 200);  // its caption
  EXPECT_EQ(sheet.at(two.width - 1, two.height - 1)[1], 255);  // paper
}

TEST(FrameTimes, EvenFramesOrGivenTimes) {
  auto t = FrameTimes(10.0, 5, {});
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(*t, (std::vector<double>{0.0, 2.5, 5.0, 7.5, 10.0}));
  EXPECT_EQ(*FrameTimes(10.0, 1, {}), std::vector<double>{0.0});
  EXPECT_EQ(*FrameTimes(10.0, 0, {3.0, 1.0}), (std::vector<double>{3.0, 1.0}));
  EXPECT_FALSE(FrameTimes(10.0, 0, {}).has_value());
  EXPECT_FALSE(FrameTimes(10.0, 3, {11.0}).has_value());
  EXPECT_FALSE(FrameTimes(10.0, 3, {-1.0}).has_value());
}

TEST(RenderJob, ChecksOptionsBeforeDrawing) {
  RenderJob job;
  job.shots.push_back({});
  job.shots.back().file_name = "a.png";
  EXPECT_TRUE(CheckRenderJob(job).has_value());
  job.width = 8;
  EXPECT_FALSE(CheckRenderJob(job).has_value());
  job.width = 640;
  job.camera.elevation_deg = 95.0;
  EXPECT_FALSE(CheckRenderJob(job).has_value());
  job.camera.elevation_deg = -30.0;
  job.camera.distance_m = 0.0;
  EXPECT_FALSE(CheckRenderJob(job).has_value());
  job.camera.distance_m.reset();
  job.shots.back().file_name = "../escape.png";
  EXPECT_FALSE(CheckRenderJob(job).has_value());
  EXPECT_EQ(*ParseGlBackend("osmesa"), GlBackend::kOsmesa);
  EXPECT_EQ(ParseGlBackend("EGL").error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace wrap::render
