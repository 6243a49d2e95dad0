// Retiming (retime.h): each segment timed along its path (a trapezoid per straight piece), the
// schedule (schedule.cpp) placing the timed segments, and the per-robot trajectories and timed
// segments of the plan.
#include "motion/retime.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "motion/retime_internal.h"

namespace wrap {
namespace detail {

namespace {

Profile Trapezoid(double vs, double as) {
  Profile p;
  if (!(vs > 0.0) || !(as > 0.0) || !std::isfinite(vs) || !std::isfinite(as)) return p;
  const double t_a = vs / as;
  if (vs * t_a >= 1.0) {  // triangular: never reaches the velocity limit
    p.t_acc = std::sqrt(1.0 / as);
    p.t_total = 2.0 * p.t_acc;
    p.s_acc = 0.5;
    p.v_peak = as * p.t_acc;
  } else {
    p.t_acc = t_a;
    p.s_acc = 0.5 * as * t_a * t_a;
    p.t_total = 2.0 * t_a + (1.0 - 2.0 * p.s_acc) / vs;
    p.v_peak = vs;
  }
  return p;
}

}  // namespace

double TimedSegment::TimeAt(double u) const {
  if (pieces.empty() || !(u > 0.0)) return 0.0;
  const size_t k = std::min(static_cast<size_t>(u), pieces.size() - 1);
  const double s = std::clamp(u - static_cast<double>(k), 0.0, 1.0);
  const Profile& p = pieces[k];
  const double t0 = piece_t0[k];
  if (!(p.t_total > 0.0) || !(p.s_acc > 0.0)) return t0;
  // The trapezoid inverted: accelerating, cruising, braking.
  if (s <= p.s_acc) return t0 + p.t_acc * std::sqrt(s / p.s_acc);
  if (s <= 1.0 - p.s_acc) return t0 + p.t_acc + (s - p.s_acc) / p.v_peak;
  return t0 + p.t_total - p.t_acc * std::sqrt(std::max(0.0, 1.0 - s) / p.s_acc);
}

JointVector TimedSegment::At(size_t i, double tau) const {
  if (!(tau > t.front())) return q.front()[i];
  if (tau >= t.back()) return q.back()[i];
  const size_t k = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), tau) - t.begin());
  const double dt = t[k] - t[k - 1];
  if (!(dt > 0.0)) return q[k][i];
  const double h = tau - t[k - 1];
  const JointVector acc = (qd[k][i] - qd[k - 1][i]) / dt;
  return q[k - 1][i] + h * qd[k - 1][i] + 0.5 * h * h * acc;
}

std::vector<double> TimedSegment::Samples(double resolution_rad) const {
  std::vector<double> out;
  for (size_t k = 0; k < t.size(); ++k) {
    if (k > 0) {
      const double dt = t[k] - t[k - 1];
      double v = 0.0;
      for (size_t i = 0; i < qd[k].size(); ++i) {
        v = std::max({v, qd[k][i].cwiseAbs().maxCoeff(), qd[k - 1][i].cwiseAbs().maxCoeff()});
      }
      const int n = static_cast<int>(std::ceil(v * dt / resolution_rad));
      for (int s = 1; s < n; ++s) out.push_back(t[k - 1] + dt * s / n);
    }
    out.push_back(t[k]);
  }
  return out;
}

