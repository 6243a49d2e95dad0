// RunCli: the `wrap` command line parsed with CLI11. Each subcommand is a small struct holding
// the arguments CLI11 fills, registered by its Add() (options in the order `--help` lists them)
// and run by its Run(); the GUI's options sit on the top-level command.
#include "cli.h"

#include <CLI/CLI.hpp>

#include <cstdint>
#include <initializer_list>
#include <ostream>

#include "core/log.h"
#include "load.h"

namespace wrap::cli {

namespace {

constexpr const char* kAbout =
    "Wrap: fixtureless wrench-aware multi-robot assembly planning (WRAP).\n"
    "Exit codes: 0 success, 1 no plan found / verification failed, 2 bad input, 3 internal "
    "error.";

/// `wrap validate PROJECT [-q] [--plan PLAN]`.
struct ValidateCli {
  CLI::App* cmd = nullptr;
  std::string project;
  bool quiet = false;
  std::string plan;

  void Add(CLI::App& app) {
    cmd = app.add_subcommand("validate",
                             "Check a project file: every problem with file, JSON path and reason");
    cmd->add_option("PROJECT", project, "Project file (.json)")->required();
    cmd->add_flag("-q,--quiet", quiet, "Print errors only, not warnings or the summary");
    cmd->add_option(
        "--plan", plan,
        "Also replay this plan (JSON) with the independent plan validator (and, for a plan "
        "with motion, the trajectory check)");
  }
  int Run(std::ostream& out, std::ostream& err) const {
    return Validate(project, plan, quiet, out, err);
  }
};

/// `wrap info PROJECT`.
struct InfoCli {
  CLI::App* cmd = nullptr;
  std::string project;

  void Add(CLI::App& app) {
    cmd = app.add_subcommand(
        "info", "Describe a project: parts, the assembly DAG, robots and end effectors");
    cmd->add_option("PROJECT", project, "Project file (.json)")->required();
  }
  int Run(std::ostream& out, std::ostream& err) const { return Info(project, out, err); }
};

/// `wrap preprocess PROJECT ...`.
struct PreprocessCli {
  CLI::App* cmd = nullptr;
  PreprocessArgs args;
  std::uint64_t seed = 0;
  CLI::Option* seed_option = nullptr;  ///< Whether --seed was given (else the project's).

  void Add(CLI::App& app) {
    cmd = app.add_subcommand(
        "preprocess", "Subassemblies, stable placements, table slots and grasp sets (paper IV-B)");
    cmd->add_option("PROJECT", args.project, "Project file (.json)")->required();
    cmd->add_option("-o,--output", args.output, "Write the result as JSON to this file");
    cmd->add_option("--grasps", args.grasps, "Grasp-set size (default: the project's)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--slots", args.slots, "Number of table slots")->check(CLI::NonNegativeNumber);
    seed_option = cmd->add_option("--seed", seed, "Random seed (default: the project's)");
  }
  int Run(std::ostream& out, std::ostream& err) {
    if (seed_option->count() > 0) args.seed = seed;
    return Preprocess(args, out, err);
  }
};

/// `wrap render PROJECT -o DIR ...`.
struct RenderCli {
  CLI::App* cmd = nullptr;
  RenderArgs args;

  void Add(CLI::App& app) {
    cmd = app.add_subcommand(
        "render",
        "Draw the cell offscreen: PNGs of the initial scene and the goal, or of a plan's "
        "keyframes, and a contact sheet");
    cmd->add_option("PROJECT", args.project, "Project file (.json)")->required();
    cmd->add_option("-o,--output", args.output, "Folder for the images (created)")->required();
    cmd->add_option("--plan", args.plan,
                    "Plan file (.json): draw its keyframes (plan_KKK_TYPE.png) instead of the "
                    "initial scene and goal");
    CLI::Option* frames = cmd->add_option(
        "--frames", args.frames,
        "With --plan: N frames (frame_NNN.png) evenly along the keyframes, frame k showing "
        "keyframe round(k*(K-1)/(N-1)) (keyframe index = time until plans are retimed)");
    cmd->add_option("--at", args.at,
                    "With --plan: keyframe indices to draw, e.g. 0,3,7 (0 = initial; "
                    "frame_NNN.png)")
        ->excludes(frames);
    cmd->add_option("--size", args.size, "Image size WIDTHxHEIGHT [px] (default 960x720)");
    cmd->add_option("--camera", args.camera, "AZIMUTH,ELEVATION[,DISTANCE] [deg, deg, m]");
    cmd->add_option("--backend", args.backend, "Offscreen GL: egl (default) or osmesa");
    cmd->add_flag("--goal", args.goal, "Only the assembled goal, not the initial scene");
    cmd->add_option("--explode", args.explode,
                    "Also the goal exploded along the insertion axes by F times its size");
    cmd->add_option("--video", args.video, "Also encode the frames as an MP4 (needs ffmpeg)");
    cmd->add_flag("--no-shadows", args.no_shadows, "Draw without shadows (faster)");
  }
  int Run(std::ostream& out, std::ostream& err) const { return Render(args, out, err); }
};

/// `wrap plan PROJECT ...`.
struct PlanCli {
  CLI::App* cmd = nullptr;
  PlanArgs args;
  std::uint64_t seed = 0;
  double time_limit = 0.0;
  CLI::Option* seed_option = nullptr;  ///< Whether --seed was given (else the project's).
  CLI::Option* time_option = nullptr;  ///< Whether --time-limit was given (else the project's).

