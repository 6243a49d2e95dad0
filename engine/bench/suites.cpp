// The named suites (paper §V) and the derived projects of the scaling study.
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>

#include "bench/bench.h"
#include "core/file_io.h"

namespace wrap::bench {

namespace {

// The paper's comparison rows (Table "comparison"), in its order.
const std::vector<std::string> kPlanners = {"optimistic", "wrap",  "flat",
                                            "counting",   "exact", "fine"};
// The scaling figure's wrench models: no wrench, gravity only, then lambda on the mating force.
const std::vector<double> kLambdas = {0.0, 0.01, 0.1, 0.5, 1.0, 2.0};

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

ProjectSpec Example(const std::string& name, const std::string& group) {
  return ProjectSpec{name, name, 0, 0, group};
}

// Adds one configuration for every seed.
void AddSeeds(std::vector<RunSpec>& out, RunSpec spec, int runs) {
  for (int s = 0; s < runs; ++s) {
    spec.seed = static_cast<std::uint64_t>(s);
    out.push_back(spec);
  }
}

RunSpec Spec(const ProjectSpec& project, const std::string& planner, const std::string& group,
             double time_limit_s) {
  RunSpec spec;
  spec.project = project;
  spec.planner = planner;
  spec.group = group;
  spec.time_limit_s = time_limit_s;
  return spec;
}

// Table "comparison" (every planner, task plans only) and the breakdown (WRAP with motion, for
// t_mp; then simulated, for Wrap's own measures: makespan, robot utilisation, simulation success
// per assembly) on the given projects.
void ComparisonAndBreakdown(std::vector<RunSpec>& out, const std::vector<std::string>& projects,
                            int runs, double task_limit, double motion_limit) {
  for (const std::string& p : projects) {
    for (const std::string& planner : kPlanners) {
      AddSeeds(out, Spec(Example(p, "comparison"), planner, "comparison", task_limit), runs);
    }
    RunSpec motion = Spec(Example(p, "breakdown"), "wrap", "breakdown", motion_limit);
    motion.motion = true;
    motion.sim = true;
    AddSeeds(out, motion, runs);
  }
}

void PaperSuite(std::vector<RunSpec>& out, int runs, double task_limit, double motion_limit) {
  ComparisonAndBreakdown(out, {"cross", "stool", "chair"}, runs, task_limit, motion_limit);
  // Convergence figure: cost over time of --optimize runs, every planner (the paper's legend).
  for (const std::string p : {"cross", "stool", "chair"}) {
    for (const std::string& planner : kPlanners) {
      RunSpec spec = Spec(Example(p, "convergence"), planner, "convergence", task_limit);
      spec.optimize = true;
      AddSeeds(out, spec, runs);
    }
  }
}

void FabricaSuite(std::vector<RunSpec>& out, int runs, double task_limit, double motion_limit) {
  ComparisonAndBreakdown(out,
                         {"fabrica_beam", "fabrica_plumbers_block", "fabrica_car",
                          "fabrica_gamepad", "fabrica_cooling_manifold"},
                         runs, task_limit, motion_limit);
}

void ScalingSuite(std::vector<RunSpec>& out, int runs, double limit) {
  // Robots: the cross (two-finger) and the 2x2x3 cube (vacuum) with 2, 3 and 4 robots, under no
  // wrench, gravity only and every lambda.
  for (const std::string base : {"cross", "cube_2x2x3"}) {
    for (int robots : {2, 3, 4}) {
      ProjectSpec project{robots == 4 ? base : base + "_r" + std::to_string(robots), base,
                          robots == 4 ? 0 : robots, 0, "scaling_robots"};
      for (const std::string wrench : {"none", "gravity"}) {
        RunSpec spec = Spec(project, "wrap", "scaling_robots", limit);
        spec.wrench = wrench;
        AddSeeds(out, spec, runs);
      }
      for (double lambda : kLambdas) {
        RunSpec spec = Spec(project, "wrap", "scaling_robots", limit);
        spec.force_scale = lambda;
        AddSeeds(out, spec, runs);
      }
    }
  }
  // Parts: prefixes of the 2x2x3 cube's sequence (4, 8, 12 cubes) and of the cross (1-6 arms).
  for (int cubes : {4, 6, 8, 10, 12}) {
    const std::string name = cubes == 12      ? "cube_2x2x3"
                             : cubes % 4 == 0 ? "cube_2x2x" + std::to_string(cubes / 4)
                                              : "cube_2x2x3_p" + std::to_string(cubes);
    ProjectSpec project{name, "cube_2x2x3", 0, cubes == 12 ? 0 : cubes - 1, "scaling_parts"};
    AddSeeds(out, Spec(project, "wrap", "scaling_parts", limit), runs);
  }
  for (int arms = 1; arms <= 6; ++arms) {
    ProjectSpec project{arms == 6 ? "cross" : "cross_arms" + std::to_string(arms), "cross", 0,
                        arms == 6 ? 0 : arms, "scaling_parts"};
    AddSeeds(out, Spec(project, "wrap", "scaling_parts", limit), runs);
  }
}

// Table "wrench_sim": plans with motion under each wrench model, then run in MuJoCo (the full
// model's runs on the cross and the chair are the breakdown's: same options, run once).
void AblationSuite(std::vector<RunSpec>& out, int runs, double limit) {
  for (const std::string p : {"cross", "cube", "chair"}) {
    for (const std::string wrench : {"none", "gravity", "full"}) {
      RunSpec spec = Spec(Example(p, "ablation"), "wrap", "ablation", limit);
      spec.wrench = wrench;
      spec.motion = true;
      spec.sim = true;
      AddSeeds(out, spec, runs);
    }
  }
}

// Every section of the report from one seed of small configurations of each study, on the
// cross (a few minutes on one core): to check a build or a cluster set-up before a long study.
void SmokeSuite(std::vector<RunSpec>& out, int runs, double task_limit, double motion_limit) {
  const ProjectSpec cross = Example("cross", "comparison");
  for (const std::string& planner : kPlanners) {
    AddSeeds(out, Spec(cross, planner, "comparison", task_limit), runs);
  }
  for (const std::string wrench : {"none", "full"}) {
    RunSpec spec = Spec(Example("cross", "ablation"), "wrap", "ablation", motion_limit);
    spec.wrench = wrench;
    spec.motion = spec.sim = true;
    AddSeeds(out, spec, runs);
  }
  for (int robots : {2, 3}) {
    for (const std::string wrench : {"none", "full"}) {
      RunSpec spec =
          Spec({"cross_r" + std::to_string(robots), "cross", robots, 0, "scaling_robots"}, "wrap",
               "scaling_robots", task_limit);
      spec.wrench = wrench;
      AddSeeds(out, spec, runs);
    }
  }
  RunSpec none = Spec(cross, "wrap", "scaling_robots", task_limit);
  none.wrench = "none";
  AddSeeds(out, none, runs);
  for (int arms : {1, 3}) {
    AddSeeds(out,
             Spec({"cross_arms" + std::to_string(arms), "cross", 0, arms, "scaling_parts"}, "wrap",
                  "scaling_parts", task_limit),
             runs);
  }
  for (const std::string planner : {"wrap", "counting"}) {
    RunSpec spec = Spec(Example("cross", "convergence"), planner, "convergence", task_limit);
    spec.optimize = true;
    AddSeeds(out, spec, runs);
  }
}

// Issue 33, cycle time: the plans with motion of every seed as planned by default, with
// `--objective makespan` (the estimate breaks the search's ties) and with `--optimize --objective
// makespan`, for makespan_s / makespan_sequential_s side by side. The projects of BENCHMARKS.md's
// issue-33 motion table but the cube, whose makespan plans all failed motion there. `--optimize`
// shares the time limit with motion, so a run whose improvements take most of it can end
// without motion (the chair's seed 0 at 60 s); the tie-breaking row has no such cost.
void MakespanSuite(std::vector<RunSpec>& out, int runs, double limit) {
  for (const std::string p :
       {"cross", "stool", "chair", "fabrica_beam", "fabrica_plumbers_block"}) {
    RunSpec plain = Spec(Example(p, "makespan"), "wrap", "makespan", limit);
    plain.motion = true;
    AddSeeds(out, plain, runs);
    RunSpec ties = plain;
    ties.objective = "makespan";
    AddSeeds(out, ties, runs);
    RunSpec shortest = plain;
    shortest.optimize = true;
    shortest.objective = "makespan";
    AddSeeds(out, shortest, runs);
  }
}

}  // namespace

std::string RunSpec::Options() const {
  std::string s = "wrench=" + wrench;
  if (wrench == "full") s += ";lambda=" + Num(force_scale);
  if (optimize) s += ";optimize";
  if (objective != "actions") s += ";objective=" + objective;
  s += motion ? ";motion" : ";task-only";
  if (sim) s += ";sim";
  s += ";limit=" + Num(time_limit_s);
  return s;
}

std::string RunSpec::Key() const {
  std::string key = project.name + "__" + planner + "__" + Options() + "__s" + std::to_string(seed);
  for (char& c : key) {
    if (c == ';' || c == '=' || c == ' ' || c == '/') c = '_';
  }
  return key;
}

std::string ToString(Status status) {
  switch (status) {
    case Status::kSolved:
      return "solved";
    case Status::kUnsolved:
      return "unsolved";
    case Status::kTimeout:
      return "timeout";
    case Status::kOutOfMemory:
      return "oom";
    case Status::kCrash:
      return "crash";
    case Status::kError:
      return "error";
  }
  return "error";
}

std::optional<Status> ParseStatus(const std::string& word) {
  for (Status s : {Status::kSolved, Status::kUnsolved, Status::kTimeout, Status::kOutOfMemory,
                   Status::kCrash, Status::kError}) {
    if (ToString(s) == word) return s;
  }
  return std::nullopt;
}

void SortResults(std::vector<RunResult>& results) {
  std::stable_sort(results.begin(), results.end(), [](const RunResult& a, const RunResult& b) {
    const auto ka = std::tie(a.spec.project.name, a.spec.planner);
    const auto kb = std::tie(b.spec.project.name, b.spec.planner);
    if (ka != kb) return ka < kb;
    const std::string oa = a.spec.Options(), ob = b.spec.Options();
    if (oa != ob) return oa < ob;
    return a.spec.seed < b.spec.seed;
  });
}

Result<std::vector<RunSpec>> MakeSuite(const BenchOptions& options) {
  if (options.runs < 1) return Fail(ErrorCode::kInvalidInput, "--runs: must be at least 1");
  const std::set<std::string> known = {"paper",    "fabrica", "scaling", "ablation",
                                       "makespan", "all",     "tiny",    "smoke"};
  if (!known.contains(options.suite)) {
    return Fail(ErrorCode::kInvalidInput,
                "--suite: unknown suite '" + options.suite +
                    "' (expected paper, fabrica, scaling, ablation, makespan, all, smoke or tiny)");
  }
  const auto limit = [&](double fallback) { return options.time_limit_s.value_or(fallback); };
  std::vector<RunSpec> specs;
  const std::string& s = options.suite;
  if (s == "tiny") {
    // The test suite's run: one small project, two planners, short limits.
    for (const std::string planner : {"counting", "wrap"}) {
      AddSeeds(specs, Spec(Example("cross", "comparison"), planner, "comparison", limit(10)),
               options.runs);
    }
  }
  // Task plans get 30 s; plans with motion (then simulated) 60 s.
  if (s == "smoke") SmokeSuite(specs, options.runs, limit(10), limit(60));
  if (s == "paper" || s == "all") PaperSuite(specs, options.runs, limit(30), limit(60));
  if (s == "fabrica" || s == "all") FabricaSuite(specs, options.runs, limit(30), limit(60));
  if (s == "scaling" || s == "all") ScalingSuite(specs, options.runs, limit(30));
  if (s == "ablation" || s == "all") AblationSuite(specs, options.runs, limit(60));
  if (s == "makespan" || s == "all") MakespanSuite(specs, options.runs, limit(60));
  // Deterministic order, so that the i-th of N shards is the same slice on every machine.
  std::stable_sort(specs.begin(), specs.end(), [](const RunSpec& a, const RunSpec& b) {
    const auto ka = std::tie(a.project.name, a.planner);
    const auto kb = std::tie(b.project.name, b.planner);
    if (ka != kb) return ka < kb;
    const std::string oa = a.Options(), ob = b.Options();
    if (oa != ob) return oa < ob;
    return a.seed < b.seed;
  });
  // A configuration that two parts of the report share (e.g. WRAP on the cross) runs once.
  std::set<std::string> keys;
  std::erase_if(specs, [&](const RunSpec& spec) { return !keys.insert(spec.Key()).second; });
  return specs;
}

Result<void> WriteDerivedProject(const ProjectSpec& spec, const std::filesystem::path& base_file,
                                 const std::filesystem::path& out_file) {
  namespace fs = std::filesystem;
  using Json = nlohmann::ordered_json;
  const std::string where = base_file.string();
  auto text = ReadFile(base_file);
  if (!text) return std::unexpected(text.error());
  Json j = Json::parse(*text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    return Fail(ErrorCode::kInvalidInput, where + ": not a JSON object");
  }
  j["name"] = spec.name;
  j["description"] =
      "Derived by `wrap bench` from '" + spec.base + "'" +
      (spec.robots > 0 ? ": its first " + std::to_string(spec.robots) + " robots" : "") +
      (spec.steps > 0 ? ": its first " + std::to_string(spec.steps) + " steps and their parts"
                      : "");
  if (spec.robots > 0) {
    if (!j.contains("robots") || !j["robots"].is_array() ||
        static_cast<int>(j["robots"].size()) < spec.robots) {
      return Fail(ErrorCode::kInvalidInput, where + ": robots: fewer than " +
                                                std::to_string(spec.robots) + " robots to keep");
    }
    j["robots"].erase(j["robots"].begin() + spec.robots, j["robots"].end());
  }
  if (spec.steps > 0) {
    if (!j.contains("steps") || !j["steps"].is_array() ||
        static_cast<int>(j["steps"].size()) < spec.steps) {
      return Fail(ErrorCode::kInvalidInput,
                  where + ": steps: fewer than " + std::to_string(spec.steps) + " steps to keep");
    }
    j["steps"].erase(j["steps"].begin() + spec.steps, j["steps"].end());
    // A prefix of a sequence: the parts that its steps join, directly or through earlier steps.
    std::set<std::string> names;
    for (const Json& step : j["steps"]) {
      if (!step.contains("inputs") || !step["inputs"].is_array()) {
        return Fail(ErrorCode::kInvalidInput, where + ": steps: a step without inputs");
      }
      for (const Json& in : step["inputs"]) names.insert(in.get<std::string>());
    }
    Json parts = Json::array();
    for (const Json& part : j["parts"]) {
      if (names.contains(part.value("name", ""))) parts.push_back(part);
    }
    j["parts"] = parts;
  }
  // Paths inside a project are relative to its file: re-anchor them at the new file.
  const fs::path base_dir = fs::absolute(base_file).parent_path();
  const fs::path out_dir = fs::absolute(out_file).parent_path();
  const auto rebase = [&](Json& v) {
    if (!v.is_string()) return;
    const std::string p = v.get<std::string>();
    if (p.empty() || p.starts_with("${") || fs::path(p).is_absolute()) return;
    v = fs::relative(fs::weakly_canonical(base_dir / p), fs::weakly_canonical(out_dir))
            .generic_string();
  };
  for (Json& part : j["parts"]) {
    if (part.contains("mesh")) rebase(part["mesh"]);
  }
  if (j.contains("paths") && j["paths"].is_object()) {
    for (auto& [name, var] : j["paths"].items()) {
      if (var.is_object() && var.contains("default")) rebase(var["default"]);
    }
  }
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  return WriteFileAtomic(out_file, j.dump(2) + "\n");
}

}  // namespace wrap::bench
