#include "motion/motion.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "motion/retime.h"
#include "motion/scene.h"
#include "motion/trajectory_check.h"
#include "task/plan_json.h"

namespace wrap {

namespace {
double Since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
// The load that an object carried by one robot puts on its gripper along timed segment `g`
// (start t0, end t1): gravity and the object's inertia (its centre of mass's acceleration from
// the trajectory; its rotational inertia neglected), in the grasp frame, against the gripper's
// box (a vacuum cup's transport limits, the two-finger limits). Kept per sample, weight and
// inertia apart, so that the load of the same path run slower can be told without sampling it
// again: Peak(s) is the largest ratio of a component to its limit with the accelerations
// scaled by s (a path run k times slower: s = 1 / k^2), 0 when no object is carried alone.
class CarryLoad {
 public:
  CarryLoad(const TaskWorld& world, const Plan& plan, const std::vector<PlanState>& states,
            const std::vector<double>& action_end_s, const GeoSegment& g, double t0, double t1) {
    if (g.action < 0 || g.action >= static_cast<int>(action_end_s.size()) || !(t1 > t0)) return;
    // Before its action, or after it (the robots' way home at the end).
    const bool after = t0 >= action_end_s[g.action] - 1e-9;
    const PlanState& st = states[static_cast<size_t>(g.action) + (after ? 1 : 0)];
    for (int r : g.robots) {
      const std::optional<SoleLoad> load = SoleLoadOf(world, st, r);
      if (!load) continue;
      const TaskRobot& robot = world.robots[r];
      auto X_WG = [&](double t) {
        return TcpPose(robot.chain, robot.X_WB, SampleTrajectory(plan.trajectories[r], t),
                       robot.end_effector.X_FT);
      };
      const Vec3& c = load->com_G;
      constexpr double h = 0.002;  // [s]
      const int n = std::max(8, static_cast<int>(std::ceil((t1 - t0) / 0.02)));
      loads_.push_back(*load);
      for (int k = 0; k <= n; ++k) {
        const double t = std::clamp(t0 + (t1 - t0) * k / n, t0 + h, t1 - h);
        const Iso3 X = X_WG(t);
        const Vec3 a = (X_WG(t + h) * c - 2.0 * (X * c) + X_WG(t - h) * c) / (h * h);
        samples_.push_back({loads_.size() - 1, X.linear(), a});
      }
    }
  }
  double Peak(double accel_scale) const {
    double peak = 0.0;
    for (const Sample& s : samples_) {
      peak = std::max(peak, LoadRatio(loads_[s.load], s.R_WG, accel_scale * s.accel_W));
    }
    return peak;
  }

