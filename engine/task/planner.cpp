// The task planner's front door (planner.h): PlanTask checks the insertion paths and its options,
// builds the search's rig and fills the milestones in the DAG's order (with backtracking), then
// improves the plan while time is left; UnpickableAtStart asks the same rig which parts no robot
// can take where they start.
#include "task/planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>
#include <set>

#include "mating/check.h"
#include "robot/cell.h"
#include "task/keyframes.h"
#include "task/search.h"
#include "task/state.h"
#include "task/world.h"

namespace wrap {
namespace {

using Clock = std::chrono::steady_clock;

// The task stage's failure record of milestone `milestone` (step node `step`; -1 for flat).
PlanFailure MilestoneFailure(int milestone, int step, MilestoneResult& r) {
  PlanFailure f;
  f.stage = "task";
  f.milestone = milestone;
  f.step = step;
  f.start = std::move(r.start);
  f.cases = std::move(r.cases);
  return f;
}

std::string ModeName(MatingWrenchMode mode) {
  switch (mode) {
    case MatingWrenchMode::kFull:
      return "full";
    case MatingWrenchMode::kGravityOnly:
      return "gravity";
    case MatingWrenchMode::kNone:
      return "none";
  }
  return "?";
}

// Plan improvement: edge validation failures before a window's (or a refill's) search gives up:
// a neighbourhood that costs much validation is left for the next one.
constexpr int kWindowFailures = 60;
// ... and search nodes per milestone of the window.
constexpr long long kWindowNodes = 40000;

// --objective makespan: actions a plan may have beyond the first plan's when its makespan
// estimate is shorter (a handover that lets two robots work at once may pay for itself).
constexpr int kMakespanExtraActions = 2;

int CostOf(const std::vector<MilestoneResult>& results, int from, int to) {
  int cost = 0;
  for (int j = from; j < to; ++j) cost += static_cast<int>(results[j].actions.size());
  return cost;
}

// The makespan estimate's clock after milestones [0, to) of `results`.
TaskClock ClockOf(const std::vector<MilestoneResult>& results, int to, const TaskClock& start) {
  TaskClock clock = start;
  for (int j = 0; j < to; ++j) {
    for (const PlanAction& a : results[j].actions) clock.Advance(a);
  }
  return clock;
}

// Whether a plan of `cost` actions and makespan estimate `makespan_s` replaces the incumbent's
// (`best_cost`, `best_makespan_s`) under `objective`; `max_cost`: the most actions allowed.
bool Better(PlanObjective objective, int cost, double makespan_s, int best_cost,
            double best_makespan_s, int max_cost) {
  if (objective == PlanObjective::kActions) return cost < best_cost;
  constexpr double kSame = 1e-3;  // [s]
  if (cost > max_cost) return false;
  if (makespan_s < best_makespan_s - kSame) return true;
  return makespan_s <= best_makespan_s + kSame && cost < best_cost;
}

// Plan improvement (paper §IV-D, "anytime"): a large neighbourhood search over the milestones of
// the incumbent. A window of n milestones is refilled by one weight-one lazy A* search over its
// n milestones bounded by the window's cost (one milestone: the variant's heuristic; more: the
// counting heuristic over the window), the milestones after it are refilled by the variant's
// own fills (or kept, when the window ends in the incumbent's state) bounded so that the whole
// plan is strictly cheaper; a cheaper plan replaces the incumbent. n grows from 1 to the whole
// horizon; the search stops early at the time limit or on cancellation. Returns false when it
// was stopped.
bool Improve(TaskSearch& search, const std::vector<int>& order, const SymState& s0,
             const ContState& c0, const TaskClock& t0, PlanObjective objective,
             std::vector<MilestoneResult>& incumbent, RunContext& ctx,
             const Clock::time_point start, std::vector<std::pair<double, int>>& history) {
  const int K = static_cast<int>(order.size());
  int cost = CostOf(incumbent, 0, K);
  double makespan_s = ClockOf(incumbent, K, t0).makespan_s();
  // The most actions a plan may have: fewer than the incumbent's (actions), or the first plan's
  // and a few more (makespan).
  const bool by_makespan = objective == PlanObjective::kMakespan;
  const int max_cost = by_makespan ? cost + kMakespanExtraActions : cost;
  const bool debug = ctx.Logs("task");
  for (int n = 1; n <= K; ++n) {
    for (int i = 0; i + n <= K; ++i) {
      if (ctx.ShouldStop()) return false;
      const int window_cost = CostOf(incumbent, i, i + n);
      // The rest: strictly cheaper (actions), or within the bound (makespan).
      const int budget = (by_makespan ? max_cost : cost - 1) - CostOf(incumbent, 0, i);
      std::vector<MilestoneResult> candidate(incumbent.begin(), incumbent.begin() + i);
      SymState s = i == 0 ? s0 : incumbent[i - 1].end;
      ContState c = i == 0 ? c0 : incumbent[i - 1].end_c;
      TaskClock t = i == 0 ? t0 : incumbent[i - 1].end_clock;
      // The window: one weight-one search over its n milestones, no longer than before
      // (actions), or within the bound (makespan).
      FillLimits window;
      window.weight = 1;
      window.max_failures = kWindowFailures;
      window.max_nodes = kWindowNodes;
      window.max_cost = std::min(by_makespan ? window_cost + kMakespanExtraActions : window_cost,
                                 budget - (K - i - n));
      if (window.max_cost < n) continue;
      const int next = i + n < K ? order[i + n] : -1;
      MilestoneResult w =
          n == 1 ? search.Fill(i, order[i], next, s, c, t, {}, window)
                 : search.FillWindow(i, std::vector<int>(order.begin() + i, order.begin() + i + n),
                                     next, s, c, t, window);
      if (debug) {
        ctx.Log("task",
                StrFormat("improve: window %d+%d (cost %d, bound %d): %s %zu at %.2f s", i, n,
                          window_cost, window.max_cost, w.ok ? "found" : "none", w.actions.size(),
                          std::chrono::duration<double>(Clock::now() - start).count()));
      }
      if (w.stopped || w.out_of_memory) return false;
      if (!w.ok) continue;
      int running = static_cast<int>(w.actions.size());
      s = w.end;
      c = w.end_c;
      // The window's actions fill candidate milestones i .. i+n-1 (by their milestone index).
      // (A milestone ends with its last action; the window's last one with the window.)
      for (int j = i; j < i + n; ++j) candidate.emplace_back().ok = true;
      for (size_t x = 0; x < w.actions.size(); ++x) {
        const int j = std::clamp(w.actions[x].milestone, i, i + n - 1);
        w.actions[x].milestone = j;
        t.Advance(w.actions[x]);
        candidate[j].actions.push_back(std::move(w.actions[x]));
        candidate[j].end = w.after[x].first;
        candidate[j].end_c = w.after[x].second;
      }
      bool ok = true;
      for (int j = i + n; j < K && ok; ++j) {
        if (s == incumbent[j - 1].end &&
            c.Fingerprint(s) == incumbent[j - 1].end_c.Fingerprint(s)) {
          // The window ends where the incumbent's did: the rest holds as it is (its clocks
          // are made again below).
          for (int x = j; x < K; ++x) candidate.push_back(incumbent[x]);
          running += CostOf(incumbent, j, K);
          break;
        }
        FillLimits limits;
        limits.max_failures = kWindowFailures;
        limits.max_nodes = kWindowNodes;
        limits.max_cost = budget - running - (K - j - 1);  // later milestones take >= 1 each
        if (limits.max_cost < 1) {
          ok = false;
          break;
        }
        MilestoneResult r =
            search.Fill(j, order[j], j + 1 < K ? order[j + 1] : -1, s, c, t, {}, limits);
        if (r.stopped || r.out_of_memory) return false;
        if (!r.ok) {
          ok = false;
          break;
        }
        running += static_cast<int>(r.actions.size());
        s = r.end;
        c = r.end_c;
        t = r.end_clock;
        candidate.push_back(std::move(r));
      }
      if (!ok || static_cast<int>(candidate.size()) != K) continue;
      // The clocks of the milestones kept from the incumbent follow the window's.
      TaskClock clock = t0;
      for (MilestoneResult& r : candidate) {
        for (const PlanAction& a : r.actions) clock.Advance(a);
        r.end_clock = clock;
      }
      const int candidate_cost = CostOf(candidate, 0, K);
      if (Better(objective, candidate_cost, clock.makespan_s(), cost, makespan_s, max_cost)) {
        incumbent = std::move(candidate);
        cost = candidate_cost;
        makespan_s = clock.makespan_s();
        const double at = std::chrono::duration<double>(Clock::now() - start).count();
        history.push_back({at, cost});
        if (debug) {
          ctx.Log("task", StrFormat("improve: window %d+%d: cost %d, makespan estimate %.1f s at "
                                    "%.2f s",
                                    i, n, cost, makespan_s, at));
        }
      }
    }
  }
  return true;
}

// Each step's moved input swept along its axis into its mating pose against the base input's
// meshes (geometry's sweep, every symmetric final pose); a blocked path fails as bad input.
Result<void> CheckInsertionPaths(const Project& project, const ProjectCheck& check) {
  if (!check.tree) return {};
  AssemblyGeometry geometry = AssemblyGeometry::FromProject(project, check);
  for (int s = 0; s < static_cast<int>(project.steps.size()); ++s) {
    const Mating& m = project.steps[s].mating;
    if (check.tree->Find(m.moved) < 0 || check.tree->Find(m.base) < 0) continue;
    const int poses = std::max<int>(1, static_cast<int>(m.final_poses.size()));
    for (int k = 0; k < poses; ++k) {
      const InsertionPath path =
          StepInsertionPath(project, *check.tree, s, m.final_poses.empty() ? -1 : k);
      const PathHit hit = SweepInsertion(geometry, path);
      if (!hit.blocked) continue;
      return Fail(ErrorCode::kInvalidInput,
                  "planner: step '" + project.steps[s].name + "': part '" +
                      geometry.name(hit.moved_part) + "' of the moved input cuts into part '" +
                      geometry.name(hit.base_part) + "' " + FormatMm(hit.at_m) +
                      " before its mating pose along " + FormatDirection(m.axis.normalized()) +
                      " (wrap validate lists the free directions)");
    }
  }
  return {};
}

// PlanTask's options out of range.
Result<void> CheckOptions(const TaskPlannerOptions& options) {
  if (!(options.force_scale >= 0.0) || !std::isfinite(options.force_scale)) {
    return Fail(ErrorCode::kInvalidInput, "planner: --force-scale must be finite and >= 0");
  }
  if (options.max_effort < 0 || options.max_effort > 2 || options.max_holders < 1 ||
      options.max_nodes < 100 || !(options.skills.robot_clearance_m >= 0.0) ||
      options.memory_limit_mb < 1) {
    return Fail(ErrorCode::kInvalidInput, "planner: options out of range");
  }
  return {};
}

// The initial state: every part resting at its initial pose, robots at home; the plan gets the
// names of robots, parts and nodes and the initial cell.
void StartTask(const Project& project, const TaskWorld& world, TaskTables& tables, SymState& s0,
               ContState& c0, Plan& plan) {
  plan.project = project.name;
  for (const Robot& r : project.robots) plan.robots.push_back(r.name);
  for (const Part& p : project.parts) plan.parts.push_back(p.name);
  for (const AssemblyNode& n : world.tree->nodes) plan.nodes.push_back(n.name);

  const int n_robots = static_cast<int>(world.robots.size());
  s0.loc.assign(world.num_nodes, kInactive);
  s0.held.assign(n_robots, -1);
  s0.grasp.assign(n_robots, -1);
  c0.X_WA.assign(world.num_nodes, Iso3::Identity());
  for (int p = 0; p < world.num_parts; ++p) {
    s0.loc[p] = static_cast<int16_t>(tables.InitialLocation(p, world.initial_X_WA[p]));
    c0.X_WA[p] = world.initial_X_WA[p];
  }
  for (const TaskRobot& r : world.robots) c0.q.push_back(r.home);
  plan.initial.q = c0.q;
  for (int p = 0; p < world.num_parts; ++p) plan.initial.objects.push_back({p, c0.X_WA[p], true});
}

// What the task search runs on, for one project: its world, the tables the search fills, the
// keyframe solver on the world's cell and the solver's counters. The solver holds references to
// the others, so a rig does not move (BuildRig makes it on the heap).
struct SearchRig {
  TaskWorld world;
  TaskTables tables;
  TaskCounters counters;
  std::optional<KeyframeSolver> solver;
};

// The rig of `project`. The solver's cell checks the objects against the table as well
// (CellOptions::objects_touch_table = false).
Result<std::unique_ptr<SearchRig>> BuildRig(const Project& project, const ProjectCheck& check,
                                            const Preprocessed& pre,
                                            const TaskPlannerOptions& options) {
  auto world = BuildTaskWorld(project, check, pre, options.project_file);
  if (!world) return std::unexpected(world.error());
  auto rig = std::make_unique<SearchRig>();
  rig->world = std::move(*world);
  CellOptions cell_options;
  cell_options.objects_touch_table = false;
  auto cell = Cell::Build(rig->world.cell_def, cell_options);
  if (!cell) return Fail(ErrorCode::kInvalidInput, "planner: " + cell.error().message);
  rig->solver.emplace(rig->world, rig->tables, options, std::move(*cell), rig->counters);
  return rig;
}

// Where the milestone loop ended.
struct MilestoneRun {
  std::vector<MilestoneResult> results;  ///< Per milestone (Flat lazy: one for the whole task).
  int reached = 0;             ///< Milestones filled in a row from the start; K when solved.
  int backtracks = 0;          ///< Milestone re-plans.
  std::string failure;         ///< Why not solved, in words.
  PlanFailure detail;          ///< The failure as data, following `failure`.
  bool stopped = false;        ///< Cancelled or out of time.
  bool out_of_memory = false;  ///< Stopped by the memory limit.
};

// Fewest expansions a backtracking probe may take at each of its two milestones.
constexpr long long kProbeMinExpansions = 2000;

// Milestone k's first resolution level found nothing from the end of milestone k - 1 though it
// searched its whole graph: that end may be a dead end that only the wider levels' exhaustive
// search would prove (the stool's seed 1: a robot that cannot back away from the seat it holds,
// 183k expansions). Before widening, probe once: another end of milestone k - 1 and milestone k
// from it, each at the first level only. Keeps both and returns true when both are found;
// otherwise leaves `results` and `excluded_before` as they were (the caller widens from the old
// end). A probe stopped by cancellation or memory returns false; the widening then stops too.
template <typename FillFn>
bool ProbeAnotherEnd(FillFn& fill, int k, long long budget,
                     std::set<std::uint64_t>& excluded_before,
                     std::vector<MilestoneResult>& results, RunContext& ctx) {
  const std::uint64_t old_end = results[k - 1].end.Hash();
  const bool added = excluded_before.insert(old_end).second;
  FillLimits probe;
  probe.first_level_only = true;
  probe.level_expansions = budget;
  MilestoneResult before = fill(k - 1, probe);
  if (before.ok) {
    MilestoneResult old = std::move(results[k - 1]);
    results[k - 1] = std::move(before);
    MilestoneResult after = fill(k, probe);
    if (after.ok) {
      ctx.Log("task", "milestone " + std::to_string(k) +
                          ": the probe of another end of the milestone before it found a plan");
      results[k] = std::move(after);
      return true;
    }
    results[k - 1] = std::move(old);
  }
  if (added) excluded_before.erase(old_end);
  return false;
}

// The milestones in the DAG's topological order `order` from (s0, c0), with backtracking; Flat
// lazy: one search.
MilestoneRun FillMilestones(TaskSearch& search, const TaskWorld& world,
                            const TaskPlannerOptions& options, const std::vector<int>& order,
                            bool flat, const SymState& s0, const ContState& c0, RunContext& ctx) {
  const int K = static_cast<int>(order.size());
  MilestoneRun run;
  run.results.resize(flat ? 1 : K);
  std::vector<MilestoneResult>& results = run.results;
  std::vector<std::set<std::uint64_t>> excluded(K);
  // Fills milestone i from the end of milestone i - 1 as `results` has it.
  auto fill = [&](int i, const FillLimits& limits) {
    const SymState& s = i == 0 ? s0 : results[i - 1].end;
    const ContState& c = i == 0 ? c0 : results[i - 1].end_c;
    const TaskClock t = i == 0 ? TaskClock(static_cast<int>(world.robots.size()), world.num_nodes)
                               : results[i - 1].end_clock;
    return search.Fill(i, order[i], i + 1 < K ? order[i + 1] : -1, s, c, t, excluded[i], limits);
  };
  int& k = run.reached;
  while (k < K) {
    const std::string words = flat
                                  ? "the whole task (flat)"
                                  : "milestone " + std::to_string(k + 1) + "/" + std::to_string(K) +
                                        " '" + world.tree->nodes[order[k]].name + "'";
    ctx.Progress("task", static_cast<double>(k) / std::max(1, K), words);
    MilestoneResult r;
    if (flat) {
      r = search.FillFlat(s0, c0);
    } else {
      const bool can_backtrack = k > 0 && run.backtracks < options.max_backtracks;
      FillLimits limits;
      limits.stop_when_first_exhausted = can_backtrack;
      const long long expansions0 = search.expansions();
      r = fill(k, limits);
      if (r.first_level_exhausted) {
        // The probe may take as much as the exhausted level took (at least a small floor).
        const long long budget = std::max(kProbeMinExpansions, search.expansions() - expansions0);
        if (ProbeAnotherEnd(fill, k, budget, excluded[k - 1], results, ctx)) {
          ++run.backtracks;
          ++k;
          continue;
        }
        limits = FillLimits{};
        limits.first_level = 1;
        r = fill(k, limits);
      }
    }
    if (r.ok) {
      if (flat) {
        results[0] = std::move(r);
        k = K;
        break;
      }
      results[k] = std::move(r);
      ++k;
      continue;
    }
    if (r.stopped || r.out_of_memory) {
      run.stopped = r.stopped;
      run.out_of_memory = r.out_of_memory;
      run.failure = words + " was being planned; checks that failed most: " + r.failure;
      run.detail = MilestoneFailure(flat ? -1 : k, flat ? -1 : order[k], r);
      if (run.out_of_memory) {
        run.failure = "out of memory (the search held more than the " +
                      std::to_string(options.memory_limit_mb) + " MiB limit) while " + run.failure;
      }
      break;
    }
    run.failure = r.failure;
    run.detail = MilestoneFailure(flat ? -1 : k, flat ? -1 : order[k], r);
    ctx.Log("task", run.failure);
    if (!flat && k > 0 && run.backtracks < options.max_backtracks) {
      excluded[k - 1].insert(results[k - 1].end.Hash());
      excluded[k].clear();
      --k;
      ++run.backtracks;
      continue;
    }
    break;
  }
  return run;
}

// The run's counters and stage times into the plan's stats (and ctx's stage times).
void CountSearch(const Project& project, const Preprocessed& pre, const TaskPlannerOptions& options,
                 const TaskSearch& search, const TaskCounters& counters, RunContext& ctx,
                 PlanStats& st) {
  st.planner = std::string(ToString(options.planner));
  st.objective = std::string(ToString(options.objective));
  st.seed = project.planner.seed;
  st.wrench_mode = ModeName(options.wrench_mode);
  st.force_scale = options.force_scale;
  st.grasps = pre.grasps_per_set;
  st.t_grasp_s = pre.times.contains("total") ? pre.times.at("total") : 0.0;
  st.expansions = search.expansions();
  st.validations = counters.validations;
  st.validation_failures = counters.validation_failures;
  st.lp_checks = counters.lp_checks;
  st.lp_cache_hits = counters.lp_cache_hits;
  st.lp_solves = counters.lp_solves;
  st.lp_pivots = counters.lp_pivots;
  st.ik_calls = counters.ik_calls;
  st.collision_checks = counters.collision_checks;
  st.t_ik_s = counters.t_ik_s;
  st.t_lp_s = counters.t_lp_s;
  // The backward abstraction's own LP and IK questions count in t_lp and t_ik as well.
  st.t_bwd_s = search.backward_seconds();
  st.t_fwd_s =
      std::max(0.0, search.search_seconds() - st.t_bwd_s - counters.t_ik_s - counters.t_lp_s);
  st.widenings = search.widenings();
  ctx.AddTime("ik", st.t_ik_s);
  ctx.AddTime("lp", st.t_lp_s);
  ctx.AddTime("fwd", st.t_fwd_s);
  ctx.AddTime("bwd", st.t_bwd_s);
}

// The solved run's actions into the plan, milestone after milestone; Flat lazy finds its
// milestones after the fact: the steps in the order the search assembled them.
void CollectActions(const std::vector<MilestoneResult>& results, bool flat, int K, Plan& plan) {
  for (const MilestoneResult& r : results) {
    plan.actions.insert(plan.actions.end(), r.actions.begin(), r.actions.end());
  }
  if (flat) {
    plan.milestone_steps.clear();
    for (PlanAction& a : plan.actions) {
      a.milestone = static_cast<int>(plan.milestone_steps.size());
      if (a.type == ActionType::kAssemble) plan.milestone_steps.push_back(a.objects.back());
    }
    for (PlanAction& a : plan.actions) a.milestone = std::min(a.milestone, K - 1);
  }
}

}  // namespace

std::string_view ToString(PlannerVariant variant) {
  switch (variant) {
    case PlannerVariant::kWrap:
      return "wrap";
    case PlannerVariant::kOptimistic:
      return "optimistic";
    case PlannerVariant::kFlat:
      return "flat";
    case PlannerVariant::kCounting:
      return "counting";
    case PlannerVariant::kExact:
      return "exact";
    case PlannerVariant::kFine:
      return "fine";
  }
  return "?";
}

std::string_view ToString(PlanObjective objective) {
  switch (objective) {
    case PlanObjective::kActions:
      return "actions";
    case PlanObjective::kMakespan:
      return "makespan";
  }
  return "?";
}

Result<PlanObjective> ParsePlanObjective(std::string_view name) {
  for (PlanObjective o : {PlanObjective::kActions, PlanObjective::kMakespan}) {
    if (ToString(o) == name) return o;
  }
  return Fail(ErrorCode::kInvalidInput,
              "planner: unknown objective '" + std::string(name) + "' (known: actions, makespan)");
}

Result<PlannerVariant> ParsePlannerVariant(std::string_view name) {
  for (PlannerVariant v :
       {PlannerVariant::kWrap, PlannerVariant::kOptimistic, PlannerVariant::kFlat,
        PlannerVariant::kCounting, PlannerVariant::kExact, PlannerVariant::kFine}) {
    if (ToString(v) == name) return v;
  }
  return Fail(ErrorCode::kInvalidInput,
              "planner: unknown variant '" + std::string(name) +
                  "' (known: wrap, optimistic, flat, counting, exact, fine)");
}

Result<Plan> PlanTask(const Project& project, const ProjectCheck& check, const Preprocessed& pre,
                      const TaskPlannerOptions& options, RunContext& ctx) {
  // The planner judges every insertion path against the meshes before it plans (its own sweep
  // of each step, whatever validation said): no plan drives one input through the other.
  if (auto free = CheckInsertionPaths(project, check); !free) return std::unexpected(free.error());
  const auto start = Clock::now();
  if (auto valid = CheckOptions(options); !valid) return std::unexpected(valid.error());
  auto rig = BuildRig(project, check, pre, options);
  if (!rig) return std::unexpected(rig.error());
  const TaskWorld& world = (*rig)->world;
  TaskTables& tables = (*rig)->tables;
  KeyframeSolver& solver = *(*rig)->solver;
  solver.set_log(&ctx);
  const std::uint64_t seed = ctx.rng()();
  const bool widen = options.widen.value_or(project.planner.widen_grasps);
  TaskSearch search(world, tables, solver, options, ctx, seed, widen);

  Plan plan;
  SymState s0;
  ContState c0;
  StartTask(project, world, tables, s0, c0, plan);

  const std::vector<int>& order = world.tree->step_order;
  plan.milestone_steps = order;
  const int K = static_cast<int>(order.size());
  const bool flat = options.planner == PlannerVariant::kFlat;
  MilestoneRun run = FillMilestones(search, world, options, order, flat, s0, c0, ctx);
  const double t_first = std::chrono::duration<double>(Clock::now() - start).count();
  std::vector<std::pair<double, int>> history;
  double t_opt = 0.0;
  if (run.reached == K) {
    history.push_back({t_first, CostOf(run.results, 0, static_cast<int>(run.results.size()))});
    if (options.optimize && !flat) {
      const TaskClock t0(static_cast<int>(world.robots.size()), world.num_nodes);
      Improve(search, order, s0, c0, t0, options.objective, run.results, ctx, start, history);
      t_opt = std::chrono::duration<double>(Clock::now() - start).count() - t_first;
    }
  }
  if (ctx.cancelled()) return Fail(ErrorCode::kCancelled, "planner: cancelled");

  PlanStats& st = plan.stats;
  CountSearch(project, pre, options, search, (*rig)->counters, ctx, st);
  st.milestones = K;
  st.backtracks = run.backtracks;
  st.t_init_s = t_first;
  st.t_opt_s = t_opt;
  st.cost_history = history;
  st.out_of_memory = run.out_of_memory;
  if (run.reached == K) {
    st.solved = true;
    CollectActions(run.results, flat, K, plan);
    st.cost = static_cast<int>(plan.actions.size());
    st.first_cost = history.front().second;
    st.makespan_est_s = EstimateMakespan(plan);
  } else {
    st.solved = false;
    std::string failure = std::move(run.failure);
    if (run.stopped) {
      failure = (ctx.timed_out() ? "time limit reached while " : "stopped while ") + failure;
    }
    if (failure.empty()) failure = "no plan";
    st.failure = failure;
    run.detail.text = failure;
    st.failure_detail = std::move(run.detail);
  }
  return plan;
}

Result<std::vector<UnpickablePart>> UnpickableAtStart(const Project& project,
                                                      const ProjectCheck& check,
                                                      const Preprocessed& pre,
                                                      const TaskPlannerOptions& options,
                                                      int max_grasps) {
  auto rig = BuildRig(project, check, pre, options);
  if (!rig) return std::unexpected(rig.error());
  const TaskWorld& world = (*rig)->world;
  TaskTables& tables = (*rig)->tables;
  RunContext ctx;
  TaskSearch search(world, tables, *(*rig)->solver, options, ctx, 0, false);
  const int grasps = max_grasps > 0 ? max_grasps : std::numeric_limits<int>::max();
  std::vector<int> locations(world.num_parts);
  for (int p = 0; p < world.num_parts; ++p) {
    locations[p] = tables.InitialLocation(p, world.initial_X_WA[p]);
  }
  std::vector<UnpickablePart> out;
  for (int p = 0; p < world.num_parts; ++p) {
    if (search.CanBePicked(p, locations[p], grasps)) continue;
    out.push_back({p, search.PickCensus(p, locations[p], grasps)});
  }
  return out;
}

}  // namespace wrap
