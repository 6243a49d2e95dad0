// The GUI as a process under Xvfb: `wrap PROJECT --screenshot` (with --run-plan and --at) and a
// scripted flow that builds a project from meshes, draws its DAG, plans and saves it. Screenshots
// are checked by pixel statistics per region of the fixed layout (panels present, scene drawn),
// not against golden images: fonts and llvmpipe versions move pixels. Needs xvfb-run.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "gui/document.h"
#include "gui_fixture.h"
#include "gui_process.h"
#include "model/project_io.h"
#include "render/image.h"

namespace wrap::gui {
namespace {

namespace fs = std::filesystem;
using testing::ExampleProject;
using testing::HaveXvfb;
using testing::ProcessRun;
using testing::ScratchDir;
using testing::WrapUnderXvfb;

/// Statistics of a rectangle of an image.
struct RegionStats {
  double mean_luminance = 0;   ///< [0, 255].
  double bright_fraction = 0;  ///< Pixels with luminance > 150.
  int colours = 0;             ///< Distinct colours (quantised to 4 bits per channel).
  long near_colour = 0;        ///< Pixels within 40 levels of a given colour.
};

RegionStats Stats(const render::Image& im, int x0, int y0, int x1, int y1,
                  std::array<int, 3> colour = {-1000, 0, 0}) {
  RegionStats s;
  std::vector<bool> seen(4096, false);
  long n = 0, bright = 0;
  double sum = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const std::uint8_t* p = im.at(x, y);
      const double l = 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
      sum += l;
      bright += l > 150;
      ++n;
      seen[(p[0] >> 4) << 8 | (p[1] >> 4) << 4 | (p[2] >> 4)] = true;
      if (std::abs(p[0] - colour[0]) < 40 && std::abs(p[1] - colour[1]) < 40 &&
          std::abs(p[2] - colour[2]) < 40) {
        ++s.near_colour;
      }
    }
  }
  s.mean_luminance = sum / std::max(1L, n);
  s.bright_fraction = static_cast<double>(bright) / std::max(1L, n);
  s.colours = static_cast<int>(std::count(seen.begin(), seen.end(), true));
  return s;
}

/// Pixels that differ (any channel by more than 24 levels) between two images of one size in a
/// rectangle, and the mean "yellowness" (r + g - 2 b, levels) of those pixels in each image.
struct PixelDiff {
  long pixels = 0;
  double yellowness_a = 0, yellowness_b = 0;
};

PixelDiff Diff(const render::Image& a, const render::Image& b, int x0, int y0, int x1, int y1) {
  PixelDiff d;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const std::uint8_t* p = a.at(x, y);
      const std::uint8_t* q = b.at(x, y);
      if (std::abs(p[0] - q[0]) <= 24 && std::abs(p[1] - q[1]) <= 24 &&
          std::abs(p[2] - q[2]) <= 24) {
        continue;
      }
      ++d.pixels;
      d.yellowness_a += p[0] + p[1] - 2.0 * p[2];
      d.yellowness_b += q[0] + q[1] - 2.0 * q[2];
    }
  }
  if (d.pixels > 0) {
    d.yellowness_a /= static_cast<double>(d.pixels);
    d.yellowness_b /= static_cast<double>(d.pixels);
  }
  return d;
}

// The layout at 1400x900 (ui/gui/app.cpp): left column 23 % (parts, robots), right 27 % (graph,
// mating, planner), centre: viewport over the top two thirds, the plan panel below.
constexpr int kW = 1400, kH = 900;

/// A dark ImGui panel with text in it.
void ExpectPanel(const render::Image& im, int x0, int y0, int x1, int y1, const char* what) {
  const RegionStats s = Stats(im, x0, y0, x1, y1);
  EXPECT_LT(s.mean_luminance, 90) << what << ": a dark panel";
  EXPECT_GT(s.bright_fraction, 0.003) << what << ": text drawn";
  EXPECT_LT(s.bright_fraction, 0.4) << what;
}