 private:
  struct Sample {
    size_t load;  // index in loads_
    Mat3 R_WG;
    Vec3 accel_W;  // the centre of mass's acceleration
  };
  std::vector<SoleLoad> loads_;
  std::vector<Sample> samples_;
};

// Retime, and where an object carried by one robot would load its gripper beyond kMaxLoad with
// its weight and inertia, that segment runs slower (the inertial part falls with the square of
// the time stretch; g.slow of `segments` set). A segment's own timing does not depend on when it
// starts, so the slow-downs are found on segments one at a time, and the schedule is made once.
Result<Timing> RetimeWithinLoads(const TaskWorld& world, Plan& plan,
                                 std::vector<GeoSegment>& segments, const RetimeOptions& options,
                                 MotionScene& scene, RunContext& ctx) {
  // An object carried by one robot loads its gripper at most this fraction of the limits, weight
  // and inertia together (MuJoCo's welds see the same), by slowing its segments down, at most
  // kMaxSlow times.
  constexpr double kMaxLoad = 0.9;
  constexpr double kMaxSlow = 6.0;
  RetimeOptions one_at_a_time = options;
  one_at_a_time.concurrent = false;
  auto timing = Retime(world, plan, segments, one_at_a_time, &ctx);
  const std::vector<PlanState> states = ReplayPlanStates(plan);
  for (int round = 0; round < 4 && timing; ++round) {
    bool slowed = false;
    plan.trajectories = timing->trajectories;
    for (size_t j = 0; j < segments.size(); ++j) {
      GeoSegment& g = segments[j];
      if (g.kind == SegmentKind::kGrip) continue;
      const CarryLoad load(world, plan, states, timing->action_end_s, g, timing->segment_start_s[j],
                           timing->segment_end_s[j]);
      const double peak = load.Peak(1.0);
      if (peak <= kMaxLoad) continue;
      // The least slow-down that brings it within kMaxLoad, or (where the weight alone comes
      // near) within a little of the weight's own load, in steps of 10%.
      const double target = std::max(kMaxLoad, load.Peak(0.0) + 0.03);
      const double f = timing->segment_stretch[j];
      double k = 1.0;
      while (f * k < kMaxSlow && load.Peak(1.0 / (k * k)) > target) k *= 1.1;
      k = std::min(k, kMaxSlow / f);
      if (ctx.Logs("motion")) {
        ctx.Log("motion",
                StrFormat("load: segment %zu (%s, action %d): peak %.2f (weight %.2f), %.2f x "
                          "slower: %.2f",
                          j, std::string(ToString(g.kind)).c_str(), g.action + 1, peak,
                          load.Peak(0.0), f * k, load.Peak(1.0 / (k * k))));
      }
      if (k <= 1.0 + 1e-9) continue;
      g.slow = f * k;
      slowed = true;
    }
    if (!slowed) break;
    timing = Retime(world, plan, segments, one_at_a_time, &ctx);
  }
  if (!timing) return timing;
  return Retime(world, plan, segments, options, &ctx, &scene);
}

// The plan takes the timing: trajectories, timed segments, the actions' times, the stats.
void KeepTiming(Plan& plan, Timing& timing, size_t n_segments) {
  plan.trajectories = std::move(timing.trajectories);
  plan.segments = std::move(timing.segments);
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    plan.actions[i].start_s = timing.action_start_s[i];
    plan.actions[i].end_s = timing.action_end_s[i];
  }
  plan.stats.motion = true;
  plan.stats.makespan_s = timing.makespan_s;
  plan.stats.makespan_sequential_s = timing.makespan_sequential_s;
  plan.stats.motion_segments = static_cast<int>(n_segments);
}

// The free paths (their free segment indices) under way at the moment of a collision issue, of
// the robot it names (any robot when it names none).
std::vector<int> FreePathsAt(const std::vector<GeoSegment>& segments, const Timing& timing,
                             const TrajectoryIssue& issue) {
  std::vector<int> redo;
  for (size_t j = 0; j < segments.size(); ++j) {
    const GeoSegment& g = segments[j];
    if (g.free_index < 0 || issue.t < timing.segment_start_s[j] - 1e-9 ||
        issue.t > timing.segment_end_s[j] + 1e-9) {
      continue;
    }
    if (issue.robot >= 0 &&
        std::find(g.robots.begin(), g.robots.end(), issue.robot) == g.robots.end()) {
      continue;
    }
    redo.push_back(g.free_index);
  }
  return redo;
}

// The segments to schedule after everything before them when the trajectory check finds a
// collision at t: the segment under way then (or the last before) of the robot it names, where
// that was scheduled beside others; otherwise every robot's such segment.
std::vector<int> ConcurrentAt(const std::vector<GeoSegment>& segments, const Timing& timing,
                              const TrajectoryIssue& issue) {
  std::map<int, int> last;  // robot -> segment
  for (size_t j = 0; j < segments.size(); ++j) {
    if (timing.segment_start_s[j] > issue.t + 1e-9) continue;
    for (int r : segments[j].robots) {
      auto [it, fresh] = last.try_emplace(r, static_cast<int>(j));
      if (!fresh && timing.segment_start_s[j] >= timing.segment_start_s[it->second]) {
        it->second = static_cast<int>(j);
      }
    }
  }
  auto movable = [&](int j) { return timing.segment_concurrent[j] && !segments[j].after_all; };
  if (auto it = last.find(issue.robot); it != last.end() && movable(it->second)) {
    return {it->second};
  }
  std::vector<int> out;
  for (const auto& [r, j] : last) {
    if (movable(j)) out.push_back(j);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// A timing and the trajectory check's verdict on it (none without the self-check).
struct Timed {
  Timing timing;
  std::optional<TrajectoryCheck> check;
};

// Retimes `segments` into `plan` (posing the schedule's timeline in `scene`, the geometric
// motion's)
// and, with options.self_check, checks the result. A collision the check finds where segments
// ran beside others is a graze between the schedule's samples (it samples other moments than
// the check): the segments under way there are scheduled after everything before them and the
// plan retimed, a few times at most. Adds its times to `out`.
Result<Timed> TimeAndCheck(const TaskWorld& world, Plan& plan, std::vector<GeoSegment>& segments,
                           const MotionOptions& options, std::optional<MotionScene>& scene,
                           RunContext& ctx, MotionAttempt& out) {
  constexpr int kMaxSeparations = 4;
  std::vector<std::string> seen;  // the colliding pairs separated for
  for (int separation = 0;; ++separation) {
    auto t0 = std::chrono::steady_clock::now();
    if (!scene) {  // (the geometric motion made it)
      auto built = MotionScene::Build(world);
      if (!built) return std::unexpected(built.error());
      scene = std::move(*built);
    }
    ctx.Progress("retime", -1.0,
                 std::to_string(segments.size()) + " segments timed into per-robot trajectories");
    auto timing = RetimeWithinLoads(world, plan, segments, options.retime, *scene, ctx);
    const double t_retime = Since(t0);
    out.t_retime_s += t_retime;
    ctx.AddTime("retime", t_retime);
    if (!timing) return std::unexpected(timing.error());
    if (ctx.Logs("motion")) {
      ctx.Log("motion",
              StrFormat("schedule: makespan %.2f s (one at a time %.2f s), %d of %zu segments wait "
                        "for a collision; %d start times tried, %d tested, %lld moments, %.3f s",
                        timing->makespan_s, timing->makespan_sequential_s, timing->collision_waits,
                        segments.size(), timing->candidates, timing->checked_candidates,
                        timing->check_samples, t_retime));
    }
    Timed result;
    KeepTiming(plan, *timing, segments.size());
    result.timing = std::move(*timing);
    if (!options.self_check) return result;
    t0 = std::chrono::steady_clock::now();
    ctx.Progress("check", -1.0, "the timed trajectories, densely");
    TrajectoryCheckOptions check_options;
    check_options.log = &ctx;
    auto check = CheckTrajectories(world, plan, check_options);
    out.t_mp_s += Since(t0);
    if (!check) return std::unexpected(check.error());
    result.check = std::move(*check);
    if (!result.check->valid && !options.dump_refused_dir.empty()) {
      // Debugging: keep every refused timed result (a folder; one file per refusal).
      static std::atomic<int> dumped = 0;
      (void)SavePlan(plan,
                     options.dump_refused_dir / ("refused_" + std::to_string(dumped++) + ".json"));
    }
    if (result.check->valid || separation >= kMaxSeparations) return result;
    const TrajectoryIssue& issue = result.check->issues.front();
    if (issue.check != "collision") return result;
    // The same two bodies again, after their segments were set apart: not the schedule's doing
    // (a graze inside one path, which the check's other moments now meet); the caller searches
    // the path again.
    const std::string pair = issue.message.substr(0, issue.message.find(" ("));
    if (std::find(seen.begin(), seen.end(), pair) != seen.end()) return result;
    seen.push_back(pair);
    const std::vector<int> apart = ConcurrentAt(segments, result.timing, issue);
    if (apart.empty()) return result;
    if (ctx.Logs("motion")) {
      std::string list;
      for (int j : apart) list += " " + std::to_string(j);
      ctx.Log("motion", "timed: " + FormatTrajectoryIssue(plan, issue) + " (segments" + list +
                            " are scheduled after everything before them)");
    }
    for (int j : apart) segments[j].after_all = true;
  }
}

// The failure of a timed result the trajectory check refused: the action under way at the first
// issue's moment, not to be retried. (failure.scene is left as it is.)
void SetTimedFailure(const Plan& plan, const TrajectoryCheck& check, MotionFailure& failure) {
  const TrajectoryIssue& issue = check.issues.front();
  int action = static_cast<int>(plan.actions.size()) - 1;
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    if (plan.actions[i].end_s >= issue.t) {
      action = static_cast<int>(i);
      break;
    }
  }
  failure.action = std::max(action, 0);
  failure.blame = failure.action;
  failure.segment = "timed";
  failure.suspend = false;
  failure.message = "the trajectory check found " + std::to_string(check.issues.size()) +
                    " issue(s), the first: " + FormatTrajectoryIssue(plan, issue);
}

}  // namespace

Result<MotionAttempt> PlanMotion(const TaskWorld& world, Plan& plan, const MotionOptions& options,
                                 const MotionRequest& request, MotionCache& cache, RunContext& ctx,
                                 std::optional<MotionScene>* kept) {
  // Times a free path is searched again with another seed when the timed result grazes
  // something inside it (a contact narrower than the path search's step: see below).
  constexpr int kMaxRepairs = 3;
  MotionAttempt out;
  const std::vector<PlanAction> original = plan.actions;
  // The motion scene of the geometric motion and of the schedule: its cells are built once.
  std::optional<MotionScene> own;
  std::optional<MotionScene>& scene = kept ? *kept : own;
  for (int repair = 0;; ++repair) {
    out.failure = {};
    plan.actions = original;
    auto t0 = std::chrono::steady_clock::now();
    Plan work = plan;  // keyframes may be rebranched: only a plan with motion keeps them
    auto segments =
        PlanGeometricMotion(world, work, options, request, cache, ctx, &out.failure, &scene);
    const double t_geo = Since(t0);
    out.t_mp_s += t_geo;
    ctx.AddTime("mp", t_geo);
    if (!segments) return std::unexpected(segments.error());
    if (segments->empty()) return out;
    plan.actions = std::move(work.actions);
    auto timed = TimeAndCheck(world, plan, *segments, options, scene, ctx, out);
    if (!timed) return std::unexpected(timed.error());
    if (!timed->check || timed->check->valid) break;
    const TrajectoryCheck* check = &*timed->check;
    const Timing* timing = &timed->timing;
    const TrajectoryIssue& issue = check->issues.front();
    // A collision inside a free path: the path search checks states 0.0025 rad apart and the
    // check samples other moments, so a graze narrower than the search's step (a finger or a
    // carried part clipping a corner) can slip through. Search the free paths under way at that
    // moment again with other seeds; the rest of the motion comes from the cache.
    std::vector<int> redo;
    if (issue.check == "collision" && repair < kMaxRepairs) {
      redo = FreePathsAt(*segments, *timing, issue);
    }
    if (ctx.Logs("motion")) {
      ctx.Log("motion", "timed: " + FormatTrajectoryIssue(plan, issue) +
                            (redo.empty() ? "" : " (its free paths are searched again)"));
    }
    plan.trajectories.clear();
    plan.segments.clear();
    plan.stats.motion = false;
    if (!redo.empty()) {
      for (int index : redo) {
        ++cache.reseed[index];
        if (index < static_cast<int>(cache.free_paths.size())) {
          cache.free_paths[index].waypoints.clear();
        }
      }
      continue;
    }
    SetTimedFailure(plan, *check, out.failure);
    return out;
  }
  out.solved = true;
  return out;
}

}  // namespace wrap
