// The benchmark harness end to end: real `wrap` children for a tiny suite, the report files, a
// run killed by its time limit, crashes recorded as results, shard + merge.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>

#include "bench/bench.h"
#include "bench/svg_plot.h"
#include "bench_test_util.h"

namespace wrap::bench {
namespace {

namespace fs = std::filesystem;

TEST(BenchSuites, TinySuiteIsOneProjectTwoPlannersPerSeed) {
  auto specs = MakeSuite(TinyOptions());
  ASSERT_TRUE(specs.has_value());
  ASSERT_EQ(specs->size(), 4u);
  std::set<std::string> planners, keys;
  for (const RunSpec& s : *specs) {
    EXPECT_EQ(s.project.name, "cross");
    planners.insert(s.planner);
    keys.insert(s.Key());
    EXPECT_EQ(s.time_limit_s, 10.0);
  }
  EXPECT_EQ(planners, (std::set<std::string>{"counting", "wrap"}));
  EXPECT_EQ(keys.size(), 4u);
}

TEST(BenchSuites, NamedSuitesCoverThePaperStudies) {
  BenchOptions o = TinyOptions();
  o.runs = 1;
  o.time_limit_s.reset();
  o.suite = "scaling";
  auto scaling = MakeSuite(o);
  ASSERT_TRUE(scaling.has_value());
  std::set<std::string> names, models;
  for (const RunSpec& s : *scaling) {
    names.insert(s.project.name);
    if (s.project.base == "cross" && s.project.steps == 0) models.insert(s.Options());
  }
  for (const char* n : {"cross_r2", "cross_r3", "cross", "cube_2x2x3_r2", "cube_2x2x3_r3",
                        "cube_2x2x3", "cube_2x2x1", "cube_2x2x2", "cross_arms1"}) {
    EXPECT_TRUE(names.contains(n)) << n;
  }
  EXPECT_EQ(models.size(), 8u);  // no wrench, gravity, 6 lambdas
  o.suite = "all";
  auto all = MakeSuite(o);
  ASSERT_TRUE(all.has_value());
  std::set<std::string> keys;
  for (const RunSpec& s : *all) EXPECT_TRUE(keys.insert(s.Key()).second) << s.Key();
  o.suite = "bogus";
  auto bad = MakeSuite(o);
  ASSERT_FALSE(bad.has_value());
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(bad.error().message.find("bogus"), std::string::npos);
}

// The paper suite: the convergence figure with all six planners (the paper's legend), the
// breakdown's runs with motion and then simulated (Wrap's own measures), 60 s for them; the smoke
// suite has a run of every study.
TEST(BenchSuites, PaperSuiteHasEveryPlannerConvergingAndSimulatedBreakdowns) {
  BenchOptions o = TinyOptions();
  o.runs = 1;
  o.time_limit_s.reset();
  o.suite = "paper";
  auto paper = MakeSuite(o);
  ASSERT_TRUE(paper.has_value());
  std::set<std::string> converging, simulated;
  for (const RunSpec& s : *paper) {
    if (s.optimize) {
      EXPECT_EQ(s.group, "convergence");
      converging.insert(s.planner);
    }
    if (s.group == "breakdown") {
      EXPECT_TRUE(s.motion && s.sim) << s.Key();
      EXPECT_EQ(s.time_limit_s, 60.0);
      simulated.insert(s.project.name);
    }
    if (!s.motion) {
      EXPECT_EQ(s.time_limit_s, 30.0) << s.Key();
    }
  }
  EXPECT_EQ(converging,
            (std::set<std::string>{"optimistic", "wrap", "flat", "counting", "exact", "fine"}));
  EXPECT_EQ(simulated, (std::set<std::string>{"cross", "stool", "chair"}));
  o.suite = "smoke";
  auto smoke = MakeSuite(o);
  ASSERT_TRUE(smoke.has_value());
  std::set<std::string> groups;
  for (const RunSpec& s : *smoke) groups.insert(s.group);
  EXPECT_EQ(groups, (std::set<std::string>{"comparison", "ablation", "scaling_robots",
                                           "scaling_parts", "convergence"}));
}

TEST(BenchDerivedProjects, FewerRobotsAndPrefixesAreValidProjects) {
  TempDir tmp;
  const fs::path r2 = tmp.path() / "projects" / "cross_r2.json";
  ASSERT_TRUE(WriteDerivedProject({"cross_r2", "cross", 2, 0, ""}, ProjectsDir() / "cross.json", r2)
                  .has_value());
  const fs::path p4 = tmp.path() / "projects" / "cube_2x2x1.json";
  ASSERT_TRUE(WriteDerivedProject({"cube_2x2x1", "cube_2x2x3", 0, 3, ""},
                                  ProjectsDir() / "cube_2x2x3.json", p4)
                  .has_value());
  const auto j2 = nlohmann::json::parse(Slurp(r2));
  EXPECT_EQ(j2["robots"].size(), 2u);
  EXPECT_EQ(j2["parts"].size(), 7u);
  const auto j4 = nlohmann::json::parse(Slurp(p4));
  EXPECT_EQ(j4["steps"].size(), 3u);
  EXPECT_EQ(j4["parts"].size(), 4u);
  EXPECT_EQ(j4["name"], "cube_2x2x1");
  // Mesh paths stay relative and point at the same files.
  const std::string mesh = j4["parts"][0]["mesh"];
  EXPECT_FALSE(fs::path(mesh).is_absolute());
  EXPECT_TRUE(fs::exists(p4.parent_path() / mesh)) << mesh;
  // And the loader accepts them.
  EXPECT_EQ(RunWrap("validate -q '" + r2.string() + "'", tmp.path()), 0);
  EXPECT_EQ(RunWrap("validate -q '" + p4.string() + "'", tmp.path()), 0);
  // A cut that the base cannot give is bad input naming the file and the field.
  auto bad = WriteDerivedProject({"x", "cross", 9, 0, ""}, ProjectsDir() / "cross.json",
                                 tmp.path() / "x.json");
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("robots"), std::string::npos);
  EXPECT_NE(bad.error().message.find("cross.json"), std::string::npos);
}

// The tiny suite through the real command line: a well-formed CSV and report.
TEST(BenchCli, TinySuiteWritesCsvAndReport) {
  TempDir tmp;
  const fs::path out = tmp.path() / "out";
  std::string err;
  ASSERT_EQ(RunWrap("bench --suite tiny --runs 2 --time-limit 10 --jobs 2 --projects '" +
                        ProjectsDir().string() + "' -o '" + out.string() + "'",
                    tmp.path(), &err),
            0)
      << err;
  EXPECT_NE(err.find("[4/4]"), std::string::npos) << err;  // progress, one line per run
  const auto rows = ReadCsv(out / "results.csv");
  ASSERT_EQ(rows.size(), 5u);
  const auto& h = rows[0];
  const int project = Column(h, "project"), planner = Column(h, "planner"),
            seed = Column(h, "seed"), status = Column(h, "status"), cost = Column(h, "cost"),
            t_init = Column(h, "t_init_s"), rss = Column(h, "peak_rss_mib");
  for (const char* c : {"options", "solved", "t_grasp_s", "t_bwd_s", "t_lp_s", "t_fwd_s", "t_ik_s",
                        "t_mp_s", "makespan_s", "sim_success"}) {
    Column(h, c);
  }
  std::set<std::pair<std::string, std::string>> seen;
  for (size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), h.size()) << "row " << i;
    EXPECT_EQ(rows[i][project], "cross");
    seen.insert({rows[i][planner], rows[i][seed]});
    // The cross is solved by both planners well within 10 s.
    EXPECT_EQ(rows[i][status], "solved") << rows[i].back();
    EXPECT_GT(std::stod(rows[i][cost]), 5.0);
    EXPECT_GT(std::stod(rows[i][t_init]), 0.0);
    EXPECT_GT(std::stod(rows[i][rss]), 1.0);
  }
  EXPECT_EQ(seen.size(), 4u);
  // Sorted: planner, then seed.
  EXPECT_EQ(rows[1][planner], "counting");
  EXPECT_EQ(rows[1][seed], "0");
  EXPECT_EQ(rows[4][planner], "wrap");
  EXPECT_EQ(rows[4][seed], "1");

  const std::string md = Slurp(out / "report.md");
  EXPECT_NE(md.find("# Wrap benchmark report"), std::string::npos);
  EXPECT_NE(md.find("Commit:"), std::string::npos);
  EXPECT_NE(md.find("Machine:"), std::string::npos);
  EXPECT_NE(md.find("Comparison"), std::string::npos);
  // (followed by " †2" where this machine was loaded while they ran)
  EXPECT_NE(md.find("| Cross | Ours (WRAP) | 2/2"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2.01 |"), std::string::npos);  // the paper's number beside ours
  const std::string html = Slurp(out / "report.html");
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<table>"), std::string::npos);
  EXPECT_NE(html.find("</html>"), std::string::npos);
  int run_files = 0;
  for (const auto& e : fs::directory_iterator(out / "runs")) run_files += e.is_regular_file();
  EXPECT_EQ(run_files, 4);
  // Plans are not kept by default; logs are.
  EXPECT_TRUE(fs::is_empty(out / "plans"));

  // A second call resumes: nothing runs again, the same rows come out.
  const std::string csv = Slurp(out / "results.csv");
  ASSERT_EQ(RunWrap("bench --suite tiny --runs 2 --time-limit 10 --projects '" +
                        ProjectsDir().string() + "' -o '" + out.string() + "'",
                    tmp.path(), &err),
            0);
  EXPECT_NE(err.find("(reused)"), std::string::npos) << err;
  EXPECT_EQ(Slurp(out / "results.csv"), csv);
}

TEST(BenchCli, BadInputExitsTwoNamingTheProblem) {
  TempDir tmp;
  std::string err;
  EXPECT_EQ(RunWrap("bench --suite nope -o '" + tmp.path().string() + "/o'", tmp.path(), &err), 2);
  EXPECT_NE(err.find("--suite"), std::string::npos) << err;
  EXPECT_EQ(RunWrap("bench --suite tiny --shard 3/2 -o '" + tmp.path().string() + "/o'", tmp.path(),
                    &err),
            2);
  EXPECT_NE(err.find("--shard"), std::string::npos) << err;
  EXPECT_EQ(RunWrap("bench --suite tiny", tmp.path(), &err), 2);
  EXPECT_NE(err.find("-o"), std::string::npos) << err;
  EXPECT_EQ(RunWrap("bench --suite tiny --projects '" + tmp.path().string() + "' -o '" +
                        tmp.path().string() + "/o'",
                    tmp.path(), &err),
            2);
  EXPECT_NE(err.find("cross.json"), std::string::npos) << err;
  EXPECT_EQ(RunWrap("bench merge '" + tmp.path().string() + "' -o '" + tmp.path().string() + "/m'",
                    tmp.path(), &err),
            2);
  EXPECT_NE(err.find("runs"), std::string::npos) << err;
}

// The real planner, stopped by the harness's wall-clock limit: a timeout, not an abort.
TEST(BenchRunner, RunKilledByItsTimeLimitIsATimeout) {
  TempDir tmp;
  RunSpec spec;
  spec.project = {"chair", "chair", 0, 0, "comparison"};
  spec.planner = "flat";  // Flat lazy runs to its own limit on the chair (BENCHMARKS.md)
  spec.time_limit_s = 120.0;
  spec.group = "comparison";
  BenchOptions o = TinyOptions();
  o.hard_limit_s = 1.5;
  auto results = RunSuite({spec}, o, tmp.path());
  ASSERT_TRUE(results.has_value()) << results.error().message;
  ASSERT_EQ(results->size(), 1u);
  const RunResult& r = results->front();
  EXPECT_EQ(r.status, Status::kTimeout);
  // Killed by the harness at its 1.5 s limit (the planner's own 120 s limit would say otherwise).
  EXPECT_NE(r.message.find("killed"), std::string::npos) << r.message;
  const auto rows = ReadCsv(tmp.path() / "results.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1][Column(rows[0], "status")], "timeout");
  EXPECT_NE(Slurp(tmp.path() / "report.md").find("timeout"), std::string::npos);
}

// What a child can do besides planning: crash, stop with bad input, hang. None aborts the suite.
TEST(BenchRunner, CrashesErrorsAndHangsAreResults) {
  TempDir tmp;
  RunSpec spec;
  spec.project = {"cross", "cross", 0, 0, "comparison"};
  spec.group = "comparison";
  const auto run = [&](const std::string& body, double hard_limit) {
    BenchOptions o = TinyOptions();
    o.hard_limit_s = hard_limit;
    o.wrap_exe = FakeWrap(tmp.path(), "fake_wrap", body);
    const fs::path out = tmp.path() / ("out" + std::to_string(std::rand()));
    auto results = RunSuite({spec}, o, out);
    EXPECT_TRUE(results.has_value());
    return results.has_value() ? results->front() : RunResult{};
  };
  const RunResult segv = run("kill -SEGV $$", 10.0);
  EXPECT_EQ(segv.status, Status::kCrash);
  EXPECT_EQ(segv.signal, 11);
  const RunResult bad = run("echo 'project.json: parts[0].mesh: not found' >&2; exit 2", 10.0);
  EXPECT_EQ(bad.status, Status::kError);
  EXPECT_NE(bad.message.find("mesh"), std::string::npos) << bad.message;
  const RunResult internal = run("echo 'wrap: internal error: std::bad_alloc' >&2; exit 3", 10.0);
  EXPECT_EQ(internal.status, Status::kOutOfMemory);
  const RunResult unsolved = run("echo 'no plan' >&2; exit 1", 10.0);
  EXPECT_EQ(unsolved.status, Status::kUnsolved);
  const RunResult hang = run("exec sleep 60", 0.5);
  EXPECT_EQ(hang.status, Status::kTimeout);
}

// Shard 1/2 and 2/2 merged give the rows of the unsharded suite.
TEST(BenchRunner, ShardsMergedEqualTheUnshardedRun) {
  TempDir tmp;
  auto specs = MakeSuite(TinyOptions());
  ASSERT_TRUE(specs.has_value());
  auto whole = RunSuite(*specs, TinyOptions(), tmp.path() / "whole");
  ASSERT_TRUE(whole.has_value()) << whole.error().message;
  for (int i = 1; i <= 2; ++i) {
    BenchOptions o = TinyOptions();
    o.shard_index = i;
    o.shard_count = 2;
    o.jobs = 1;
    auto part = RunSuite(*specs, o, tmp.path() / ("shard" + std::to_string(i)));
    ASSERT_TRUE(part.has_value()) << part.error().message;
    EXPECT_EQ(part->size(), 2u);
  }
  std::string err;
  ASSERT_EQ(RunWrap("bench merge '" + (tmp.path() / "shard1").string() + "' '" +
                        (tmp.path() / "shard2").string() + "' -o '" +
                        (tmp.path() / "merged").string() + "'",
                    tmp.path(), &err),
            0)
      << err;
  // Same rows: the run's identity and outcome (times differ from run to run).
  const auto a = ReadCsv(tmp.path() / "whole" / "results.csv");
  const auto b = ReadCsv(tmp.path() / "merged" / "results.csv");
  ASSERT_EQ(a.size(), 5u);
  ASSERT_EQ(b.size(), a.size());
  ASSERT_EQ(a[0], b[0]);
  for (size_t i = 1; i < a.size(); ++i) {
    for (const char* c :
         {"project", "planner", "options", "seed", "status", "solved", "cost", "first_cost"}) {
      const int k = Column(a[0], c);
      EXPECT_EQ(a[i][k], b[i][k]) << "row " << i << " column " << c;
    }
  }
  EXPECT_NE(Slurp(tmp.path() / "merged" / "report.md").find("merged from 2"), std::string::npos);
}

TEST(BenchResults, RunResultRoundTripsAndBadFilesAreNamed) {
  RunResult r;
  r.spec.project = {"cube_2x2x1", "cube_2x2x3", 0, 3, "scaling_parts"};
  r.spec.group = "scaling_parts";
  r.spec.planner = "exact";
  r.spec.wrench = "gravity";
  r.spec.optimize = true;
  r.spec.seed = 7;
  r.status = Status::kSolved;
  r.stats = {{"cost", 12}, {"t_init_s", 0.5}};
  r.cost_history = {{0.5, 14}, {2.0, 12}};
  r.sim_success = false;
  r.spec.sim = true;
  r.sim_failure = "slip";
  r.sim_util = {{"transport_vac", 47}};
  r.message = "a, \"quoted\" message";
  auto back = RunResultFromJson(RunResultToJson(r), "x.json");
  ASSERT_TRUE(back.has_value()) << back.error().message;
  EXPECT_EQ(back->spec.Key(), r.spec.Key());
  EXPECT_EQ(back->stats, r.stats);
  EXPECT_EQ(back->cost_history, r.cost_history);
  EXPECT_EQ(back->sim_failure, "slip");
  EXPECT_EQ(back->sim_util, r.sim_util);
  EXPECT_EQ(ResultsCsv({*back}), ResultsCsv({r}));
  const auto rows = CsvRow(ResultsCsv({r}).substr(ResultsCsv({r}).find('\n') + 1));
  EXPECT_EQ(rows.back(), "a, \"quoted\" message\n");

  auto bad = RunResultFromJson("{\"format\": \"wrap-bench-run\", \"project\": 3}", "runs/x.json");
  ASSERT_FALSE(bad.has_value());
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(bad.error().message.find("runs/x.json"), std::string::npos);
}

TEST(BenchSvg, PlotsHaveAxesLinesAndLegend) {
  LinePlot plot;
  plot.title = "t <init>";
  plot.log_y = true;
  plot.series.push_back({"wrap", "#111111", {{2, 0.1}, {3, 1.0}, {4, 10.0}}});
  PlotSeries step{"opt", "#ff0000", {{0.5, 30}, {2.0, 25}}};
  step.step = true;
  step.step_end_x = 10.0;
  plot.series.push_back(step);
  const std::string svg = RenderSvg(plot);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("t &lt;init&gt;"), std::string::npos);
  EXPECT_NE(svg.find("<path"), std::string::npos);
  EXPECT_NE(svg.find(">wrap</text>"), std::string::npos);
  EXPECT_NE(svg.find(" H"), std::string::npos);  // the staircase
  EXPECT_EQ(svg.find("no data"), std::string::npos);
  EXPECT_NE(RenderSvg(LinePlot{}).find("no data"), std::string::npos);
}

}  // namespace
}  // namespace wrap::bench