  void Add(CLI::App& app) {
    cmd = app.add_subcommand(
        "plan",
        "Plan the assembly: a validated multi-robot action plan with keyframes (paper IV-D)");
    cmd->add_option("PROJECT", args.project, "Project file (.json)")->required();
    cmd->add_option("-o,--output", args.output, "Write the plan JSON to this file (atomic)");
    seed_option = cmd->add_option("--seed", seed, "Random seed (default: the project's)");
    time_option = cmd->add_option("--time-limit", time_limit,
                                  "Time limit in seconds (default: the project's)");
    cmd->add_option("--budget", args.budget,
                    "Scale of the work budgets of the motion searches (default 1): collision "
                    "checks per path search, poses per carry search. The budgets, not the "
                    "machine's speed, decide the plan; --time-limit is an outer wall-clock bound")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--wrench", args.wrench,
                    "Wrench model: full (default), gravity (gravity only) or none");
    cmd->add_option("--force-scale", args.force_scale,
                    "Scale lambda on the mating force and torque (default 1)");
    cmd->add_option("--planner", args.planner,
                    "Planner variant (the paper's comparison rows): wrap (default: backward "
                    "abstract heuristic), optimistic (assembly grasps chosen first), flat (Flat "
                    "lazy: no milestones), counting (Milestones + counting), exact (wrap with "
                    "weight-one A* fills), fine (wrap, finer projection)");
    cmd->add_flag("--optimize", args.optimize,
                  "After the first plan, improve it (large neighbourhood search) until the time "
                  "limit or until no window of milestones gives a cheaper plan");
    cmd->add_option("--objective", args.objective,
                    "What --optimize minimises: actions (default: the number of actions) or "
                    "makespan (the task plan's makespan estimate, a few more actions allowed)");
    cmd->add_option("--memory-limit", args.memory_limit_mb,
                    "Memory the search may hold, in MiB (default 4096); beyond it the run stops "
                    "with \"out of memory\"")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--grasps", args.grasps, "Grasp-set size (default: the project's)")
        ->check(CLI::PositiveNumber);
    cmd->add_flag("--validate", args.validate,
                  "Replay the plan with the independent validator; exit 1 if it fails");
    cmd->add_flag("--no-keyframe-opt", args.no_keyframe_opt,
                  "Skip the joint keyframe optimisation (the task plan's keyframes go to motion "
                  "as planned; the plan changes)");
    cmd->add_option("--dump-refused", args.dump_refused,
                    "Debugging: save every timed result the planner's own trajectory check "
                    "refuses into this folder (refused_N.json)");
    cmd->add_flag("--task-only", args.task_only,
                  "Stop after the task plan: no keyframe optimisation, motion planning or "
                  "retiming");
  }
  int Run(std::ostream& out, std::ostream& err) {
    if (seed_option->count() > 0) args.seed = seed;
    if (time_option->count() > 0) args.time_limit = time_limit;
    return PlanCommand(args, out, err);
  }
};

/// `wrap sim PROJECT --plan PLAN ...`.
struct SimCli {
  CLI::App* cmd = nullptr;
  SimArgs args;