// The stool saved into `dir` with an hour's time limit: the GUI plans within the project's own
// wall-clock limit (60 s), which a loaded machine or a sanitizer's slowdown can exceed at nice 15
// beside a drawing window; the plan is decided by the planner's work budgets, so it is the same
// (ctest's timeout catches a hang).
fs::path StoolWithoutItsTimeLimit(const fs::path& dir) {
  auto doc = Document::Open(ExampleProject("stool"));
  EXPECT_TRUE(doc.has_value());
  Project project = doc->project();
  project.planner.time_limit_s = 3600.0;
  Document copy(project, ExampleProject("stool"));
  EXPECT_TRUE(copy.SaveAs(dir / "stool.json"));
  return dir / "stool.json";
}

TEST(GuiCli, ScreenshotOfTheStoolAfterPlanningAndScrubbing) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_cli_stool");
  const ProcessRun r = WrapUnderXvfb(dir, "'" + StoolWithoutItsTimeLimit(dir).string() +
                                              "' --run-plan --at 40 --screenshot shot.png --size " +
                                              std::to_string(kW) + "x" + std::to_string(kH));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("frames meanwhile"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" fps, drawing "), std::string::npos) << "the frame rate reported";
  auto im = render::ReadPng(dir / "shot.png");
  ASSERT_TRUE(im) << im.error().message;
  ASSERT_EQ(im->width, kW);
  ASSERT_EQ(im->height, kH);
  ExpectPanel(*im, 5, 60, 310, 520, "parts panel");
  ExpectPanel(*im, 5, 580, 310, 860, "robots panel");
  ExpectPanel(*im, 1030, 60, 1395, 340, "assembly graph");
  ExpectPanel(*im, 1030, 640, 1395, 860, "planner panel");
  // The scene: light (sky, table), many colours (robots, parts, shadows), the seat's orange.
  const RegionStats scene = Stats(*im, 340, 60, 1010, 560, {242, 142, 43});
  EXPECT_GT(scene.mean_luminance, 120);
  EXPECT_GT(scene.colours, 60) << "robots, parts, table, shadows: many colours";
  EXPECT_GT(scene.near_colour, 200) << "the orange seat is in view";
  // The plan panel: lanes with assemble bars (orange) after --run-plan.
  const RegionStats plan = Stats(*im, 330, 600, 1010, 880, {230, 140, 50});
  EXPECT_GT(plan.near_colour, 100) << "assemble bars on the robots' lanes";
}

