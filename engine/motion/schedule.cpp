// The schedule of the timed segments (retime_internal.h), in plan order. Segments are planned
// geometrically one after another, each in the cell as the sequence leaves it; here each is
// placed at the earliest candidate start at which nothing placed before it conflicts with it:
// its robots' previous segments and the earlier segments on its objects have ended, and its
// timed motion, with its robots' rest at its end afterwards, collides with nothing placed
// before it (schedule_check.cpp). The swept boxes of the segments (GeoSegment::sweep) with the
// times of their chunks are the cheap prefilter: where they never meet, nothing is posed.
#include <algorithm>
#include <cmath>
#include <deque>
#include <string>
#include <tuple>

#include "motion/retime_internal.h"

namespace wrap::detail {

namespace {

// The spans where some body of `a` and some body of `b` may come within `grow` of each other:
// for each pair of bodies whose whole boxes meet, the chunks of both that overlap in time and
// whose boxes meet.
void Meet(const TimedBoxes& a, const TimedBoxes& b, double grow, std::vector<Span>& out) {
  const size_t na = a.t.size() - 1, nb = b.t.size() - 1;
  if (a.t.back() < b.t.front() || b.t.back() < a.t.front()) return;
  for (const std::vector<Aabb>& x : *a.boxes) {
    for (const std::vector<Aabb>& y : *b.boxes) {
      if (!Overlap(x[0], y[0], grow)) continue;
      size_t i = 0, k = 0;
      while (i < na && k < nb) {
        const double lo = std::max(a.t[i], b.t[k]), hi = std::min(a.t[i + 1], b.t[k + 1]);
        if (lo <= hi && Overlap(x[i + 1], y[k + 1], grow)) {
          out.push_back({lo, hi, a.segment, b.segment});
        }
        if (a.t[i + 1] < b.t[k + 1]) {
          ++i;
        } else {
          ++k;
        }
      }
    }
  }
}

// Spans within [lo, hi], sorted, those of the same moving segments merged.
std::vector<Span> Merge(std::vector<Span> spans, double lo, double hi) {
  for (Span& s : spans) {
    s.lo = std::max(s.lo, lo);
    s.hi = std::min(s.hi, hi);
  }
  std::erase_if(spans, [](const Span& s) { return s.hi < s.lo; });
  std::sort(spans.begin(), spans.end(), [](const Span& x, const Span& y) {
    return std::tie(x.moving_a, x.moving_b, x.lo) < std::tie(y.moving_a, y.moving_b, y.lo);
  });
  std::vector<Span> out;
  for (const Span& s : spans) {
    if (!out.empty() && out.back().moving_a == s.moving_a && out.back().moving_b == s.moving_b &&
        s.lo <= out.back().hi + kEps) {
      out.back().hi = std::max(out.back().hi, s.hi);
    } else {
      out.push_back(s);
    }
  }
  return out;
}

// A box that meets every other: a segment whose sweep is unknown.
std::vector<std::vector<Aabb>> Everywhere() {
  constexpr double kFar = 1e6;  // [m]
  const Aabb all{Vec3::Constant(-kFar), Vec3::Constant(kFar)};
  return {{all, all}};
}

}  // namespace

Result<std::vector<Slot>> Scheduler::Run(ScheduleStats* stats) {
  const int n = static_cast<int>(segs_.size());
  const int n_robots = static_cast<int>(w_.robots.size());
  slots_.assign(n, {});
  placed_.assign(n, 0);
  robot_segments_.assign(n_robots, {});
  last_of_robot_.assign(n_robots, -1);
  if (n > 1 && opt_.concurrent && scene_ == nullptr) {
    auto scene = MotionScene::Build(w_);
    if (!scene) return std::unexpected(scene.error());
    own_scene_ = std::move(*scene);
    scene_ = &*own_scene_;
  }
  Prepare();
  for (int j = 0; j < n; ++j) Place(j);
  if (stats) *stats = stats_;
  return slots_;
}

void Scheduler::Prepare() {
  const int n = static_cast<int>(segs_.size());
  boxes_.assign(n, nullptr);
  own_.assign(n, {});
  chunk_t_.assign(n, {});
  first_boxes_.assign(n, {});
  last_boxes_.assign(n, {});
  samples_.assign(n, {});
  grip_of_action_.assign(plan_.actions.size(), -1);
  acts_.assign(n, {});
  const std::vector<PlanState> states = ReplayPlanStates(plan_);
  std::vector<char> gripped(plan_.actions.size(), 0);
  for (int j = 0; j < n; ++j) {
    // The objects it acts on: a free path only on what its robots carry (one that heads for an
    // object to grasp keeps clear of it), the others on all they name. Its robots hold in the
    // state it was planned in: before its action, or after it (the robots' way home).
    const GeoSegment& g = segs_[j];
    const int a = g.action;
    if (g.kind != SegmentKind::kFree || a >= static_cast<int>(gripped.size())) {
      acts_[j] = g.objects;
    } else {
      // (No action: before the first.)
      const PlanState& state = a < 0 ? states.front() : states[a + (gripped[a] ? 1 : 0)];
      for (int o : g.objects) {
        if (std::any_of(g.robots.begin(), g.robots.end(), [&](int r) {
              return r < static_cast<int>(state.held.size()) && state.held[r] == o;
            })) {
          acts_[j].push_back(o);
        }
      }
    }
    if (g.kind == SegmentKind::kGrip && a >= 0 && a < static_cast<int>(gripped.size())) {
      gripped[a] = 1;
    }
  }
  for (int j = 0; j < n; ++j) {
    const GeoSegment& g = segs_[j];
    const TimedSegment& ts = timed_[j];
    const size_t chunks = g.sweep.empty() ? 0 : g.sweep[0].size() - 1;
    const bool timed_chunks =
        chunks >= 1 && g.sweep_u.size() == chunks &&
        std::all_of(g.sweep.begin(), g.sweep.end(),
                    [&](const std::vector<Aabb>& b) { return b.size() == chunks + 1; });
    if (timed_chunks) {
      boxes_[j] = &g.sweep;
      for (size_t c = 0; c < chunks; ++c) {
        const double t = c == 0 ? 0.0 : ts.TimeAt(g.sweep_u[c]);
        chunk_t_[j].push_back(c == 0 ? 0.0 : std::max(chunk_t_[j].back(), t));
      }
      chunk_t_[j].push_back(std::max(chunk_t_[j].back(), ts.duration));
      for (const std::vector<Aabb>& b : g.sweep) {
        first_boxes_[j].push_back({b[1], b[1]});
        last_boxes_[j].push_back({b.back(), b.back()});
      }
    } else {
      // Without chunks: its whole boxes (or, without a sweep, everywhere) all along.
      if (g.sweep.empty()) {
        own_[j] = Everywhere();
      } else {
        for (const std::vector<Aabb>& b : g.sweep) own_[j].push_back({b[0], b[0]});
      }
      boxes_[j] = &own_[j];
      chunk_t_[j] = {0.0, ts.duration};
      first_boxes_[j] = own_[j];
      last_boxes_[j] = own_[j];
    }
    samples_[j] = ts.Samples(opt_.resolution_rad);
    if (g.kind == SegmentKind::kGrip && g.main && g.action >= 0 &&
        g.action < static_cast<int>(grip_of_action_.size())) {
      grip_of_action_[g.action] = j;
    }
  }
  for (int p = 0; p < w_.num_parts; ++p) {
    Aabb box{Vec3::Constant(1e300), Vec3::Constant(-1e300)};
    for (const Vec3& v : w_.cell_def.objects[p].mesh.vertices) {
      box.min = box.min.cwiseMin(v);
      box.max = box.max.cwiseMax(v);
    }
    part_box_.push_back(box);
  }
}

void Scheduler::Place(int j) {
  const GeoSegment& g = segs_[j];
  const double duration = timed_[j].duration;
  // Ready when its robots' previous segments and the earlier segments on its objects have
  // ended (events on one robot or one object keep the plan's order).
  double ready = 0.0;
  int binding = -1;
  WaitKind kind = WaitKind::kNone;
  auto after = [&](int i, WaitKind why) {
    if (i >= 0 && (binding < 0 || slots_[i].end_s > ready)) {
      ready = slots_[i].end_s;
      binding = i;
      kind = why;
    }
  };
  for (int r : g.robots) after(last_of_robot_[r], WaitKind::kRobot);
  for (int o : acts_[j]) {
    if (auto it = last_of_object_.find(o); it != last_of_object_.end()) {
      after(it->second, WaitKind::kObject);
    }
  }
  // Candidate starts: when it is ready, then each later end of a placed segment. The latest of
  // them (everything placed has ended) is the cell the segment was planned in: robots where the
  // sequence left them, objects where its events put them. It is always feasible, so the loop
  // ends there at the latest, untested; every earlier one is tested.
  std::vector<double> candidates = {ready};
  for (int i = 0; i < j; ++i) {
    if (slots_[i].end_s > ready + kEps) candidates.push_back(slots_[i].end_s);
  }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end(),
                               [](double a, double b) { return std::abs(a - b) <= kEps; }),
                   candidates.end());
  const bool alone = g.after_all || !opt_.concurrent;
  double start = std::max(ready, latest_);
  int blame = -1;
  double failed = -1.0;       // the latest start that failed
  double not_before = ready;  // no start before it can succeed
  // What a failed start at t says of later ones: what it hit stays there until hit.until, so
  // the same collision recurs for every start that brings the same moment of its motion there
  // before then (at rest at its end: every start that ends before then).
  auto learn = [&](double t, const Conflict& hit) {
    blame = hit.segment;
    failed = std::max(failed, t);
    const double moment = std::min(hit.t - t, duration);
    not_before = std::max(not_before, std::max(hit.until, hit.t) - moment);
  };
  for (double t : candidates) {
    if (t < not_before - kEps || (alone && t < latest_ - kEps)) continue;
    ++stats_.candidates;
    if (t >= latest_ - kEps) {
      start = t;
      break;
    }
    const std::optional<Conflict> hit = TryStart(j, t);
    if (!hit) {
      start = t;
      break;
    }
    learn(t, *hit);
  }
  // Between the last start that failed and the one that succeeded, a few halvings look for an
  // earlier one (any start that passes the test is sound; the latest one still stands).
  constexpr int kHalvings = 3;
  constexpr double kMinGap = 0.1;  // [s]
  for (int k = 0; k < kHalvings && !alone && failed >= 0.0; ++k) {
    const double lo = std::max(failed, not_before);
    if (start - lo < kMinGap) break;
    const double mid = 0.5 * (lo + start);
    ++stats_.candidates;
    const std::optional<Conflict> hit = TryStart(j, mid);
    if (hit) {
      learn(mid, *hit);
    } else {
      start = mid;
    }
  }
  Slot& slot = slots_[j];
  slot.start_s = start;
  slot.end_s = start + duration;
  slot.concurrent = start < latest_ - kEps;
  if (start > ready + kEps) {
    // Scheduled after everything before it without a test: it waits for the last to end.
    for (int i = 0; i < j && blame < 0; ++i) {
      if (slots_[i].end_s >= latest_ - kEps) blame = i;
    }
    slot.wait = WaitKind::kCollision;
    slot.wait_on = blame;
  } else if (binding >= 0) {
    slot.wait = kind;
    slot.wait_on = binding;
  }
  if (log_ && log_->Logs("motion") && opt_.concurrent) {
    constexpr const char* kNames[] = {"nothing", "robot", "object", "collision with"};
    log_->Log("motion", StrFormat("schedule: %d %s a%d at %.2f s (ready %.2f s), waits for %s %d",
                                  j, std::string(ToString(g.kind)).c_str(), g.action + 1, start,
                                  ready, kNames[static_cast<int>(slot.wait)], slot.wait_on));
  }
  placed_[j] = 1;
  latest_ = std::max(latest_, slot.end_s);
  for (int r : g.robots) {
    robot_segments_[r].push_back(j);
    last_of_robot_[r] = j;
  }
  for (int o : acts_[j]) last_of_object_[o] = j;
}

