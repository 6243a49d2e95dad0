#include "task/planner.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <set>

#include "robot/cell.h"
#include "task/keyframes.h"
#include "task/search.h"
#include "task/state.h"
#include "task/world.h"

namespace wrap {
namespace {

using Clock = std::chrono::steady_clock;

std::string ModeName(MatingWrenchMode mode) {
  switch (mode) {
    case MatingWrenchMode::kFull: return "full";
    case MatingWrenchMode::kGravityOnly: return "gravity";
    case MatingWrenchMode::kNone: return "none";
  }
  return "?";
}

}  // namespace

Result<Plan> PlanTask(const Project& project, const ProjectCheck& check, const Preprocessed& pre,
                      const TaskPlannerOptions& options, RunContext& ctx) {
  const auto start = Clock::now();
  if (options.planner != "counting" && options.planner != "wrap" && options.planner != "exact") {
    return Fail(ErrorCode::kInvalidInput,
                "planner: unknown variant '" + options.planner + "' (known: wrap, exact, counting)");
  }
  if (!(options.force_scale >= 0.0) || !std::isfinite(options.force_scale)) {
    return Fail(ErrorCode::kInvalidInput, "planner: --force-scale must be finite and >= 0");
  }
  if (options.max_effort < 0 || options.max_effort > 2 || options.max_holders < 1 ||
      options.max_nodes < 100 || !(options.min_clearance_m >= 0.0)) {
    return Fail(ErrorCode::kInvalidInput, "planner: options out of range");
  }
  auto world_or = BuildTaskWorld(project, check, pre, options.project_file);
  if (!world_or) return std::unexpected(world_or.error());
  const TaskWorld& world = *world_or;
  CellOptions cell_options;
  cell_options.objects_touch_table = false;
  auto cell = Cell::Build(world.cell_def, cell_options);
  if (!cell) return Fail(ErrorCode::kInvalidInput, "planner: " + cell.error().message);

  TaskTables tables;
  TaskCounters counters;
  KeyframeSolver solver(world, tables, options, std::move(*cell), counters);
  const std::uint64_t seed = ctx.rng()();
  const bool widen = options.widen.value_or(project.planner.widen_grasps);
  TaskSearch search(world, tables, solver, options, ctx, seed, widen);

  Plan plan;
  plan.project = project.name;
  for (const Robot& r : project.robots) plan.robots.push_back(r.name);
  for (const Part& p : project.parts) plan.parts.push_back(p.name);
  for (const AssemblyNode& n : world.tree->nodes) plan.nodes.push_back(n.name);

  // The initial state: every part resting at its initial pose, robots at home.
  const int n_robots = static_cast<int>(world.robots.size());
  SymState s0;
  s0.loc.assign(world.num_nodes, kInactive);
  s0.held.assign(n_robots, -1);
  s0.grasp.assign(n_robots, -1);
  ContState c0;
  c0.X_WA.assign(world.num_nodes, Iso3::Identity());
  for (int p = 0; p < world.num_parts; ++p) {
    s0.loc[p] = static_cast<int16_t>(tables.InitialLocation(p, world.initial_X_WA[p]));
    c0.X_WA[p] = world.initial_X_WA[p];
  }
  for (const TaskRobot& r : world.robots) c0.q.push_back(r.home);
  plan.initial.q = c0.q;
  for (int p = 0; p < world.num_parts; ++p) plan.initial.objects.push_back({p, c0.X_WA[p], true});

  // Milestones in the DAG's topological order, with backtracking.
  const std::vector<int>& order = world.tree->step_order;
  plan.milestone_steps = order;
  const int K = static_cast<int>(order.size());
  std::vector<MilestoneResult> results(K);
  std::vector<std::set<std::uint64_t>> excluded(K);
  int k = 0;
  int backtracks = 0;
  std::string failure;
  bool stopped = false;
  while (k < K) {
    ctx.Progress("task", static_cast<double>(k) / std::max(1, K),
                 "milestone " + std::to_string(k + 1) + "/" + std::to_string(K) + " '" +
                     world.tree->nodes[order[k]].name + "'");
    const SymState& s = k == 0 ? s0 : results[k - 1].end;
    const ContState& c = k == 0 ? c0 : results[k - 1].end_c;
    MilestoneResult r =
        search.Fill(k, order[k], k + 1 < K ? order[k + 1] : -1, s, c, excluded[k]);
    if (r.ok) {
      results[k] = std::move(r);
      ++k;
      continue;
    }
    if (r.stopped) {
      stopped = true;
      failure = "milestone " + std::to_string(k + 1) + "/" + std::to_string(K) + " '" +
                world.tree->nodes[order[k]].name + "' was being planned; checks that failed most: " +
                r.failure;
      break;
    }
    failure = r.failure;
    if (std::getenv("WRAP_TASK_DEBUG")) std::fprintf(stderr, "[task] %s\n", failure.c_str());
    if (k > 0 && backtracks < options.max_backtracks) {
      excluded[k - 1].insert(results[k - 1].end.Hash());
      excluded[k].clear();
      --k;
      ++backtracks;
      continue;
    }
    break;
  }
  if (ctx.cancelled()) return Fail(ErrorCode::kCancelled, "planner: cancelled");

  PlanStats& st = plan.stats;
  st.planner = options.planner;
  st.seed = project.planner.seed;
  st.wrench_mode = ModeName(options.wrench_mode);
  st.force_scale = options.force_scale;
  st.grasps = pre.grasps_per_set;
  st.t_grasp_s = pre.times.contains("total") ? pre.times.at("total") : 0.0;
  st.expansions = search.expansions();
  st.validations = counters.validations;
  st.validation_failures = counters.validation_failures;
  st.lp_checks = counters.lp_checks;
  st.ik_calls = counters.ik_calls;
  st.collision_checks = counters.collision_checks;
  st.t_ik_s = counters.t_ik_s;
  st.t_lp_s = counters.t_lp_s;
  // The backward abstraction's own LP and IK questions count in t_lp and t_ik as well.
  st.t_bwd_s = search.backward_seconds();
  st.t_fwd_s = std::max(0.0, search.search_seconds() - st.t_bwd_s - counters.t_ik_s -
                                 counters.t_lp_s);
  st.milestones = K;
  st.backtracks = backtracks;
  st.widenings = search.widenings();
  ctx.AddTime("ik", st.t_ik_s);
  ctx.AddTime("lp", st.t_lp_s);
  ctx.AddTime("fwd", st.t_fwd_s);
  ctx.AddTime("bwd", st.t_bwd_s);
  st.t_init_s = std::chrono::duration<double>(Clock::now() - start).count();
  if (k == K) {
    st.solved = true;
    for (const MilestoneResult& r : results) {
      plan.actions.insert(plan.actions.end(), r.actions.begin(), r.actions.end());
    }
    st.cost = static_cast<int>(plan.actions.size());
  } else {
    st.solved = false;
    if (stopped) {
      failure = (ctx.timed_out() ? "time limit reached while " : "stopped while ") + failure;
    }
    st.failure = failure;
  }
  return plan;
}

}  // namespace wrap
