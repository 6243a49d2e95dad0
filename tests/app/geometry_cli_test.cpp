// The geometry checks through the CLI: wrap validate and wrap plan refuse what the meshes say is
// impossible, wrap info prints the contact graph, and every example project passes.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"
#include "geometry/mesh_export.h"

namespace wrap::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A copy of an example project in a fresh temporary folder, its mesh paths made absolute, changed
// by `edit`.
fs::path Variant(const std::string& name, const std::string& tag,
                 const std::function<void(json&)>& edit) {
  const fs::path dir =
      fs::temp_directory_path() / ("wrap_geometry_cli_" + std::to_string(::getpid()) + "_" + tag);
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ifstream in(Project(name));
  json p = json::parse(in);
  const fs::path projects = fs::path(WRAP_SOURCE_DIR) / "projects";
  for (json& part : p["parts"]) {
    part["mesh"] = fs::weakly_canonical(projects / part["mesh"].get<std::string>()).string();
  }
  edit(p);
  const fs::path file = dir / (name + ".json");
  std::ofstream(file) << p.dump(2);
  return file;
}

json& StepNamed(json& p, const std::string& name) {
  for (json& s : p["steps"]) {
    if (s["name"] == name) return s;
  }
  throw std::runtime_error("no step " + name);
}

TEST(GeometryCli, SidewaysLegIsRefusedWithTheFreeDirection) {
  const fs::path file = Variant("stool", "sideways", [](json& p) {
    StepNamed(p, "seat+leg1")["mating"]["axis"] = {1, 0, 0};
  });
  const CliRun v = Wrap({"validate", file.string()});
  EXPECT_EQ(v.code, 2) << v.out << v.err;
  EXPECT_NE(v.err.find("step 'seat+leg1', mating.axis: error: 'leg1' moving along "
                       "[1, 0, 0] hits 'seat'"),
            std::string::npos)
      << v.err;
  EXPECT_NE(v.err.find("before its mating pose; free directions: [0, 0, 1]"), std::string::npos)
      << v.err;
  // The planner refuses it too, with the same words, before it plans.
  const CliRun plan = Wrap({"plan", file.string(), "--task-only"});
  EXPECT_EQ(plan.code, 2) << plan.out << plan.err;
  EXPECT_NE(plan.err.find("'leg1' moving along [1, 0, 0] hits 'seat'"), std::string::npos)
      << plan.err;
}

TEST(GeometryCli, LegFromAboveThroughTheSeatIsRefused) {
  const fs::path file = Variant("stool", "above", [](json& p) {
    StepNamed(p, "seat+leg1")["mating"]["axis"] = {0, 0, -1};
  });
  const CliRun v = Wrap({"validate", file.string()});
  EXPECT_EQ(v.code, 2) << v.out << v.err;
  EXPECT_NE(v.err.find("'leg1' moving along [0, 0, -1] hits 'seat'"), std::string::npos) << v.err;
}

TEST(GeometryCli, PartsStackedAtTheStartAreRefused) {
  const fs::path file = Variant("stool", "stacked", [](json& p) {
    p["parts"][2]["initial_pose"] = p["parts"][1]["initial_pose"];
  });
  const CliRun v = Wrap({"validate", file.string()});
  EXPECT_EQ(v.code, 2) << v.out << v.err;
  EXPECT_NE(v.err.find("part 'leg2', initial_pose: error: part 'leg2' overlaps part 'leg1' by "),
            std::string::npos)
      << v.err;
}

TEST(GeometryCli, InfoPrintsTheContactGraphAndInsertionPaths) {
  const CliRun r = Wrap({"info", Project("stool")});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("Contacts (parts whose surfaces come within 1.0 mm, assembled; 4 pairs)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("seat - leg1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("seat+leg1             free over 30.0 mm along +z"), std::string::npos)
      << r.out;
}

