// `wrap sim` end to end through the CLI: exit codes and the report file.
#include <gtest/gtest.h>

#include <cstdlib>
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

// A task plan without motion is replayed from its keyframes (no longer refused), and the report
// says so. Whether it holds depends on the replay's straight joint-space moves (see the
// physics test of a motion plan's keyframes, which holds), so only the verdict's form is checked.
TEST(SimCli, TaskOnlyPlanReplaysKeyframes) {
  TempDir dir;
  const std::string plan = (dir.path / "plan.json").string();
  const std::string report = (dir.path / "report.json").string();
  ASSERT_EQ(Wrap({"plan", Project("half_stool"), "-o", plan, "--task-only"}).code, 0);
  CliRun sim = Wrap({"sim", Project("half_stool"), "--plan", plan, "-o", report});
  EXPECT_TRUE(sim.code == 0 || sim.code == 1) << sim.out << sim.err;
  EXPECT_NE(sim.out.find("keyframes were replayed"), std::string::npos) << sim.out;
  const nlohmann::json j = nlohmann::json::parse(Read(report));
  EXPECT_EQ(j["motion"], "keyframes");
  EXPECT_FALSE(j["collisions_judged"].get<bool>());
  EXPECT_EQ(j["success"].get<bool>(), sim.code == 0);
}

// PATH set for one test, restored after it.
struct ScopedPath {
  std::string old;
  explicit ScopedPath(const std::string& path) {
    const char* p = std::getenv("PATH");
    old = p ? p : "";
    setenv("PATH", path.c_str(), 1);
  }
  ~ScopedPath() { setenv("PATH", old.c_str(), 1); }
};

// A stand-in ffmpeg: keeps its concat list (the frames it was given) and writes its output file
// (its last argument). The real encoder's tests are the renderer's; here what matters is that
// the simulated run is drawn and handed over, and that no partial file is left.
fs::path FakeFfmpeg(const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path exe = dir / "ffmpeg";
  std::ofstream(exe) << "#!/bin/sh\n"
                     << "for a; do last=\"$a\"; case \"$a\" in *.ffconcat) cp \"$a\" \""
                     << (dir / "list").string() << "\";; esac; done\n"
                     << "echo video > \"$last\"\n";
  fs::permissions(exe, fs::perms::owner_all);
  return dir;
}

TEST(SimCli, VideoRecordsTheSimulatedRun) {
  TempDir dir;
  const std::string plan = (dir.path / "plan.json").string();
  ASSERT_EQ(Wrap({"plan", Project("half_stool"), "-o", plan}).code, 0);
  const fs::path out = dir.path / "out";
  fs::create_directories(out);
  const fs::path bin = FakeFfmpeg(dir.path / "bin");
  const fs::path video = out / "run.mp4";
  CliRun sim;
  {
    ScopedPath path(bin.string() + ":/usr/bin:/bin");
    sim = Wrap({"sim", Project("half_stool"), "--plan", plan, "--video", video.string()});
  }
#ifndef WRAP_TEST_HAVE_RENDERER
  // A build without ui/: said before the run.
  EXPECT_EQ(sim.code, 2);
  EXPECT_NE(sim.err.find("no renderer"), std::string::npos) << sim.err;
  EXPECT_FALSE(fs::exists(video));
  return;
#endif
  ASSERT_EQ(sim.code, 0) << sim.out << sim.err;
  EXPECT_TRUE(fs::exists(video));
  EXPECT_NE(sim.out.find("run.mp4"), std::string::npos) << sim.out;
  // One frame every 0.1 s of simulated time: the plan's makespan plus the settling second.
  const nlohmann::json p = nlohmann::json::parse(Read(plan));
  const double makespan = p["stats"]["makespan_s"].get<double>();
  const std::string list = Read(bin / "list");
  size_t frames = 0;
  for (size_t at = list.find("frame_"); at != std::string::npos; at = list.find("frame_", at + 1)) {
    ++frames;
  }
  EXPECT_GE(frames, static_cast<size_t>(10.0 * makespan)) << list.substr(0, 300);
  // The frames and the temporary video are gone: only the video is left.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    ++entries;
    EXPECT_EQ(e.path().filename(), "run.mp4");
  }
  EXPECT_EQ(entries, 1);
}

TEST(SimCli, VideoWithoutFfmpegExitsTwoBeforeSimulating) {
  TempDir dir;
  const std::string plan = (dir.path / "plan.json").string();
  ASSERT_EQ(Wrap({"plan", Project("half_stool"), "-o", plan, "--task-only"}).code, 0);
  const fs::path empty = dir.path / "empty";
  fs::create_directories(empty);
  const fs::path report = dir.path / "report.json";
  const fs::path video = dir.path / "run.mp4";
  CliRun sim;
  {
    ScopedPath path(empty.string());
    sim = Wrap({"sim", Project("half_stool"), "--plan", plan, "-o", report.string(), "--video",
                video.string()});
  }
  EXPECT_EQ(sim.code, 2);
  EXPECT_NE(sim.err.find("ffmpeg"), std::string::npos) << sim.err;
  // Said before the run: no report, no video.
  EXPECT_FALSE(fs::exists(report));
  EXPECT_FALSE(fs::exists(video));
  EXPECT_TRUE(sim.out.empty()) << sim.out;
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