std::optional<Conflict> Scheduler::TryStart(int j, double t) {
  const Window window = WindowAt(t);
  const std::vector<Span> spans = Suspect(j, window);
  if (spans.empty()) return std::nullopt;
  ++stats_.checked;
  return Check(j, window, spans);
}

Window Scheduler::WindowAt(double t) const {
  Window window;
  window.t = t;
  window.end = latest_;
  window.robots.assign(w_.robots.size(), 0);
  window.robot_end.assign(w_.robots.size(), t);
  std::map<int, double> objects;
  for (size_t i = 0; i < segs_.size(); ++i) {
    if (!placed_[i] || slots_[i].end_s <= t + kEps) continue;
    window.segments.push_back(static_cast<int>(i));
    for (int r : segs_[i].robots) {
      window.robots[r] = 1;
      window.robot_end[r] = std::max(window.robot_end[r], slots_[i].end_s);
    }
    for (int o : segs_[i].objects) {
      double& e = objects.try_emplace(o, t).first->second;
      e = std::max(e, slots_[i].end_s);
    }
  }
  window.objects.assign(objects.begin(), objects.end());
  return window;
}

TimedBoxes Scheduler::MotionBoxes(int j, double t0) const {
  TimedBoxes out;
  out.boxes = boxes_[j];
  out.segment = j;
  for (double t : chunk_t_[j]) out.t.push_back(t0 + t);
  return out;
}