TEST(GuiCli, ScriptBuildsAProjectFromMeshesPlansAndSavesIt) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_cli_script");
  // The stool's cell (table, robots) without parts or steps.
  {
    auto doc = Document::Open(ExampleProject("stool"));
    ASSERT_TRUE(doc);
    Project empty = doc->project();
    empty.parts.clear();
    empty.steps.clear();
    empty.name = "built";
    Document blank(empty, {});
    ASSERT_TRUE(blank.SaveAs(dir / "empty.json"));
  }
  const fs::path meshes = fs::path(WRAP_SOURCE_DIR) / "assets/parts/stool";
  const fs::path kUrdf = fs::path(WRAP_SOURCE_DIR) / "tests/fuzz/seeds/urdf/three_joint_arm.urdf";
  std::ofstream(dir / "flow.wrapscript") << "# a half stool from meshes\n"
                                         << "import " << (meshes / "seat.stl").string() << " mm\n"
                                         << "import " << (meshes / "leg.stl").string() << " mm\n"
                                         << "rename leg leg1\n"
                                         << "import " << (meshes / "leg.stl").string() << " mm\n"
                                         << "rename leg leg2\n"
                                         << "set part.seat.assembled_xyz 0 0 0.185\n"
                                         << "set part.leg1.assembled_xyz 0.085 0.085 0\n"
                                         << "set part.leg2.assembled_xyz -0.085 0.085 0\n"
                                         << "set part.seat.initial_xyz -0.2 0 0.75\n"
                                         << "set part.leg1.initial_xyz 0.16 0.16 0.75\n"
                                         << "set part.leg2.initial_xyz 0.16 0.05 0.75\n"
                                         << "add-step seat+leg1\n"
                                         << "add-edge seat seat+leg1\n"
                                         << "add-edge leg1 seat+leg1\n"
                                         << "add-step half\n"
                                         << "add-edge seat+leg1 half\n"
                                         << "add-edge leg2 half\n"
                                         << "expect-refused add-edge half seat+leg1\n"
                                         << "set mating.half.force_N 12\n"
                                         << "select step half\n"
                                         << "option task_only 1\n"
                                         << "run\n"
                                         << "wait\n"
                                         << "expect-plan\n"
                                         << "scrub 3\n"
                                         << "save built.json\n"
                                         << "screenshot built.png\n"
                                         << "view quality fine\n"
                                         << "screenshot tinted.png\n"
                                         << "view utilisation off\n"
                                         << "screenshot plain.png\n"
                                         << "view quality fast\n"
                                         << "screenshot fast.png\n"
                                         << "add-urdf " << kUrdf.string() << " vacuum_cup\n"
                                         << "expect-refused add-urdf missing.urdf vacuum_cup\n"
                                         << "save with_urdf.json\n";
  const ProcessRun r = WrapUnderXvfb(dir, "empty.json --script flow.wrapscript --size 1400x900");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("ok 19: expect-refused"), std::string::npos) << r.output;

  // Reload the saved file and compare with what the script built.
  auto built = Document::Open(dir / "built.json");
  ASSERT_TRUE(built) << built.error().message;
  const Project& p = built->project();
  ASSERT_EQ(p.parts.size(), 3u);
  EXPECT_EQ(p.parts[0].name, "seat");
  EXPECT_EQ(p.parts[1].name, "leg1");
  EXPECT_EQ(p.parts[2].name, "leg2");
  EXPECT_DOUBLE_EQ(p.parts[0].scale, 0.001);
  EXPECT_EQ(p.parts[1].assembled_pose.xyz, Vec3(0.085, 0.085, 0));
  EXPECT_EQ(p.parts[2].initial_pose.xyz, Vec3(0.16, 0.05, 0.75));
  for (const Part& part : p.parts) {
    EXPECT_TRUE(fs::exists(dir / part.mesh)) << part.mesh << " relative to the saved file";
  }
  ASSERT_EQ(p.steps.size(), 2u);
  EXPECT_EQ(p.steps[0].inputs, (std::vector<std::string>{"seat", "leg1"}));
  EXPECT_EQ(p.steps[1].inputs, (std::vector<std::string>{"seat+leg1", "leg2"}));
  EXPECT_EQ(p.steps[1].mating.base, "seat+leg1");
  EXPECT_EQ(p.steps[1].mating.moved, "leg2");
  EXPECT_DOUBLE_EQ(p.steps[1].mating.force_N, 12);
  EXPECT_EQ(p.robots.size(), 4u);

  auto im = render::ReadPng(dir / "built.png");
  ASSERT_TRUE(im) << im.error().message;
  const RegionStats scene = Stats(*im, 340, 60, 1010, 560);
  EXPECT_GT(scene.colours, 60) << "robots, parts, table, shadows: many colours";
  const RegionStats plan = Stats(*im, 330, 600, 1010, 880, {230, 140, 50});
  EXPECT_GT(plan.near_colour, 100) << "the plan's lanes";

  // At the scrubbed action the loaded grippers are tinted by their utilisation (green through
  // yellow to red, all with little blue): those pixels turn yellower than without the tint.
  auto tinted = render::ReadPng(dir / "tinted.png");
  auto plain = render::ReadPng(dir / "plain.png");
  auto fast = render::ReadPng(dir / "fast.png");
  ASSERT_TRUE(tinted && plain && fast);
  const PixelDiff tint = Diff(*tinted, *plain, 340, 60, 1010, 560);
  EXPECT_GT(tint.pixels, 30) << "grippers tinted";
  EXPECT_GT(tint.yellowness_a, tint.yellowness_b + 20) << "tinted towards utilisation colours";
  // Fast drawing: no shadows, no antialiasing: many pixels change, the scene is still drawn.
  const PixelDiff quality = Diff(*plain, *fast, 340, 60, 1010, 560);
  EXPECT_GT(quality.pixels, 2000) << "shadows gone";
  EXPECT_GT(Stats(*fast, 340, 60, 1010, 560).colours, 30) << "the scene is drawn";

  // The URDF robot: added with its path relative to the saved file; a missing URDF is refused.
  auto with_urdf = Document::Open(dir / "with_urdf.json");
  ASSERT_TRUE(with_urdf) << with_urdf.error().message;
  ASSERT_EQ(with_urdf->project().robots.size(), 5u);
  const Robot& arm = with_urdf->project().robots.back();
  EXPECT_EQ(arm.name, "three_joint_arm");
  EXPECT_TRUE(arm.model.empty());
  EXPECT_EQ(arm.end_effector, "vacuum_cup");
  EXPECT_TRUE(fs::exists(dir / arm.urdf)) << arm.urdf << " relative to the saved file";
  EXPECT_TRUE(fs::path(arm.urdf).is_relative()) << arm.urdf;
}

