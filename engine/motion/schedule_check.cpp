// The schedule's collision test (retime_internal.h): the timeline's cell at a moment (every
// robot where the placed segments, and the candidate, have it; the objects as the placed events
// up to then leave them, posed by the motion planner's scene) and the test of what the candidate
// changes (its robots, what they carry, its objects) against what differs from the cell it was
// planned in (the robots of the segments still under way and the objects they name or carry).
// Everything else is where the candidate's plan had it, and the motion planner checked that.
#include <algorithm>
#include <cmath>

#include "motion/retime_internal.h"

namespace wrap::detail {

void Scheduler::RobotAt(int r, double tau, int j, double t, JointVector& q, double& opening) const {
  auto opening_in = [&](int k) {
    const std::vector<double>& o = segs_[k].openings;
    return r < static_cast<int>(o.size()) ? o[r] : -1.0;
  };
  auto index_in = [&](int k) {
    const std::vector<int>& robots = segs_[k].robots;
    return static_cast<size_t>(std::find(robots.begin(), robots.end(), r) - robots.begin());
  };
  if (tau >= t && index_in(j) < segs_[j].robots.size()) {
    q = timed_[j].At(index_in(j), tau - t);
    opening = opening_in(j);
    return;
  }
  // The placed segment under way, or the last one before tau (at rest at its end since).
  const std::vector<int>& list = robot_segments_[r];
  const auto it = std::upper_bound(list.begin(), list.end(), tau,
                                   [&](double x, int k) { return x < slots_[k].start_s; });
  if (it == list.begin()) {
    q = plan_.initial.q[r];
    opening = -1.0;
    return;
  }
  const int k = *(it - 1);
  q = timed_[k].At(index_in(k), tau - slots_[k].start_s);
  opening = opening_in(k);
}

std::vector<double> Scheduler::SampleTimes(int j, const Window& window,
                                           const std::vector<Span>& spans) const {
  std::vector<double> times;
  auto add = [&](int k, const Span& s) {
    if (k < 0) return;
    const double t0 = k == j ? window.t : slots_[k].start_s;
    const std::vector<double>& rel = samples_[k];
    for (auto it = std::lower_bound(rel.begin(), rel.end(), s.lo - t0);
         it != rel.end() && *it <= s.hi - t0; ++it) {
      times.push_back(t0 + *it);
    }
  };
  for (const Span& s : spans) {
    times.push_back(s.lo);
    times.push_back(s.hi);
    add(s.moving_a, s);
    if (s.moving_b != s.moving_a) add(s.moving_b, s);
  }
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end(),
                          [](double a, double b) { return std::abs(a - b) <= kEps; }),
              times.end());
  return times;
}

std::optional<Conflict> Scheduler::Check(int j, const Window& window,
                                         const std::vector<Span>& spans) {
  const int n_robots = static_cast<int>(w_.robots.size());
  const std::vector<double> times = SampleTimes(j, window, spans);
  const std::vector<std::pair<double, int>> events = Events(j, window.t);
  // Coarse to fine: a start that fails mostly fails over a stretch of moments, so every 16th
  // moment first, then those halfway between, and so on (each pass in time order, for the
  // events); a start that passes is tested at every moment all the same.
  constexpr int kCoarsest = 16;
  MomentState m;
  m.q.resize(n_robots);
  m.openings.resize(n_robots);
  for (int stride = kCoarsest; stride >= 1; stride /= 2) {
    m.state = InitialPlanState(plan_.initial, n_robots);
    m.posed_openings.clear();
    size_t e = 0;
    for (size_t k = 0; k < times.size(); k += stride) {
      if (stride < kCoarsest && k % (2 * stride) == 0) continue;  // an earlier pass's
      const double tau = times[k];
      while (e < events.size() && events[e].first <= tau + 1e-12) {
        m.state = ApplyAction(m.state, plan_.actions[events[e].second]);
        m.posed_openings.clear();
        ++e;
      }
      if (auto hit = CheckMoment(j, window, tau, m)) return hit;
    }
  }
  return std::nullopt;
}