  void Add(CLI::App& app) {
    cmd = app.add_subcommand(
        "sim", "Run a plan in MuJoCo: does it hold, gripper utilisation, failure (paper V-B)");
    cmd->add_option("PROJECT", args.project, "Project file (.json)")->required();
    cmd->add_option("--plan", args.plan,
                    "Plan file (.json); without motion its keyframes are replayed")
        ->required();
    cmd->add_option("-o,--output", args.output, "Write the report JSON to this file (atomic)");
    cmd->add_option("--video", args.video,
                    "Record the simulated run as an MP4 (offscreen renderer, needs ffmpeg)");
    cmd->add_option("--force-scale", args.force_scale,
                    "Scale lambda on the applied mating wrench (default 1)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--mjcf", args.mjcf_dir,
                    "Also write the physics model (cell.xml + meshes) to this folder");
  }
  int Run(std::ostream& out, std::ostream& err) const { return Sim(args, out, err); }
};

/// `wrap bench ...` and `wrap bench merge DIR... -o OUT`.
struct BenchCli {
  CLI::App* cmd = nullptr;
  CLI::App* merge = nullptr;
  BenchArgs args;
  double time_limit = 0.0;
  CLI::Option* time_option = nullptr;  ///< Whether --time-limit was given (else the suite's).
  std::string merge_output;            ///< `merge -o`: becomes the output folder.

  void Add(CLI::App& app) {
    cmd = app.add_subcommand(
        "bench",
        "Benchmark suites (paper V): planner runs in child processes with time and memory "
        "limits, results.csv and a report with the paper's tables and figures");
    cmd->add_option("--suite", args.suite,
                    "paper (comparison, breakdown, convergence on cross, stool, chair), "
                    "fabrica, scaling (robots, wrench models, parts), ablation (wrench models "
                    "simulated), makespan (plans with motion by default and with --optimize "
                    "--objective makespan: makespan against one segment at a time), all, smoke "
                    "(every section once, small, on the cross: minutes) or tiny (the test "
                    "suite's)");
    cmd->add_option("--runs", args.runs, "Seeds per configuration (default 3)")
        ->check(CLI::PositiveNumber);
    time_option =
        cmd->add_option("--time-limit", time_limit, "Planner time limit [s] (default: the suite's)")
            ->check(CLI::PositiveNumber);
    cmd->add_option("--jobs", args.jobs, "Runs at once (default: the number of cores)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--shard", args.shard,
                    "Run the I-th of N slices of the suite, e.g. 3/8 (combine with 'merge')");
    cmd->add_option("-o,--output", args.output, "Output folder (created; a rerun resumes)");
    cmd->add_option("--projects", args.projects,
                    "Folder of the example projects (default: projects)");
    cmd->add_option("--hard-limit", args.hard_limit_s,
                    "Wall-clock limit of each child [s] after which it is killed and recorded "
                    "as a timeout (default: time limit + max(10 s, half of it))")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--memory-limit", args.memory_limit_mib,
                    "Planner memory limit [MiB] (default 4096); the child's address space is "
                    "limited to 4x this")
        ->check(CLI::PositiveNumber);
    cmd->add_flag("--keep-plans", args.keep_plans, "Keep every plan JSON under plans/");
    cmd->add_flag("--rerun-loaded", args.rerun_loaded,
                  "Resuming: run again the runs made while the machine was loaded (more "
                  "threads ready to run than cores; marked in the report)");
    cmd->add_flag("--dry-run", args.dry_run,
                  "Only list this shard's runs and the longest it can take; run nothing");
    merge = cmd->add_subcommand(
        "merge",
        "Combine the results of shard folders into one results.csv and report; refuses folders "
        "of different revisions or settings, and missing or unfinished shards");
    merge->add_option("DIR", args.merge_dirs, "Shard output folders")->required();
    merge->add_option("-o,--output", merge_output, "Output folder")->required();
    merge->add_flag("--partial", args.partial,
                    "Merge although shards are missing or unfinished (the report says which)");
  }
  int Run(std::ostream& out, std::ostream& err) {
    if (time_option->count() > 0) args.time_limit_s = time_limit;
    if (merge->parsed()) args.output = merge_output;
    return Bench(args, out, err);
  }
};

/// `wrap new MESH... -o PROJECT ...`.
struct NewCli {
  CLI::App* cmd = nullptr;
  NewArgs args;

  void Add(CLI::App& app) {
    cmd = app.add_subcommand(
        "new",
        "Make a project from an assembly's meshes (one file per part, in assembled "
        "positions): the DAG, axes, roles, robots and an initial layout from the geometry");
    cmd->add_option("MESH", args.meshes, "Mesh files, or folders of them")->required();
    cmd->add_option("-o,--output", args.output, "Project file to write (.json)")->required();
    cmd->add_option("--unit", args.unit, "Unit of the mesh files: auto, mm, cm or m")
        ->default_val("auto");
    cmd->add_option("--robots", args.robots, "Robots around the table")->default_val(4);
    cmd->add_option("--robot-model", args.robot_model, "Catalog robot model")->default_val("ur5e");
    cmd->add_option("--end-effector", args.end_effector, "Catalog end effector")
        ->default_val("robotiq_2f85");
    cmd->add_option("--force", args.force_N, "Mating force of every step [N]")->default_val(10.0);
    cmd->add_option("--name", args.name, "Project name (default: the output's stem)");
  }
  int Run(std::ostream& out, std::ostream& err) const { return NewCommand(args, out, err); }
};

/// `wrap suggest PROJECT [--apply -o OUT]`.
struct SuggestCli {
  CLI::App* cmd = nullptr;
  SuggestArgs args;