TimedSegment TimeSegment(const TaskWorld& world, const GeoSegment& seg) {
  TimedSegment out;
  const size_t n = seg.robots.size();
  auto zero = [&](size_t i) { return JointVector::Zero(seg.waypoints[0][i].size()); };
  out.t.push_back(0.0);
  out.q.push_back(seg.waypoints[0]);
  out.qd.emplace_back();
  for (size_t i = 0; i < n; ++i) out.qd.back().push_back(zero(i));
  if (seg.kind == SegmentKind::kGrip) {
    out.duration = seg.hold_s;
    out.t.push_back(seg.hold_s);
    out.q.push_back(seg.waypoints[0]);
    out.qd.push_back(out.qd.back());
    return out;
  }
  // Per piece: the limits in s.
  std::vector<Profile> pieces;
  double total = 0.0;
  for (size_t k = 1; k < seg.waypoints.size(); ++k) {
    double vs = std::numeric_limits<double>::infinity();
    double as = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < n; ++i) {
      const Chain& chain = world.robots[seg.robots[i]].chain;
      const JointVector d = seg.waypoints[k][i] - seg.waypoints[k - 1][i];
      for (int j = 0; j < d.size(); ++j) {
        const double a = std::abs(d[j]);
        if (a < 1e-12) continue;
        vs = std::min(vs, chain.joints[j].max_velocity / a);
        as = std::min(as, chain.joints[j].max_acceleration / a);
      }
    }
    Profile p = Trapezoid(vs, as);
    pieces.push_back(p);
    total += p.t_total;
  }
  // Skills go no faster than their speed: stretch every piece by one factor (velocities / f,
  // accelerations / f^2 keep the limits).
  double f = 1.0;
  if (seg.skill_speed_mps > 0.0 && total > 0.0) {
    f = std::max(1.0, seg.skill_length_m / seg.skill_speed_mps / total);
  }
  f = std::max(f, seg.slow);
  out.stretch = f;
  double t0 = 0.0;
  for (size_t k = 1; k < seg.waypoints.size(); ++k) {
    Profile p = pieces[k - 1];
    p.t_acc *= f;
    p.t_total *= f;
    p.v_peak /= f;
    out.pieces.push_back(p);
    out.piece_t0.push_back(t0);
    if (p.t_total <= 0.0) continue;
    const auto& a = seg.waypoints[k - 1];
    const auto& b = seg.waypoints[k];
    auto push = [&](double t, double s, double sd) {
      std::vector<JointVector> q(n), qd(n);
      for (size_t i = 0; i < n; ++i) {
        q[i] = s >= 1.0 ? b[i] : JointVector(a[i] + s * (b[i] - a[i]));
        qd[i] = sd * (b[i] - a[i]);
      }
      out.t.push_back(t);
      out.q.push_back(std::move(q));
      out.qd.push_back(std::move(qd));
    };
    push(t0 + p.t_acc, p.s_acc, p.v_peak);
    if (p.t_total - 2.0 * p.t_acc > 1e-12) push(t0 + p.t_total - p.t_acc, 1.0 - p.s_acc, p.v_peak);
    push(t0 + p.t_total, 1.0, 0.0);
    t0 += p.t_total;
  }
  out.duration = t0;
  return out;
}

}  // namespace detail

namespace {

constexpr const char* kWaitNames[] = {"none", "robot", "object", "collision"};

// Per robot, from the segments' slots: knots at every segment's start and end (resting between).
std::vector<RobotTrajectory> Trajectories(const Plan& plan, const std::vector<GeoSegment>& segments,
                                          const std::vector<detail::TimedSegment>& timed,
                                          const std::vector<detail::Slot>& slots,
                                          const std::vector<int>& order, double makespan) {
  const int n_robots = static_cast<int>(plan.initial.q.size());
  std::vector<RobotTrajectory> out(n_robots);
  for (int r = 0; r < n_robots; ++r) {
    RobotTrajectory& tr = out[r];
    tr.robot = r;
    TrajectoryKnot k0;
    k0.t = 0.0;
    k0.q = plan.initial.q[r];
    k0.qd = JointVector::Zero(k0.q.size());
    tr.knots.push_back(k0);
  }
  for (int j : order) {
    const GeoSegment& s = segments[j];
    const detail::TimedSegment& ts = timed[j];
    const double start = slots[j].start_s;
    for (size_t i = 0; i < s.robots.size(); ++i) {
      const int r = s.robots[i];
      RobotTrajectory& tr = out[r];
      const double opening = r < static_cast<int>(s.openings.size()) ? s.openings[r] : -1.0;
      if (start > tr.knots.back().t + 1e-12) {
        TrajectoryKnot wait = tr.knots.back();
        wait.t = start;
        wait.qd.setZero();
        tr.knots.push_back(wait);
      }
      tr.knots.back().opening_m = opening;
      for (size_t k = 1; k < ts.t.size(); ++k) {
        TrajectoryKnot knot;
        knot.t = start + ts.t[k];
        knot.q = ts.q[k][i];
        knot.qd = ts.qd[k][i];
        knot.opening_m = opening;
        if (knot.t <= tr.knots.back().t + 1e-12) {
          knot.t = tr.knots.back().t;
          tr.knots.back() = knot;
        } else {
          tr.knots.push_back(knot);
        }
      }
    }
  }
  for (RobotTrajectory& tr : out) {
    if (makespan > tr.knots.back().t + 1e-12) {
      TrajectoryKnot rest = tr.knots.back();
      rest.t = makespan;
      rest.qd.setZero();
      tr.knots.push_back(rest);
    }
  }
  return out;
}

}  // namespace