// A 2 mm plate lying flat on the table: a two-finger gripper would have to put a finger under it
// (the plate is wider than the stroke across its face), so no grasp clears the table: a warning
// that says so, by the planner's own pick checks.
TEST(GeometryCli, PartThatNoGraspCanTakeFromTheTableIsAWarning) {
  const fs::path dir =
      fs::temp_directory_path() / ("wrap_geometry_cli_plate_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_TRUE(WriteStl(dir / "block.stl", BoxMesh(Vec3(-0.03, -0.03, 0), Vec3(0.03, 0.03, 0.04))));
  ASSERT_TRUE(
      WriteStl(dir / "plate.stl", BoxMesh(Vec3(-0.05, -0.05, 0.04), Vec3(0.05, 0.05, 0.042))));
  const json project = json::parse(R"({
    "format": "wrap-project", "version": 1, "name": "plate",
    "parts": [
      {"name": "block", "mesh": "block.stl", "initial_pose": {"xyz": [-0.15, 0, 0.75]}},
      {"name": "plate", "mesh": "plate.stl", "initial_pose": {"xyz": [0.15, 0, 0.71]}}
    ],
    "steps": [{"name": "block+plate", "inputs": ["block", "plate"],
               "mating": {"moved": "plate", "base": "block", "axis": [0, 0, -1]}}],
    "robots": [
      {"name": "a", "model": "ur5e", "end_effector": "robotiq_2f85",
       "base_pose": {"xyz": [0.45, 0.35, 0.75], "rpy_deg": [0, 0, -142]}},
      {"name": "b", "model": "ur5e", "end_effector": "robotiq_2f85",
       "base_pose": {"xyz": [-0.45, -0.35, 0.75], "rpy_deg": [0, 0, 38]}}
    ]})");
  std::ofstream(dir / "plate.json") << project.dump(2);
  const CliRun v = Wrap({"validate", (dir / "plate.json").string()});
  EXPECT_EQ(v.code, 0) << v.err;  // a warning, not an error
  EXPECT_NE(
      v.err.find("part 'plate', initial_pose: warning: no grasp of 'plate' can be taken where it "
                 "rests (every one of the"),
      std::string::npos)
      << v.err;
  EXPECT_NE(v.err.find("gripper into the table)"), std::string::npos) << v.err;
  EXPECT_EQ(v.err.find("'block' can be taken"), std::string::npos) << v.err;
  // The planner names the same blocker first, before any count of failed checks.
  const CliRun plan = Wrap({"plan", (dir / "plate.json").string(), "--task-only"});
  EXPECT_EQ(plan.code, 1) << plan.out << plan.err;
  const std::string words = plan.out + plan.err;
  const size_t blocker = words.find("no grasp of 'plate' can be taken where it rests");
  EXPECT_NE(blocker, std::string::npos) << words;
  EXPECT_LT(blocker, words.find("failed ")) << words;
}

// Every example project is consistent with its meshes: no error, no warning.
class ExampleGeometry : public ::testing::TestWithParam<std::string> {};

TEST_P(ExampleGeometry, ValidatesWithoutWarnings) {
  const std::string name = GetParam();
  if (name.rfind("fabrica", 0) == 0 && !fs::exists(fs::path(WRAP_SHARED_DIR) / "fabrica") &&
      std::getenv("WRAP_FABRICA_DIR") == nullptr) {
    GTEST_SKIP() << "the Fabrica meshes are not beside the repository";
  }
  const CliRun r = Wrap({"validate", Project(name)});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find(", 0 warning(s)"), std::string::npos) << r.out << r.err;
}

INSTANTIATE_TEST_SUITE_P(Examples, ExampleGeometry,
                         ::testing::Values("stool", "half_stool", "chair", "cross", "cross_openarm",
                                           "cube", "cube_2x2x3", "fabrica_beam",
                                           "fabrica_plumbers_block", "fabrica_car", "fabrica_gamepad",
                                           "fabrica_cooling_manifold"),
                         [](const auto& param_info) { return param_info.param; });

}  // namespace
}  // namespace wrap::cli
