// Project format: round trip, every validation rule with a broken fixture, the example projects.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "geometry/mesh_export.h"
#include "model/catalog.h"
#include "model/entity_path.h"
#include "model/paths.h"
#include "model/project_io.h"
#include "model/validate.h"
#include "test_build_config.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// A closed axis-aligned box mesh centred at the origin [m].
TriangleMesh Box(const Vec3& size) {
  TriangleMesh m;
  const Vec3 h = size / 2;
  for (int i = 0; i < 8; ++i) {
    m.vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                            (i & 4) ? h.z() : -h.z());
  }
  const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                        {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& t : f) m.triangles.emplace_back(t[0], t[1], t[2]);
  return m;
}

// A folder with a valid small project: two 4 cm cubes stacked, two UR5e.
class ProjectFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("wrap_model_test_" + std::to_string(::getpid()) + "_" +
                                        info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "meshes");
    ASSERT_TRUE(WriteObj(dir_ / "meshes" / "cube.obj", Box(Vec3(40, 40, 40)), 1.0));
    doc_ = json::parse(R"({
      "format": "wrap-project", "version": 1, "name": "two cubes",
      "table": {"size": [1.6, 1.2, 0.05], "height": 0.75, "friction": 0.4},
      "parts": [
        {"name": "bottom", "mesh": "meshes/cube.obj", "scale": 0.001,
         "assembled_pose": {"xyz": [0, 0, 0.02]},
         "initial_pose": {"xyz": [0.1, 0.0, 0.77]}, "color": [0.9, 0.4, 0.1]},
        {"name": "top", "mesh": "meshes/cube.obj", "scale": 0.001, "mass_kg": 0.05,
         "assembled_pose": {"xyz": [0, 0, 0.06]},
         "initial_pose": {"xyz": [-0.1, 0.0, 0.77], "rpy_deg": [0, 0, 90]}}
      ],
      "steps": [
        {"name": "stack", "inputs": ["bottom", "top"],
         "mating": {"moved": "top", "base": "bottom", "axis": [0, 0, -1], "force_N": 10,
                    "transverse_fraction": 0.1, "offset_m": 0.005}}
      ],
      "robots": [
        {"name": "a", "model": "ur5e", "end_effector": "robotiq_2f85",
         "base_pose": {"xyz": [-0.5, -0.4, 0.75]}},
        {"name": "b", "model": "ur5e", "end_effector": "vacuum_cup",
         "base_pose": {"xyz": [0.5, 0.4, 0.75], "rpy": [0, 0, 3.14159]}}
      ],
      "planner": {"grasps": 20, "time_limit_s": 30, "seed": 3}
    })");
  }

  // Writes the document and validates it.
  LoadedProject Load(const std::string& text) {
    const fs::path f = dir_ / "project.json";
    EXPECT_TRUE(WriteFileAtomic(f, text));
    return LoadProject(f);
  }
  LoadedProject Load() { return Load(doc_.dump(2)); }

  // Asserts exactly which diagnostic appears: severity, JSON path and a key phrase.
  static void ExpectDiag(const LoadedProject& lp, Severity sev, const std::string& path,
                         const std::string& phrase) {
    for (const Diagnostic& d : lp.check.diagnostics.items) {
      if (d.severity == sev && d.path == path && d.message.find(phrase) != std::string::npos) {
        EXPECT_NE(d.file.find("project.json"), std::string::npos) << "file not named";
        return;
      }
    }
    std::string all;
    for (const Diagnostic& d : lp.check.diagnostics.items) all += Format(d) + "\n";
    ADD_FAILURE() << "no " << (sev == Severity::kError ? "error" : "warning") << " at '" << path
                  << "' containing '" << phrase << "'; got:\n"
                  << all;
  }
  static void ExpectError(const LoadedProject& lp, const std::string& path,
                          const std::string& phrase) {
    EXPECT_FALSE(lp.ok());
    ExpectDiag(lp, Severity::kError, path, phrase);
  }

  fs::path dir_;
  json doc_;
};

