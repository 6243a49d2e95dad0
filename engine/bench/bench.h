// The benchmark harness (paper §V "Experiments"): suites of planner runs, each run in a child
// `wrap` process under a wall-clock and a memory limit, results as files, and the report.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/result.h"

namespace wrap::bench {

/// A project of a suite: an example project, or a variant derived from one (fewer robots, or a
/// prefix of its assembly sequence) that the harness writes into the output folder.
struct ProjectSpec {
  std::string name;   ///< Name in the results, e.g. "cross", "cross_r2", "cube_2x2x1".
  std::string base;   ///< Example project it comes from (file `<projects>/<base>.json`).
  int robots = 0;     ///< Keep the first N robots of the base; 0: all.
  int steps = 0;      ///< Keep the first N steps of the base's sequence (and their parts); 0: all.
  std::string group;  ///< Which part of the report uses it: "comparison", "scaling", ...
};

/// One configuration of a suite: a project, a planner and its options, run once per seed.
struct RunSpec {
  ProjectSpec project;           ///< The project.
  std::string planner = "wrap";  ///< `wrap plan --planner`.
  std::string wrench = "full";   ///< `--wrench full|gravity|none`.
  double force_scale = 1.0;      ///< `--force-scale` lambda.
  bool optimize = false;         ///< `--optimize`.
  /// `--objective`: "actions" (the planner's default: fewest actions) or "makespan" (the task
  /// plan's makespan estimate, so that idle robots get work).
  std::string objective = "actions";
  bool motion = false;         ///< Plan motion too (no `--task-only`).
  bool sim = false;            ///< Then run `wrap sim` on the plan (needs motion).
  std::uint64_t seed = 0;      ///< `--seed`.
  double time_limit_s = 30.0;  ///< `--time-limit` given to the planner [s].
  std::string group;           ///< Report section: comparison, breakdown, scaling_robots,
                               ///< scaling_parts, convergence, ablation, makespan, tiny.

  /// The options as one CSV-safe string, e.g. "wrench=full;lambda=1;task-only". The objective
  /// appears only when it is not "actions", so that the keys of earlier suites stay the same.
  std::string Options() const;
  /// A file-name-safe unique key: project, planner, options, seed.
  std::string Key() const;
};

/// Outcome of a run as the harness classifies it.
enum class Status { kSolved, kUnsolved, kTimeout, kOutOfMemory, kCrash, kError };
/// "solved", "unsolved", "timeout", "oom", "crash", "error".
std::string ToString(Status status);
/// Inverse of ToString; nullopt for an unknown word.
std::optional<Status> ParseStatus(const std::string& word);

/// Equal slices of a plan's makespan over which the robots' motion is profiled.
constexpr int kProfileBins = 20;

/// How busy the robots of a plan with motion are, from its motion segments: a robot is moving
/// while it takes part in a segment (free path, approach, lift, carry, insert, descend, retreat,
/// gripper closing or opening). Holding still (bracing a part another robot inserts) is not
/// moving.
struct Utilisation {
  std::map<std::string, double> moving;  ///< Per robot: the share of the makespan it moves [0, 1].
  /// Robots moving, averaged over each of kProfileBins equal slices of the makespan.
  std::vector<double> profile;
  /// Mean over the robots of their moving share [0, 1].
  double MeanMoving() const;
};

/// What one run gave: the spec's columns, the classification and the plan's stats.
struct RunResult {
  RunSpec spec;                    ///< What was run.
  Status status = Status::kError;  ///< Classification (see RunSuite).
  int exit_code = -1;              ///< Child exit code; -1 when it died of a signal.
  int signal = 0;                  ///< Signal that ended the child, 0 if none.
  double wall_s = 0.0;             ///< Wall time of the plan child [s].
  double peak_rss_mib = 0.0;       ///< Peak resident memory of the plan child (wait4) [MiB].
  double cpu_s = 0.0;              ///< CPU time (user + system) of its children, plan and sim [s].
  double sim_wall_s = 0.0;         ///< Wall time of the sim child [s]; 0 when not simulated.
  /// The plan's stats by name (cost, first_cost, t_init_s, t_grasp_s, t_bwd_s, t_lp_s, t_fwd_s,
  /// t_ik_s, t_kf_s, t_mp_s, t_retime_s, t_opt_s, makespan_s, makespan_sequential_s); absent
  /// where the plan gave none.
  std::map<std::string, double> stats;
  std::vector<std::pair<double, double>> cost_history;  ///< (t [s], cost) after each improvement.
  std::optional<bool> sim_success;  ///< `wrap sim` verdict; absent when not simulated.
  int sim_tasks_completed = 0;      ///< Actions the simulation completed.
  int sim_tasks_total = 0;          ///< Actions of the plan.
  std::string sim_failure;          ///< Failure reason of the simulation, empty if none.
  /// Peak utilisations [%] of the simulation: transport_2f, transport_vac, insertion_2f,
  /// insertion_vac (absent where no gripper of the kind took part).
  std::map<std::string, double> sim_util;
  std::string message;  ///< Why it did not solve (planner failure or the log's last line).
  std::optional<Utilisation> utilisation;  ///< Plans with motion: how busy the robots are.
  /// Threads ready to run on the machine while the plan ran, averaged over samples every 0.1 s
  /// (/proc/loadavg's running count, the harness itself not counted); negative: not measured.
  double load = -1.0;
  int cores = 0;     ///< Cores of the machine it ran on (online CPUs).
  std::string host;  ///< Host name of the machine it ran on.

