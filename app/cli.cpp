#include "cli.h"

#include <CLI/CLI.hpp>

#include "core/log.h"
#include "load.h"
#include <cstdint>
#include <ostream>

namespace wrap::cli {

namespace {

constexpr const char* kAbout =
    "Wrap: fixtureless wrench-aware multi-robot assembly planning (WRAP).\n"
    "Exit codes: 0 success, 1 no plan found / verification failed, 2 bad input, 3 internal "
    "error.";

}  // namespace

int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  CLI::App app{kAbout, "wrap"};
  app.set_version_flag("--version", std::string("wrap ") + WRAP_VERSION);
  app.require_subcommand(0, 1);

  std::string project;
  bool quiet = false;
  CLI::App* validate = app.add_subcommand(
      "validate", "Check a project file: every problem with file, JSON path and reason");
  validate->add_option("PROJECT", project, "Project file (.json)")->required();
  validate->add_flag("-q,--quiet", quiet, "Print errors only, not warnings or the summary");
  std::string validate_plan;
  validate->add_option(
      "--plan", validate_plan,
      "Also replay this plan (JSON) with the independent plan validator (and, for a plan "
      "with motion, the trajectory check)");

  CLI::App* info = app.add_subcommand(
      "info", "Describe a project: parts, the assembly DAG, robots and end effectors");
  info->add_option("PROJECT", project, "Project file (.json)")->required();

  PreprocessArgs pre;
  std::uint64_t seed = 0;
  CLI::App* preprocess = app.add_subcommand(
      "preprocess", "Subassemblies, stable placements, table slots and grasp sets (paper IV-B)");
  preprocess->add_option("PROJECT", pre.project, "Project file (.json)")->required();
  preprocess->add_option("-o,--output", pre.output, "Write the result as JSON to this file");
  preprocess->add_option("--grasps", pre.grasps, "Grasp-set size (default: the project's)")
      ->check(CLI::PositiveNumber);
  preprocess->add_option("--slots", pre.slots, "Number of table slots")
      ->check(CLI::NonNegativeNumber);
  CLI::Option* seed_option =
      preprocess->add_option("--seed", seed, "Random seed (default: the project's)");

  RenderArgs ren;
  CLI::App* render = app.add_subcommand(
      "render",
      "Draw the cell offscreen: PNGs of the initial scene and the goal, or of a plan's keyframes, "
      "and a contact sheet");
  render->add_option("PROJECT", ren.project, "Project file (.json)")->required();
  render->add_option("-o,--output", ren.output, "Folder for the images (created)")->required();
  render->add_option("--plan", ren.plan,
                     "Plan file (.json): draw its keyframes (plan_KKK_TYPE.png) instead of the "
                     "initial scene and goal");
  CLI::Option* frames = render->add_option(
      "--frames", ren.frames,
      "With --plan: N frames (frame_NNN.png) evenly along the keyframes, frame k showing "
      "keyframe round(k*(K-1)/(N-1)) (keyframe index = time until plans are retimed)");
  render
      ->add_option("--at", ren.at,
                   "With --plan: keyframe indices to draw, e.g. 0,3,7 (0 = initial; "
                   "frame_NNN.png)")
      ->excludes(frames);
  render->add_option("--size", ren.size, "Image size WIDTHxHEIGHT [px] (default 960x720)");
  render->add_option("--camera", ren.camera, "AZIMUTH,ELEVATION[,DISTANCE] [deg, deg, m]");
  render->add_option("--backend", ren.backend, "Offscreen GL: egl (default) or osmesa");
  render->add_flag("--goal", ren.goal, "Only the assembled goal, not the initial scene");
  render->add_option("--explode", ren.explode,
                     "Also the goal exploded along the insertion axes by F times its size");
  render->add_option("--video", ren.video, "Also encode the frames as an MP4 (needs ffmpeg)");
  render->add_flag("--no-shadows", ren.no_shadows, "Draw without shadows (faster)");