TEST_F(ProjectFixture, ValidFixtureHasNoProblems) {
  const LoadedProject lp = Load();
  for (const Diagnostic& d : lp.check.diagnostics.items) ADD_FAILURE() << Format(d);
  ASSERT_TRUE(lp.ok());
  const Project& p = *lp.project;
  EXPECT_EQ(p.parts.size(), 2u);
  EXPECT_NEAR(p.parts[1].initial_pose.rpy.z(), M_PI / 2, 1e-12);  // rpy_deg converted
  EXPECT_EQ(p.planner.seed, 3u);
  // Mass from density (PLA) times the cube's volume; given mass kept.
  EXPECT_NEAR(lp.check.parts[0].mass_kg, 1240.0 * 0.04 * 0.04 * 0.04, 1e-9);
  EXPECT_DOUBLE_EQ(lp.check.parts[1].mass_kg, 0.05);
  ASSERT_TRUE(lp.check.tree);
  EXPECT_EQ(lp.check.tree->nodes[lp.check.tree->root].name, "stack");
  EXPECT_EQ(lp.check.tree->nodes[lp.check.tree->root].parts, (std::vector<int>{0, 1}));
}

TEST_F(ProjectFixture, DefaultsMatchThePaperTable) {
  const Project p = *Load().project;
  EXPECT_EQ(p.wrench_limits.two_finger.force_N, Vec3(50.0, 39.7, 50.0));
  EXPECT_EQ(p.wrench_limits.two_finger.torque_Nm, Vec3(4.7, 4.5, 3.0));
  EXPECT_EQ(p.wrench_limits.vacuum_assembly.force_N, Vec3(0.0, 0.0, 110.0));
  EXPECT_EQ(p.wrench_limits.vacuum_assembly.torque_Nm, Vec3::Zero());
  EXPECT_EQ(p.wrench_limits.vacuum_transport.force_N, Vec3(67.4, 67.4, 110.0));
  EXPECT_EQ(p.wrench_limits.vacuum_transport.torque_Nm, Vec3(5.0, 5.0, 2.1));
}

TEST_F(ProjectFixture, LoadSaveLoadIsIdentical) {
  doc_["paths"] = {{"M", {{"default", "meshes"}, {"env", "WRAP_TEST_UNSET_VAR"}}}};
  doc_["parts"][0]["mesh"] = "${M}/cube.obj";
  doc_["steps"][0]["mating"]["final_poses"] = {{{"xyz", {0, 0, 0.04}}},
                                               {{"xyz", {0, 0, 0.04}}, {"rpy", {0, 0, 1.5}}}};
  doc_["steps"][0]["mating"]["connection_limits"] = {{"force_N", {1, 2, 3}},
                                                     {"torque_Nm", {0.1, 0.2, 0.3}}};
  doc_["steps"][0]["parts"] = {"bottom", "top"};
  doc_["robots"][1]["wrench_limits"] = {
      {"two_finger", {{"force_N", {1, 1, 1}}, {"torque_Nm", {1, 1, 1}}}}};
  const LoadedProject first = Load();
  ASSERT_TRUE(first.ok());
  const fs::path saved = dir_ / "saved.json";
  ASSERT_TRUE(SaveProject(*first.project, saved));
  const LoadedProject second = LoadProject(saved);
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(*first.project, *second.project);
  // And the text is stable: saving again gives the same bytes.
  EXPECT_EQ(SerializeProject(*second.project), *ReadFile(saved));
  // Key order puts the format first.
  EXPECT_EQ(ReadFile(saved)->find("\"format\""), 4u);
}

TEST_F(ProjectFixture, SaveNeverLeavesAHalfWrittenFile) {
  const Project p = *Load().project;
  const fs::path target = dir_ / "target.json";
  ASSERT_TRUE(WriteFileAtomic(target, "old contents"));
  // Saving into a folder that is not there fails and leaves the old file alone.
  EXPECT_FALSE(SaveProject(p, dir_ / "nope" / "target.json"));
  EXPECT_EQ(*ReadFile(target), "old contents");
  ASSERT_TRUE(SaveProject(p, target));
  EXPECT_EQ(*ReadFile(target), SerializeProject(p));
}

