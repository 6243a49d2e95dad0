// The CLI on projects whose parts come from a STEP assembly (written in the test by the team's
// generator through OpenCASCADE): validate, info and plan work on it, a damaged STEP file is bad
// input (exit 2, the file and the field named, nothing written), and a build without
// OpenCASCADE says that STEP is unavailable.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_runner.h"
#include "generator/step_designs.h"
#include "geometry/step_cache.h"
#include "test_build_config.h"

namespace wrap::cli {
namespace {

namespace fs = std::filesystem;

class StepCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("wrap_step_cli_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ClearStepMemoryCache();
    // The example project, its STEP file written here.
    std::ifstream in(Project("stool_step"));
    nlohmann::ordered_json project = nlohmann::ordered_json::parse(in);
    for (auto& part : project["parts"]) part["mesh"] = "stool.step";
    std::ofstream(dir_ / "project.json") << project.dump(2);
#if WRAP_TEST_WITH_OCCT
    auto ok = WriteStep(partgen::StepStoolSpec(), dir_ / "stool.step");
    ASSERT_TRUE(ok.has_value()) << ok.error().message;
#else
    std::ofstream(dir_ / "stool.step") << "ISO-10303-21;\nHEADER;\nENDSEC;\nEND-ISO-10303-21;\n";
#endif
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string File() const { return (dir_ / "project.json").string(); }
  fs::path dir_;
};

#if WRAP_TEST_WITH_OCCT
TEST_F(StepCli, ValidateInfoAndPlan) {
  CliRun r = Wrap({"validate", File()});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_TRUE(fs::is_directory(StepCacheDirFor(File()))) << "tessellations cached beside it";
  r = Wrap({"info", File()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("leg_4"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("stool.step [leg]"), std::string::npos) << r.out;
  const fs::path plan = dir_ / "plan.json";
  r = Wrap({"plan", File(), "-o", plan.string(), "--validate", "--task-only"});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Validated:"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::is_regular_file(plan));
}

TEST_F(StepCli, DamagedStepIsBadInputAndWritesNothing) {
  std::stringstream text;
  text << std::ifstream(dir_ / "stool.step").rdbuf();
  std::ofstream(dir_ / "stool.step", std::ios::trunc)
      << text.str().substr(0, text.str().size() / 2);
  const fs::path plan = dir_ / "plan.json";
  const CliRun r = Wrap({"plan", File(), "-o", plan.string()});
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("stool.step"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("part 'seat', mesh: error"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(plan));
  const CliRun v = Wrap({"validate", File()});
  EXPECT_EQ(v.code, 2);
}
#else
TEST_F(StepCli, WithoutOpenCascadeStepIsUnavailable) {
  const CliRun r = Wrap({"validate", File()});
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("STEP is unavailable"), std::string::npos) << r.err;
}
#endif  // WRAP_TEST_WITH_OCCT

}  // namespace
}  // namespace wrap::cli