Result<Timing> Retime(const TaskWorld& world, const Plan& plan,
                      const std::vector<GeoSegment>& segments, const RetimeOptions& options,
                      const RunContext* log, MotionScene* scene) {
  const int n_robots = static_cast<int>(world.robots.size());
  const int n_seg = static_cast<int>(segments.size());
  for (const GeoSegment& s : segments) {
    if (s.waypoints.empty()) return Fail(ErrorCode::kInvalidInput, "a motion segment is empty");
    for (int r : s.robots) {
      if (r < 0 || r >= n_robots) {
        return Fail(ErrorCode::kInvalidInput, "a motion segment names robot " + std::to_string(r));
      }
    }
  }
  if (static_cast<int>(plan.initial.q.size()) != n_robots) {
    return Fail(ErrorCode::kInvalidInput, "the plan's robots do not match the world's");
  }
  if (!(options.resolution_rad > 0.0)) {
    return Fail(ErrorCode::kInvalidInput, "the schedule's resolution must be positive");
  }
  Timing out;
  std::vector<detail::TimedSegment> timed;
  for (const GeoSegment& s : segments) timed.push_back(detail::TimeSegment(world, s));
  for (const detail::TimedSegment& ts : timed) out.makespan_sequential_s += ts.duration;

  detail::Scheduler scheduler(world, plan, segments, timed, options, log, scene);
  detail::ScheduleStats stats;
  auto slots = scheduler.Run(&stats);
  if (!slots) return std::unexpected(slots.error());
  out.candidates = stats.candidates;
  out.checked_candidates = stats.checked;
  out.check_samples = stats.samples;
  for (const detail::Slot& slot : *slots) {
    out.makespan_s = std::max(out.makespan_s, slot.end_s);
    out.dependencies += slot.wait != detail::WaitKind::kNone;
    out.collision_waits += slot.wait == detail::WaitKind::kCollision;
  }

  std::vector<int> order(n_seg);
  for (int j = 0; j < n_seg; ++j) order[j] = j;
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return (*slots)[a].start_s < (*slots)[b].start_s; });
  std::vector<int> position(n_seg);
  for (int k = 0; k < n_seg; ++k) position[order[k]] = k;
  out.trajectories = Trajectories(plan, segments, timed, *slots, order, out.makespan_s);

  // Segments and actions.
  const int n_actions = static_cast<int>(plan.actions.size());
  out.action_start_s.assign(n_actions, std::numeric_limits<double>::infinity());
  out.action_end_s.assign(n_actions, 0.0);
  for (int j : order) {
    const GeoSegment& s = segments[j];
    const detail::Slot& slot = (*slots)[j];
    MotionSegment m;
    m.kind = std::string(ToString(s.kind));
    m.action = s.action;
    m.robots = s.robots;
    m.objects = s.objects;
    m.start_s = slot.start_s;
    m.end_s = slot.end_s;
    m.wait = kWaitNames[static_cast<int>(slot.wait)];
    m.wait_segment = slot.wait_on >= 0 ? position[slot.wait_on] : -1;
    out.segments.push_back(std::move(m));
    if (s.action >= 0 && s.action < n_actions && s.main) {
      out.action_start_s[s.action] = std::min(out.action_start_s[s.action], slot.start_s);
      if (s.kind == SegmentKind::kGrip) out.action_end_s[s.action] = slot.end_s;
    }
  }
  for (int i = 0; i < n_actions; ++i) {
    if (!std::isfinite(out.action_start_s[i])) out.action_start_s[i] = out.action_end_s[i];
  }
  for (const detail::Slot& slot : *slots) {
    out.segment_start_s.push_back(slot.start_s);
    out.segment_end_s.push_back(slot.end_s);
    out.segment_concurrent.push_back(slot.concurrent ? 1 : 0);
  }
  for (const detail::TimedSegment& ts : timed) out.segment_stretch.push_back(ts.stretch);
  return out;
}

}  // namespace wrap