TEST_F(ProjectFixture, MalformedJsonGivesLineAndColumn) {
  const LoadedProject lp = Load("{\n  \"format\": \"wrap-project\",\n  \"version\": 1,\n  ]\n}");
  ASSERT_FALSE(lp.ok());
  ASSERT_EQ(lp.check.diagnostics.items.size(), 1u);
  const std::string& msg = lp.check.diagnostics.items[0].message;
  EXPECT_NE(msg.find("malformed JSON"), std::string::npos) << msg;
  EXPECT_NE(msg.find("line 4"), std::string::npos) << msg;
  EXPECT_NE(msg.find("column"), std::string::npos) << msg;
}

TEST_F(ProjectFixture, WrongFormatAndVersion) {
  doc_["format"] = "something-else";
  ExpectError(Load(), "format", "expected \"wrap-project\"");
  doc_["format"] = "wrap-project";
  doc_["version"] = 7;
  ExpectError(Load(), "version", "newer Wrap");
  doc_.erase("version");
  ExpectError(Load(), "version", "required field is missing");
}

TEST_F(ProjectFixture, WrongTypes) {
  doc_["parts"][0]["scale"] = "big";
  doc_["table"]["size"] = {1, 2};
  doc_["planner"]["grasps"] = 2.5;
  doc_["steps"][0]["inputs"] = "bottom";
  doc_["robots"][0]["base_pose"]["xyz"][1] = "x";
  const LoadedProject lp = Load();
  ExpectError(lp, "parts[0].scale", "expected a number, found a string");
  ExpectError(lp, "table.size", "expected an array of 3 numbers, found an array of 2");
  ExpectError(lp, "planner.grasps", "expected an integer");
  ExpectError(lp, "steps[0].inputs", "expected an array, found a string");
  ExpectError(lp, "robots[0].base_pose.xyz[1]", "expected a number");
}

TEST_F(ProjectFixture, DeeplyNestedJsonDoesNotCrash) {
  const int depth = 200000;
  const std::string text = std::string(depth, '[') + std::string(depth, ']');
  const ProjectParse parse = ParseProject(text, "deep.json");
  EXPECT_FALSE(parse.project);
  EXPECT_TRUE(parse.diagnostics.has_errors());
  // Deep nesting inside a valid project: reported as a wrong type, not a crash. (Built as
  // text: nlohmann's dump() itself recurses.)
  std::string doc = doc_.dump();
  doc.insert(1, "\"description\": " + text + ", ");
  ExpectError(Load(doc), "description", "expected a string");
}

TEST_F(ProjectFixture, TopLevelNotAnObject) {
  ExpectError(Load("[1, 2, 3]"), "", "expected a JSON object");
}

TEST_F(ProjectFixture, MissingRequiredFields) {
  doc_["parts"][0].erase("initial_pose");
  doc_["robots"][0].erase("end_effector");
  doc_["steps"][0]["mating"].erase("moved");
  const LoadedProject lp = Load();
  ExpectError(lp, "parts[0].initial_pose", "required field is missing");
  ExpectError(lp, "robots[0].end_effector", "required field is missing");
  ExpectError(lp, "steps[0].mating.moved", "required field is missing");
}

TEST_F(ProjectFixture, UnknownFieldsWarnButStayValid) {
  doc_["parts"][0]["colour"] = {1, 0, 0};
  doc_["extra"] = true;
  const LoadedProject lp = Load();
  EXPECT_TRUE(lp.ok());
  ExpectDiag(lp, Severity::kWarning, "parts[0].colour", "unknown field");
  ExpectDiag(lp, Severity::kWarning, "extra", "unknown field");
}