  void Add(CLI::App& app) {
    cmd = app.add_subcommand(
        "suggest",
        "Check a project against its meshes and propose fixes (free axes, roles, "
        "order, initial poses); --apply writes them");
    cmd->add_option("PROJECT", args.project, "Project file (.json)")->required();
    cmd->add_flag("--apply", args.apply, "Write the edited project (needs -o)");
    cmd->add_option("-o,--output", args.output, "Where --apply writes");
  }
  int Run(std::ostream& out, std::ostream& err) const { return SuggestCommand(args, out, err); }
};

/// No subcommand: the GUI, optionally on a project, with its headless hooks (options of the
/// top-level command).
struct GuiCli {
  GuiArgs args;
  double at = 0.0;
  CLI::Option* at_option = nullptr;  ///< Whether --at was given.

  void Add(CLI::App& app) {
    app.add_option("PROJECT", args.project, "Project to open in the GUI (no subcommand)");
    app.add_option("--screenshot", args.screenshot,
                   "GUI: draw a few frames, save the whole window as this PNG and exit");
    app.add_flag("--run-plan", args.run_plan, "GUI with --screenshot: plan first");
    at_option = app.add_option("--at", at, "GUI with --screenshot: the timeline's time [s]");
    app.add_option("--size", args.size, "GUI window size WIDTHxHEIGHT [px] (default 1600x960)");
    app.add_option("--script", args.script,
                   "GUI: run this file of UI commands (select, set, add-edge, run, scrub, save, "
                   "...) and exit");
  }
  int Run(std::ostream& out, std::ostream& err) {
    if (at_option->count() > 0) args.at = at;
    return Gui(args, out, err);
  }
};

/// The log: every subcommand that plans or simulates takes --log (or WRAP_LOG) into `spec`.
void AddLogOption(std::initializer_list<CLI::App*> commands, std::string& spec) {
  std::string help =
      "Log these topics to stderr, comma-separated, each optionally :trace "
      "(also from WRAP_LOG): all";
  for (const LogTopic& t : KnownLogTopics()) help += ", " + std::string(t.name);
  for (CLI::App* a : commands) a->add_option("--log", spec, help)->envname("WRAP_LOG");
}

}  // namespace

int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  CLI::App app{kAbout, "wrap"};
  app.set_version_flag("--version", std::string("wrap ") + WRAP_VERSION);
  app.require_subcommand(0, 1);

  // Registered in the order `wrap --help` lists them.
  ValidateCli validate;
  InfoCli info;
  PreprocessCli preprocess;
  RenderCli render;
  PlanCli plan;
  SimCli sim;
  BenchCli bench;
  NewCli new_cmd;
  SuggestCli suggest;
  GuiCli gui;
  validate.Add(app);
  info.Add(app);
  preprocess.Add(app);
  render.Add(app);
  plan.Add(app);
  sim.Add(app);
  bench.Add(app);
  new_cmd.Add(app);
  suggest.Add(app);
  gui.Add(app);
  std::string log_spec;
  AddLogOption({preprocess.cmd, plan.cmd, sim.cmd}, log_spec);

  // CLI11 takes arguments in reverse order.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    // --help and --version arrive here as "errors" with exit code 0.
    const int code = app.exit(e, out, err);
    return code == 0 ? 0 : 2;
  }
  if (!SetLogTopics(log_spec, err)) return 2;
  if (validate.cmd->parsed()) return validate.Run(out, err);
  if (info.cmd->parsed()) return info.Run(out, err);
  if (preprocess.cmd->parsed()) return preprocess.Run(out, err);
  if (render.cmd->parsed()) return render.Run(out, err);
  if (new_cmd.cmd->parsed()) return new_cmd.Run(out, err);
  if (suggest.cmd->parsed()) return suggest.Run(out, err);
  if (sim.cmd->parsed()) return sim.Run(out, err);
  if (bench.cmd->parsed()) return bench.Run(out, err);
  if (plan.cmd->parsed()) return plan.Run(out, err);
  return gui.Run(out, err);
}

}  // namespace wrap::cli
