// The geometry in the GUI, as a user drives it (scripted, under Xvfb): a blocked insertion axis
// shows its free directions, "Use" on one makes the validation clean and undo brings the error
// back; the assembled view draws the swept insertion path (red where blocked) and the contacts;
// Import assembly of the stool's meshes exported as assembled gives parts and a DAG that
// validate, as one undoable edit; Suggest assembly order and Lay out say what they changed.
#include <gtest/gtest.h>

#include <fstream>

#include "geometry/mesh_export.h"
#include "gui_fixture.h"
#include "gui_process.h"
#include "model/validate.h"
#include "render/image.h"

namespace wrap::gui {
namespace {

namespace fs = std::filesystem;
using testing::ExampleProject;
using testing::HaveXvfb;
using testing::ProcessRun;
using testing::ScratchDir;
using testing::WrapUnderXvfb;

// Pixels of a rectangle close to a colour (each channel within 60 levels).
long NearColour(const render::Image& im, int x0, int y0, int x1, int y1, int r, int g, int b) {
  long n = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const std::uint8_t* p = im.at(x, y);
      n += std::abs(p[0] - r) < 60 && std::abs(p[1] - g) < 60 && std::abs(p[2] - b) < 60;
    }
  }
  return n;
}

// The viewport at 1400x900 (ui/gui/app.cpp's layout): the centre column's top two thirds.
constexpr int kVx0 = 330, kVy0 = 30, kVx1 = 1015, kVy1 = 580;

TEST(GuiGeometry, ABlockedAxisShowsFreeDirectionsAndUsingOneMakesItClean) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_geometry_axis");
  std::ofstream(dir / "axis.wrapscript")
      << "select step seat+leg1\n"
      << "view assembled on\n"
      << "validate\n"
      << "expect-path seat+leg1 free\n"
      << "screenshot free.png\n"
      << "set mating.seat+leg1.axis 1 0 0\n"
      << "validate\n"
      << "expect-path seat+leg1 blocked\n"
      << "expect-problem 'leg1' moving along [1, 0, 0] hits 'seat'\n"
      << "expect-free-direction seat+leg1 0 0 1\n"
      << "screenshot blocked.png\n"
      << "use-free-direction seat+leg1 1\n"
      << "expect-undo use insertion axis\n"
      << "validate\n"
      << "expect-path seat+leg1 free\n"
      << "expect-no-problem hits 'seat'\n"
      << "undo\n"
      << "validate\n"
      << "expect-path seat+leg1 blocked\n"
      << "view contacts on\n"
      << "select part leg1\n"
      << "expect-touch seat leg1\n"
      << "expect-no-touch leg1 leg2\n"
      << "screenshot contacts.png\n";
  const ProcessRun r = WrapUnderXvfb(
      dir, "'" + ExampleProject("stool").string() + "' --script axis.wrapscript --size 1400x900");
  ASSERT_EQ(r.code, 0) << r.output;
  auto free_png = render::ReadPng(dir / "free.png");
  auto blocked_png = render::ReadPng(dir / "blocked.png");
  auto contacts_png = render::ReadPng(dir / "contacts.png");
  ASSERT_TRUE(free_png && blocked_png && contacts_png);
  // The swept outline: green along a free path, red from where a blocked one hits.
  const long green_free = NearColour(*free_png, kVx0, kVy0, kVx1, kVy1, 40, 215, 75);
  const long red_blocked = NearColour(*blocked_png, kVx0, kVy0, kVx1, kVy1, 240, 40, 25);
  const long red_free = NearColour(*free_png, kVx0, kVy0, kVx1, kVy1, 240, 40, 25);
  EXPECT_GT(green_free, 15) << "the free path's sweep is drawn green";
  EXPECT_GT(red_blocked, red_free + 15) << "the blocked path's sweep is drawn red";
  // The contacts: yellow balls and lines.
  EXPECT_GT(NearColour(*contacts_png, kVx0, kVy0, kVx1, kVy1, 255, 205, 25), 20);
}

// The stool's parts written where they sit in the assembly (metres), as a CAD export.
fs::path ExportStool(const fs::path& dir) {
  const LoadedProject lp = LoadProject(ExampleProject("stool"));
  EXPECT_TRUE(lp.ok());
  const fs::path out = dir / "meshes";
  fs::create_directories(out);
  for (size_t i = 0; i < lp.project->parts.size(); ++i) {
    const Part& part = lp.project->parts[i];
    const TriangleMesh placed =
        Transformed(lp.check.parts[i].mesh, ToIsometry(part.assembled_pose));
    EXPECT_TRUE(WriteStl(out / (part.name + ".stl"), placed));
  }
  return out;
}

TEST(GuiGeometry, ImportAssemblySuggestOrderAndLayOutAreUndoableEdits) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_geometry_import");
  ExportStool(dir);
  std::ofstream(dir / "import.wrapscript") << "import-assembly auto meshes\n"
                                           << "expect-count parts 5\n"
                                           << "expect-count steps 4\n"
                                           << "expect-count robots 4\n"
                                           << "expect-undo import assembly (5 parts)\n"
                                           << "expect-change part 'seat' added\n"
                                           << "expect-change decided: unit: m\n"
                                           << "validate\n"
                                           << "expect-no-problem error\n"
                                           << "expect-touch seat leg1\n"
                                           << "screenshot imported.png\n"
                                           << "delete-step s4_leg1\n"
                                           << "delete-step s3_leg2\n"
                                           << "expect-count steps 2\n"
                                           << "suggest-order\n"
                                           << "expect-count steps 4\n"
                                           << "expect-undo suggest assembly order\n"
                                           << "expect-change added\n"
                                           << "validate\n"
                                           << "expect-no-problem error\n"
                                           << "set part.leg2.initial_xyz 0 0 0.75\n"
                                           << "set part.leg3.initial_xyz 0 0 0.75\n"
                                           << "lay-out\n"
                                           << "expect-undo lay out parts on the table\n"
                                           << "expect-change part 'leg2' moved on the table\n"
                                           << "validate\n"
                                           << "expect-no-problem error\n"
                                           << "screenshot laid_out.png\n"
                                           << "undo\n"
                                           << "undo\n"
                                           << "undo\n"
                                           << "undo\n"
                                           << "undo\n"
                                           << "undo\n"
                                           << "expect-count steps 4\n"  // as imported
                                           << "undo\n"
                                           << "expect-count parts 0\n"
                                           << "redo\n"
                                           << "expect-count parts 5\n";
  const ProcessRun r = WrapUnderXvfb(dir, "--script import.wrapscript --size 1400x900");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("step 1:"), std::string::npos) << r.output;
  ASSERT_TRUE(render::ReadPng(dir / "imported.png"));
}

}  // namespace
}  // namespace wrap::gui