TEST_F(ProjectFixture, UnknownReferences) {
  doc_["steps"][0]["inputs"][1] = "lid";
  doc_["steps"][0]["mating"]["moved"] = "lid";
  const LoadedProject lp = Load();
  ExpectError(lp, "steps[0].inputs[1]", "unknown input 'lid'");
  ExpectError(lp, "steps", "more than one root ('top', 'stack')");
  doc_["steps"][0]["inputs"][1] = "top";
  ExpectError(Load(), "steps[0].mating.moved", "'lid' is not an input of step 'stack'");
}

TEST_F(ProjectFixture, MatingMustNameBothInputs) {
  doc_["steps"][0]["mating"]["base"] = "top";
  ExpectError(Load(), "steps[0].mating.base", "must differ");
}

TEST_F(ProjectFixture, CycleInTheDag) {
  doc_["parts"].push_back(doc_["parts"][1]);
  doc_["parts"][2]["name"] = "third";
  doc_["parts"][2]["initial_pose"]["xyz"] = {0.0, 0.2, 0.77};
  doc_["steps"] = json::parse(R"([
    {"name": "s1", "inputs": ["bottom", "s2"], "mating": {"moved": "s2", "base": "bottom"}},
    {"name": "s2", "inputs": ["s1", "top"], "mating": {"moved": "top", "base": "s1"}}
  ])");
  ExpectError(Load(), "steps", "cycle through steps 's1', 's2'");
}

TEST_F(ProjectFixture, PartInTwoInputsOfAStep) {
  doc_["parts"].push_back(doc_["parts"][1]);
  doc_["parts"][2]["name"] = "third";
  doc_["parts"][2]["initial_pose"]["xyz"] = {0.0, 0.2, 0.77};
  // 'bottom' is consumed by s1 and by s2; s3 joins both, so 'bottom' would be in it twice.
  doc_["steps"] = json::parse(R"([
    {"name": "s1", "inputs": ["bottom", "top"], "mating": {"moved": "top", "base": "bottom"}},
    {"name": "s2", "inputs": ["bottom", "third"], "mating": {"moved": "third", "base": "bottom"}},
    {"name": "s3", "inputs": ["s1", "s2"], "mating": {"moved": "s2", "base": "s1"}}
  ])");
  const LoadedProject lp = Load();
  ExpectError(lp, "steps[1].inputs[0]", "'bottom' is already an input of step 's1'");
}

TEST_F(ProjectFixture, InputsDoNotPartitionTheDeclaredParts) {
  doc_["steps"][0]["parts"] = {"bottom"};
  ExpectError(Load(), "steps[0].parts", "do not partition");
  doc_["steps"][0]["parts"] = {"bottom", "top", "ghost"};
  ExpectError(Load(), "steps[0].parts", "unknown part 'ghost'");
}

TEST_F(ProjectFixture, StepNeedsTwoInputs) {
  doc_["steps"][0]["inputs"] = {"bottom"};
  ExpectError(Load(), "steps[0].inputs", "exactly two inputs");
}

TEST_F(ProjectFixture, MoreThanOneRoot) {
  doc_["parts"].push_back(doc_["parts"][1]);
  doc_["parts"][2]["name"] = "loose";
  doc_["parts"][2]["initial_pose"]["xyz"] = {0.0, 0.2, 0.77};
  ExpectError(Load(), "steps", "more than one root ('loose', 'stack')");
}

TEST_F(ProjectFixture, DuplicateNames) {
  doc_["parts"][1]["name"] = "bottom";
  doc_["robots"][1]["name"] = "a";
  const LoadedProject lp = Load();
  ExpectError(lp, "parts[1].name", "already used at parts[0].name");
  ExpectError(lp, "robots[1].name", "already used");
}