void Scheduler::RestBoxes(int r, double lo, double hi, std::vector<TimedBoxes>& out) const {
  // Between its segments (before the first: where its first starts), within [lo, hi].
  double from = 0.0;
  int previous = -1;
  for (int k : robot_segments_[r]) {
    const double to = slots_[k].start_s;
    if (to > from + kEps && to > lo && from < hi) {
      TimedBoxes rest;
      rest.boxes = previous >= 0 ? &last_boxes_[previous] : &first_boxes_[k];
      rest.t = {std::max(from, lo), std::min(to, hi)};
      out.push_back(std::move(rest));
    }
    from = slots_[k].end_s;
    previous = k;
  }
}

std::vector<std::pair<double, int>> Scheduler::Events(int j, double t) const {
  std::vector<std::pair<double, int>> events;
  for (size_t a = 0; a < grip_of_action_.size(); ++a) {
    const int g = grip_of_action_[a];
    if (g < 0) continue;
    if (placed_[g]) {
      events.push_back({slots_[g].end_s, static_cast<int>(a)});
    } else if (g == j) {
      events.push_back({t + timed_[j].duration, static_cast<int>(a)});
    }
  }
  std::sort(events.begin(), events.end());
  return events;
}

void Scheduler::ObjectRestBoxes(const Window& window,
                                std::deque<std::vector<std::vector<Aabb>>>& store,
                                std::vector<TimedBoxes>& out) const {
  // The window's objects that nobody holds, between the placed events (an object held by a
  // robot of the window moves with that robot's boxes; one held by another robot stays where
  // the cell it was planned in had it).
  const std::vector<std::pair<double, int>> events = Events(-1, 0.0);
  PlanState state = InitialPlanState(plan_.initial, static_cast<int>(w_.robots.size()));
  size_t e = 0;
  while (e < events.size() && events[e].first <= window.t + kEps) {
    state = ApplyAction(state, plan_.actions[events[e].second]);
    ++e;
  }
  double lo = window.t;
  while (lo < window.end) {
    const double hi = e < events.size() ? std::min(events[e].first, window.end) : window.end;
    for (const auto& [node, last] : window.objects) {
      const auto it = state.objects.find(node);
      if (it == state.objects.end() || !state.Holders(node).empty() || last <= lo) continue;
      Aabb box{Vec3::Constant(1e300), Vec3::Constant(-1e300)};
      for (int p : w_.tree->nodes[node].parts) {
        const Iso3 X_WP = it->second.X_WA * w_.X_AP[p];
        for (int c = 0; c < 8; ++c) {
          const Aabb& b = part_box_[p];
          const Vec3 corner((c & 1) ? b.max.x() : b.min.x(), (c & 2) ? b.max.y() : b.min.y(),
                            (c & 4) ? b.max.z() : b.min.z());
          const Vec3 x = X_WP * corner;
          box.min = box.min.cwiseMin(x);
          box.max = box.max.cwiseMax(x);
        }
      }
      store.push_back({{box, box}});
      TimedBoxes rest;
      rest.boxes = &store.back();
      rest.t = {lo, std::min(hi, last)};
      out.push_back(std::move(rest));
    }
    if (e >= events.size()) break;
    const double at = events[e].first;
    while (e < events.size() && events[e].first <= at + kEps) {
      state = ApplyAction(state, plan_.actions[events[e].second]);
      ++e;
    }
    lo = at;
  }
}

