#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "core/diagnostics.h"
#include "core/file_io.h"
#include "core/flat_map.h"
#include "core/pose.h"
#include "core/result.h"
#include "core/run_context.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  fs::path dir =
      fs::temp_directory_path() / ("wrap_core_test_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(Pose, RpyRoundTripsThroughRotation) {
  const Vec3 rpy(0.3, -1.1, 2.5);
  const Mat3 R = RotationFromRpy(rpy);
  EXPECT_TRUE(R.isUnitary(1e-12));
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  EXPECT_TRUE(RpyFromRotation(R).isApprox(rpy, 1e-12));
}

TEST(Pose, RpyIsUrdfConvention) {
  // Yaw of 90 deg maps x to y; roll of 90 deg maps y to z.
  const double h = std::numbers::pi / 2;
  EXPECT_TRUE((RotationFromRpy(Vec3(0, 0, h)) * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-12));
  EXPECT_TRUE((RotationFromRpy(Vec3(h, 0, 0)) * Vec3::UnitY()).isApprox(Vec3::UnitZ(), 1e-12));
  // Fixed axes: R = Rz * Ry * Rx, so roll is applied first.
  const Mat3 R = RotationFromRpy(Vec3(h, h, 0));
  // Rx(90) takes y to z, then Ry(90) takes z to x.
  EXPECT_TRUE((R * Vec3::UnitY()).isApprox(Vec3(1, 0, 0), 1e-12));
}

TEST(Pose, GimbalLockStillReproducesTheRotation) {
  const Mat3 R = RotationFromRpy(Vec3(0.4, std::numbers::pi / 2, -0.2));
  EXPECT_TRUE(RotationFromRpy(RpyFromRotation(R)).isApprox(R, 1e-9));
}

TEST(Pose, IsometryRoundTrip) {
  Pose p{Vec3(1, -2, 0.5), Vec3(0.1, 0.2, 0.3)};
  const Iso3 X = ToIsometry(p);
  EXPECT_TRUE((X * Vec3::Zero()).isApprox(p.xyz));
  const Pose q = FromIsometry(X);
  EXPECT_TRUE(q.xyz.isApprox(p.xyz, 1e-12));
  EXPECT_TRUE(q.rpy.isApprox(p.rpy, 1e-12));
}

TEST(Result, ExitCodesFollowTheContract) {
  EXPECT_EQ(ExitCodeFor(ErrorCode::kInvalidInput), 2);
  EXPECT_EQ(ExitCodeFor(ErrorCode::kIo), 2);
  EXPECT_EQ(ExitCodeFor(ErrorCode::kInfeasible), 1);
  EXPECT_EQ(ExitCodeFor(ErrorCode::kTimeout), 1);
  EXPECT_EQ(ExitCodeFor(ErrorCode::kCancelled), 1);
  EXPECT_EQ(ExitCodeFor(ErrorCode::kInternal), 3);
  Result<int> r = Fail(ErrorCode::kIo, "no");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kIo);
}

TEST(Diagnostics, FormatsFilePathSeverityMessage) {
  Diagnostics d;
  d.Error("stool.json", "parts[3].mesh", "file 'leg4.stl' not found");
  d.Warning("stool.json", "", "odd");
  EXPECT_EQ(Format(d.items[0]), "stool.json: parts[3].mesh: error: file 'leg4.stl' not found");
  EXPECT_EQ(Format(d.items[1]), "stool.json: warning: odd");
  EXPECT_TRUE(d.has_errors());
  EXPECT_EQ(d.error_count(), 1);
  EXPECT_EQ(d.warning_count(), 1);
}

TEST(FileIo, AtomicWriteReplacesWholeFileAndLeavesNoTemporary) {
  const fs::path dir = FreshDir("atomic");
  const fs::path f = dir / "a.json";
  ASSERT_TRUE(WriteFileAtomic(f, "first"));
  ASSERT_TRUE(WriteFileAtomic(f, "second, longer"));
  auto text = ReadFile(f);
  ASSERT_TRUE(text);
  EXPECT_EQ(*text, "second, longer");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(FileIo, FailedWriteKeepsTheOldFile) {
  const fs::path dir = FreshDir("atomic_fail");
  const fs::path f = dir / "keep.json";
  ASSERT_TRUE(WriteFileAtomic(f, "precious"));
  // A path whose folder does not exist cannot be written, and nothing else is touched.
  auto r = WriteFileAtomic(dir / "missing" / "x.json", "data");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kIo);
  // Writing over a directory fails at the rename; the directory and the old file survive.
  fs::create_directories(dir / "sub");
  EXPECT_FALSE(WriteFileAtomic(dir / "sub", "data"));
  EXPECT_TRUE(fs::is_directory(dir / "sub"));
  EXPECT_EQ(*ReadFile(f), "precious");
}

TEST(FileIo, ReadFileErrorsNameThePath) {
  auto r = ReadFile("/nonexistent/wrap/file.json");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kIo);
  EXPECT_NE(r.error().message.find("/nonexistent/wrap/file.json"), std::string::npos);
  auto d = ReadFile(fs::temp_directory_path());
  ASSERT_FALSE(d);
  EXPECT_NE(d.error().message.find("directory"), std::string::npos);
}