TEST_F(ProjectFixture, NonPositiveAndNonFiniteNumbers) {
  doc_["parts"][0]["scale"] = 0;
  doc_["parts"][1]["mass_kg"] = -1;
  doc_["parts"][0]["density_kg_m3"] = -5;
  doc_["table"]["friction"] = 0;
  doc_["table"]["size"][2] = -0.05;
  doc_["steps"][0]["mating"]["force_N"] = -10;
  doc_["steps"][0]["mating"]["axis"] = {0, 0, 0};
  doc_["planner"]["time_limit_s"] = 0;
  doc_["wrench_limits"] = {{"two_finger", {{"force_N", {50, -1, 50}}, {"torque_Nm", {1, 1, 1}}}}};
  const LoadedProject lp = Load();
  ExpectError(lp, "parts[0].scale", "must be positive, found 0");
  ExpectError(lp, "parts[1].mass_kg", "must be positive, found -1");
  ExpectError(lp, "parts[0].density_kg_m3", "must be positive");
  ExpectError(lp, "table.friction", "must be positive");
  ExpectError(lp, "table.size[2]", "must be positive");
  ExpectError(lp, "steps[0].mating.force_N", "must not be negative");
  ExpectError(lp, "steps[0].mating.axis", "must not be zero");
  ExpectError(lp, "planner.time_limit_s", "positive finite");
  ExpectError(lp, "wrench_limits.two_finger.force_N[1]", "must not be negative");
}

TEST_F(ProjectFixture, OverflowingNumberIsRejected) {
  std::string text = doc_.dump(2);
  const std::string from = "\"friction\": 0.4";
  text.replace(text.find(from), from.size(), "\"friction\": 1e999");
  const LoadedProject lp = Load(text);
  EXPECT_FALSE(lp.ok());
}

TEST_F(ProjectFixture, UnknownRobotModelAndEndEffector) {
  doc_["robots"][0]["model"] = "ur3";
  doc_["robots"][1]["end_effector"] = "magnet";
  const LoadedProject lp = Load();
  ExpectError(lp, "robots[0].model", "unknown robot model 'ur3' (known: ur5e, ur10e, openarm)");
  ExpectError(lp, "robots[1].end_effector", "unknown end effector 'magnet'");
}

TEST_F(ProjectFixture, RobotNeedsModelXorUrdf) {
  doc_["robots"][0]["urdf"] = "arm.urdf";
  ExpectError(Load(), "robots[0]", "exactly one of 'model'");
  doc_["robots"][0].erase("model");
  ExpectError(Load(), "robots[0].urdf", "not found");
}

TEST_F(ProjectFixture, MountedRobotsNeedABaseAndAMount) {
  doc_["mobile_bases"] = {{{"name", "husky"}, {"model", "husky_dual_ur5e"}}};
  doc_["robots"][0]["mounted_on"] = "husky";
  doc_["robots"][0]["mount"] = "middle";
  doc_["robots"][1]["mounted_on"] = "cart";
  const LoadedProject lp = Load();
  ExpectError(lp, "robots[0].mount", "has no mount 'middle' (known: left, right)");
  ExpectError(lp, "robots[1].mounted_on", "no mobile base named 'cart'");
  doc_["mobile_bases"][0]["model"] = "segway";
  ExpectError(Load(), "mobile_bases[0].model", "unknown mobile base 'segway'");
}

TEST_F(ProjectFixture, HuskyMountPlacesArmsHalfAMetreUp) {
  doc_["mobile_bases"] = {{{"name", "husky"}, {"model", "husky_dual_ur5e"}}};
  doc_["robots"][0]["mounted_on"] = "husky";
  doc_["robots"][0]["mount"] = "left";
  doc_["robots"][0].erase("base_pose");
  const LoadedProject lp = Load();
  const Iso3 X = RobotBaseInWorld(*lp.project, lp.project->robots[0]);
  // ROBOTS.md §4.3 (derived): left base at (0.1225, 0.14891, 0.35771) in base_link, which
  // stands 0.13228 m above the ground (0.490 m in all), z axis tilted 45 deg outward.
  EXPECT_TRUE(X.translation().isApprox(Vec3(0.1225, 0.14891, 0.48999), 1e-4));
  EXPECT_TRUE(X.linear().col(2).isApprox(Vec3(0, 0.70711, 0.70711), 1e-4));
}