  bool solved() const { return status == Status::kSolved; }
  /// Made while the machine was loaded: on average at least one thread more was ready to run
  /// than the machine has cores, so the run waited for a core and its times are inflated.
  bool loaded() const { return cores > 0 && load >= cores + 1.0; }
};

/// Where a suite stands, for a progress bar.
struct Progress {
  int done = 0;                       ///< Runs finished (this call's and reused ones).
  int total = 0;                      ///< Runs of this shard.
  int running = 0;                    ///< Children running now.
  std::map<std::string, int> counts;  ///< Finished runs by status word.
  double elapsed_s = 0.0;             ///< Since the suite started [s].
  double eta_s = -1.0;                ///< Estimated time left [s]; negative while unknown.
  std::string last;                   ///< The run that just finished, in words.
};

/// Options of a suite run.
struct BenchOptions {
  std::string suite = "paper";  ///< paper, fabrica, scaling, ablation, makespan, all, smoke, tiny.
  int runs = 3;                 ///< Seeds 0..runs-1 per configuration.
  std::optional<double> time_limit_s;  ///< Planner time limit; absent: each suite's default.
  int jobs = 0;                        ///< Runs at once; 0: the number of cores.
  int shard_index = 1;                 ///< This shard, 1..shard_count.
  int shard_count = 1;                 ///< Number of shards.
  std::filesystem::path projects_dir = "projects";  ///< Where the example projects are.
  std::filesystem::path wrap_exe;                   ///< The `wrap` to run; empty: this executable.
  /// Hard wall-clock limit of a child [s] after which it gets SIGTERM (SIGKILL 2 s later); 0:
  /// the planner's time limit plus max(10 s, half of it). A killed run is a timeout.
  double hard_limit_s = 0.0;
  long long memory_limit_mib = 4096;  ///< Planner memory limit (`--memory-limit`) [MiB]; the
                                      ///< child's address space is limited to 4x this.
  bool keep_plans = false;            ///< Keep every plan JSON (plans/); default: deleted.
  /// Runs made while the machine was loaded (RunResult::loaded) are run again on resumption
  /// instead of being kept (their earlier result stays until the new one replaces it).
  bool rerun_loaded = false;
  /// Called after each finished run (and for runs reused from an earlier, interrupted suite).
  std::function<void(const Progress&)> on_progress;
};

/// The configurations of a named suite in deterministic order (project, planner, options, seed).
/// Fails with kInvalidInput for an unknown suite name.
Result<std::vector<RunSpec>> MakeSuite(const BenchOptions& options);

/// This shard's slice of a suite: every shard_count-th configuration from shard_index-1, so that
/// shards get a mix of sizes.
std::vector<RunSpec> ShardSlice(const std::vector<RunSpec>& specs, int shard_index,
                                int shard_count);

/// The command line of a run's `wrap plan` child: `exe` plans `project_file` into `plan_file`
/// with the spec's planner, seed, limits and options.
std::vector<std::string> PlanArguments(const RunSpec& spec, const BenchOptions& options,
                                       const std::filesystem::path& exe,
                                       const std::filesystem::path& project_file,
                                       const std::filesystem::path& plan_file);

/// The longest a run can take [s]: the plan child's hard limit (BenchOptions::hard_limit_s, or
/// the planner's limit plus max(10 s, half of it)), and four times that for `wrap sim` after it.
double LongestRunS(const RunSpec& spec, const BenchOptions& options);

/// Runs `specs` (this shard's slice, ShardSlice) writing each result to `out/runs/KEY.json` as
/// it finishes (existing ones are kept: a suite resumes), then results.csv, report.md and
/// report.html. The folder belongs to one shard of one suite: it is locked while a process uses
/// it (a second one is refused, naming the first), and its meta.json records the shard's
/// identity (revision of this build, suite, seeds, limits, shard, the suite's runs and the
/// projects' contents); resuming it with another identity is refused, naming what differs.
/// Children run pinned to their own cores where the cores suffice, and die with the harness.
/// Classification: killed by the hard limit -> timeout; exit 0 -> solved; exit 1 -> unsolved, or
/// timeout when the planner stopped at its limit, or oom when it stopped at its memory limit; exit
/// 2 -> error; other exits and signals -> crash (oom when the log shows an allocation failure).
/// Fails with kIo when `out` cannot be written.
Result<std::vector<RunResult>> RunSuite(const std::vector<RunSpec>& specs,
                                        const BenchOptions& options,
                                        const std::filesystem::path& out);

/// Reads every run result under `dirs` (their runs/ folders), in deterministic order; the same
/// key twice keeps the first. Fails with kInvalidInput naming a malformed file.
Result<std::vector<RunResult>> ReadRunResults(const std::vector<std::filesystem::path>& dirs);

/// `wrap bench merge DIR... -o OUT`: the runs of all shard folders into one results.csv and
/// report (run files are copied to OUT/runs). Refused (kInvalidInput, every problem named by
/// folder) when the folders come from different revisions, when folders of one suite differ in
/// settings, when a shard of a suite is missing, given twice or unfinished (unless `partial`:
/// then the report's header says what is missing), when a folder is not a shard folder, or when
/// OUT is one of them.
Result<std::vector<RunResult>> MergeShards(const std::vector<std::filesystem::path>& dirs,
                                           const std::filesystem::path& out, bool partial = false);

/// The plan stats a run keeps (read from the plan file's `stats`), in results.csv's column order.
const std::vector<std::string>& PlanStatKeys();

/// Sorts results by project, planner, options, seed.
void SortResults(std::vector<RunResult>& results);

/// One run result as JSON (the runs/KEY.json files) and back.
std::string RunResultToJson(const RunResult& result);
/// Parses a run result; fails with kInvalidInput naming `source` and the field.
Result<RunResult> RunResultFromJson(const std::string& text, const std::string& source);

/// results.csv: a header and one row per run (RFC 4180 quoting).
std::string ResultsCsv(const std::vector<RunResult>& results);

/// Facts about the run for the report: machine, commit, date, suite options.
struct RunInfo {
  std::string machine;   ///< CPU model, cores, memory.
  std::string load;      ///< Load averages at the start and the end.
  std::string commit;    ///< The build's source revision (BuildRevision), or "unknown".
  std::string date;      ///< UTC date and time of the start.
  std::string settings;  ///< Suite, runs, time limit, jobs, shards.
  std::string caveats;   ///< What the reader must know first (a partial merge), or empty.
};

/// Writes results.csv, report.md, report.html and the SVG figures into `out` (atomically).
Result<void> WriteReport(const std::vector<RunResult>& results, const RunInfo& info,
                         const std::filesystem::path& out);

/// Writes a derived project (robots or steps cut) from `base_file` to `out_file`, mesh paths
/// rewritten relative to the new place. Fails with kInvalidInput naming the base file and field.
Result<void> WriteDerivedProject(const ProjectSpec& spec, const std::filesystem::path& base_file,
                                 const std::filesystem::path& out_file);

}  // namespace wrap::bench
