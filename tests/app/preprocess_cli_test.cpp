// `wrap preprocess`: exit codes, the printed summary and the JSON it writes.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_runner.h"

namespace wrap::cli {
namespace {

namespace fs = std::filesystem;

fs::path TempDir() {
  const fs::path dir =
      fs::temp_directory_path() / ("wrap_preprocess_cli_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

nlohmann::json ReadJson(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

TEST(CliPreprocess, StoolPrintsSummaryAndWritesJson) {
  const fs::path json = TempDir() / "stool_pre.json";
  fs::remove(json);
  const CliRun r = Wrap({"preprocess", Project("stool"), "-o", json.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("Subassemblies"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("seat+leg1"), std::string::npos);
  EXPECT_NE(r.out.find("robotiq_2f85 20"), std::string::npos);
  EXPECT_NE(r.out.find("placements"), std::string::npos);
  EXPECT_NE(r.out.find("t_grasp"), std::string::npos);
  ASSERT_TRUE(fs::exists(json));
  const nlohmann::json doc = ReadJson(json);
  EXPECT_EQ(doc["format"], "wrap-preprocess");
  ASSERT_TRUE(doc["subassemblies"].is_array());
  ASSERT_EQ(doc["subassemblies"].size(), 9u);  // 5 parts + 4 steps
  for (const auto& sub : doc["subassemblies"]) {
    EXPECT_TRUE(sub["name"].is_string());
    EXPECT_FALSE(sub["parts"].empty());
    EXPECT_FALSE(sub["placements"].empty()) << sub["name"];
    EXPECT_FALSE(sub["grasps"].empty()) << sub["name"];
    for (const auto& g : sub["grasps"]) {
      EXPECT_TRUE(g.contains("part") && g.contains("X_PG") && g.contains("end_effector") &&
                  g.contains("quality"));
    }
    for (const auto& p : sub["placements"]) {
      EXPECT_GE(p["support_T"].size(), 3u);
      EXPECT_GT(p["margin_m"].get<double>(), 0.0);
    }
  }
  EXPECT_EQ(doc["subassemblies"][8]["name"], "stool");
  EXPECT_EQ(doc["subassemblies"][8]["parts"].size(), 5u);
  EXPECT_GT(doc["timings_s"]["total"].get<double>(), 0.0);
  EXPECT_EQ(doc["table_slots"]["slots"].size(), 9u);
}

TEST(CliPreprocess, OptionsAndDeterminism) {
  const fs::path a = TempDir() / "a.json", b = TempDir() / "b.json", c = TempDir() / "c.json";
  ASSERT_EQ(Wrap({"preprocess", Project("cross"), "--grasps", "5", "--slots", "3", "--seed", "7",
                  "-o", a.string()})
                .code,
            0);
  ASSERT_EQ(Wrap({"preprocess", Project("cross"), "--grasps", "5", "--slots", "3", "--seed", "7",
                  "-o", b.string()})
                .code,
            0);
  ASSERT_EQ(Wrap({"preprocess", Project("cross"), "--grasps", "5", "--slots", "3", "--seed", "8",
                  "-o", c.string()})
                .code,
            0);
  const auto ja = ReadJson(a), jb = ReadJson(b), jc = ReadJson(c);
  EXPECT_EQ(ja["grasps_per_set"], 5);
  EXPECT_EQ(ja["table_slots"]["slots"].size(), 3u);
  for (const auto& sub : ja["subassemblies"]) EXPECT_LE(sub["grasps"].size(), 5u);
  EXPECT_EQ(ja["subassemblies"], jb["subassemblies"]) << "same seed, same result";
  EXPECT_NE(ja["subassemblies"], jc["subassemblies"]) << "another seed, other grasps";
}

TEST(CliPreprocess, BadInputExitsTwo) {
  CliRun r = Wrap({"preprocess", "/nonexistent/dir/project.json"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent/dir/project.json"), std::string::npos) << r.err;
  EXPECT_EQ(Wrap({"preprocess"}).code, 2);
  EXPECT_EQ(Wrap({"preprocess", Project("stool"), "--grasps", "0"}).code, 2);
  EXPECT_EQ(Wrap({"preprocess", Project("stool"), "--grasps", "many"}).code, 2);
  r = Wrap({"preprocess", Project("cube"), "-o", "/nonexistent/dir/out.json"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent/dir/out.json"), std::string::npos) << r.err;
  const fs::path broken = TempDir() / "broken.json";
  std::ofstream(broken) << R"({"format": "wrap-project", "version": 1, "parts": [)";
  EXPECT_EQ(Wrap({"preprocess", broken.string()}).code, 2);
}

}  // namespace
}  // namespace wrap::cli