TEST_F(ProjectFixture, MissingMeshNamesFileAndResolvedPath) {
  doc_["parts"][1]["mesh"] = "meshes/leg4.stl";
  const LoadedProject lp = Load();
  ExpectError(lp, "parts[1].mesh", "file 'meshes/leg4.stl' not found (resolved to ");
  ExpectError(lp, "parts[1].mesh", (dir_ / "meshes" / "leg4.stl").string());
}

TEST_F(ProjectFixture, PathVariablesUseEnvironmentThenDefault) {
  doc_["paths"] = {
      {"LIB", {{"default", "elsewhere"}, {"env", "WRAP_TEST_LIB_DIR"}, {"hint", "get it"}}}};
  doc_["parts"][0]["mesh"] = "${LIB}/cube.obj";
  ::unsetenv("WRAP_TEST_LIB_DIR");
  LoadedProject lp = Load();
  ExpectError(lp, "parts[0].mesh", "$WRAP_TEST_LIB_DIR not set");
  ExpectError(lp, "parts[0].mesh", "get it");
  ::setenv("WRAP_TEST_LIB_DIR", (dir_ / "meshes").c_str(), 1);
  lp = Load();
  ::unsetenv("WRAP_TEST_LIB_DIR");
  EXPECT_TRUE(lp.ok());
  doc_["parts"][0]["mesh"] = "${NOPE}/cube.obj";
  ExpectError(Load(), "parts[0].mesh", "${NOPE}");
}

TEST_F(ProjectFixture, UnreadableMesh) {
  std::ofstream(dir_ / "meshes" / "junk.stl") << "this is not a mesh at all";
  doc_["parts"][0]["mesh"] = "meshes/junk.stl";
  ExpectError(Load(), "parts[0].mesh", "cannot read mesh 'meshes/junk.stl'");
}

TEST_F(ProjectFixture, EmptyMesh) {
  std::ofstream(dir_ / "meshes" / "empty.obj") << "# nothing\n";
  doc_["parts"][0]["mesh"] = "meshes/empty.obj";
  ExpectError(Load(), "parts[0].mesh", "cannot read mesh");
}

TEST_F(ProjectFixture, DegenerateMeshIsAnError) {
  // All four vertices on one plane: zero thickness.
  std::ofstream(dir_ / "meshes" / "flat.obj")
      << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\nf 1 3 2\nf 1 4 3\n";
  doc_["parts"][0]["mesh"] = "meshes/flat.obj";
  doc_["parts"][0]["scale"] = 0.05;
  ExpectError(Load(), "parts[0].mesh", "degenerate");
}

TEST_F(ProjectFixture, OpenMeshIsAWarning) {
  TriangleMesh open = Box(Vec3(40, 40, 40));
  open.triangles.pop_back();
  open.triangles.pop_back();
  ASSERT_TRUE(WriteObj(dir_ / "meshes" / "open.obj", open, 1.0));
  doc_["parts"][0]["mesh"] = "meshes/open.obj";
  const LoadedProject lp = Load();
  EXPECT_TRUE(lp.ok());
  ExpectDiag(lp, Severity::kWarning, "parts[0].mesh", "not closed (4 boundary edges");
  ExpectDiag(lp, Severity::kWarning, "parts[0].mass_kg", "open mesh");
}

TEST_F(ProjectFixture, UnitMistakesWarn) {
  doc_["parts"][0]["scale"] = 1.0;   // 40 m cube: mm read as m
  doc_["parts"][1]["scale"] = 1e-6;  // 0.04 mm cube
  const LoadedProject lp = Load();
  ExpectDiag(lp, Severity::kWarning, "parts[0].scale", "larger than 5 m");
  ExpectDiag(lp, Severity::kWarning, "parts[1].scale", "smaller than 1 mm");
}

