#include "motion/retime.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <string>

namespace wrap {

namespace {

// A time-optimal rest-to-rest trapezoid in the path parameter s in [0, 1] of one straight piece.
struct Profile {
  double t_acc = 0.0;    // acceleration phase [s]
  double t_total = 0.0;  // whole piece [s]
  double s_acc = 0.0;    // s reached at the end of the acceleration phase
  double v_peak = 0.0;   // peak ds/dt [1/s]
};

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

bool Overlap(const Aabb& a, const Aabb& b) {
  return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

// Sweeps (per body: the whole, then runs) meet: some pair of bodies whose wholes overlap has a
// pair of runs that overlap.
bool SweepsMeet(const std::vector<std::vector<Aabb>>& a, const std::vector<std::vector<Aabb>>& b) {
  for (const auto& x : a) {
    for (const auto& y : b) {
      if (x.empty() || y.empty() || !Overlap(x[0], y[0])) continue;
      for (size_t i = 1; i < x.size(); ++i) {
        if (!Overlap(x[i], y[0])) continue;
        for (size_t j = 1; j < y.size(); ++j) {
          if (Overlap(x[i], y[j])) return true;
        }
      }
    }
  }
  return false;
}

// A segment's motion as knots relative to its start: per knot the time, and per robot q, qd.
struct TimedSegment {
  double duration = 0.0;
  double stretch = 1.0;  // how much slower than its fastest timing
  std::vector<double> t;
  std::vector<std::vector<JointVector>> q;   // q[k][i]
  std::vector<std::vector<JointVector>> qd;  // qd[k][i]
};

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
    if (p.t_total <= 0.0) continue;
    p.t_acc *= f;
    p.t_total *= f;
    p.v_peak /= f;
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

}  // namespace

Result<Timing> Retime(const TaskWorld& world, const Plan& plan,
                      const std::vector<GeoSegment>& segments, const RunContext* log) {
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
  Timing out;
  std::vector<TimedSegment> timed;
  for (const GeoSegment& s : segments) timed.push_back(TimeSegment(world, s));

  // The schedule.
  std::vector<double> start(n_seg, 0.0), end(n_seg, 0.0);
  std::vector<int> last_of_robot(n_robots, -1);
  std::map<int, int> last_of_object;
  for (int j = 0; j < n_seg; ++j) {
    const GeoSegment& s = segments[j];
    std::vector<char> dep(j, 0);  // 1 robot, 2 object, 3 sweep
    for (int r : s.robots) {
      if (last_of_robot[r] >= 0) dep[last_of_robot[r]] = 1;
    }
    for (int o : s.objects) {
      if (auto it = last_of_object.find(o); it != last_of_object.end() && !dep[it->second]) {
        dep[it->second] = 2;
      }
    }
    for (int i = 0; i < j; ++i) {
      if (!dep[i] && SweepsMeet(segments[i].sweep, s.sweep)) dep[i] = 3;
    }
    double t = 0.0;
    int binding = -1;
    for (int i = 0; i < j; ++i) {
      if (dep[i]) {
        if (end[i] > t) binding = i;
        t = std::max(t, end[i]);
        ++out.dependencies;
      }
    }
    if (log && log->Logs("motion")) {
      log->Log("motion", StrFormat("schedule: %d %s a%d waits for %d (%s)", j,
                                   std::string(ToString(s.kind)).c_str(), s.action + 1, binding,
                                   binding < 0                ? "-"
                                   : dep[binding] == 1 ? "robot"
                                   : dep[binding] == 2 ? "object"
                                                       : "sweep"));
    }
    start[j] = t;
    end[j] = t + timed[j].duration;
    out.makespan_sequential_s += timed[j].duration;
    for (int r : s.robots) last_of_robot[r] = j;
    for (int o : s.objects) last_of_object[o] = j;
  }
  for (int j = 0; j < n_seg; ++j) out.makespan_s = std::max(out.makespan_s, end[j]);

  // Trajectories.
  std::vector<int> order(n_seg);
  for (int j = 0; j < n_seg; ++j) order[j] = j;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return start[a] < start[b]; });
  out.trajectories.resize(n_robots);
  for (int r = 0; r < n_robots; ++r) {
    RobotTrajectory& tr = out.trajectories[r];
    tr.robot = r;
    TrajectoryKnot k0;
    k0.t = 0.0;
    k0.q = plan.initial.q[r];
    k0.qd = JointVector::Zero(k0.q.size());
    tr.knots.push_back(k0);
  }
  for (int j : order) {
    const GeoSegment& s = segments[j];
    const TimedSegment& ts = timed[j];
    for (size_t i = 0; i < s.robots.size(); ++i) {
      const int r = s.robots[i];
      RobotTrajectory& tr = out.trajectories[r];
      const double opening = r < static_cast<int>(s.openings.size()) ? s.openings[r] : -1.0;
      if (start[j] > tr.knots.back().t + 1e-12) {
        TrajectoryKnot wait = tr.knots.back();
        wait.t = start[j];
        wait.qd.setZero();
        tr.knots.push_back(wait);
      }
      tr.knots.back().opening_m = opening;
      for (size_t k = 1; k < ts.t.size(); ++k) {
        TrajectoryKnot knot;
        knot.t = start[j] + ts.t[k];
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
  for (RobotTrajectory& tr : out.trajectories) {
    if (out.makespan_s > tr.knots.back().t + 1e-12) {
      TrajectoryKnot rest = tr.knots.back();
      rest.t = out.makespan_s;
      rest.qd.setZero();
      tr.knots.push_back(rest);
    }
  }

  // Segments and actions.
  const int n_actions = static_cast<int>(plan.actions.size());
  out.action_start_s.assign(n_actions, std::numeric_limits<double>::infinity());
  out.action_end_s.assign(n_actions, 0.0);
  for (int j : order) {
    const GeoSegment& s = segments[j];
    MotionSegment m;
    m.kind = std::string(ToString(s.kind));
    m.action = s.action;
    m.robots = s.robots;
    m.objects = s.objects;
    m.start_s = start[j];
    m.end_s = end[j];
    out.segments.push_back(std::move(m));
    if (s.action >= 0 && s.action < n_actions && s.main) {
      out.action_start_s[s.action] = std::min(out.action_start_s[s.action], start[j]);
      if (s.kind == SegmentKind::kGrip) out.action_end_s[s.action] = end[j];
    }
  }
  for (int i = 0; i < n_actions; ++i) {
    if (!std::isfinite(out.action_start_s[i])) out.action_start_s[i] = out.action_end_s[i];
  }
  out.segment_start_s = start;
  out.segment_end_s = end;
  for (const TimedSegment& ts : timed) out.segment_stretch.push_back(ts.stretch);
  return out;
}

}  // namespace wrap