  PlanArgs plan_args;
  std::uint64_t plan_seed = 0;
  double plan_time_limit = 0.0;
  CLI::App* plan = app.add_subcommand(
      "plan", "Plan the assembly: a validated multi-robot action plan with keyframes (paper IV-D)");
  plan->add_option("PROJECT", plan_args.project, "Project file (.json)")->required();
  plan->add_option("-o,--output", plan_args.output, "Write the plan JSON to this file (atomic)");
  CLI::Option* plan_seed_option =
      plan->add_option("--seed", plan_seed, "Random seed (default: the project's)");
  CLI::Option* plan_time_option = plan->add_option(
      "--time-limit", plan_time_limit, "Time limit in seconds (default: the project's)");
  plan->add_option("--budget", plan_args.budget,
                   "Scale of the work budgets of the motion searches (default 1): collision "
                   "checks per path search, poses per carry search. The budgets, not the "
                   "machine's speed, decide the plan; --time-limit is an outer wall-clock bound")
      ->check(CLI::PositiveNumber);
  plan->add_option("--wrench", plan_args.wrench,
                   "Wrench model: full (default), gravity (gravity only) or none");
  plan->add_option("--force-scale", plan_args.force_scale,
                   "Scale lambda on the mating force and torque (default 1)");
  plan->add_option("--planner", plan_args.planner,
                   "Planner variant (the paper's comparison rows): wrap (default: backward "
                   "abstract heuristic), optimistic (assembly grasps chosen first), flat (Flat "
                   "lazy: no milestones), counting (Milestones + counting), exact (wrap with "
                   "weight-one A* fills), fine (wrap, finer projection)");
  plan->add_flag("--optimize", plan_args.optimize,
                 "After the first plan, improve it (large neighbourhood search) until the time "
                 "limit or until no window of milestones gives a cheaper plan");
  plan->add_option("--memory-limit", plan_args.memory_limit_mb,
                   "Memory the search may hold, in MiB (default 4096); beyond it the run stops "
                   "with \"out of memory\"")
      ->check(CLI::PositiveNumber);
  plan->add_option("--grasps", plan_args.grasps, "Grasp-set size (default: the project's)")
      ->check(CLI::PositiveNumber);
  plan->add_flag("--validate", plan_args.validate,
                 "Replay the plan with the independent validator; exit 1 if it fails");
  plan->add_flag("--no-keyframe-opt", plan_args.no_keyframe_opt,
                 "Skip the joint keyframe optimisation (the task plan's keyframes go to motion "
                 "as planned; the plan changes)");
  plan->add_option("--dump-refused", plan_args.dump_refused,
                   "Debugging: save every timed result the planner's own trajectory check "
                   "refuses into this folder (refused_N.json)");
  plan->add_flag("--task-only", plan_args.task_only,
                 "Stop after the task plan: no keyframe optimisation, motion planning or "
                 "retiming");

  SimArgs sim_args;
  CLI::App* sim = app.add_subcommand(
      "sim", "Run a plan in MuJoCo: does it hold, gripper utilisation, failure (paper V-B)");
  sim->add_option("PROJECT", sim_args.project, "Project file (.json)")->required();
  sim->add_option("--plan", sim_args.plan,
                  "Plan file (.json); without motion its keyframes are replayed")
      ->required();
  sim->add_option("-o,--output", sim_args.output, "Write the report JSON to this file (atomic)");
  sim->add_option("--video", sim_args.video,
                  "Record the simulated run as an MP4 (offscreen renderer, needs ffmpeg)");
  sim->add_option("--force-scale", sim_args.force_scale,
                  "Scale lambda on the applied mating wrench (default 1)")
      ->check(CLI::NonNegativeNumber);
  sim->add_option("--mjcf", sim_args.mjcf_dir,
                  "Also write the physics model (cell.xml + meshes) to this folder");

  BenchArgs bench_args;
  double bench_time_limit = 0.0;
  CLI::App* bench = app.add_subcommand(
      "bench",
      "Benchmark suites (paper V): planner runs in child processes with time and memory limits, "
      "results.csv and a report with the paper's tables and figures");
  bench->add_option("--suite", bench_args.suite,
                    "paper (comparison, breakdown, convergence on cross, stool, chair), fabrica, "
                    "scaling (robots, wrench models, parts), ablation (wrench models simulated), "
                    "all, smoke (every section once, small, on the cross: minutes) or tiny (the "
                    "test suite's)");
  bench->add_option("--runs", bench_args.runs, "Seeds per configuration (default 3)")
      ->check(CLI::PositiveNumber);
  CLI::Option* bench_time_option = bench->add_option(
      "--time-limit", bench_time_limit, "Planner time limit [s] (default: the suite's)")
      ->check(CLI::PositiveNumber);
  bench->add_option("--jobs", bench_args.jobs, "Runs at once (default: the number of cores)")
      ->check(CLI::PositiveNumber);
  bench->add_option("--shard", bench_args.shard,
                    "Run the I-th of N slices of the suite, e.g. 3/8 (combine with 'merge')");
  bench->add_option("-o,--output", bench_args.output, "Output folder (created; a rerun resumes)");
  bench->add_option("--projects", bench_args.projects,
                    "Folder of the example projects (default: projects)");
  bench->add_option("--hard-limit", bench_args.hard_limit_s,
                    "Wall-clock limit of each child [s] after which it is killed and recorded as "
                    "a timeout (default: time limit + max(10 s, half of it))")
      ->check(CLI::PositiveNumber);
  bench->add_option("--memory-limit", bench_args.memory_limit_mib,
                    "Planner memory limit [MiB] (default 4096); the child's address space is "
                    "limited to 4x this")
      ->check(CLI::PositiveNumber);
  bench->add_flag("--keep-plans", bench_args.keep_plans, "Keep every plan JSON under plans/");
  bench->add_flag("--rerun-loaded", bench_args.rerun_loaded,
                  "Resuming: run again the runs made while the machine was loaded (more threads "
                  "ready to run than cores; marked in the report)");
  bench->add_flag("--dry-run", bench_args.dry_run,
                  "Only list this shard's runs and the longest it can take; run nothing");
  CLI::App* bench_merge = bench->add_subcommand(
      "merge",
      "Combine the results of shard folders into one results.csv and report; refuses folders "
      "of different revisions or settings, and missing or unfinished shards");
  bench_merge->add_option("DIR", bench_args.merge_dirs, "Shard output folders")->required();
  std::string merge_output;
  bench_merge->add_option("-o,--output", merge_output, "Output folder")->required();
  bench_merge->add_flag("--partial", bench_args.partial,
                        "Merge although shards are missing or unfinished (the report says which)");