TEST_F(ProjectFixture, PartsMustRestOnTheTableWithinReach) {
  doc_["parts"][0]["initial_pose"]["xyz"] = {0.1, 0.0, 0.9};
  doc_["parts"][1]["initial_pose"]["xyz"] = {1.5, 0.0, 0.77};
  const LoadedProject lp = Load();
  EXPECT_TRUE(lp.ok());
  ExpectDiag(lp, Severity::kWarning, "parts[0].initial_pose", "floats 130 mm above");
  ExpectDiag(lp, Severity::kWarning, "parts[1].initial_pose", "edge of the table");
  ExpectDiag(lp, Severity::kWarning, "parts[1].initial_pose", "within reach of 0 robot(s)");
}

TEST_F(ProjectFixture, ColourOutOfRange) {
  doc_["parts"][0]["color"] = {1.5, 0, 0};
  ExpectError(Load(), "parts[0].color[0]", "[0, 1]");
}

TEST_F(ProjectFixture, EveryProblemIsReportedInOnePass) {
  doc_["parts"][0]["scale"] = -1;
  doc_["robots"][0]["model"] = "ur3";
  doc_["steps"][0]["mating"]["force_N"] = -1;
  const LoadedProject lp = Load();
  EXPECT_GE(lp.check.diagnostics.error_count(), 3);
}

TEST(Catalog, KnowsThePapersRobotsAndGrippers) {
  ASSERT_NE(FindRobotModel("ur5e"), nullptr);
  EXPECT_EQ(FindRobotModel("ur5e")->dof, 6);
  EXPECT_EQ(FindRobotModel("openarm")->dof, 7);
  EXPECT_EQ(FindEndEffector("vacuum_cup")->kind, EndEffectorKind::kVacuum);
  EXPECT_EQ(FindEndEffector("robotiq_2f85")->kind, EndEffectorKind::kTwoFinger);
  EXPECT_EQ(FindRobotModel("ur3"), nullptr);
}

// Every example project must validate from a clean checkout. The Fabrica projects need
// ../shared/fabrica (or WRAP_FABRICA_DIR); without it they must fail with a clear message.
class ExampleProject : public ::testing::TestWithParam<std::string> {};

TEST_P(ExampleProject, Validates) {
  const fs::path file = fs::path(WRAP_SOURCE_DIR) / "projects" / (GetParam() + ".json");
  ASSERT_TRUE(fs::exists(file)) << file;
  const bool fabrica = GetParam().rfind("fabrica_", 0) == 0;
  if (fabrica && !std::getenv("WRAP_FABRICA_DIR") &&
      !fs::exists(fs::path(WRAP_SHARED_DIR) / "fabrica")) {
    const LoadedProject lp = LoadProject(file);
    ASSERT_FALSE(lp.ok());
    EXPECT_NE(Format(lp.check.diagnostics.items[0]).find("WRAP_FABRICA_DIR"), std::string::npos);
    GTEST_SKIP() << "Fabrica meshes not present beside the repository";
  }
  const LoadedProject lp = LoadProject(file);
  for (const Diagnostic& d : lp.check.diagnostics.items) ADD_FAILURE() << Format(d);
  ASSERT_TRUE(lp.ok());
  for (const PartGeometry& g : lp.check.parts) {
    EXPECT_TRUE(g.topology.closed()) << g.resolved;
    EXPECT_GT(g.mass_kg, 0.0);
  }
  // Round trip of the real file.
  const Project again = *ParseProject(SerializeProject(*lp.project), "again").project;
  EXPECT_EQ(again, *lp.project);
}

// stool_step's parts come from a STEP file: only a build with OpenCASCADE reads it.
// clang-format off
const std::vector<std::string> kExampleProjects = {
    "stool", "chair", "cross", "cross_openarm", "cube", "cube_2x2x3", "half_stool",
#if WRAP_TEST_WITH_OCCT
    "stool_step",
#endif
    "fabrica_beam", "fabrica_plumbers_block", "fabrica_car", "fabrica_gamepad",
    "fabrica_cooling_manifold"};
// clang-format on

INSTANTIATE_TEST_SUITE_P(Projects, ExampleProject, ::testing::ValuesIn(kExampleProjects));