namespace wrap::bench {
namespace {

RunResult Synthetic(const ProjectSpec& project, const std::string& planner, std::uint64_t seed,
                    double t_init, double cost) {
  RunResult r;
  r.spec.project = project;
  r.spec.group = project.group;
  r.spec.planner = planner;
  r.spec.seed = seed;
  r.spec.time_limit_s = 20.0;
  r.status = Status::kSolved;
  r.stats = {{"t_init_s", t_init}, {"cost", cost}, {"first_cost", cost}, {"t_grasp_s", 0.1}};
  r.cost_history = {{t_init, cost}};
  return r;
}

// Every section of the report from results made up here: the scaling and convergence figures,
// the simulation table with the paper's row, means and the paper's numbers.
TEST(BenchReport, SectionsFiguresAndThePapersNumbers) {
  TempDir tmp;
  std::vector<RunResult> results;
  // Comparison: WRAP on the cross, 2 seeds, 1.0 and 3.0 s.
  results.push_back(Synthetic({"cross", "cross", 0, 0, "comparison"}, "wrap", 0, 1.0, 24));
  results.push_back(Synthetic({"cross", "cross", 0, 0, "comparison"}, "wrap", 1, 3.0, 26));
  // Scaling: the cross with 2 robots under no wrench; a prefix of the cube.
  RunResult r2 = Synthetic({"cross_r2", "cross", 2, 0, "scaling_robots"}, "wrap", 0, 0.5, 30);
  r2.spec.wrench = "none";
  results.push_back(r2);
  results.push_back(
      Synthetic({"cube_2x2x1", "cube_2x2x3", 0, 3, "scaling_parts"}, "wrap", 0, 0.7, 20));
  // Convergence: an --optimize run improving 30 -> 25.
  RunResult opt = Synthetic({"stool", "stool", 0, 0, "convergence"}, "wrap", 0, 2.0, 25);
  opt.spec.optimize = true;
  opt.stats["first_cost"] = 30;
  opt.cost_history = {{2.0, 30}, {9.0, 25}};
  results.push_back(opt);
  // Ablation: the cross with full wrench, simulated, holds.
  RunResult sim = Synthetic({"cross", "cross", 0, 0, "ablation"}, "wrap", 0, 1.5, 22);
  sim.spec.motion = sim.spec.sim = true;
  sim.sim_success = true;
  sim.sim_tasks_completed = sim.sim_tasks_total = 22;
  sim.sim_util = {{"transport_2f", 40}, {"insertion_2f", 30}};
  results.push_back(sim);
  // A timeout.
  RunResult t = Synthetic({"chair", "chair", 0, 0, "comparison"}, "flat", 0, 0, 0);
  t.status = Status::kTimeout;
  t.stats.clear();
  t.message = "killed by the harness";
  results.push_back(t);

  RunInfo info{"test machine", "load 0", "abc1234", "2026-01-01", "test"};
  ASSERT_TRUE(WriteReport(results, info, tmp.path()).has_value());
  for (const char* f : {"fig_scaling_robots_cross.svg", "fig_scaling_parts.svg",
                        "fig_convergence_stool.svg"}) {
    EXPECT_TRUE(fs::exists(tmp.path() / f)) << f;
  }
  // No run of the 2x2x3 cube: no empty figure for it.
  EXPECT_FALSE(fs::exists(tmp.path() / "fig_scaling_robots_cube_2x2x3.svg"));
  const std::string md = Slurp(tmp.path() / "report.md");
  EXPECT_NE(md.find("abc1234"), std::string::npos);
  // Mean ± sample std of 1 and 3 s, the paper's 2.01 s and the ratio 2.0 / 2.01.
  EXPECT_NE(md.find("| Cross | Ours (WRAP) | 2/2 | 2.00 ± 1.41 | 2.01 | 0.995 |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| Chair | Flat lazy | 0/1 (timeout 1) | – | OOM |"), std::string::npos);
  EXPECT_NE(md.find("![Cross, two-finger grippers](fig_scaling_robots_cross.svg)"),
            std::string::npos);
  EXPECT_NE(md.find("| no wrench | 0.50 (1 run) [1/1] |"), std::string::npos) << md;
  EXPECT_NE(md.find("| cube_2x2x1 | 4 | 1/1 |"), std::string::npos);
  EXPECT_NE(md.find("| Stool | Ours (WRAP) | 1/1 | 30.0 (1 run) | 25.0 (1 run) |"),
            std::string::npos);
  EXPECT_NE(md.find("| Cross | full | 1/1 | 100 / 100 | 22.0/22.0 / 22/22 | -- / -- | 40 / 25 |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("killed by the harness"), std::string::npos);
  const std::string conv = Slurp(tmp.path() / "fig_convergence_stool.svg");
  EXPECT_NE(conv.find("Ours (WRAP)"), std::string::npos);
  EXPECT_NE(conv.find(" V"), std::string::npos);  // the improvement is a step down
  const std::string html = Slurp(tmp.path() / "report.html");
  EXPECT_NE(html.find("<figure><svg"), std::string::npos);
}

}  // namespace
}  // namespace wrap::bench
