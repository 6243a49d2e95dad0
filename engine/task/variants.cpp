// The paper's comparison variants on top of the milestone search (search.h): Flat lazy (one
// search over the whole task), the windows of several milestones that plan improvement searches
// as one, and Optimistic (assembly grasps chosen first, like Dogar et al.).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <unordered_set>

#include "task/search.h"

namespace wrap {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

int TaskSearch::TargetDistance(const SymState& s, const Milestone& m) {
  // Optimistic: actions beyond the counting ones that the target's grasps need. An input held
  // with another grasp or by another robot than the target's needs a handover (or a set-down and
  // a pick); one resting where the target's robot cannot take it with the target's grasp needs
  // a regrasp first; a base to rest that is held needs a set-down.
  int h = 0;
  auto grasp_distance = [&](int node, int robot, int grasp) {
    if (s.held[robot] == node && s.grasp[robot] == grasp) return 0;
    if (s.loc[node] >= 0) return CheapPick(robot, node, s.loc[node], grasp) ? 0 : 2;
    return 1;
  };
  h += grasp_distance(m.moved, target_.rm, target_.gm);
  if (target_.rb >= 0) h += grasp_distance(m.base, target_.rb, target_.gb);
  if (target_.base_rests && s.loc[m.base] < 0) h += 1;
  if (target_.base_moved && s.loc[m.base] == target_start_loc_) h += 2;
  return h;
}

bool TaskSearch::TargetAllows(const SymState& s, const Milestone& m) const {
  if (target_.rm < 0) return true;
  if (s.held[target_.rm] != m.moved || s.grasp[target_.rm] != target_.gm) return false;
  if (target_.base_rests != (s.loc[m.base] >= 0)) return false;
  if (target_.base_moved && s.loc[m.base] == target_start_loc_) return false;
  return target_.rb < 0 || (s.held[target_.rb] == m.base && s.grasp[target_.rb] == target_.gb);
}

void TaskSearch::FlatSuccessors(const SymState& s, const Resolution& res, SuccessorList& out) {
  out.clear();
  SuccessorList some;
  std::unordered_set<std::uint64_t> seen;  // releases and set-downs come from every step
  auto add = [&](const Milestone& m) {
    Successors(s, m, res, some);
    for (auto& e : some) {
      if (seen.insert(e.first.Hash()).second) out.push_back(std::move(e));
    }
  };
  if (!window_.empty()) {
    // A window of milestones: the steps in their order.
    const int t = WindowDone(s);
    const int n = static_cast<int>(window_.size());
    if (t < n) {
      add(StepMilestone(window_[t], t + 1 < n ? window_[t + 1] : window_next_));
    } else {
      add(StepMilestone(window_.back(), window_next_));
    }
    return;
  }
  for (int step : flat_order_) {
    if (s.loc[step] != kInactive) continue;
    const StepInterface& st = world_.interface(step);
    if (s.loc[st.moved] == kInactive || s.loc[st.base] == kInactive) continue;
    add(StepMilestone(step, step));
  }
  const int product = flat_order_.back();
  if (s.loc[product] != kInactive) add(StepMilestone(product, -1));
}

int TaskSearch::WindowDone(const SymState& s) const {
  for (int t = static_cast<int>(window_.size()) - 1; t >= 0; --t) {
    if (s.loc[window_[t]] != kInactive) return t + 1;
  }
  return 0;
}

MilestoneResult TaskSearch::FillWindow(int index, const std::vector<int>& steps, int next_step,
                                       const SymState& s0, const ContState& c0, const TaskClock& t0,
                                       const FillLimits& limits) {
  const auto start = Clock::now();
  window_ = steps;
  window_next_ = next_step;
  Milestone m = StepMilestone(steps.back(), next_step);
  m.flat = true;
  weight_ = limits.weight >= 0 ? limits.weight : default_weight_;
  tally_ = GateTally{};
  ++tally_round_;
  fill_failures_ = 0;
  MilestoneResult result;
  const int levels = 3;
  for (int level = 0; level < levels; ++level) {
    if (level + 1 == levels) reduced_grasps_ = true;
    if (Rounds(index, m, ResolutionAt(level), s0, c0, t0, {}, limits, result) !=
        SearchStatus::kExhausted) {
      break;
    }
  }
  window_.clear();
  search_s_ += std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

MilestoneResult TaskSearch::FillFlat(const SymState& s0, const ContState& c0) {
  const auto start = Clock::now();
  Milestone m = StepMilestone(flat_order_.back(), -1);
  m.flat = true;
  weight_ = default_weight_;
  tally_ = GateTally{};
  ++tally_round_;
  fill_failures_ = 0;
  MilestoneResult result;
  for (int step : flat_order_) {
    if (std::string why; !AssemblyPossible(StepMilestone(step, -1), &why)) {
      result.failure = "step " + StepWords(step) +
                       ": no combination of grasps and supports balances the mating wrench, "
                       "whatever the robots' reach: " +
                       why;
      return result;
    }
  }
  const int levels = 3;
  for (int level = 0; level < levels; ++level) {
    if (level + 1 == levels) reduced_grasps_ = true;
    const SearchStatus status = Rounds(0, m, ResolutionAt(level), s0, c0,
                                       TaskClock(n_robots_, world_.num_nodes), {}, {}, result);
    if (status != SearchStatus::kExhausted) break;
    if (level + 1 < levels) ++widenings_;
  }
  search_s_ += std::chrono::duration<double>(Clock::now() - start).count();
  if (!result.ok && !result.stopped && !result.out_of_memory) {
    result.failure =
        "the whole task (flat, no milestones): no plan with every grasp, placement "
        "and effort level; " +
        tally_.Summary();
    Explain(s0, c0, result);
  }
  return result;
}

std::vector<TaskSearch::AssemblyTarget> TaskSearch::OptimisticTargets(const Milestone& m,
                                                                      const Resolution& res,
                                                                      const SymState& s0) {
  // Like Dogar et al.: the assembly's grasps (and the base's support) are chosen first, by the
  // checks of the assembly alone (reach and clearance at the mating pose where the base rests,
  // the wrench LP), without asking how the robots get there; the search then plans the picks,
  // handovers and set-downs to reach them. Grasps in set order (best spread first), robots
  // interleaved; per grasp the base resting where it is, else braced, else held in the air.
  constexpr int kTargets = 16;
  SetClasses(m);
  target_start_loc_ = s0.loc[m.base];
  std::vector<AssemblyTarget> targets;
  // The assembly check on a hypothetical state: s0 with the chosen grasps in hand.
  auto holds = [&](const AssemblyTarget& t) {
    SymState s = s0;
    for (int r = 0; r < n_robots_; ++r) {
      if (s.held[r] == m.moved || s.held[r] == m.base) {
        s.held[r] = -1;
        s.grasp[r] = -1;
      }
    }
    s.loc[m.moved] = kInAir;
    s.held[t.rm] = static_cast<int16_t>(m.moved);
    s.grasp[t.rm] = t.gm;
    if (!t.base_rests) s.loc[m.base] = kInAir;
    if (t.rb >= 0) {
      s.held[t.rb] = static_cast<int16_t>(m.base);
      s.grasp[t.rb] = t.gb;
    }
    return CheapAssemble(s, m);
  };
  auto first_support = [&](AssemblyTarget t) -> std::optional<AssemblyTarget> {
    for (int rb = 0; rb < n_robots_; ++rb) {
      if (rb == t.rm) continue;
      const std::vector<int>& ids = GraspIds(m.base, rb);
      for (int j = 0; j < std::min<int>(res.grasps, static_cast<int>(ids.size())); ++j) {
        if (!AssemblyGrasp(1, rb, ids[j])) continue;
        t.rb = rb;
        t.gb = ids[j];
        if (holds(t)) return t;
      }
    }
    return std::nullopt;
  };
  int most = 0;
  for (int r = 0; r < n_robots_; ++r) {
    most = std::max(most, static_cast<int>(GraspIds(m.moved, r).size()));
  }
  most = std::min(most, res.grasps);
  const bool base_rests = s0.loc[m.base] >= 0;
  for (int i = 0; i < most && static_cast<int>(targets.size()) < kTargets; ++i) {
    for (int r = 0; r < n_robots_ && static_cast<int>(targets.size()) < kTargets; ++r) {
      const std::vector<int>& ids = GraspIds(m.moved, r);
      if (i >= static_cast<int>(ids.size()) || !AssemblyGrasp(0, r, ids[i])) continue;
      AssemblyTarget t{r, ids[i], -1, -1, base_rests};
      if (base_rests && holds(t)) {
        targets.push_back(t);
        continue;
      }
      if (base_rests) {
        // Optimistic about the pose too: the base set down in some placement elsewhere.
        AssemblyTarget placed = t;
        placed.base_moved = true;
        targets.push_back(placed);
      }
      std::optional<AssemblyTarget> found;
      if (base_rests) found = first_support(t);
      if (!found) {
        t.base_rests = false;
        found = first_support(t);
      }
      if (found) targets.push_back(*found);
    }
  }
  return targets;
}

}  // namespace wrap
