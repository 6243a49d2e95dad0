// The objective of bench runs (issue 33, cycle time): `--objective makespan` as a run setting,
// its results, the makespan suite and its report section. No planning: specs, results and plan
// files are made up here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/bench.h"
#include "bench/child_output.h"
#include "bench/shard.h"
#include "bench_test_util.h"

namespace wrap::bench {
namespace {

RunSpec MotionSpec(const std::string& project, std::uint64_t seed) {
  RunSpec s;
  s.project = {project, project, 0, 0, "makespan"};
  s.group = "makespan";
  s.motion = true;
  s.time_limit_s = 60.0;
  s.seed = seed;
  return s;
}

RunSpec MakespanSpec(const std::string& project, std::uint64_t seed) {
  RunSpec s = MotionSpec(project, seed);
  s.optimize = true;
  s.objective = "makespan";
  return s;
}

// A default run's key, options and command line are those of the harness before the objective
// was a setting: earlier results folders resume and merge as they did.
TEST(BenchObjective, DefaultRunKeepsItsKeyAndCommandLine) {
  const RunSpec plain = MotionSpec("cross", 0);
  EXPECT_EQ(plain.Options(), "wrench=full;lambda=1;motion;limit=60");
  EXPECT_EQ(plain.Key(), "cross__wrap__wrench_full_lambda_1_motion_limit_60__s0");
  const RunSpec shortest = MakespanSpec("cross", 0);
  EXPECT_EQ(shortest.Options(), "wrench=full;lambda=1;optimize;objective=makespan;motion;limit=60");
  EXPECT_EQ(shortest.Key(),
            "cross__wrap__wrench_full_lambda_1_optimize_objective_makespan_motion_limit_60__s0");

  BenchOptions o;
  const auto plain_args = PlanArguments(plain, o, "wrap", "cross.json", "plan.json");
  EXPECT_EQ(std::find(plain_args.begin(), plain_args.end(), "--objective"), plain_args.end());
  EXPECT_EQ(std::find(plain_args.begin(), plain_args.end(), "--optimize"), plain_args.end());
  const auto args = PlanArguments(shortest, o, "wrap", "cross.json", "plan.json");
  const auto at = std::find(args.begin(), args.end(), "--objective");
  ASSERT_NE(at, args.end());
  ASSERT_NE(at + 1, args.end());
  EXPECT_EQ(*(at + 1), "makespan");
  EXPECT_NE(std::find(args.begin(), args.end(), "--optimize"), args.end());
  EXPECT_EQ(std::find(args.begin(), args.end(), "--task-only"), args.end());
  EXPECT_EQ(args[1], "plan");
  EXPECT_EQ(args[2], "cross.json");
}

TEST(BenchObjective, ObjectiveRoundTripsAndOldFilesReadAsActions) {
  RunResult r;
  r.spec = MakespanSpec("stool", 2);
  r.status = Status::kSolved;
  r.stats = {{"cost", 22}, {"makespan_s", 60.5}, {"makespan_sequential_s", 90.25}};
  auto back = RunResultFromJson(RunResultToJson(r), "x.json");
  ASSERT_TRUE(back.has_value()) << back.error().message;
  EXPECT_EQ(back->spec.objective, "makespan");
  EXPECT_EQ(back->spec.Key(), r.spec.Key());
  EXPECT_EQ(back->stats, r.stats);
  EXPECT_EQ(ResultsCsv({*back}), ResultsCsv({r}));

  // A file written before the objective was recorded.
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(RunResultToJson(r));
  j.erase("objective");
  j["optimize"] = false;
  auto old = RunResultFromJson(j.dump(), "old.json");
  ASSERT_TRUE(old.has_value()) << old.error().message;
  EXPECT_EQ(old->spec.objective, "actions");
  EXPECT_EQ(old->spec.Key(), "stool__wrap__wrench_full_lambda_1_motion_limit_60__s2");

  j["objective"] = "speed";
  auto bad = RunResultFromJson(j.dump(), "runs/bad.json");
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("runs/bad.json: objective"), std::string::npos)
      << bad.error().message;
}

// results.csv names the makespan one segment at a time beside the makespan.
TEST(BenchObjective, CsvHasTheSequentialMakespan) {
  RunResult r;
  r.spec = MakespanSpec("cross", 0);
  r.status = Status::kSolved;
  r.stats = {{"makespan_s", 70.5}, {"makespan_sequential_s", 120.25}};
  const std::string csv = ResultsCsv({r});
  const auto header = CsvRow(csv.substr(0, csv.find('\n')));
  const auto row = CsvRow(csv.substr(csv.find('\n') + 1));
  std::map<std::string, std::string> cell;
  for (size_t i = 0; i < header.size() && i < row.size(); ++i) cell[header[i]] = row[i];
  EXPECT_EQ(cell["makespan_s"], "70.5");
  EXPECT_EQ(cell["makespan_sequential_s"], "120.25");
  EXPECT_EQ(cell["options"], "wrench=full;lambda=1;optimize;objective=makespan;motion;limit=60");
}

// The plan file's sequential makespan reaches the result where the plan has motion.
TEST(BenchObjective, PlanFileGivesBothMakespans) {
  TempDir tmp;
  const auto write = [&](bool solved, bool motion) {
    nlohmann::json plan = {{"stats",
                            {{"solved", solved},
                             {"motion", motion},
                             {"cost", 20},
                             {"makespan_s", motion ? 40.0 : 0.0},
                             {"makespan_sequential_s", motion ? 64.0 : 0.0}}}};
    std::ofstream(tmp.path() / "plan.json") << plan.dump();
    RunResult r;
    ReadPlanFile(r, tmp.path() / "plan.json");
    return r.stats;
  };
  auto stats = write(true, true);
  EXPECT_EQ(stats["makespan_s"], 40.0);
  EXPECT_EQ(stats["makespan_sequential_s"], 64.0);
  EXPECT_FALSE(write(true, false).contains("makespan_sequential_s"));  // task plan only
  EXPECT_FALSE(write(false, true).contains("makespan_sequential_s"));  // no plan
}

TEST(BenchObjective, MakespanSuitePlansEverySeedThreeWays) {
  BenchOptions o;
  o.suite = "makespan";
  o.runs = 2;
  o.projects_dir = ProjectsDir();
  auto specs = MakeSuite(o);
  ASSERT_TRUE(specs.has_value()) << specs.error().message;
  std::map<std::string, std::set<std::string>> ways;  // project -> "objective/seed"
  for (const RunSpec& s : *specs) {
    EXPECT_EQ(s.planner, "wrap");
    EXPECT_TRUE(s.motion);
    EXPECT_FALSE(s.sim);
    EXPECT_EQ(s.group, "makespan");
    EXPECT_EQ(s.time_limit_s, 60.0);
    EXPECT_TRUE(!s.optimize || s.objective == "makespan") << s.Key();
    ways[s.project.name].insert((s.optimize ? "optimize " : "") + s.objective + "/" +
                                std::to_string(s.seed));
    EXPECT_TRUE(fs::exists(ProjectsDir() / (s.project.base + ".json"))) << s.project.base;
  }
  const std::set<std::string> three = {"actions/0",  "actions/1",           "makespan/0",
                                       "makespan/1", "optimize makespan/0", "optimize makespan/1"};
  for (const char* p : {"cross", "stool", "chair", "fabrica_beam", "fabrica_plumbers_block"}) {
    EXPECT_EQ(ways[p], three) << p;
  }
  EXPECT_EQ(ways.size(), 5u);
  EXPECT_EQ(specs->size(), 30u);

  // `all` holds them too; a shard folder of the makespan suite is not one of another suite with
  // the same projects (merge and resume compare these identities).
  o.suite = "all";
  auto all = MakeSuite(o);
  ASSERT_TRUE(all.has_value());
  std::set<std::string> keys;
  for (const RunSpec& s : *all) keys.insert(s.Key());
  for (const RunSpec& s : *specs) EXPECT_TRUE(keys.contains(s.Key())) << s.Key();
  std::vector<RunSpec> plain_only = *specs;
  for (RunSpec& s : plain_only) {
    s.optimize = false;
    s.objective = "actions";
  }
  o.suite = "makespan";
  EXPECT_NE(MakeShardId(plain_only, o).suite_fingerprint, MakeShardId(*specs, o).suite_fingerprint);
}

RunResult MotionRun(const RunSpec& spec, double makespan, double sequential, double actions) {
  RunResult r;
  r.spec = spec;
  r.status = Status::kSolved;
  r.stats = {{"cost", actions}, {"makespan_s", makespan}, {"makespan_sequential_s", sequential}};
  return r;
}

// The section's rows from made-up runs: medians and means of both makespans and of their ratio,
// runs without motion counted but not averaged, the default before the makespan objective.
TEST(BenchObjective, ReportSectionHasARowPerAssemblyAndObjective) {
  std::vector<RunResult> results;
  results.push_back(MotionRun(MotionSpec("cross", 0), 60, 120, 24));  // ratio 0.50
  results.push_back(MotionRun(MotionSpec("cross", 1), 80, 100, 26));  // 0.80
  results.push_back(MotionRun(MotionSpec("cross", 2), 90, 100, 28));  // 0.90
  results.push_back(MotionRun(MakespanSpec("cross", 0), 50, 100, 27));
  RunResult failed = MotionRun(MakespanSpec("cross", 1), 0, 0, 0);
  failed.status = Status::kUnsolved;
  failed.stats.clear();
  failed.message = "no motion for the task plans tried";
  results.push_back(failed);
  results.push_back(MotionRun(MotionSpec("fabrica_beam", 0), 40, 60, 15));
  // Another section's run with motion: not in this one.
  RunSpec breakdown = MotionSpec("stool", 0);
  breakdown.group = breakdown.project.group = "breakdown";
  results.push_back(MotionRun(breakdown, 70, 90, 23));

  TempDir tmp;
  RunInfo info{"test machine", "load 0", "abc1234", "2026-01-01", "test"};
  ASSERT_TRUE(WriteReport(results, info, tmp.path()).has_value());
  const std::string md = Slurp(tmp.path() / "report.md");
  const size_t at = md.find("## Cycle time: robots at work together");
  ASSERT_NE(at, std::string::npos) << md;
  const std::string section = md.substr(at, md.find("\n## ", at + 1) - at);
  EXPECT_NE(section.find("| assembly | plan | with motion | makespan [s] | sequential [s] | "
                         "makespan / sequential | actions |"),
            std::string::npos)
      << section;
  const std::string plain =
      "| Cross | default | 3/3 | 80.0 / 76.7 | 100.0 / 106.7 | 0.80 / 0.73 | 26.0 |";
  const std::string shortest =
      "| Cross | `--optimize --objective makespan` | 1/2 (unsolved 1) | 50.0 / 50.0 | "
      "100.0 / 100.0 | 0.50 / 0.50 | 27.0 |";
  ASSERT_NE(section.find(plain), std::string::npos) << section;
  ASSERT_NE(section.find(shortest), std::string::npos) << section;
  EXPECT_LT(section.find(plain), section.find(shortest));
  EXPECT_NE(
      section.find("| F. Beam | default | 1/1 | 40.0 / 40.0 | 60.0 / 60.0 | 0.67 / 0.67 | 15.0 |"),
      std::string::npos)
      << section;
  EXPECT_EQ(section.find("Stool"), std::string::npos) << section;

  // No run of the suite: no section.
  results.erase(results.begin(), results.end() - 1);
  TempDir other;
  ASSERT_TRUE(WriteReport(results, info, other.path()).has_value());
  EXPECT_EQ(Slurp(other.path() / "report.md").find("Cycle time"), std::string::npos);
}

}  // namespace
}  // namespace wrap::bench