TEST(RunContext, StopTokenAndDeadline) {
  std::stop_source src;
  RunContext ctx(42);
  ctx.set_stop_token(src.get_token());
  EXPECT_FALSE(ctx.ShouldStop());
  src.request_stop();
  EXPECT_TRUE(ctx.cancelled());
  EXPECT_TRUE(ctx.ShouldStop());

  RunContext timed;
  timed.set_time_limit_s(0.01);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_TRUE(timed.timed_out());
}

TEST(RunContext, SameSeedSameNumbers) {
  RunContext a(7), b(7), c(8);
  EXPECT_EQ(a.rng()(), b.rng()());
  RunContext a2(7);
  EXPECT_NE(a2.rng()(), c.rng()());
}

TEST(Log, TopicsParseWithLevelsAndNameWhatIsWrong) {
  auto t = LogTopics::Parse("motion,task:trace");
  ASSERT_TRUE(t.has_value()) << t.error().message;
  EXPECT_TRUE(t->Enabled("motion", LogLevel::kDebug));
  EXPECT_FALSE(t->Enabled("motion", LogLevel::kTrace));
  EXPECT_TRUE(t->Enabled("task", LogLevel::kTrace));
  EXPECT_FALSE(t->Enabled("sim", LogLevel::kDebug));
  EXPECT_FALSE(t->Enabled("motion.diag", LogLevel::kDebug));  // not implied by "motion"
  auto all = LogTopics::Parse("all");
  ASSERT_TRUE(all.has_value());
  EXPECT_TRUE(all->Enabled("sim", LogLevel::kDebug));
  EXPECT_FALSE(all->Enabled("sim", LogLevel::kTrace));
  auto none = LogTopics::Parse("");
  ASSERT_TRUE(none.has_value());
  EXPECT_TRUE(none->empty());
  auto bad = LogTopics::Parse("motion,plannr");
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("unknown log topic 'plannr'"), std::string::npos);
  EXPECT_NE(bad.error().message.find("motion.diag"), std::string::npos);  // lists the known
  auto level = LogTopics::Parse("task:loud");
  ASSERT_FALSE(level.has_value());
  EXPECT_NE(level.error().message.find("'loud'"), std::string::npos);
}

TEST(Log, RunContextSendsOnlyEnabledLinesToItsSink) {
  RunContext ctx;
  EXPECT_FALSE(ctx.Logs("motion"));  // no sink: nothing logged
  std::vector<std::string> lines;
  ctx.set_log([&](std::string_view topic, LogLevel,
                  const std::string& text) { lines.push_back(std::string(topic) + ": " + text); },
              *LogTopics::Parse("motion"));
  ctx.Log("motion", StrFormat("query %d: %s", 3, "solved"));
  ctx.Log("motion", "every check", LogLevel::kTrace);
  ctx.Log("task", "a fill");
  RunContext sub;
  sub.set_log_from(ctx);
  sub.Log("motion", "from a sub-run");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "motion: query 3: solved");
  EXPECT_EQ(lines[1], "motion: from a sub-run");
}

TEST(RunContext, StageTimerAccumulates) {
  RunContext ctx;
  { ScopedStageTimer t(ctx, "grasp"); }
  { ScopedStageTimer t(ctx, "grasp"); }
  ASSERT_EQ(ctx.stage_times().count("grasp"), 1u);
  EXPECT_GE(ctx.stage_times().at("grasp"), 0.0);
}

// FlatMap answers like std::unordered_map over random inserts and lookups, through its growth
// and a clear, with keys that share their low bits or their high bits (the probe's worst cases).
TEST(FlatMap, AgreesWithUnorderedMap) {
  std::mt19937_64 rng(5);
  FlatMap<int> flat;
  std::unordered_map<std::uint64_t, int> reference;
  auto key_of = [&](int k) -> std::uint64_t {
    switch (k % 3) {
      case 0:
        return rng() % 5000;  // small keys, many repeats
      case 1:
        return (rng() % 5000) << 40;  // low bits all zero
      default:
        return rng() | 0x8000000000000000ULL;  // anything
    }
  };
  for (int round = 0; round < 2; ++round) {
    for (int k = 0; k < 20000; ++k) {
      const std::uint64_t key = key_of(k);
      const int value = static_cast<int>(rng() % 1000);
      const auto [it, inserted] = reference.try_emplace(key, value);
      const auto [v, flat_inserted] = flat.try_emplace(key, value);
      ASSERT_EQ(flat_inserted, inserted) << key;
      ASSERT_EQ(*v, it->second) << key;
      if (k % 7 == 0) {
        flat[key] = k;
        it->second = k;
      }
      const std::uint64_t probe = key_of(k + 1);
      const int* found = flat.find(probe);
      const auto ref = reference.find(probe);
      ASSERT_EQ(found != nullptr, ref != reference.end()) << probe;
      if (found) {
        ASSERT_EQ(*found, ref->second);
      }
    }
    EXPECT_EQ(flat.size(), reference.size());
    flat.clear();
    reference.clear();
    EXPECT_TRUE(flat.empty());
    EXPECT_FALSE(flat.contains(0));
  }
}

}  // namespace
}  // namespace wrap