std::optional<Conflict> Scheduler::CheckMoment(int j, const Window& window, double tau,
                                               MomentState& m) {
  const GeoSegment& g = segs_[j];
  const int n_robots = static_cast<int>(w_.robots.size());
  const PlanState& state = m.state;
  // The robots that matter: the candidate's, the window's, and the holders of what they hold
  // or name (the objects follow their first holder).
  std::vector<char>& posed = m.posed;
  posed.assign(n_robots, 0);
  for (int r = 0; r < n_robots; ++r) posed[r] = window.robots[r];
  for (int r : g.robots) posed[r] = 1;
  for (const auto& [node, o] : state.objects) {
    const std::vector<int> holders = state.Holders(node);
    if (holders.empty()) continue;
    const bool wanted =
        std::any_of(holders.begin(), holders.end(), [&](int r) { return posed[r] != 0; }) ||
        std::any_of(window.objects.begin(), window.objects.end(),
                    [&](const auto& x) { return x.first == node; });
    if (wanted) {
      for (int r : holders) posed[r] = 2;  // (2: only for what it holds)
    }
  }
  for (int r = 0; r < n_robots; ++r) {
    if (posed[r]) RobotAt(r, tau, j, window.t, m.q[r], m.openings[r]);
  }
  ++stats_.samples;
  // The whole scene when the state or a finger opening changes; else only the robots that
  // matter move.
  if (m.openings != m.posed_openings) {
    for (int r = 0; r < n_robots; ++r) RobotAt(r, tau, j, window.t, m.q[r], m.openings[r]);
    if (!scene_->Set(state, m.openings, m.q)) return Conflict{tau, window.segments.front(), tau};
    m.posed_openings = m.openings;
  } else {
    for (int r = 0; r < n_robots; ++r) {
      if (posed[r]) scene_->SetRobot(r, m.q[r]);
    }
  }
  Cell& cell = scene_->cell();
  CollisionWorld& cw = cell.world();
  // What the candidate changes: its robots, what they hold, the objects it acts on. What
  // differs from its plan's cell: the window's robots, what they hold, the objects the window
  // names.
  std::vector<Body>& changed = m.changed;
  std::vector<Body>& other = m.other;
  changed.clear();
  other.clear();
  auto add_robot = [&](int r, std::vector<Body>& to) {
    const int links = static_cast<int>(w_.robots[r].chain.links.size());
    for (int i = 1; i < links; ++i) to.push_back({cell.link_body(r, i), {}, r, false, -1});
    to.push_back({cell.end_effector_body(r), {}, r, true, -1});
  };
  auto add_object = [&](int node, std::vector<Body>& to) {
    for (int p : w_.tree->nodes[node].parts)
      to.push_back({cell.object_body(p), {}, -1, false, node});
  };
  auto is_changed = [&](int node) {
    if (std::find(acts_[j].begin(), acts_[j].end(), node) != acts_[j].end()) return true;
    return std::any_of(g.robots.begin(), g.robots.end(),
                       [&](int r) { return state.held[r] == node; });
  };
  for (int r : g.robots) add_robot(r, changed);
  for (int r = 0; r < n_robots; ++r) {
    if (window.robots[r] && std::find(g.robots.begin(), g.robots.end(), r) == g.robots.end()) {
      add_robot(r, other);
    }
  }
  for (const auto& [node, o] : state.objects) {
    if (is_changed(node)) {
      add_object(node, changed);
      continue;
    }
    const bool named = std::any_of(window.objects.begin(), window.objects.end(),
                                   [&](const auto& x) { return x.first == node; });
    const std::vector<int> holders = state.Holders(node);
    const bool carried =
        std::any_of(holders.begin(), holders.end(), [&](int r) { return window.robots[r] != 0; });
    if (named || carried) add_object(node, other);
  }
  for (Body& b : changed) b.box = cw.body_aabb(b.id);
  for (Body& b : other) b.box = cw.body_aabb(b.id);
  // A gripper may touch what it holds.
  auto holds = [&](const Body& a, const Body& b) {
    return a.gripper && b.node >= 0 && state.held[a.robot] == b.node;
  };
  CollisionRequest request;
  request.margin_m = opt_.clearance_m;
  for (const Body& a : changed) {
    for (const Body& b : other) {
      if (!Overlap(a.box, b.box, opt_.clearance_m) || holds(a, b) || holds(b, a)) continue;
      ++stats_.pair_tests;
      if (cw.Collide(a.id, b.id, request)) return Blame(b.robot, b.node, tau, window, state);
    }
  }
  return std::nullopt;
}

Conflict Scheduler::Blame(int robot, int node, double tau, const Window& window,
                          const PlanState& state) const {
  Conflict out{tau, -1, tau};
  // A robot: its segment then; at rest, until its next segment starts.
  auto robot_blame = [&](int r) {
    out.segment = SegmentOf(r, tau);
    const std::vector<int>& list = robot_segments_[r];
    const auto next = std::upper_bound(list.begin(), list.end(), tau,
                                       [&](double x, int k) { return x < slots_[k].start_s; });
    const bool moving = next != list.begin() && slots_[*(next - 1)].end_s > tau &&
                        slots_[*(next - 1)].start_s <= tau;
    if (!moving) out.until = next == list.end() ? window.end : slots_[*next].start_s;
    return out;
  };
  if (robot >= 0) return robot_blame(robot);
  // An object: its carrier's; else it stays until the next segment that acts on it starts (the
  // one it waits for), or it was last moved by one.
  for (int r : state.Holders(node)) {
    if (window.robots[r]) return robot_blame(r);
  }
  int next = -1, last = -1;
  for (int i : window.segments) {
    if (std::find(acts_[i].begin(), acts_[i].end(), node) == acts_[i].end()) continue;
    const double s = slots_[i].start_s;
    if (s >= tau && (next < 0 || s < slots_[next].start_s)) next = i;
    if (s < tau && (last < 0 || s > slots_[last].start_s)) last = i;
  }
  out.segment = next >= 0 ? next : last >= 0 ? last : window.segments.front();
  out.until = next >= 0 ? slots_[next].start_s : window.end;
  return out;
}

}  // namespace wrap::detail