std::vector<Span> Scheduler::Suspect(int j, const Window& window) const {
  const double t = window.t;
  const double end_j = t + timed_[j].duration;
  std::vector<TimedBoxes> others;
  for (int i : window.segments) others.push_back(MotionBoxes(i, slots_[i].start_s));
  for (size_t r = 0; r < window.robots.size(); ++r) {
    if (window.robots[r]) RestBoxes(static_cast<int>(r), t, window.robot_end[r], others);
  }
  std::deque<std::vector<std::vector<Aabb>>> store;  // (stable addresses)
  ObjectRestBoxes(window, store, others);
  const TimedBoxes motion = MotionBoxes(j, t);
  TimedBoxes rest;
  rest.boxes = &last_boxes_[j];
  rest.t = {end_j, window.end};
  std::vector<Span> spans;
  for (const TimedBoxes& other : others) {
    Meet(motion, other, opt_.clearance_m, spans);
    if (end_j < window.end) Meet(rest, other, opt_.clearance_m, spans);
  }
  return Merge(std::move(spans), t, window.end);
}

int Scheduler::SegmentOf(int robot, double tau) const {
  const std::vector<int>& list = robot_segments_[robot];
  const auto it = std::upper_bound(list.begin(), list.end(), tau,
                                   [&](double x, int k) { return x < slots_[k].start_s; });
  if (it == list.begin()) return list.empty() ? -1 : list.front();
  return *(it - 1);
}

}  // namespace wrap::detail
