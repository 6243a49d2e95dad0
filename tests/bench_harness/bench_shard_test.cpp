// Shards at scale: a shard killed outright resumes from its finished runs (and its children die
// with it), a folder in use is refused, a folder resumed with other settings is refused, merge
// refuses different revisions, settings, missing, duplicated and unfinished shards (and says
// which), runs on a loaded machine are marked and can be run again, the robots' utilisation is
// read from a plan, and --dry-run sizes a shard. Shell scripts stand in for `wrap` where the
// planner's answer does not matter.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <thread>

#include "bench/bench.h"
#include "bench/child_output.h"
#include "bench/report_blocks.h"
#include "bench/shard.h"
#include "bench_test_util.h"

namespace wrap::bench {
namespace {

using Json = nlohmann::json;

int CountRuns(const fs::path& out) {
  int n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out / "runs", ec)) {
    n += e.path().extension() == ".json" ? 1 : 0;
  }
  return n;
}

// The tiny suite (4 runs) with a stand-in `wrap` that runs for `seconds` and succeeds.
BenchOptions FakeOptions(const fs::path& dir, double seconds, const std::string& pids = "") {
  BenchOptions o = TinyOptions();
  o.jobs = 1;
  std::string body = pids.empty() ? "" : "echo $$ >> '" + pids + "'\n";
  body += "exec sleep " + std::to_string(seconds);
  o.wrap_exe = FakeWrap(dir, "fake_wrap_" + std::to_string(static_cast<int>(seconds * 1000)), body);
  return o;
}

std::vector<RunSpec> Tiny(const BenchOptions& o) {
  auto specs = MakeSuite(o);
  EXPECT_TRUE(specs.has_value());
  return specs.value_or(std::vector<RunSpec>{});
}