TEST(EntityPath, NamesTheEntityAJsonPathPointsAt) {
  Project p;
  p.parts.push_back(Part{});
  p.parts[0].name = "seat";
  p.parts.push_back(Part{});
  p.parts[1].name = "leg1";
  p.steps.push_back(Step{});
  p.steps[0].name = "seat+leg1";
  p.robots.push_back(Robot{});
  p.robots[0].name = "ur5e_a";
  const EntityRef leg = EntityOfPath(p, "parts[1].initial_pose");
  EXPECT_EQ(leg.kind, EntityKind::kPart);
  EXPECT_EQ(leg.name, "leg1");
  EXPECT_EQ(leg.field, "initial_pose");
  EXPECT_EQ(leg.Label(), "part 'leg1'");
  const EntityRef force = EntityOfPath(p, "steps[0].mating.force_N");
  EXPECT_EQ(force.kind, EntityKind::kStep);
  EXPECT_EQ(force.name, "seat+leg1");
  EXPECT_EQ(force.field, "mating.force_N");
  EXPECT_EQ(EntityOfPath(p, "robots[0]").Label(), "robot 'ur5e_a'");
  EXPECT_EQ(EntityOfPath(p, "robots[0]").field, "");
  EXPECT_EQ(EntityOfPath(p, "table.friction").kind, EntityKind::kTable);
  EXPECT_EQ(EntityOfPath(p, "table.friction").field, "friction");
  EXPECT_EQ(EntityOfPath(p, "planner.seed").kind, EntityKind::kPlanner);
  EXPECT_EQ(EntityOfPath(p, "").kind, EntityKind::kProject);
  // An index beyond the lists, or a malformed one: the path itself, nothing selected.
  const EntityRef beyond = EntityOfPath(p, "parts[7].mesh");
  EXPECT_EQ(beyond.kind, EntityKind::kOther);
  EXPECT_EQ(beyond.field, "parts[7].mesh");
  EXPECT_EQ(EntityOfPath(p, "parts[x].mesh").kind, EntityKind::kOther);
  EXPECT_EQ(EntityOfPath(p, "connection_limits.force_N").kind, EntityKind::kProject);
}

// The terminal's one-line form names entities instead of indexing lists (brief: errors name the
// field by name, not list index), drops a repeated name, and keeps paths that name no entity.
TEST(EntityPath, FormatNamedPrintsTheEntityByName) {
  Project p;
  p.parts.push_back(Part{});
  p.parts[0].name = "seat";
  p.parts.push_back(Part{});  // no name yet: nothing to name it by
  p.steps.push_back(Step{});
  p.steps[0].name = "seat+leg1";
  auto diag = [](std::string path, std::string message, Severity s = Severity::kError) {
    return Diagnostic{s, "stool.json", std::move(path), std::move(message)};
  };
  EXPECT_EQ(FormatNamed(diag("parts[0].mesh", "file 'seat.stl' not found"), p),
            "stool.json: part 'seat', mesh: error: file 'seat.stl' not found");
  EXPECT_EQ(FormatNamed(diag("steps[0].mating.axis", "step 'seat+leg1': 'leg1' hits 'seat'"), p),
            "stool.json: step 'seat+leg1', mating.axis: error: 'leg1' hits 'seat'");
  EXPECT_EQ(FormatNamed(diag("steps[0]", "joins nothing", Severity::kWarning), p),
            "stool.json: step 'seat+leg1': warning: joins nothing");
  EXPECT_EQ(FormatNamed(diag("parts[1].name", "a part needs a non-empty name"), p),
            "stool.json: parts[1].name: error: a part needs a non-empty name");
  EXPECT_EQ(FormatNamed(diag("parts[9].mesh", "x"), p), "stool.json: parts[9].mesh: error: x");
  EXPECT_EQ(FormatNamed(diag("table.friction", "too high"), p),
            "stool.json: table.friction: error: too high");
  EXPECT_EQ(FormatNamed(diag("", "malformed JSON"), nullptr), "stool.json: error: malformed JSON");
}

}  // namespace
}  // namespace wrap
