// The CLI contract: exit codes, messages on stderr naming file, field and problem.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "cli_runner.h"

namespace wrap::cli {
namespace {

namespace fs = std::filesystem;

fs::path TempFile(const std::string& name, const std::string& contents) {
  const fs::path dir = fs::temp_directory_path() / ("wrap_cli_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path f = dir / name;
  std::ofstream(f, std::ios::binary) << contents;
  return f;
}

TEST(Cli, HelpAndVersion) {
  CliRun r = Wrap({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("validate"), std::string::npos);
  EXPECT_NE(r.out.find("info"), std::string::npos);
  r = Wrap({"--version"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("wrap " WRAP_VERSION), std::string::npos);
}

TEST(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(Wrap({"validate"}).code, 2);
  EXPECT_EQ(Wrap({"frobnicate"}).code, 2);
  EXPECT_EQ(Wrap({"validate", "a.json", "b.json"}).code, 2);
  EXPECT_EQ(Wrap({"--no-such-flag"}).code, 2);
}

TEST(Cli, ValidateStool) {
  const CliRun r = Wrap({"validate", Project("stool")});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("valid: 5 parts, 4 steps, 4 robots"), std::string::npos) << r.out;
}

TEST(Cli, ValidateMissingFile) {
  const CliRun r = Wrap({"validate", "/nonexistent/dir/project.json"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent/dir/project.json"), std::string::npos) << r.err;
}

TEST(Cli, ValidateReportsEveryProblemOnStderr) {
  const fs::path f = TempFile("broken.json", R"({"format": "wrap-project", "version": 1,
    "parts": [{"name": "a", "mesh": "nope.stl", "scale": -1, "initial_pose": {}}],
    "robots": [{"name": "r", "model": "ur3", "end_effector": "robotiq_2f85"}]})");
  const CliRun r = Wrap({"validate", f.string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("broken.json: part 'a', scale: error: must be positive"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("broken.json: part 'a', mesh: error: file 'nope.stl' not found"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("robot 'r', model: error: unknown robot model 'ur3'"), std::string::npos);
  EXPECT_NE(r.err.find("3 error(s)"), std::string::npos) << r.err;
}

// A project whose robots come from URDF files: validation imports them and reports their
// problems at the robot's JSON path.
TEST(Cli, ValidateImportsUrdfRobots) {
  const std::string joint =
      R"(type="revolute"><limit lower="-1" upper="1" velocity="1" effort="1"/>)";
  auto urdf = [&](const std::string& name, bool two_tips) {
    std::string t = "<robot name=\"" + name + "\"><link name=\"base\"/><link name=\"a\"/>";
    t += "<link name=\"b\"/><joint name=\"j1\" " + joint +
         "<parent link=\"base\"/><child link=\"a\"/></joint>";
    t += "<joint name=\"j2\" " + joint + "<parent link=\"a\"/><child link=\"b\"/></joint>";
    if (two_tips) {
      t += "<link name=\"c\"/><joint name=\"j3\" " + joint +
           "<parent link=\"a\"/><child link=\"c\"/></joint>";
    }
    return t + "</robot>";
  };
  TempFile("good_arm.urdf", urdf("good", false));
  TempFile("forked_arm.urdf", urdf("forked", true));
  const std::string mesh = (fs::path(WRAP_SOURCE_DIR) / "assets/parts/cross/arm.obj").string();
  auto project = [&](const std::string& urdf_file, const std::string& extra) {
    return R"({"format": "wrap-project", "version": 1,
      "parts": [{"name": "a", "mesh": ")" +
           mesh + R"(", "scale": 0.001, "initial_pose": {"xyz": [0, 0, 0.78]}}],
      "robots": [{"name": "r", "urdf": ")" +
           urdf_file + R"(", "end_effector": "vacuum_cup")" + extra + "}]}";
  };
  CliRun r = Wrap({"validate", TempFile("urdf_good.json", project("good_arm.urdf", "")).string()});
  EXPECT_EQ(r.code, 0) << r.err;
  r = Wrap({"validate", TempFile("urdf_forked.json", project("forked_arm.urdf", "")).string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("robot 'r', urdf: error: cannot use URDF 'forked_arm.urdf'"),
            std::string::npos)
      << r.err;
  // Naming the tip resolves it.
  r = Wrap(
      {"validate",
       TempFile("urdf_tip.json", project("forked_arm.urdf", R"(, "urdf_tip": "c")")).string()});
  EXPECT_EQ(r.code, 0) << r.err;
}

TEST(Cli, InfoShowsPartsTreeAndRobots) {
  const CliRun r = Wrap({"info", Project("stool")});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("Parts (5)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("seat"), std::string::npos);
  EXPECT_NE(r.out.find("Assembly (4 steps"), std::string::npos);
  EXPECT_NE(r.out.find("(moved)"), std::string::npos);
  EXPECT_NE(r.out.find("(base)"), std::string::npos);
  EXPECT_NE(r.out.find("Robots (4)"), std::string::npos);
  EXPECT_NE(r.out.find("vacuum_cup (vacuum)"), std::string::npos);
  EXPECT_NE(r.out.find("robotiq_2f85 (two-finger)"), std::string::npos);
  EXPECT_NE(r.out.find("F <= (50, 39.7, 50) N"), std::string::npos);
}

TEST(Cli, InfoOnBrokenProjectExitsTwo) {
  const fs::path f = TempFile("broken_info.json", "{ not json");
  const CliRun r = Wrap({"info", f.string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("malformed JSON"), std::string::npos);
}

// No input file, however broken, may crash, hang or throw: random bytes and random
// truncations of a real project all end in exit 0 or 2.
TEST(Cli, BrokenInputsNeverCrash) {
  std::ifstream in(Project("stool"), std::ios::binary);
  std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(good.empty());
  std::mt19937 rng(1234);
  for (int i = 0; i < 60; ++i) {
    std::string text = good;
    switch (i % 3) {
      case 0:
        text.resize(rng() % good.size());
        break;
      case 1:
        for (int k = 0; k < 5; ++k) text[rng() % text.size()] = static_cast<char>(rng() % 256);
        break;
      default:
        text.assign(rng() % 512, ' ');
        for (char& c : text) c = static_cast<char>(rng() % 256);
    }
    const fs::path f = TempFile("fuzz.json", text);
    const CliRun r = Wrap({"validate", f.string()});
    EXPECT_TRUE(r.code == 0 || r.code == 2) << "iteration " << i << " exit " << r.code;
  }
}

}  // namespace
}  // namespace wrap::cli
