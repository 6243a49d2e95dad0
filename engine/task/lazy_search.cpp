// The lazy search of one fill of the task planner (paper Alg. 2; search.h): a weighted
// best-first search over the symbolic state, whose best candidate plan is validated edge by edge
// by the KeyframeSolver; what holds is committed, a failed edge is suspended until the next
// effort level (or for good), and a committed state from which nothing is found is abandoned.
#include <algorithm>
#include <cmath>
#include <queue>
#include <span>
#include <tuple>
#include <unordered_set>

#include "task/search.h"
#include "task/search_internal.h"

namespace wrap {
namespace {

// Node budget of a search from a committed state past the milestone's start: beyond it the
// state counts as a dead end and the search backs up.
constexpr long long kLocalNodes = 20000;
// Validation failures after which the fill stops searching from the milestone's start and
// commits to the validated prefix of its candidates.
constexpr int kRootFailures = 15;
// Most actions in one milestone's plan: longer candidates count as dead ends.
constexpr int kMaxMilestoneActions = 16;
// Optimistic: failures of the target's assembly before the next target.
constexpr int kTargetFailures = 3;
// Optimistic: nodes of a search towards one target (an unreachable target exhausts it).
constexpr long long kTargetNodes = 200000;
// Validation failures in one round (resolution and effort level) before moving to the next.
constexpr int kRoundFailures = 400;
// Failed assembly edges after which a resolution level that is not the last gives up and widens:
// its few grasps admit no assembly the keyframes can hold (the plumber's block seed 6: 181 of
// them in 50k expansions at the first level, which the next solved at once). Of the examples'
// seeds 0-9 it changes that one and cross_openarm's seeds 0 (101k -> 60k expansions) and 9
// (23k -> 75k). The last level is never cut short.
constexpr int kLevelAssemblyFailures = 48;

}  // namespace

std::size_t TaskSearch::MemoryBytes(std::size_t open, std::size_t closed) const {
  // A node: the struct, its state's three vectors (heap blocks with their headers).
  const std::size_t state = static_cast<std::size_t>(world_.num_nodes) * 2 +
                            static_cast<std::size_t>(n_robots_) * 6 + 3 * 32;
  const std::size_t clock = static_cast<std::size_t>(world_.num_nodes + n_robots_) * 4 + 16;
  std::size_t bytes = nodes_.capacity() * (sizeof(Node) + state + clock);
  bytes += open * 48 + closed * 48;  // the queue's entries, the hash map's
  // Caches that live across searches: witnesses hold keyframes (joint vectors, poses).
  bytes += witnesses_.size() * 2048 + cheap_.size() * 96 + failed_level_.size() * 48;
  return bytes;
}

TaskSearch::SearchStatus TaskSearch::BestFirst(
    const SymState& s0, const TaskClock& t0, const Milestone& m, const Resolution& res, int effort,
    const std::set<std::uint64_t>& excluded,
    const std::unordered_map<std::uint64_t, bool>& dead_ends,
    const std::unordered_set<std::uint64_t>& forbidden, long long node_budget, int g0, int max_cost,
    std::vector<int>& path) {
  nodes_.clear();
  FlatMap<int> best_g;
  // Ordered by f, then deeper first, then the order of insertion. The makespan objective puts
  // the makespan estimate before the depth and its sum of action ends after it: among
  // candidates as long, the one whose work runs more at once comes first.
  using Entry = std::tuple<int, long long, long long, long long, long long, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  long long sequence = 0;
  const bool by_makespan = options_.objective == PlanObjective::kMakespan;
  auto entry = [&](int f, int g, const TaskClock& clock, int node) {
    if (!by_makespan) return Entry{f, -g, 0, 0, sequence++, node};
    const long long makespan_ms = std::llround(1000.0 * clock.makespan_s());
    const long long sum_ms = std::llround(1000.0 * clock.completion_sum_s());
    return Entry{f, makespan_ms, -g, sum_ms, sequence++, node};
  };
  const int h0 = Heuristic(s0, m);
  if (g0 + h0 > max_cost) return SearchStatus::kExhausted;
  nodes_.push_back({s0, 0, -1, {}, s0.Hash(), t0});
  best_g[nodes_.back().hash] = 0;
  open.push(entry(weight_ * h0, 0, t0, 0));
  const std::size_t memory_limit = static_cast<std::size_t>(options_.memory_limit_mb) << 20;
  SuccessorList successors;
  while (!open.empty()) {
    if ((++expansions_ & 127) == 0) {
      if (ctx_.ShouldStop()) return SearchStatus::kStopped;
      if (MemoryBytes(open.size(), best_g.size()) > memory_limit) {
        return SearchStatus::kOutOfMemory;
      }
      // What the estimate misses (caches of the solver, the allocator's slack): the process's
      // growth since the planner started.
      if ((expansions_ & 4095) == 0) {
        const std::size_t rss = ResidentMemoryBytes();
        if (rss > rss0_ && rss - rss0_ > memory_limit) return SearchStatus::kOutOfMemory;
      }
    }
    const int index = std::get<5>(open.top());
    open.pop();
    const int g = nodes_[index].g;
    const std::uint64_t h = nodes_[index].hash;
    if (best_g[h] < g) continue;
    if (IsGoal(nodes_[index].s, m, excluded)) {
      path.clear();
      for (int i = index; i > 0; i = nodes_[i].parent) path.push_back(i);
      std::reverse(path.begin(), path.end());
      return SearchStatus::kFound;
    }
    if (static_cast<long long>(nodes_.size()) > node_budget || expansions_ > level_cap_) {
      return SearchStatus::kNodeLimit;
    }
    const SymState s = nodes_[index].s;
    Successors(s, m, res, successors);
    for (auto& [a, s2] : successors) {
      const std::uint64_t edge = EdgeKey(h, a);
      const int* failed = failed_level_.find(edge);
      if (failed && *failed >= effort) continue;
      if (!dead_ends.empty() && dead_ends.contains(edge)) continue;
      const int g2 = g + 1;
      const std::uint64_t h2 = s2.Hash();
      if (!forbidden.empty() && forbidden.contains(h2)) continue;
      auto [best, inserted] = best_g.try_emplace(h2, g2);
      if (!inserted) {
        if (*best <= g2) continue;
        *best = g2;
      }
      const int hv = Heuristic(s2, m);
      if (g0 + g2 + hv > max_cost) continue;  // plan improvement: cannot beat the bound
      const int child = static_cast<int>(nodes_.size());
      // Only the makespan objective orders by the clock; the committed prefix keeps its own.
      TaskClock clock;
      if (by_makespan) {
        clock = nodes_[index].clock;
        Advance(s, a, clock);
      }
      open.push(entry(g2 + weight_ * hv, g2, clock, child));
      nodes_.push_back({std::move(s2), g2, index, a, h2, std::move(clock)});
    }
  }
  return SearchStatus::kExhausted;
}

TaskSearch::SearchStatus TaskSearch::Rounds(int index, const Milestone& m, const Resolution& res,
                                            const SymState& s0, const ContState& c0,
                                            const TaskClock& t0,
                                            const std::set<std::uint64_t>& excluded,
                                            const FillLimits& limits, MilestoneResult& result) {
  // The committed prefix: validated states from s0 on. The search starts from its last state;
  // a candidate plan's validated edges are committed (greedy, like the paper's lazy greedy fill);
  // when the search from a committed state finds nothing, that state is abandoned (its entering
  // edge marked a dead end for this resolution and effort) and the search backs up one state.
  const int max_actions =
      std::min(limits.max_cost,
               m.flat ? kMaxMilestoneActions *
                            static_cast<int>(window_.empty() ? flat_order_.size() : window_.size())
                      : kMaxMilestoneActions);
  // Flat lazy searches the whole task at once: only the memory limit bounds it.
  const long long max_nodes = limits.max_nodes > 0 ? limits.max_nodes : options_.max_nodes;
  const long long root_budget = target_.rm >= 0 ? std::min(max_nodes, kTargetNodes)
                                : !m.flat       ? max_nodes
                                : window_.empty()
                                    ? (1LL << 62)
                                    : max_nodes * static_cast<long long>(window_.size());
  const long long local_budget = m.flat ? max_nodes : std::min(max_nodes, kLocalNodes);
  auto stop = [&](SearchStatus status) {
    result.stopped = status == SearchStatus::kStopped;
    result.out_of_memory = status == SearchStatus::kOutOfMemory;
    result.failure = tally_.Summary();
    Explain(s0, c0, result);
    return status;
  };
  std::vector<int> path;
  int target_failures = 0;
  for (int effort = 0; effort <= options_.max_effort; ++effort) {
    bool suspended_below = false;  // an edge that failed at this effort could be retried
    std::vector<Committed> prefix{{s0, c0, 0, t0}};
    std::vector<PlanAction> actions;
    std::unordered_map<std::uint64_t, bool> dead_ends;  // edges into abandoned states
    int root_failures = 0;
    int round_failures = 0;
    std::unordered_set<std::uint64_t> on_prefix;  // states the committed prefix visited
    while (!prefix.empty()) {
      if (expansions_ > level_cap_) return SearchStatus::kExhausted;  // widen now
      on_prefix.clear();
      for (const Committed& p : prefix) on_prefix.insert(p.s.Hash());
      const int g0 = static_cast<int>(prefix.size()) - 1;
      SearchStatus status = BestFirst(
          prefix.back().s, prefix.back().clock, m, res, effort, excluded, dead_ends, on_prefix,
          prefix.size() == 1 ? root_budget : local_budget, g0, max_actions, path);
      if (ctx_.Logs("task")) {
        ctx_.Log("task",
                 StrFormat("milestone %d effort %d depth %d: status %d, %zu nodes, path %zu", index,
                           effort, g0, static_cast<int>(status), nodes_.size(), path.size()));
      }
      if (status == SearchStatus::kStopped || status == SearchStatus::kOutOfMemory) {
        return stop(status);
      }
      if (status == SearchStatus::kFound) level_cap_ = std::max(level_cap_, level_full_cap_);
      if (status == SearchStatus::kFound && g0 + static_cast<int>(path.size()) > max_actions) {
        status = SearchStatus::kExhausted;  // too long: treat as a dead end
      }
      if (status != SearchStatus::kFound) {
        // Nothing from here: abandon this state.
        if (prefix.size() == 1) break;
        dead_ends[prefix.back().entering_edge] = true;
        prefix.pop_back();
        actions.pop_back();
        continue;
      }
      const CandidateStatus candidate = CommitCandidate(index, m, path, limits, prefix, actions,
                                                        target_failures, suspended_below);
      if (candidate == CandidateStatus::kStopped) return stop(SearchStatus::kStopped);
      if (candidate == CandidateStatus::kGiveUp) return SearchStatus::kExhausted;
      const bool valid = candidate == CandidateStatus::kValid;
      if (!valid && ++round_failures > kRoundFailures) break;  // try more effort or width
      if (!valid && ++root_failures <= kRootFailures) {
        // Early on, search again from the milestone's start: shorter plans.
        prefix.resize(1);
        actions.clear();
      }
      if (valid) {
        result.ok = true;
        result.actions = std::move(actions);
        result.after.clear();
        for (size_t i = 1; i < prefix.size(); ++i)
          result.after.push_back({prefix[i].s, prefix[i].c});
        result.end = prefix.back().s;
        result.end_c = prefix.back().c;
        result.end_clock = prefix.back().clock;
        return SearchStatus::kFound;
      }
    }
    if (!suspended_below) break;  // more effort would search the same graph
  }
  return SearchStatus::kExhausted;
}

TaskSearch::CandidateStatus TaskSearch::CommitCandidate(
    int index, const Milestone& m, const std::vector<int>& path, const FillLimits& limits,
    std::vector<Committed>& prefix, std::vector<PlanAction>& actions, int& target_failures,
    bool& suspended_below) {
  // Validate the candidate plan edge by edge, committing what holds.
  for (int node_index : path) {
    if (ctx_.ShouldStop()) return CandidateStatus::kStopped;
    const SymState& s = prefix.back().s;
    const ContState& c = prefix.back().c;
    const TaskAction a = nodes_[node_index].a;
    const SymState next = nodes_[node_index].s;
    const std::uint64_t edge = EdgeKey(s, a);
    const std::uint64_t witness_key = HashMix(c.Fingerprint(s), a.Hash());
    auto w = witnesses_.find(witness_key);
    if (w == witnesses_.end()) {
      const int* failed = failed_level_.find(edge);
      const int edge_level = failed ? *failed + 1 : 0;
      // The first failure of each collision-like gate in a milestone keeps its picture.
      solver_.set_explain(tally_.count[static_cast<int>(Gate::kCollision)] == 0 ||
                          tally_.count[static_cast<int>(Gate::kSkill)] == 0 ||
                          tally_.count[static_cast<int>(Gate::kApproach)] == 0);
      EdgeOutcome outcome = solver_.Validate(s, c, a, next, edge_level, HashMix(seed_, edge));
      solver_.set_explain(false);
      if (!outcome.ok) {
        TallyEdgeFailure(s, c, a, outcome);
        failed_level_[edge] = outcome.permanent ? kPermanentFailure : edge_level;
        if (++fill_failures_ > limits.max_failures) return CandidateStatus::kGiveUp;
        if (a.type == ActionType::kAssemble &&
            level_cap_ != std::numeric_limits<long long>::max() &&
            ++level_assembly_failures_ > kLevelAssemblyFailures) {
          return CandidateStatus::kGiveUp;
        }
        // Optimistic: an assembly with the target's grasps that fails several times is a
        // bad choice of target, not of the way there.
        if (target_.rm >= 0 && a.type == ActionType::kAssemble &&
            ++target_failures >= kTargetFailures) {
          return CandidateStatus::kGiveUp;
        }
        if (!outcome.permanent && edge_level < options_.max_effort) suspended_below = true;
        return CandidateStatus::kInvalid;
      }
      w = witnesses_.emplace(witness_key, std::move(outcome)).first;
    }
    actions.push_back(
        MakeAction(s, a, w->second, m.flat && !window_.empty() ? index + WindowDone(s) : index));
    TaskClock clock = prefix.back().clock;
    Advance(s, a, clock);
    prefix.push_back({next, w->second.next, edge, std::move(clock)});
  }
  return CandidateStatus::kValid;
}

void TaskSearch::TallyEdgeFailure(const SymState& s, const ContState& c, const TaskAction& a,
                                  EdgeOutcome& outcome) {
  if (ctx_.Logs("task")) {
    ctx_.Log("task", StrFormat("  edge %s r%d r%d obj %d g%d l%d: %s: %s%s",
                               std::string(ToString(a.type)).c_str(), a.r1, a.r2, a.obj, a.grasp,
                               a.loc, std::string(GateName(outcome.gate)).c_str(),
                               outcome.message.c_str(), outcome.permanent ? " (permanent)" : ""));
  }
  // What the edge was about: the acting robot (the taker of a handover), or for an assembly the
  // moved input and its first holder.
  CheckSubject about;
  about.object = a.obj;
  about.robot = a.type == ActionType::kHandover ? a.r2 : a.r1;
  about.grasp = a.grasp;
  about.loc = a.loc;
  if (a.type == ActionType::kAssemble) {
    about.object = world_.interface(a.obj).moved;
    about.robot = -1;
    for (int r = 0; r < n_robots_ && about.robot < 0; ++r) {
      if (s.held[r] == about.object) {
        about.robot = r;
        about.grasp = s.grasp[r];
      }
    }
  }
  if (about.loc < 0 && about.object >= 0 && about.object < static_cast<int>(c.X_WA.size())) {
    about.X_WA = c.X_WA[about.object];
  }
  tally_.Add(outcome.gate, outcome.message, about);
  if (tally_.count[static_cast<int>(outcome.gate)] == 1) {
    tally_.scene[static_cast<int>(outcome.gate)] = std::move(outcome.scene);
  }
}

void TaskSearch::Advance(const SymState& s, const TaskAction& a, TaskClock& clock) const {
  if (a.type != ActionType::kAssemble) {
    const int robots[2] = {a.r1, a.r2};
    const int object = a.obj;
    clock.Advance(a.type, std::span<const int>(robots, a.type == ActionType::kHandover ? 2 : 1),
                  std::span<const int>(&object, 1));
    return;
  }
  const StepInterface& st = world_.interface(a.obj);
  const int objects[3] = {st.moved, st.base, a.obj};
  std::vector<int> robots;
  for (int r = 0; r < n_robots_; ++r) {
    if (s.held[r] == st.moved || s.held[r] == st.base) robots.push_back(r);
  }
  clock.Advance(a.type, robots, objects);
}

PlanAction TaskSearch::MakeAction(const SymState& s, const TaskAction& a, const EdgeOutcome& e,
                                  int milestone) const {
  PlanAction p;
  p.type = a.type;
  p.milestone = milestone;
  p.edge = EdgeKey(s, a);
  p.keyframe = e.keyframe;
  p.approach = e.approach;
  auto hold = [&](int robot, int grasp_id) {
    const GraspRef& g = tables_.grasp(grasp_id);
    PlanHold h;
    h.robot = robot;
    h.grasp.subassembly = g.subassembly;
    h.grasp.index = g.index;
    h.grasp.part = g.part;
    h.grasp.X_PG = g.X_PG;
    h.grasp.width_m = g.width_m;
    h.grasp.type = g.type;
    h.grasp.torque_scale = g.torque_scale;
    return h;
  };
  switch (a.type) {
    case ActionType::kPick:
    case ActionType::kAddGrasp:
      p.robots = {a.r1};
      p.objects = {a.obj};
      p.grasps = {hold(a.r1, a.grasp)};
      break;
    case ActionType::kPlace: {
      p.robots = {a.r1};
      p.objects = {a.obj};
      p.grasps = {hold(a.r1, s.grasp[a.r1])};
      p.placement = tables_.location(a.loc).placement;
      break;
    }
    case ActionType::kRelease:
      p.robots = {a.r1};
      p.objects = {a.obj};
      p.grasps = {hold(a.r1, s.grasp[a.r1])};
      break;
    case ActionType::kHandover:
      p.robots = {a.r1, a.r2};
      p.objects = {a.obj};
      p.grasps = {hold(a.r1, s.grasp[a.r1]), hold(a.r2, a.grasp)};
      break;
    case ActionType::kAssemble: {
      const StepInterface& st = world_.interface(a.obj);
      p.objects = {st.moved, st.base, a.obj};
      for (int node : {st.moved, st.base}) {
        for (int r = 0; r < n_robots_; ++r) {
          if (s.held[r] == node) {
            p.robots.push_back(r);
            p.grasps.push_back(hold(r, s.grasp[r]));
          }
        }
      }
      break;
    }
  }
  return p;
}

}  // namespace wrap
