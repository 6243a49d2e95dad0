// `wrap new` and `wrap suggest` through the CLI: bad input says what is wrong and exits 2;
// projects made from the example meshes (exported in their assembled positions) and from the
// Fabrica folders validate cleanly and plan.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>

#include "../app/cli_runner.h"
#include "geometry/mesh_export.h"
#include "geometry/step_import.h"
#include "model/project_io.h"
#include "model/validate.h"
#include "test_build_config.h"

namespace wrap::cli {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("wrap_new_cli_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The parts of an example project, each written as an STL in its assembled position (m).
fs::path ExportAssembled(const std::string& name) {
  const fs::path dir = TempDir("meshes_" + name);
  const LoadedProject lp = LoadProject(Project(name));
  EXPECT_TRUE(lp.ok());
  for (size_t i = 0; i < lp.project->parts.size(); ++i) {
    const Part& part = lp.project->parts[i];
    const TriangleMesh placed =
        Transformed(lp.check.parts[i].mesh, ToIsometry(part.assembled_pose));
    EXPECT_TRUE(WriteStl(dir / (part.name + ".stl"), placed));
  }
  return dir;
}

bool HaveFabrica() { return fs::exists(fs::path(WRAP_SHARED_DIR) / "fabrica" / "beam"); }

TEST(NewCli, BadInputExitsTwoSayingWhy) {
  const fs::path empty = TempDir("empty");
  CliRun r = Wrap({"new", empty.string(), "-o", (empty / "p.json").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("holds no mesh file"), std::string::npos) << r.err;

  const fs::path one = TempDir("one");
  ASSERT_TRUE(WriteStl(one / "a.stl", BoxMesh(Vec3(0, 0, 0), Vec3(0.05, 0.05, 0.05))));
  r = Wrap({"new", one.string(), "-o", (one / "p.json").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("only one mesh"), std::string::npos) << r.err;

  const fs::path bad = TempDir("bad");
  ASSERT_TRUE(WriteStl(bad / "a.stl", BoxMesh(Vec3(0, 0, 0), Vec3(0.05, 0.05, 0.05))));
  std::ofstream(bad / "b.stl") << "this is not a mesh";
  r = Wrap({"new", bad.string(), "-o", (bad / "p.json").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("b.stl"), std::string::npos) << r.err;

  const fs::path open = TempDir("open");
  TriangleMesh box = BoxMesh(Vec3(0, 0, 0), Vec3(0.05, 0.05, 0.05));
  ASSERT_TRUE(WriteStl(open / "a.stl", box));
  box.triangles.pop_back();
  ASSERT_TRUE(WriteStl(open / "b.stl", box));
  r = Wrap({"new", open.string(), "-o", (open / "p.json").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("is not closed"), std::string::npos) << r.err;

  const fs::path overlap = TempDir("overlap");
  ASSERT_TRUE(WriteStl(overlap / "a.stl", BoxMesh(Vec3(0, 0, 0), Vec3(0.05, 0.05, 0.05))));
  ASSERT_TRUE(WriteStl(overlap / "b.stl", BoxMesh(Vec3(0.03, 0, 0), Vec3(0.08, 0.05, 0.05))));
  r = Wrap({"new", overlap.string(), "-o", (overlap / "p.json").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("overlap where they are assembled"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(overlap / "p.json"));  // nothing written
}

// From meshes only: the project validates with no warning and plans (task only, seed 0).
class NewFromMeshes : public ::testing::TestWithParam<std::string> {};

TEST_P(NewFromMeshes, ValidatesAndPlans) {
  const std::string name = GetParam();
  fs::path meshes;
  if (name.rfind("fabrica_", 0) == 0) {
    if (!HaveFabrica()) GTEST_SKIP() << "the Fabrica meshes are not beside the repository";
    meshes = fs::path(WRAP_SHARED_DIR) / "fabrica" / name.substr(8);
  } else {
    meshes = ExportAssembled(name);
  }
  const fs::path out = TempDir("project_" + name) / (name + ".json");
  const CliRun made = Wrap({"new", meshes.string(), "-o", out.string()});
  ASSERT_EQ(made.code, 0) << made.out << made.err;
  EXPECT_NE(made.out.find("unit: "), std::string::npos) << made.out;
  EXPECT_NE(made.out.find("step 1: "), std::string::npos) << made.out;
  const CliRun v = Wrap({"validate", out.string()});
  EXPECT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.out.find(", 0 warning(s)"), std::string::npos) << v.out << v.err;
  const CliRun plan = Wrap({"plan", out.string(), "--task-only", "--validate", "--seed", "0"});
  EXPECT_EQ(plan.code, 0) << made.out << plan.out << plan.err;
  EXPECT_NE(plan.out.find("Validated:"), std::string::npos) << plan.out;
}

#if WRAP_TEST_WITH_OCCT
// From one STEP assembly file (the shipped stool: a seat and four instances of one leg, in
// millimetres): one part per instance, named after it, sharing the leg's solid, placed where the
// file places it; each rests on the table (validation warns of a floating part), and the project
// plans with motion and validates. (Both STEP tests: a build with OpenCASCADE only.)
TEST(NewCli, FromAStepAssemblyFile) {
  const fs::path step = fs::path(WRAP_SOURCE_DIR) / "assets" / "parts" / "step" / "stool.step";
  const fs::path out = TempDir("from_step") / "stool_new.json";
  const CliRun made = Wrap({"new", step.string(), "-o", out.string()});
  ASSERT_EQ(made.code, 0) << made.out << made.err;
  EXPECT_NE(made.out.find("the STEP file's own unit (millimetre)"), std::string::npos) << made.out;
  const CliRun v = Wrap({"validate", out.string()});
  EXPECT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.out.find(", 0 warning(s)"), std::string::npos) << v.out << v.err;

  const LoadedProject lp = LoadProject(out);
  ASSERT_TRUE(lp.ok());
  const wrap::Project& p = *lp.project;
  ASSERT_EQ(p.parts.size(), 5u);
  int legs = 0;
  for (const Part& part : p.parts) {
    EXPECT_EQ(fs::path(part.mesh).filename(), "stool.step") << part.name;
    EXPECT_EQ(part.scale, 1.0) << part.name;
    if (part.solid == "leg") {
      ++legs;
      // The legs stand at the seat's corners: placed by the file, not at the origin.
      EXPECT_GT(part.assembled_pose.xyz.head<2>().norm(), 0.05) << part.name;
    }
  }
  EXPECT_EQ(legs, 4);
  EXPECT_EQ(p.steps.size(), 4u);

  const CliRun plan = Wrap({"plan", out.string(), "--validate", "--seed", "0"});
  EXPECT_EQ(plan.code, 0) << made.out << plan.out << plan.err;
  EXPECT_NE(plan.out.find("Trajectories checked:"), std::string::npos) << plan.out;
}

// A STEP file with a single part is not an assembly: exit 2 saying so, nothing written.
TEST(NewCli, AStepFileWithOnePartIsRefused) {
  const fs::path step =
      fs::path(WRAP_SOURCE_DIR) / "tests" / "fuzz" / "seeds" / "step" / "box_mm.step";
  const fs::path out = TempDir("from_step_one") / "p.json";
  const CliRun r = Wrap({"new", step.string(), "-o", out.string()});
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("box_mm.step"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("an assembly needs at least two"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}
#endif  // WRAP_TEST_WITH_OCCT

INSTANTIATE_TEST_SUITE_P(Examples, NewFromMeshes,
                         ::testing::Values("stool", "cross", "fabrica_beam",
                                           "fabrica_plumbers_block", "fabrica_car",
                                           "fabrica_gamepad", "fabrica_cooling_manifold"),
                         [](const auto& param_info) { return param_info.param; });

TEST(SuggestCli, SidewaysLegGetsItsFreeAxisAndApplies) {
  const fs::path dir = TempDir("suggest");
  std::ifstream in(Project("stool"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Mesh paths relative to the projects folder: write the variant there's sibling, absolute.
  const std::string from = "\"../assets/";
  const std::string to = "\"" + (fs::path(WRAP_SOURCE_DIR) / "assets").generic_string() + "/";
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
    text.replace(at, from.size(), to);
  }
  const std::string axis = "\"moved\": \"leg1\", \"base\": \"seat\", \"axis\": [0, 0, 1]";
  const size_t a = text.find(axis);
  ASSERT_NE(a, std::string::npos) << "the stool's first mating changed; update the test";
  text.replace(a, axis.size(), "\"moved\": \"leg1\", \"base\": \"seat\", \"axis\": [1, 0, 0]");
  const fs::path file = dir / "stool.json";
  std::ofstream(file) << text;
  const CliRun s = Wrap({"suggest", file.string()});
  EXPECT_EQ(s.code, 1) << s.out << s.err;
  EXPECT_NE(s.out.find("steps[0].mating.axis: use [0, 0, 1] instead of [1, 0, 0]"),
            std::string::npos)
      << s.out;
  const fs::path fixed = dir / "fixed.json";
  const CliRun apply = Wrap({"suggest", file.string(), "--apply", "-o", fixed.string()});
  EXPECT_EQ(apply.code, 0) << apply.out << apply.err;
  const CliRun v = Wrap({"validate", fixed.string()});
  EXPECT_EQ(v.code, 0) << v.err;
  // --apply without -o refuses; the input is never overwritten unless named.
  EXPECT_EQ(Wrap({"suggest", file.string(), "--apply"}).code, 2);
}

// The car's wheels, the manifold's pipes and the gamepad's buttons are held by fingertip grasps
// where mated (no full-pad grasp clears their partner): `wrap suggest` counted full-pad grasps
// only and proposed moving the body, plate or housing onto them instead, a base that cannot take
// the insertion. With reduced grasps counted it finds nothing to fix in the shipped projects.
TEST(SuggestCli, PartsHeldByTheirFingertipsKeepTheMovedRole) {
  if (!HaveFabrica()) GTEST_SKIP() << "the Fabrica meshes are not beside the repository";
  for (const char* name : {"fabrica_car", "fabrica_cooling_manifold", "fabrica_gamepad"}) {
    const CliRun s = Wrap({"suggest", Project(name)});
    EXPECT_EQ(s.code, 0) << name << ": " << s.out << s.err;
    EXPECT_EQ(s.out.find("swap moved and base"), std::string::npos) << name << ": " << s.out;
    EXPECT_NE(s.out.find("finds nothing to fix"), std::string::npos) << name << ": " << s.out;
  }
}

}  // namespace
}  // namespace wrap::cli