TEST(GuiCli, BadScriptIsBadInputNamingTheLine) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_cli_bad_script");
  std::ofstream(dir / "bad.wrapscript") << "undo\nteleport seat\n";
  const ProcessRun r =
      WrapUnderXvfb(dir, "'" + ExampleProject("stool").string() + "' --script bad.wrapscript");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("line 2"), std::string::npos) << r.output;
}

TEST(GuiCli, AFailingScriptLineExitsOne) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_cli_failing_script");
  std::ofstream(dir / "f.wrapscript") << "add-edge stool seat+leg1\n";
  const ProcessRun r =
      WrapUnderXvfb(dir, "'" + ExampleProject("stool").string() + "' --script f.wrapscript");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("two inputs"), std::string::npos) << r.output;
}

// A failing check (an expect-* line, run after the frame it reads) names its line once: one from
// the script's own checks (script_expect.cpp), one from the authoring ones (script_authoring.cpp).
TEST(GuiCli, AFailingCheckNamesItsLineOnce) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_cli_failing_check");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"select step seat+leg1\nexpect-selected step seat+leg2\n",
       "script line 2: selected step is 'seat+leg1', not 'seat+leg2'"},
      {"expect-count parts 9\n", "script line 1: the project has 5 parts, not 9"}};
  for (const auto& [script, message] : cases) {
    std::ofstream(dir / "check.wrapscript", std::ios::trunc) << script;
    const ProcessRun r =
        WrapUnderXvfb(dir, "'" + ExampleProject("stool").string() + "' --script check.wrapscript");
    EXPECT_EQ(r.code, 1) << r.output;
    const size_t at = r.output.find(message);
    EXPECT_NE(at, std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("script line"), at) << "named more than once:\n" << r.output;
  }
}

