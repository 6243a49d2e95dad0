// `wrap sim` end to end through the CLI: exit codes and the report file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>

#include "../app/cli_runner.h"

namespace wrap::cli {
namespace {

namespace fs = std::filesystem;

// A fresh folder under the system's temporary folder, removed at the end of the test.
struct TempDir {
  fs::path path;
  TempDir() {
    std::random_device rd;
    path = fs::temp_directory_path() / ("wrap_sim_cli_" + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string Read(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(SimCli, PlanHoldsAndReportIsWritten) {
  TempDir dir;
  const std::string plan = (dir.path / "plan.json").string();
  const std::string report = (dir.path / "report.json").string();
  CliRun planned = Wrap({"plan", Project("half_stool"), "-o", plan});
  ASSERT_EQ(planned.code, 0) << planned.err;
  CliRun sim = Wrap({"sim", Project("half_stool"), "--plan", plan, "-o", report});
  EXPECT_EQ(sim.code, 0) << sim.out << sim.err;
  EXPECT_NE(sim.out.find("holds"), std::string::npos) << sim.out;
  const nlohmann::json j = nlohmann::json::parse(Read(report));
  EXPECT_TRUE(j["success"].get<bool>());
  EXPECT_TRUE(j["failure"].is_null());
  EXPECT_EQ(j["tasks_completed"], j["tasks_total"]);
  EXPECT_EQ(j["actions"].size(), j["tasks_total"].get<size_t>());
  EXPECT_TRUE(j["peak_utilisation_percent"]["transport"]["two_finger"].is_number());
  EXPECT_TRUE(j["peak_utilisation_percent"]["transport"]["vacuum"].is_null());  // no vacuum
  // No temporary file left beside the report.
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir.path)) files += e.is_regular_file();
  EXPECT_EQ(files, 2);
}

TEST(SimCli, TaskOnlyPlanIsBadInput) {
  TempDir dir;
  const std::string plan = (dir.path / "plan.json").string();
  ASSERT_EQ(Wrap({"plan", Project("half_stool"), "-o", plan, "--task-only"}).code, 0);
  CliRun sim = Wrap({"sim", Project("half_stool"), "--plan", plan});
  EXPECT_EQ(sim.code, 2);
  EXPECT_NE(sim.err.find("plan.json"), std::string::npos) << sim.err;
  EXPECT_NE(sim.err.find("trajectories"), std::string::npos) << sim.err;
}

TEST(SimCli, BadInputExitsTwo) {
  TempDir dir;
  // A plan file that does not exist, one that is not JSON, no --plan, a missing project.
  CliRun missing = Wrap({"sim", Project("half_stool"), "--plan", (dir.path / "no.json").string()});
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("no.json"), std::string::npos) << missing.err;
  const fs::path garbage = dir.path / "garbage.json";
  std::ofstream(garbage) << "{ not json";
  CliRun bad = Wrap({"sim", Project("half_stool"), "--plan", garbage.string()});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("garbage.json"), std::string::npos) << bad.err;
  EXPECT_EQ(Wrap({"sim", Project("half_stool")}).code, 2);
  const std::string plan = (dir.path / "plan.json").string();
  ASSERT_EQ(Wrap({"plan", Project("half_stool"), "-o", plan, "--task-only"}).code, 0);
  CliRun no_project = Wrap({"sim", (dir.path / "nothing.json").string(), "--plan", plan});
  EXPECT_EQ(no_project.code, 2);
  EXPECT_NE(no_project.err.find("nothing.json"), std::string::npos) << no_project.err;
}

}  // namespace
}  // namespace wrap::cli