  NewArgs new_args;
  CLI::App* new_cmd = app.add_subcommand(
      "new", "Make a project from an assembly's meshes (one file per part, in assembled "
             "positions): the DAG, axes, roles, robots and an initial layout from the geometry");
  new_cmd->add_option("MESH", new_args.meshes, "Mesh files, or folders of them")->required();
  new_cmd->add_option("-o,--output", new_args.output, "Project file to write (.json)")->required();
  new_cmd->add_option("--unit", new_args.unit, "Unit of the mesh files: auto, mm, cm or m")
      ->default_val("auto");
  new_cmd->add_option("--robots", new_args.robots, "Robots around the table")->default_val(4);
  new_cmd->add_option("--robot-model", new_args.robot_model, "Catalog robot model")
      ->default_val("ur5e");
  new_cmd->add_option("--end-effector", new_args.end_effector, "Catalog end effector")
      ->default_val("robotiq_2f85");
  new_cmd->add_option("--force", new_args.force_N, "Mating force of every step [N]")
      ->default_val(10.0);
  new_cmd->add_option("--name", new_args.name, "Project name (default: the output's stem)");

  SuggestArgs suggest_args;
  CLI::App* suggest = app.add_subcommand(
      "suggest", "Check a project against its meshes and propose fixes (free axes, roles, "
                 "order, initial poses); --apply writes them");
  suggest->add_option("PROJECT", suggest_args.project, "Project file (.json)")->required();
  suggest->add_flag("--apply", suggest_args.apply, "Write the edited project (needs -o)");
  suggest->add_option("-o,--output", suggest_args.output, "Where --apply writes");

  // No subcommand: the GUI, optionally on a project, with its headless hooks.
  GuiArgs gui;
  double gui_at = 0.0;
  app.add_option("PROJECT", gui.project, "Project to open in the GUI (no subcommand)");
  app.add_option("--screenshot", gui.screenshot,
                 "GUI: draw a few frames, save the whole window as this PNG and exit");
  app.add_flag("--run-plan", gui.run_plan, "GUI with --screenshot: plan first");
  CLI::Option* gui_at_option =
      app.add_option("--at", gui_at, "GUI with --screenshot: the timeline's time [s]");
  app.add_option("--size", gui.size, "GUI window size WIDTHxHEIGHT [px] (default 1600x960)");
  app.add_option("--script", gui.script,
                 "GUI: run this file of UI commands (select, set, add-edge, run, scrub, save, "
                 "...) and exit");

  // The log: every subcommand that plans or simulates takes --log (or WRAP_LOG).
  std::string log_spec;
  std::string log_help = "Log these topics to stderr, comma-separated, each optionally :trace "
                         "(also from WRAP_LOG): all";
  for (const LogTopic& t : KnownLogTopics()) log_help += ", " + std::string(t.name);
  for (CLI::App* a : {preprocess, plan, sim}) {
    a->add_option("--log", log_spec, log_help)->envname("WRAP_LOG");
  }

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
  if (validate->parsed()) return Validate(project, validate_plan, quiet, out, err);
  if (info->parsed()) return Info(project, out, err);
  if (preprocess->parsed()) {
    if (seed_option->count() > 0) pre.seed = seed;
    return Preprocess(pre, out, err);
  }
  if (render->parsed()) return Render(ren, out, err);
  if (new_cmd->parsed()) return NewCommand(new_args, out, err);
  if (suggest->parsed()) return SuggestCommand(suggest_args, out, err);
  if (sim->parsed()) return Sim(sim_args, out, err);
  if (bench->parsed()) {
    if (bench_time_option->count() > 0) bench_args.time_limit_s = bench_time_limit;
    if (bench_merge->parsed()) bench_args.output = merge_output;
    return Bench(bench_args, out, err);
  }
  if (plan->parsed()) {
    if (plan_seed_option->count() > 0) plan_args.seed = plan_seed;
    if (plan_time_option->count() > 0) plan_args.time_limit = plan_time_limit;
    return PlanCommand(plan_args, out, err);
  }
  if (gui_at_option->count() > 0) gui.at = gui_at;
  return Gui(gui, out, err);
}

}  // namespace wrap::cli