TEST(GuiCli, NoDisplayIsBadInputWithAHint) {
  const auto dir = ScratchDir("gui_cli_no_display");
  const ProcessRun r =
      WrapUnderXvfb(dir, "'" + ExampleProject("stool").string() + "' --screenshot x.png",
                    /*xvfb=*/false);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("DISPLAY"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

TEST(GuiCli, MissingProjectIsBadInput) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_cli_missing");
  const ProcessRun r = WrapUnderXvfb(dir, "nope.json --screenshot x.png");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("nope.json"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace wrap::gui

namespace wrap::gui {
namespace {

std::string Slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The GUI killed (SIGKILL, no chance to clean up) while the user edits: the recovery file holds
// the last edit, the project file is untouched, and opening the project again offers the
// recovery, which gives back the edited project.
TEST(GuiCli, KilledWhileEditingTheRecoveryFileHoldsTheLastEdit) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_cli_kill");
  {
    auto doc = Document::Open(ExampleProject("stool"));
    ASSERT_TRUE(doc);
    ASSERT_TRUE(doc->SaveAs(dir / "p.json"));
  }
  const std::string saved = Slurp(dir / "p.json");
  std::ofstream(dir / "edit.wrapscript") << "autosave\n"
                                         << "set part.seat.mass_kg 0.321\n"
                                         << "set part.seat.mass_kg 0.654\n"
                                         << "sleep 600\n";
  // In the background; the shell that xvfb-run starts leaves its pid and becomes wrap.
  const std::string cmd = "cd '" + dir.string() +
                          "' && (xvfb-run -a -s '-screen 0 1600x1000x24' sh -c 'echo $$ > "
                          "wrap.pid; exec \"" +
                          WRAP_EXE + "\" p.json --script edit.wrapscript' > wrap.log 2>&1 &)";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const fs::path recovery = dir / "p.json.recovery";
  auto recovered_mass = [&]() -> double {
    if (!fs::exists(recovery)) return -1.0;
    ProjectParse parse = ParseProject(Slurp(recovery), "recovery");
    if (!parse.project) return -2.0;  // a torn file would show here
    for (const Part& p : parse.project->parts) {
      if (p.name == "seat" && p.mass_kg) return *p.mass_kg;
    }
    return -3.0;
  };
  // Both edits done (the script reports each line as it finishes), then the recovery file
  // follows; the watchdog only bounds a hang.
  double mass = -1.0;
  for (int i = 0; i < 1200; ++i) {
    if (Slurp(dir / "wrap.log").find("ok 3:") != std::string::npos) {
      mass = recovered_mass();
      if (mass == 0.654) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const std::string pid = Slurp(dir / "wrap.pid");
  ASSERT_FALSE(pid.empty()) << Slurp(dir / "wrap.log");
  ASSERT_EQ(std::system(("kill -KILL " + pid).c_str()), 0) << "wrap was not running";
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(mass, 0.654) << Slurp(dir / "wrap.log");
  EXPECT_EQ(recovered_mass(), 0.654) << "the recovery file after the kill";
  EXPECT_EQ(Slurp(dir / "p.json"), saved) << "the project file itself is not touched";
  // Opening again: the recovery is offered and gives the edited project back.
  EXPECT_TRUE(Document::HasRecovery(dir / "p.json"));
  auto doc = Document::Open(dir / "p.json");
  ASSERT_TRUE(doc);
  ASSERT_TRUE(doc->Recover());
  bool found = false;
  for (const Part& p : doc->project().parts) {
    if (p.name == "seat") {
      found = true;
      EXPECT_EQ(p.mass_kg.value_or(0.0), 0.654);
    }
  }
  EXPECT_TRUE(found);
  EXPECT_TRUE(doc->dirty());
}

}  // namespace
}  // namespace wrap::gui

namespace wrap::gui {
namespace {

// A failed plan, as a user meets it: the Problems panel shows the planner's words (the CLI's),
// the failing step is marked on the canvas, "Show" selects the part that was tried and puts the
// viewport into the failing state. Then the live validation lists a warning by entity name, and
// a negative force typed into the mating editor is refused at the field.
TEST(GuiCli, AFailedPlanIsExplainedWhereItHappened) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_cli_failure");
  // Only vacuum cups, and the first step needs a transverse force a cup cannot take while
  // mating: the planner stops at milestone 1 at once (task planner test: VacuumOnly...).
  std::ofstream(dir / "fail.wrapscript")
      << "set robot.ur5e_a.end_effector vacuum_cup\n"
      << "set robot.ur5e_b.end_effector vacuum_cup\n"
      << "set robot.ur5e_c.end_effector vacuum_cup\n"
      << "set robot.ur5e_d.end_effector vacuum_cup\n"
      << "set mating.seat+leg1.transverse_fraction 0.5\n"
      << "set mating.seat+leg1.offset_m 0.01\n"
      << "option task_only 1\n"
      << "screenshot cell.png\n"
      << "run\n"
      << "wait\n"
      << "expect-problem No plan found\n"
      << "expect-problem balances the mating wrench\n"
      << "expect-marked seat+leg1\n"
      << "show 1\n"
      << "expect-selected part leg1\n"
      << "expect-selected step seat+leg1\n"
      << "screenshot shown.png\n"
      << "show off\n"
      << "set part.leg4.initial_xyz 1.5 0 0.75\n"
      << "validate\n"
      << "expect-problem warning part 'leg4' / initial_pose\n"
      << "select step seat+leg1\n"
      << "expect-refused set mating.seat+leg1.force_N -5\n"
      << "expect-field-error mating.seat+leg1.force_N at least 0\n"
      << "screenshot refused.png\n";
  const ProcessRun r = WrapUnderXvfb(
      dir, "'" + ExampleProject("stool").string() + "' --script fail.wrapscript --size 1400x900");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("ok 25: screenshot refused.png"), std::string::npos) << r.output;
  // Show: the viewport changed (the tried part highlighted amber, the scene as the check saw it).
  auto cell = render::ReadPng(dir / "cell.png");
  auto shown = render::ReadPng(dir / "shown.png");
  auto refused = render::ReadPng(dir / "refused.png");
  ASSERT_TRUE(cell && shown && refused);
  const PixelDiff show = Diff(*cell, *shown, 340, 60, 1010, 560);
  EXPECT_GT(show.pixels, 300) << "the failing state is drawn";
  // The refusal is written at the field, in the mating panel (right column, middle): red text.
  const RegionStats mating = Stats(*refused, 1030, 400, 1395, 640, {255, 115, 102});
  EXPECT_GT(mating.near_colour, 20) << "the refusal's red text under the force field";
}

// No stale picture: File > New draws the empty cell (as a GUI started without a project does);
// an edit marks the plan out of date (not played as current) and undo makes it current again;
// Save As keeps the undo history.
TEST(GuiCli, NewAndEditsNeverShowAStalePicture) {
  ASSERT_TRUE(HaveXvfb()) << "xvfb-run not installed (scripts/install_deps.sh installs it)";
  const auto dir = ScratchDir("gui_cli_stale");
  std::ofstream(dir / "empty.wrapscript") << "expect-viewport empty\nscreenshot empty.png\n";
  const ProcessRun e = WrapUnderXvfb(dir, "--script empty.wrapscript --size 1400x900");
  ASSERT_EQ(e.code, 0) << e.output;
  std::ofstream(dir / "stale.wrapscript") << "option task_only 1\n"
                                          << "run\n"
                                          << "wait\n"
                                          << "expect-plan\n"
                                          << "expect-plan-current\n"
                                          << "scrub 2\n"
                                          << "screenshot current.png\n"
                                          << "set part.leg1.initial_xyz 0.12 0.2 0.47\n"
                                          << "expect-plan-stale\n"
                                          << "screenshot stale.png\n"
                                          << "undo\n"
                                          << "expect-plan-current\n"
                                          << "set part.seat.mass_kg 0.3\n"
                                          << "save elsewhere/moved.json\n"
                                          << "expect-undo seat\n"
                                          << "undo\n"
                                          << "save\n"
                                          << "expect-viewport cell\n"
                                          << "new\n"
                                          << "expect-viewport empty\n"
                                          << "screenshot new.png\n";
  fs::create_directories(dir / "elsewhere");
  const ProcessRun r = WrapUnderXvfb(dir, "'" + ExampleProject("half_stool").string() +
                                              "' --script stale.wrapscript --size 1400x900");
  ASSERT_EQ(r.code, 0) << r.output;
  // New: the viewport as without a project (the empty cell), not the half stool's.
  auto empty = render::ReadPng(dir / "empty.png");
  auto fresh = render::ReadPng(dir / "new.png");
  auto current = render::ReadPng(dir / "current.png");
  auto stale = render::ReadPng(dir / "stale.png");
  ASSERT_TRUE(empty && fresh && current && stale);
  const PixelDiff same = Diff(*empty, *fresh, 340, 60, 1010, 560);
  EXPECT_LT(same.pixels, 0.01 * 670 * 500) << "New draws the empty cell";
  const PixelDiff cell = Diff(*current, *fresh, 340, 60, 1010, 560);
  EXPECT_GT(cell.pixels, 0.05 * 670 * 500) << "... which differs from the half stool's";
  // Out of date: the lanes are grey (no orange assemble bars), the plan is not shown as current.
  EXPECT_GT(Stats(*current, 330, 600, 1010, 880, {230, 140, 50}).near_colour, 100);
  EXPECT_LT(Stats(*stale, 330, 600, 1010, 880, {230, 140, 50}).near_colour, 20);
  // Save As then undo: the saved file holds the undone state, its meshes found from its folder.
  auto saved = Document::Open(dir / "elsewhere/moved.json");
  ASSERT_TRUE(saved) << saved.error().message;
  EXPECT_FALSE(saved->project().parts[0].mass_kg.has_value() &&
               *saved->project().parts[0].mass_kg == 0.3);
  for (const Part& part : saved->project().parts) {
    EXPECT_TRUE(fs::exists(dir / "elsewhere" / part.mesh)) << part.mesh;
  }
}

}  // namespace
}  // namespace wrap::gui
