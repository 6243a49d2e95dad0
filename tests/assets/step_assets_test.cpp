// The committed STEP assembly (assets/parts/step/stool.step, the stool_step example's) is what the
// generator writes: the same parts, names, placements, colours and tessellated solids. Compared
// after import rather than byte for byte: OpenCASCADE writes colour entities in an order of its
// own. A build without OpenCASCADE (WRAP_WITH_OCCT) has none of these tests.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "generator/step_designs.h"
#include "geometry/step_import.h"
#include "test_build_config.h"

#if WRAP_TEST_WITH_OCCT
namespace wrap::partgen {
namespace {

namespace fs = std::filesystem;

TEST(StepAssets, CommittedStoolMatchesTheGenerator) {
  const fs::path committed = fs::path(WRAP_SOURCE_DIR) / "assets" / "parts" / kStepStoolFile;
  const fs::path fresh =
      fs::path(::testing::TempDir()) / ("wrap_step_assets_" + std::to_string(::getpid()) + ".step");
  ASSERT_TRUE(WriteStep(StepStoolSpec(), fresh).has_value());
  auto a = ImportStep(committed);
  auto b = ImportStep(fresh);
  fs::remove(fresh);
  ASSERT_TRUE(a.has_value()) << a.error().message;
  ASSERT_TRUE(b.has_value()) << b.error().message;
  const char* hint =
      "regenerate: build, then run `build/assets/generator/wrap_make_parts assets/parts`";
  ASSERT_EQ(a->solids.size(), b->solids.size()) << hint;
  ASSERT_EQ(a->instances.size(), b->instances.size()) << hint;
  for (size_t i = 0; i < a->solids.size(); ++i) {
    EXPECT_EQ(a->solids[i].name, b->solids[i].name) << hint;
    EXPECT_EQ(a->solids[i].mesh.vertices, b->solids[i].mesh.vertices) << hint;
    EXPECT_EQ(a->solids[i].mesh.triangles, b->solids[i].mesh.triangles) << hint;
  }
  for (size_t i = 0; i < a->instances.size(); ++i) {
    EXPECT_EQ(a->instances[i].name, b->instances[i].name) << hint;
    EXPECT_TRUE(a->instances[i].X_AS.isApprox(b->instances[i].X_AS, 1e-12)) << hint;
    EXPECT_EQ(a->instances[i].color, b->instances[i].color) << hint;
  }
}

TEST(StepAssets, StoolPegsFitTheirPockets) {
  const StepStoolDesign d;
  // 0.5 mm lateral clearance and 1 mm to the pocket floor, as designed.
  EXPECT_NEAR(d.pocket_radius - d.peg_radius, 0.0005, 1e-12);
  EXPECT_NEAR(d.pocket_depth - d.peg_length, 0.001, 1e-12);
  auto a = ImportStep(fs::path(WRAP_SOURCE_DIR) / "assets" / "parts" / kStepStoolFile);
  ASSERT_TRUE(a.has_value()) << a.error().message;
  ASSERT_EQ(a->instances.size(), 5u);
  // In the assembly, every leg's peg top is 1 mm under its pocket floor, and each leg's body
  // top touches the seat's underside.
  const double seat_bottom = a->instances[0].X_AS.translation().z();
  const Aabb leg = ComputeAabb(a->solids[1].mesh);
  for (size_t i = 1; i < 5; ++i) {
    const double top = a->instances[i].X_AS.translation().z() + leg.max.z();
    EXPECT_NEAR(top, seat_bottom + d.pocket_depth - 0.001, 1e-6);
  }
  EXPECT_NEAR(seat_bottom, d.leg_length, 1e-9);
}

}  // namespace
}  // namespace wrap::partgen
#endif  // WRAP_TEST_WITH_OCCT
