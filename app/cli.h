// The command-line face of Wrap: one function per subcommand, dispatched by RunCli.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace wrap {
struct LoadedProject;
struct Plan;
struct Preprocessed;
}  // namespace wrap

namespace wrap::cli {

/// Runs `wrap` with `args` (without the program name), printing to `out` and `err`. Returns the
/// process exit code: 0 success, 1 no plan / verification failed, 2 bad input, 3 internal error.
int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// `wrap validate PROJECT [--plan PLAN.json]`: every problem of the project, one per line; with a
/// plan, also replays it with the independent plan validator (its wrench mode and lambda from the
/// plan's stats) and lists every issue. Exit 0 valid (warnings allowed), 1 the plan is not valid,
/// 2 the project or the plan file is bad input or they do not match.
int Validate(const std::string& project, const std::string& plan, bool quiet, std::ostream& out,
             std::ostream& err);

/// Replays `plan` of the loaded project with the independent validator and prints the verdict:
/// the issues to `err`, or a one-line summary to `out`. Returns the exit code (0 valid, 1 not,
/// 2 or 3 when the plan cannot be interpreted).

int ReportPlanValidation(const LoadedProject& loaded, const Plan& plan, const std::string& project,
                         std::ostream& out, std::ostream& err);

/// Checks the trajectories of a plan with motion densely (motion/trajectory_check) and prints the
/// verdict like ReportPlanValidation. `pre`: the project's preprocessing, or null to run it.
int ReportTrajectoryCheck(const LoadedProject& loaded, const Plan& plan, const std::string& project,
                          const Preprocessed* pre, std::ostream& out, std::ostream& err);

/// `wrap info PROJECT`: parts with mass and size, the DAG as a tree, robots and end effectors.
int Info(const std::string& project, std::ostream& out, std::ostream& err);

/// Arguments of `wrap new`.
struct NewArgs {
  std::vector<std::string> meshes;  ///< Mesh files or folders.
  std::string output;               ///< Project file to write.
  std::string unit = "auto";        ///< auto, mm, cm or m.
  int robots = 4;                   ///< Robots around the table.
  std::string robot_model = "ur5e";
  std::string end_effector = "robotiq_2f85";
  double force_N = 10.0;            ///< Mating force [N].
  std::string name;                 ///< Project name.
};

/// `wrap new MESH... -o PROJECT`: writes the project (atomically) and prints each decision.
/// 0 written; 1 no sequence or layout; 2 bad input.
int NewCommand(const NewArgs& args, std::ostream& out, std::ostream& err);

/// Arguments of `wrap suggest`.
struct SuggestArgs {
  std::string project;  ///< Project file.
  bool apply = false;   ///< Write the edited project.
  std::string output;   ///< Where.
};

/// `wrap suggest PROJECT [--apply -o OUT]`: prints the proposed edits; with --apply writes the
/// edited project to OUT (atomically; the input only when OUT names it). 0 when nothing needs
/// fixing or the edits were written, 1 when edits are proposed and not applied, 2 bad input.
int SuggestCommand(const SuggestArgs& args, std::ostream& out, std::ostream& err);

/// Arguments of `wrap preprocess`.
struct PreprocessArgs {
  std::string project;                ///< Project file.
  std::string output;                 ///< JSON file to write (atomically); empty: none.
  int grasps = 0;                     ///< Grasp-set size; 0: the project's planner.grasps.
  int slots = -1;                     ///< Table slots; negative: the default.
  std::optional<std::uint64_t> seed;  ///< Random seed; absent: the project's planner.seed.
};

/// `wrap preprocess PROJECT [-o FILE.json]`: per subassembly its parts, stable placements and
/// grasps per end effector, the table slots, and timings; exit 0, 2 bad input, 3 internal.
int Preprocess(const PreprocessArgs& args, std::ostream& out, std::ostream& err);

/// Arguments of `wrap plan`.
struct PlanArgs {
  std::string project;                ///< Project file.
  std::string output;                 ///< -o PLAN.json (atomic); empty: not written.
  std::optional<std::uint64_t> seed;  ///< --seed; absent: the project's planner.seed.
  std::optional<double> time_limit;   ///< --time-limit [s]; absent: the project's.
  double budget = 1.0;                ///< --budget: scale of the motion searches' work budgets.
  std::string wrench = "full";        ///< --wrench full|gravity|none.
  double force_scale = 1.0;           ///< --force-scale lambda.
  std::string planner = "wrap";       ///< --planner variant.
  bool optimize = false;              ///< --optimize: improve the plan until the time limit.
  std::string objective = "actions";  ///< --objective actions|makespan: what --optimize lowers.
  long long memory_limit_mb = 4096;   ///< --memory-limit [MiB].
  int grasps = 0;                     ///< --grasps; 0: the project's planner.grasps.
  bool validate = false;              ///< --validate with the independent validator.
  bool task_only = false;             ///< --task-only.
  bool no_keyframe_opt = false;       ///< --no-keyframe-opt.
  std::string dump_refused;           ///< --dump-refused DIR; empty: none.
};

/// `wrap plan PROJECT [-o PLAN.json] ...`: preprocesses, plans, prints the actions in words and
/// writes the plan JSON; exit 0 solved (and valid with --validate), 1 no plan within the limits
/// or validation failed, 2 bad input, 3 internal error.
int PlanCommand(const PlanArgs& args, std::ostream& out, std::ostream& err);

/// Arguments of `wrap render`.
struct RenderArgs {
  std::string project;           ///< Project file.
  std::string output;            ///< -o DIR: folder for the PNGs (created if missing).
  std::string plan;              ///< --plan PLAN.json; empty: none (initial scene and goal).
  int frames = -1;               ///< --frames N along the plan's keyframes; -1: not given.
  std::string at;                ///< --at K1,K2,... keyframe indices of the plan; empty: none.
  std::string size = "960x720";  ///< --size WIDTHxHEIGHT [px].
  std::string camera;            ///< --camera AZ,EL[,DIST] [deg, deg, m]; empty: automatic.
  std::string backend = "egl";   ///< --backend egl|osmesa.
  bool goal = false;             ///< --goal: only the goal (no initial scene).
  double explode = 0.0;          ///< --explode F: also the goal exploded by F (0: not).
  std::string video;             ///< --video FILE.mp4 through ffmpeg; empty: none.
  bool no_shadows = false;       ///< --no-shadows.
};

/// `wrap render PROJECT -o DIR`: PNGs of the initial scene and the assembled goal (and the
/// exploded goal), or with --plan of the plan's keyframes, a captioned contact sheet and
/// optionally a video; exit 0, 2 bad input (bad option, unwritable folder, GL backend or ffmpeg
/// unavailable, invalid project, a plan that is malformed or for another project), 3 internal.
int Render(const RenderArgs& args, std::ostream& out, std::ostream& err);

/// Arguments of `wrap sim`.
struct SimArgs {
  std::string project;       ///< Project file.
  std::string plan;          ///< --plan PLAN.json (with motion).
  std::string output;        ///< -o REPORT.json (atomic); empty: not written.
  std::string video;         ///< --video FILE.mp4: the simulated run drawn and encoded (ffmpeg).
  double force_scale = 1.0;  ///< --force-scale lambda on the applied mating wrench.
  std::string mjcf_dir;      ///< --mjcf DIR: also write the physics model there.
};

/// `wrap sim PROJECT --plan PLAN [-o REPORT.json] [--video FILE.mp4]`: runs the plan in MuJoCo
/// (paper V-B; a plan without motion replays its keyframes) and reports whether it holds, the
/// grippers' peak utilisations and the failure, optionally recording the run as a video; exit 0
/// holds, 1 fails, 2 bad input (also: no renderer or ffmpeg for --video, said before the run),
/// 3 internal (a MuJoCo error).
int Sim(const SimArgs& args, std::ostream& out, std::ostream& err);

/// Arguments of `wrap bench` and `wrap bench merge`.
struct BenchArgs {
  std::string suite = "paper";           ///< --suite paper|fabrica|scaling|ablation|all|smoke|tiny.
  int runs = 3;                          ///< --runs: seeds per configuration.
  std::optional<double> time_limit_s;    ///< --time-limit [s]; absent: the suite's default.
  int jobs = 0;                          ///< --jobs; 0: the number of cores.
  std::string shard;                     ///< --shard I/N; empty: the whole suite.
  std::string output;                    ///< -o DIR (created).
  std::string projects = "projects";     ///< --projects DIR of the example projects.
  double hard_limit_s = 0.0;             ///< --hard-limit [s] per child; 0: automatic.
  long long memory_limit_mib = 4096;     ///< --memory-limit [MiB] of each planner run.
  bool keep_plans = false;               ///< --keep-plans.
  bool rerun_loaded = false;             ///< --rerun-loaded.
  bool dry_run = false;                  ///< --dry-run: list the shard's runs, run nothing.
  std::vector<std::string> merge_dirs;   ///< `bench merge DIR...`; empty: run a suite.
  bool partial = false;                  ///< `bench merge --partial`.
};

/// `wrap bench --suite S -o DIR`: runs the suite's planner runs in child processes (time and
/// memory limits; timeouts, out-of-memory and crashes recorded), writes runs/, results.csv,
/// report.md and report.html; `wrap bench merge DIR... -o OUT` combines shards (refusing shards
/// that do not belong together). Exit 0, 1 interrupted (resume by running again), 2 bad input
/// (also: a folder in use, or of another shard or setting), 3 internal.
int Bench(const BenchArgs& args, std::ostream& out, std::ostream& err);

/// Arguments of the GUI (`wrap` without a subcommand).
struct GuiArgs {
  std::string project;       ///< PROJECT to open; empty: a new project.
  std::string screenshot;    ///< --screenshot FILE.png: draw a few frames, save, exit.
  bool run_plan = false;     ///< --run-plan: plan before the screenshot.
  std::optional<double> at;  ///< --at T: timeline time of the screenshot [s].
  std::string size;          ///< --size WIDTHxHEIGHT of the window; empty: 1600x960.
  std::string script;        ///< --script FILE: UI commands to run, then exit.
};

/// `wrap [PROJECT]`: opens the GUI (or, with --screenshot or --script, runs it headless under
/// X/Xvfb and exits); exit 0, 1 no plan (--run-plan) or a failed script line, 2 bad input or
/// no display, 3 internal.
int Gui(const GuiArgs& args, std::ostream& out, std::ostream& err);

}  // namespace wrap::cli
