// The milestones of the task search (search.h): a milestone per assembly step, its fill over
// widening resolutions (and, for Optimistic, its assembly targets), the variant's heuristic and
// the goal test. The actions of a state are in successors.cpp, their cheap checks in
// cheap_checks.cpp, the lazy search with edge validation in lazy_search.cpp.
#include "task/search.h"

#include <chrono>
#include <limits>

#include "task/search_internal.h"

namespace wrap {
namespace {

using Clock = std::chrono::steady_clock;

// Work budget of a resolution level that is not the last, in forward-search expansions: well
// above what a solvable level takes (the median seed of every example needs under 20k for the
// whole task), far below what an unsolvable one can take.
constexpr long long kLevelExpansions = 50000;
// Work budget of such a level until its search has found a first candidate plan: the car's seeds
// 0, 2 and 5 searched 50k expansions at the second level without one (the abstraction said 3
// actions; the grippers of every grasp of the subset hit the base when mated), and the next
// level found a plan in 35.
constexpr long long kBlindExpansions = 10000;

}  // namespace

TaskSearch::TaskSearch(const TaskWorld& world, TaskTables& tables, KeyframeSolver& solver,
                       const TaskPlannerOptions& options, RunContext& ctx, std::uint64_t seed,
                       bool widen)
    : world_(world),
      tables_(tables),
      solver_(solver),
      options_(options),
      ctx_(ctx),
      seed_(seed),
      widen_(widen),
      n_robots_(static_cast<int>(world.robots.size())),
      use_backward_(options.planner == PlannerVariant::kWrap ||
                    options.planner == PlannerVariant::kExact ||
                    options.planner == PlannerVariant::kFine),
      default_weight_(options.planner == PlannerVariant::kExact ? 1 : 2),
      weight_(default_weight_),
      fine_(options.planner == PlannerVariant::kFine),
      flat_(options.planner == PlannerVariant::kFlat),
      optimistic_(options.planner == PlannerVariant::kOptimistic),
      flat_order_(world.tree->step_order),
      rss0_(ResidentMemoryBytes()) {
  // Edges on which the motion of an earlier task plan failed: never taken (motion feedback).
  for (std::uint64_t edge : options.banned_edges) failed_level_[edge] = kPermanentFailure;
}

TaskSearch::Milestone TaskSearch::StepMilestone(int step, int next_step) const {
  Milestone m;
  m.step = step;
  m.moved = world_.interface(step).moved;
  m.base = world_.interface(step).base;
  m.final = next_step < 0;
  // Objects robots may still hold at the end: the inputs of the next step (none at the end).
  if (next_step >= 0) {
    m.keep[0] = world_.interface(next_step).moved;
    m.keep[1] = world_.interface(next_step).base;
  }
  return m;
}

std::string TaskSearch::StepWords(int step) const {
  const StepInterface& st = world_.interface(step);
  return "'" + world_.tree->nodes[step].name + "' (moving '" + world_.tree->nodes[st.moved].name +
         "' onto '" + world_.tree->nodes[st.base].name + "')";
}

void TaskSearch::SetClasses(const Milestone& m) {
  if (backward_.step == m.step) return;
  backward_ = Backward{};
  backward_.step = m.step;
  backward_.moved = m.moved;
  backward_.base = m.base;
}

TaskSearch::Resolution TaskSearch::ResolutionAt(int level) const {
  constexpr int kGrasps[] = {6, 12, 1 << 20};
  constexpr int kPlacements[] = {2, 4, 1 << 20};
  constexpr int kSlots[] = {3, 6, 1 << 20};
  constexpr int kYaws[] = {2, 2, 1 << 20};
  Resolution r;
  r.grasps = widen_ ? kGrasps[level] : 1 << 20;
  r.placements = kPlacements[level];
  r.slots = kSlots[level];
  r.yaws = kYaws[level];
  return r;
}

int TaskSearch::Heuristic(const SymState& s, const Milestone& m) {
  int h = 0;
  if (m.flat && !window_.empty()) {
    // A window of milestones: per step still to assemble the assembly and, when its moved input
    // rests on the table, a pick; a release per object held that no step still needs.
    const int done = WindowDone(s);
    const int n = static_cast<int>(window_.size());
    for (int t = done; t < n; ++t)
      h += 1 + (s.loc[world_.interface(window_[t]).moved] >= 0 ? 1 : 0);
    for (int r = 0; r < n_robots_; ++r) {
      const int o = s.held[r];
      if (o < 0 || o == m.keep[0] || o == m.keep[1]) continue;
      bool needed = false;
      for (int t = done; t < n && !needed; ++t) {
        needed = o == world_.interface(window_[t]).moved || o == world_.interface(window_[t]).base;
      }
      if (!needed) h += 1;
    }
    return h;
  }
  if (m.flat) {
    // Flat lazy: per step not yet assembled the assembly and, when its moved input exists but
    // is not in a hand, a pick; a release per robot holding something.
    for (int step : flat_order_) {
      if (s.loc[step] != kInactive) continue;
      h += 1;
      const int moved = world_.interface(step).moved;
      if (s.loc[moved] >= 0) h += 1;
    }
    for (int r = 0; r < n_robots_; ++r) h += s.held[r] >= 0 ? 1 : 0;
    return h;
  }
  const bool done = s.loc[m.step] != kInactive;
  if (use_backward_ && !done) {
    // WRAP: the abstract distance to the assembly, the releases of other objects, and the
    // release of the product when no later step takes it from the hands that hold it.
    h = BackwardDistance(s);
    for (int r = 0; r < n_robots_; ++r) {
      const int o = s.held[r];
      if (o >= 0 && o != m.moved && o != m.base && o != m.keep[0] && o != m.keep[1]) h += 1;
    }
    if (m.final || (m.step != m.keep[0] && m.step != m.keep[1])) h += 1;
    return h;
  }
  bool m_needs_grasp = false;
  if (!done) {
    h += 1;
    m_needs_grasp = s.NumHolders(m.moved) == 0 || s.loc[m.moved] >= 0;
    if (m_needs_grasp) h += 1;
  }
  for (int r = 0; r < n_robots_; ++r) {
    if (s.held[r] >= 0 && s.held[r] != m.keep[0] && s.held[r] != m.keep[1]) h += 1;
  }
  if (m.final && m_needs_grasp) h += 1;
  if (!done && target_.rm >= 0) h += TargetDistance(s, m);
  return h;
}

bool TaskSearch::IsGoal(const SymState& s, const Milestone& m,
                        const std::set<std::uint64_t>& excluded) const {
  if (s.loc[m.step] == kInactive) return false;
  if (m.flat && !window_.empty()) {
    for (int r = 0; r < n_robots_; ++r) {
      if (s.held[r] >= 0 && s.held[r] != m.keep[0] && s.held[r] != m.keep[1]) return false;
    }
    return true;
  }
  if (m.flat) {
    for (int r = 0; r < n_robots_; ++r) {
      if (s.held[r] >= 0) return false;
    }
    return true;
  }
  for (int r = 0; r < n_robots_; ++r) {
    if (s.held[r] >= 0 && s.held[r] != m.keep[0] && s.held[r] != m.keep[1]) return false;
  }
  return excluded.empty() || !excluded.contains(s.Hash());
}

MilestoneResult TaskSearch::Fill(int index, int step, int next_step, const SymState& s0,
                                 const ContState& c0, const TaskClock& t0,
                                 const std::set<std::uint64_t>& excluded,
                                 const FillLimits& limits) {
  const auto start = Clock::now();
  const Milestone m = StepMilestone(step, next_step);
  weight_ = limits.weight >= 0 ? limits.weight : default_weight_;
  tally_ = GateTally{};
  ++tally_round_;
  fill_failures_ = 0;
  MilestoneResult result;
  const std::string words = "milestone " + std::to_string(index + 1) + " " + StepWords(step);
  if (std::string why; !AssemblyPossible(m, &why)) {
    const std::string reason =
        "no combination of grasps and supports balances the mating wrench, whatever the "
        "robots' reach: " +
        why;
    result.failure = words + ": " + reason;
    FailureCase fc;
    fc.check = std::string(GateName(Gate::kWrenchAssembly));
    fc.count = 1;
    fc.text = reason;
    fc.example = why;
    fc.object = m.moved;
    result.start = SceneOf(s0, c0);
    fc.scene = result.start;
    result.cases = {std::move(fc)};
    return result;
  }
  const int levels = 3;
  std::string abstract_failure;  // why the backward abstraction found no way, at the last level
  auto finish = [&]() {
    target_ = AssemblyTarget{};
    level_cap_ = std::numeric_limits<long long>::max();
    level_full_cap_ = level_cap_;
    search_s_ += std::chrono::duration<double>(Clock::now() - start).count();
  };
  for (int level = limits.first_level; level < levels; ++level) {
    if (level + 1 == levels) reduced_grasps_ = true;
    const Resolution res = ResolutionAt(level);
    // A level that is not the last gets a work budget: a seed whose grasps at this resolution
    // admit no plan would otherwise exhaust a large graph (100k-600k expansions: the tails of
    // BENCHMARKS.md) before the next level, which usually solves it at once.
    // Until its search finds a first candidate plan, such a level gets kBlindExpansions: the
    // abstraction promised a short way the forward graph does not have.
    const long long budget =
        limits.level_expansions > 0 ? limits.level_expansions : kLevelExpansions;
    level_full_cap_ =
        level + 1 < levels ? expansions_ + budget : std::numeric_limits<long long>::max();
    level_cap_ = level + 1 < levels ? expansions_ + std::min(budget, kBlindExpansions)
                                    : std::numeric_limits<long long>::max();
    level_assembly_failures_ = 0;
    if (use_backward_) {
      const auto bwd_start = Clock::now();
      BuildBackward(m, res, s0);
      bwd_s_ += std::chrono::duration<double>(Clock::now() - bwd_start).count();
      if (ctx_.Logs("task")) {
        ctx_.Log("task", StrFormat("milestone %d level %d: backward distance %d at the start",
                                   index, level, BackwardDistance(s0)));
      }
      if (!backward_.why.empty()) {
        // The relaxation cannot reach the assembly: neither can the search at this resolution.
        abstract_failure = backward_.why;
        if (limits.first_level_only) break;
        if (level + 1 < levels) ++widenings_;
        continue;
      }
      abstract_failure.clear();  // this level searches: its failures are the report
    }
    std::vector<AssemblyTarget> targets{AssemblyTarget{}};
    if (optimistic_) targets = OptimisticTargets(m, res, s0);
    const long long level_start = expansions_;
    for (const AssemblyTarget& target : targets) {
      target_ = target;
      const SearchStatus status = Rounds(index, m, res, s0, c0, t0, excluded, limits, result);
      if (status != SearchStatus::kExhausted) {
        if (ctx_.Logs("task") && result.ok) {
          ctx_.Log("task", StrFormat("milestone %d level %d: found after %lld expansions", index,
                                     level, expansions_ - level_start));
        }
        finish();
        return result;
      }
    }
    if (ctx_.Logs("task")) {
      ctx_.Log("task", StrFormat("milestone %d level %d: nothing after %lld expansions%s; %s",
                                 index, level, expansions_ - level_start,
                                 expansions_ > level_cap_ ? " (level budget spent)" : "",
                                 tally_.Summary().c_str()));
    }
    if (level == limits.first_level &&
        (limits.first_level_only ||
         (limits.stop_when_first_exhausted && expansions_ <= level_cap_ && !optimistic_))) {
      result.first_level_exhausted = expansions_ <= level_cap_;
      finish();
      result.failure = words + ": nothing at resolution level " + std::to_string(level) + "; " +
                       tally_.Summary();
      return result;
    }
    if (optimistic_ && targets.empty()) {
      abstract_failure = "no assembly grasp of '" + world_.tree->nodes[m.moved].name +
                         "' with a support of '" + world_.tree->nodes[m.base].name +
                         "' balances the mating wrench";
    }
    if (level + 1 < levels) ++widenings_;
  }
  finish();
  result.failure =
      words + ": no plan with every grasp, placement and effort level" +
      (limits.max_cost < (1 << 30) ? " within " + std::to_string(limits.max_cost) + " actions"
                                   : std::string()) +
      "; " + (abstract_failure.empty() ? tally_.Summary() : abstract_failure);
  if (abstract_failure.empty()) {
    Explain(s0, c0, result);
  } else {
    FailureCase fc;
    fc.check = "abstraction";
    fc.count = 1;
    fc.text = abstract_failure;
    fc.example = abstract_failure;
    fc.object = m.moved;
    result.start = SceneOf(s0, c0);
    fc.scene = result.start;
    result.cases = {std::move(fc)};
  }
  return result;
}

int TaskSearch::StartHeuristic(int step, int next_step, const SymState& s) {
  const Milestone m = StepMilestone(step, next_step);
  if (use_backward_) BuildBackward(m, ResolutionAt(2), s);
  return Heuristic(s, m);
}

}  // namespace wrap