bool Alive(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const size_t close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

// Node loss, or `kill -9` of the harness: the shard folder resumes from its finished runs, and
// the run that was in flight did not go on in an orphan.
TEST(BenchShards, ShardKilledOutrightResumesFromItsFinishedRuns) {
  TempDir tmp;
  const fs::path out = tmp.path() / "shard";
  const fs::path pids = tmp.path() / "pids.txt";
  const BenchOptions o = FakeOptions(tmp.path(), 0.4, pids.string());
  const std::vector<RunSpec> specs = Tiny(o);
  ASSERT_EQ(specs.size(), 4u);
  const pid_t harness = fork();
  ASSERT_GE(harness, 0);
  if (harness == 0) {
    auto r = RunSuite(specs, o, out);
    _exit(r ? 0 : 1);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (CountRuns(out) < 1 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // Kill it while the second run's child is up.
  const auto started = [&] {
    const std::string text = Slurp(pids);
    return std::count(text.begin(), text.end(), '\n');
  };
  while (started() < 2 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(harness, SIGKILL);
  waitpid(harness, nullptr, 0);
  const int done = CountRuns(out);
  ASSERT_GE(done, 1);
  ASSERT_LT(done, 4);
  // Its child died with it.
  std::ifstream in(pids);
  pid_t child = 0, last = 0;
  while (in >> child) last = child;
  ASSERT_GT(last, 0);
  for (int i = 0; i < 100 && Alive(last); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_FALSE(Alive(last)) << "the run in flight outlived its harness (pid " << last << ")";

  // Run again: the finished runs are reused, the others run; nothing else changes.
  int reused = 0;
  BenchOptions again = o;
  again.on_progress = [&](const Progress& p) { reused += p.last.starts_with("(reused)") ? 1 : 0; };
  auto results = RunSuite(specs, again, out);
  ASSERT_TRUE(results.has_value()) << results.error().message;
  EXPECT_EQ(reused, done);
  EXPECT_EQ(results->size(), 4u);
  EXPECT_EQ(CountRuns(out), 4);
  for (const RunResult& r : *results) EXPECT_EQ(r.status, Status::kSolved);
  auto meta = ReadFolderMeta(out);
  ASSERT_TRUE(meta.has_value()) << meta.error().message;
  ASSERT_EQ(meta->shards.size(), 1u);
  const auto& sessions = meta->shards.front().sessions;
  ASSERT_EQ(sessions.size(), 2u);
  EXPECT_TRUE(sessions[0].end.empty());  // killed: it never ended
  EXPECT_FALSE(sessions[1].end.empty());
  EXPECT_EQ(meta->shards.front().runs_done, 4);
}

// Two processes never write one folder: the second is refused, naming the first.
TEST(BenchShards, FolderInUseIsRefused) {
  TempDir tmp;
  const fs::path out = tmp.path() / "o";
  fs::create_directories(out);
  {
    auto lock = FolderLock::Acquire(out);
    ASSERT_TRUE(lock.has_value()) << lock.error().message;
    std::string err;
    EXPECT_EQ(RunWrap("bench --suite tiny --runs 1 --projects '" + ProjectsDir().string() +
                          "' -o '" + out.string() + "'",
                      tmp.path(), &err),
              2);
    EXPECT_NE(err.find("in use by another `wrap bench` (pid " + std::to_string(getpid())),
              std::string::npos)
        << err;
    EXPECT_FALSE(fs::exists(out / "runs"));
    EXPECT_FALSE(FolderLock::Acquire(out).has_value());  // also within one process
  }
  // Released with its holder.
  EXPECT_TRUE(FolderLock::Acquire(out).has_value());
}

// A folder is one shard's: resuming it with other settings, or as another shard, is refused.
TEST(BenchShards, ResumingWithOtherSettingsIsRefused) {
  TempDir tmp;
  const fs::path out = tmp.path() / "o";
  BenchOptions o = FakeOptions(tmp.path(), 0.0);
  o.runs = 1;
  ASSERT_TRUE(RunSuite(Tiny(o), o, out).has_value());
  BenchOptions more = o;
  more.runs = 2;
  auto r = RunSuite(Tiny(more), more, out);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(r.error().message.find("--runs: 2 here, 1 there"), std::string::npos)
      << r.error().message;
  BenchOptions other_shard = o;
  other_shard.shard_index = 2;
  other_shard.shard_count = 2;
  r = RunSuite(Tiny(other_shard), other_shard, out);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().message.find("shards (--shard I/N): 2 here, 1 there"), std::string::npos)
      << r.error().message;
  BenchOptions slower = o;
  slower.time_limit_s = 5.0;
  r = RunSuite(Tiny(slower), slower, out);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().message.find("--time-limit: 5 s here, 10 s there"), std::string::npos)
      << r.error().message;
  // The same settings resume (nothing to run).
  EXPECT_TRUE(RunSuite(Tiny(o), o, out).has_value());
}

// Two shards of the tiny suite, made with the stand-in.
struct TwoShards {
  explicit TwoShards(const fs::path& dir) : a(dir / "s1"), b(dir / "s2") {
    BenchOptions o = FakeOptions(dir, 0.0);
    o.shard_count = 2;
    for (int i = 1; i <= 2; ++i) {
      o.shard_index = i;
      EXPECT_TRUE(RunSuite(Tiny(o), o, i == 1 ? a : b).has_value());
    }
  }
  fs::path a, b;
};

Result<std::vector<RunResult>> Merge(const std::vector<fs::path>& dirs, const fs::path& out,
                                     bool partial = false) {
  return MergeShards(dirs, out, partial);
}

TEST(BenchMerge, MergesTheShardsOfOneStudy) {
  TempDir tmp;
  TwoShards s(tmp.path());
  auto m = Merge({s.a, s.b}, tmp.path() / "m");
  ASSERT_TRUE(m.has_value()) << m.error().message;
  EXPECT_EQ(m->size(), 4u);
  auto meta = ReadFolderMeta(tmp.path() / "m");
  ASSERT_TRUE(meta.has_value());
  EXPECT_EQ(meta->kind, "merged");
  EXPECT_EQ(meta->shards.size(), 2u);
  // A merged folder merges again (e.g. with another suite's shards), into another folder.
  EXPECT_TRUE(Merge({tmp.path() / "m"}, tmp.path() / "m2").has_value());
  // Each session's load is in the header; many (a cluster's) as their range.
  EXPECT_NE(Slurp(tmp.path() / "m" / "report.md").find("shard 2/2 of suite 'tiny' on "),
            std::string::npos);
  BenchOptions resume = FakeOptions(tmp.path(), 0.0);
  resume.shard_index = 2;
  resume.shard_count = 2;
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(RunSuite(Tiny(resume), resume, s.b).has_value());
  ASSERT_TRUE(Merge({s.a, s.b}, tmp.path() / "m").has_value());
  EXPECT_NE(Slurp(tmp.path() / "m" / "report.md").find("5 sessions on 1 host(s), 1-minute load "),
            std::string::npos)
      << Slurp(tmp.path() / "m" / "report.md").substr(0, 800);
  // Never into one of its inputs, nor into a shard's folder.
  auto self = Merge({s.a, s.b}, s.a);
  ASSERT_FALSE(self.has_value());
  EXPECT_NE(self.error().message.find("one of the folders to merge"), std::string::npos);
  BenchOptions o = FakeOptions(tmp.path(), 0.0);
  ASSERT_TRUE(RunSuite(Tiny(o), o, tmp.path() / "whole").has_value());
  auto onto_shard = Merge({s.a, s.b}, tmp.path() / "whole");
  ASSERT_FALSE(onto_shard.has_value());
  EXPECT_NE(onto_shard.error().message.find("is a shard's folder"), std::string::npos);
}

TEST(BenchMerge, RefusesShardsOfDifferentRevisions) {
  TempDir tmp;
  TwoShards s(tmp.path());
  auto meta = ReadFolderMeta(s.b);
  ASSERT_TRUE(meta.has_value());
  meta->shards.front().id.revision = "0123456789+changes.abcdef01";
  ASSERT_TRUE(WriteFolderMeta(s.b, *meta).has_value());
  auto m = Merge({s.a, s.b}, tmp.path() / "m");
  ASSERT_FALSE(m.has_value());
  EXPECT_EQ(m.error().code, ErrorCode::kInvalidInput);
  const std::string& e = m.error().message;
  EXPECT_NE(e.find("different revisions"), std::string::npos) << e;
  EXPECT_NE(e.find(s.b.string() + ": 0123456789+changes.abcdef01"), std::string::npos) << e;
  EXPECT_NE(e.find(s.a.string() + ": " + std::string(ReadFolderMeta(s.a)->shards[0].id.revision)),
            std::string::npos)
      << e;
  EXPECT_FALSE(fs::exists(tmp.path() / "m" / "report.md"));
}

TEST(BenchMerge, RefusesShardsOfDifferentSettings) {
  TempDir tmp;
  TwoShards s(tmp.path());
  BenchOptions o = FakeOptions(tmp.path(), 0.0);
  o.shard_index = 2;
  o.shard_count = 2;
  o.runs = 3;
  ASSERT_TRUE(RunSuite(Tiny(o), o, tmp.path() / "s2_runs3").has_value());
  auto m = Merge({s.a, tmp.path() / "s2_runs3"}, tmp.path() / "m");
  ASSERT_FALSE(m.has_value());
  const std::string& e = m.error().message;
  EXPECT_NE(e.find("s2_runs3 (shard 2/2 of suite 'tiny') was run with other settings than"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("--runs: 3 here, 2 there"), std::string::npos) << e;
}

TEST(BenchMerge, RefusesMissingDuplicatedAndUnfinishedShardsUnlessPartial) {
  TempDir tmp;
  TwoShards s(tmp.path());
  auto missing = Merge({s.a}, tmp.path() / "m");
  ASSERT_FALSE(missing.has_value());
  EXPECT_NE(missing.error().message.find("shard 2/2 of suite 'tiny' is missing"), std::string::npos)
      << missing.error().message;
  EXPECT_NE(missing.error().message.find("--partial"), std::string::npos);

  fs::copy(s.a, tmp.path() / "s1_copy", fs::copy_options::recursive);
  auto twice = Merge({s.a, tmp.path() / "s1_copy", s.b}, tmp.path() / "m");
  ASSERT_FALSE(twice.has_value());
  EXPECT_NE(twice.error().message.find("shard 1/2 of suite 'tiny' is in more than one folder"),
            std::string::npos)
      << twice.error().message;

  // Shard 2 lost a run (as if cancelled before it).
  std::vector<fs::path> runs;
  for (const auto& e : fs::directory_iterator(s.b / "runs")) runs.push_back(e.path());
  ASSERT_EQ(runs.size(), 2u);
  fs::remove(runs.front());
  auto unfinished = Merge({s.a, s.b}, tmp.path() / "m");
  ASSERT_FALSE(unfinished.has_value());
  EXPECT_NE(unfinished.error().message.find(s.b.string() +
                                            " (shard 2/2 of suite 'tiny') has 1 of its 2 runs"),
            std::string::npos)
      << unfinished.error().message;

  // --partial merges what there is and says so first thing in the report.
  auto partial = Merge({s.a, s.b}, tmp.path() / "m", true);
  ASSERT_TRUE(partial.has_value()) << partial.error().message;
  EXPECT_EQ(partial->size(), 3u);
  const std::string md = Slurp(tmp.path() / "m" / "report.md");
  EXPECT_NE(md.find("**Incomplete: partial merge: " + s.b.string() + " (shard 2/2"),
            std::string::npos)
      << md.substr(0, 600);
  // ... and such a merge is not merged again as if it were whole.
  auto again = Merge({tmp.path() / "m"}, tmp.path() / "m2");
  ASSERT_FALSE(again.has_value());
  EXPECT_NE(again.error().message.find("is a partial merge"), std::string::npos);
}

// A run on a loaded machine is marked in the report and runs again with rerun_loaded.
TEST(BenchLoad, LoadedRunsAreMarkedAndRunAgainOnRequest) {
  RunResult r;
  r.cores = 2;
  r.load = 2.9;
  EXPECT_FALSE(r.loaded());
  r.load = 3.0;
  EXPECT_TRUE(r.loaded());
  r.cores = 0;
  EXPECT_FALSE(r.loaded());  // not measured

  TempDir tmp;
  const fs::path out = tmp.path() / "o";
  BenchOptions o = FakeOptions(tmp.path(), 0.0);
  ASSERT_TRUE(RunSuite(Tiny(o), o, out).has_value());
  // One run recorded as made with 50 threads waiting for the cores, the others on an idle
  // machine (whatever this machine's load was).
  fs::path first;
  for (const auto& e : fs::directory_iterator(out / "runs")) first = std::max(first, e.path());
  for (const auto& e : fs::directory_iterator(out / "runs")) {
    Json j = Json::parse(Slurp(e.path()));
    j["load"] = e.path() == first ? 50.0 + j["cores"].get<int>() : 0.0;
    std::ofstream(e.path()) << j.dump(2);
  }
  auto again = RunSuite(Tiny(o), o, out);
  ASSERT_TRUE(again.has_value());
  EXPECT_NE(Slurp(out / "report.md").find("1 of 4 runs were made while the machine was loaded"),
            std::string::npos);
  EXPECT_NE(Slurp(out / "report.md").find("| 2/2 †1 |"), std::string::npos)
      << Slurp(out / "report.md");
  int fresh = 0;
  o.rerun_loaded = true;
  o.on_progress = [&](const Progress& p) { fresh += p.last.starts_with("(reused)") ? 0 : 1; };
  ASSERT_TRUE(RunSuite(Tiny(o), o, out).has_value());
  EXPECT_EQ(fresh, 1);
  EXPECT_LT(Json::parse(Slurp(first))["load"].get<double>(), 50.0);
}

TEST(BenchUtilisation, RobotsMovingFromThePlansSegments) {
  // Two robots over a 10 s makespan: a moves in [0, 2] and [1, 3] (overlapping: 3 s), b in
  // [4, 5]; c never moves.
  const Json plan = {{"robots", {"a", "b", "c"}},
                     {"stats", {{"makespan_s", 10.0}}},
                     {"segments",
                      {{{"kind", "free"}, {"robots", {"a"}}, {"start_s", 0.0}, {"end_s", 2.0}},
                       {{"kind", "carry"}, {"robots", {"a"}}, {"start_s", 1.0}, {"end_s", 3.0}},
                       {{"kind", "insert"}, {"robots", {"b"}}, {"start_s", 4.0}, {"end_s", 5.0}}}}};
  const auto u = UtilisationOfPlan(plan.dump());
  ASSERT_TRUE(u.has_value());
  EXPECT_NEAR(u->moving.at("a"), 0.3, 1e-12);
  EXPECT_NEAR(u->moving.at("b"), 0.1, 1e-12);
  EXPECT_NEAR(u->moving.at("c"), 0.0, 1e-12);
  EXPECT_NEAR(u->MeanMoving(), 0.4 / 3.0, 1e-12);
  ASSERT_EQ(u->profile.size(), static_cast<size_t>(kProfileBins));
  // Slices of 0.5 s: a alone in [0, 3), nobody in [3, 4), b in [4, 5), nobody after.
  for (int k = 0; k < kProfileBins; ++k) {
    const double t = 0.5 * k;
    const double expected = t < 3.0 ? 1.0 : (t >= 4.0 && t < 5.0) ? 1.0 : 0.0;
    EXPECT_NEAR(u->profile[k], expected, 1e-12) << "slice " << k;
  }
  EXPECT_FALSE(UtilisationOfPlan(Json{{"robots", {"a"}}}.dump()).has_value());  // no motion
}

TEST(BenchReport, OwnMeasuresMakespanUtilisationAndSimulation) {
  TempDir tmp;
  std::vector<RunResult> results;
  for (int seed = 0; seed < 2; ++seed) {
    RunResult r;
    r.spec.project = {"stool", "stool", 0, 0, "breakdown"};
    r.spec.group = "breakdown";
    r.spec.motion = r.spec.sim = true;
    r.spec.seed = static_cast<std::uint64_t>(seed);
    r.status = Status::kSolved;
    r.stats = {{"makespan_s", seed == 0 ? 100.0 : 120.0}, {"t_mp_s", 3.0}};
    Utilisation u;
    u.moving = {{"a", seed == 0 ? 0.5 : 0.7}, {"b", 0.3}};
    u.profile.assign(kProfileBins, 1.0);
    u.profile[3] = 2.0;
    r.utilisation = u;
    r.sim_success = seed == 0;
    r.sim_tasks_completed = seed == 0 ? 20 : 12;
    r.sim_tasks_total = 20;
    r.sim_failure = seed == 0 ? "" : "slip";
    results.push_back(r);
  }
  ASSERT_TRUE(WriteReport(results, RunInfo{"m", "l", "c", "d", "s", ""}, tmp.path()).has_value());
  const std::string md = Slurp(tmp.path() / "report.md");
  // Makespan 110 ± 14.1; moving 40% and 50%: 45 ± 7; the busiest slice 2 robots; 1 of 2 held.
  EXPECT_NE(md.find("| Stool | 2/2 | 110.0 ± 14.1 | 45 ± 7 | 2.0 ± 0.0 | 1/2 (50%) | 16.0/20.0 | "
                    "slip (1) |"),
            std::string::npos)
      << md;
  EXPECT_NE(Slurp(tmp.path() / "fig_utilisation.svg").find("Stool"), std::string::npos);
}

// --dry-run lists a shard's runs and bounds their time, running nothing.
TEST(BenchCli, DryRunSizesAShard) {
  TempDir tmp;
  const fs::path out_file = tmp.path() / "stdout.txt";
  const std::string cmd = std::string("'") + WRAP_EXE +
                          "' bench --suite all --runs 10 --shard 3/40 --jobs 2 --dry-run > '" +
                          out_file.string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const std::string text = Slurp(out_file);
  BenchOptions o;
  o.suite = "all";
  o.runs = 10;
  const auto all = MakeSuite(o);
  ASSERT_TRUE(all.has_value());
  const auto slice = ShardSlice(*all, 3, 40);
  EXPECT_NE(text.find("Suite 'all': " + std::to_string(all->size()) +
                      " runs; shard 3/40: " + std::to_string(slice.size()) + " runs"),
            std::string::npos)
      << text;
  double longest = 0.0;
  for (const RunSpec& s : slice) longest += LongestRunS(s, o);
  EXPECT_NE(text.find("(" + std::to_string(static_cast<long long>(std::ceil(longest / 2))) +
                      " s) at --jobs 2"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find(slice.front().Key()), std::string::npos);
}

}  // namespace
}  // namespace wrap::bench
