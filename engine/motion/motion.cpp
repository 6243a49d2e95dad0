#include "motion/motion.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "motion/retime.h"
#include "motion/trajectory_check.h"
#include "task/plan_json.h"

namespace wrap {

namespace {
double Since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

Result<MotionAttempt> PlanMotion(const TaskWorld& world, Plan& plan, const MotionOptions& options,
                                 int effort, std::uint64_t seed, MotionCache& cache,
                                 RunContext& ctx) {
  // Times a free path is searched again with another seed when the timed result grazes
  // something inside it (a contact narrower than the path search's step: see below).
  constexpr int kMaxRepairs = 3;
  MotionAttempt out;
  const std::vector<PlanAction> original = plan.actions;
  for (int repair = 0;; ++repair) {
    out.failure = {};
    plan.actions = original;
    auto t0 = std::chrono::steady_clock::now();
    Plan work = plan;  // keyframes may be rebranched: only a plan with motion keeps them
    auto segments =
        PlanGeometricMotion(world, work, options, effort, seed, cache, ctx, &out.failure);
    const double t_geo = Since(t0);
    out.t_mp_s += t_geo;
    ctx.AddTime("mp", t_geo);
    if (!segments) return std::unexpected(segments.error());
    if (segments->empty()) return out;
    t0 = std::chrono::steady_clock::now();
    plan.actions = std::move(work.actions);
    auto timing = Retime(world, plan, *segments);
    const double t_retime = Since(t0);
    out.t_retime_s += t_retime;
    ctx.AddTime("retime", t_retime);
    if (!timing) return std::unexpected(timing.error());
    plan.trajectories = std::move(timing->trajectories);
    plan.segments = std::move(timing->segments);
    for (size_t i = 0; i < plan.actions.size(); ++i) {
      plan.actions[i].start_s = timing->action_start_s[i];
      plan.actions[i].end_s = timing->action_end_s[i];
    }
    plan.stats.motion = true;
    plan.stats.makespan_s = timing->makespan_s;
    plan.stats.makespan_sequential_s = timing->makespan_sequential_s;
    plan.stats.motion_segments = static_cast<int>(segments->size());
    if (!options.self_check) break;
    t0 = std::chrono::steady_clock::now();
    auto check = CheckTrajectories(world, plan, TrajectoryCheckOptions{});
    out.t_mp_s += Since(t0);
    if (!check) return std::unexpected(check.error());
    if (check->valid) break;
    const TrajectoryIssue& issue = check->issues.front();
    // A collision inside a free path: the path search checks states 0.0025 rad apart and the
    // check samples other moments, so a graze narrower than the search's step (a finger or a
    // carried part clipping a corner) can slip through. Search the free paths under way at that
    // moment again with other seeds; the rest of the motion comes from the cache.
    std::vector<int> redo;
    if (issue.check == "collision" && repair < kMaxRepairs) {
      for (size_t j = 0; j < segments->size(); ++j) {
        const GeoSegment& g = (*segments)[j];
        if (g.free_index < 0 || issue.t < timing->segment_start_s[j] - 1e-9 ||
            issue.t > timing->segment_end_s[j] + 1e-9) {
          continue;
        }
        if (issue.robot >= 0 &&
            std::find(g.robots.begin(), g.robots.end(), issue.robot) == g.robots.end()) {
          continue;
        }
        redo.push_back(g.free_index);
      }
    }
    if (std::getenv("WRAP_MOTION_DEBUG")) {
      std::fprintf(stderr, "[timed] %s%s\n", FormatTrajectoryIssue(plan, issue).c_str(),
                   redo.empty() ? "" : " (its free paths are searched again)");
    }
    if (const char* dump = std::getenv("WRAP_MOTION_DUMP")) {
      // Debugging: keep every refused timed result (a folder; one file per refusal).
      static int dumped = 0;
      (void)SavePlan(
          plan, std::filesystem::path(dump) / ("refused_" + std::to_string(dumped++) + ".json"));
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
    // The action under way at the first issue's moment.
    int action = static_cast<int>(plan.actions.size()) - 1;
    for (size_t i = 0; i < plan.actions.size(); ++i) {
      if (plan.actions[i].end_s >= issue.t) {
        action = static_cast<int>(i);
        break;
      }
    }
    out.failure.action = std::max(action, 0);
    out.failure.blame = out.failure.action;
    out.failure.segment = "timed";
    out.failure.suspend = false;
    out.failure.message = "the trajectory check found " + std::to_string(check->issues.size()) +
                          " issue(s), the first: " + FormatTrajectoryIssue(plan, issue);
    return out;
  }
  out.solved = true;
  return out;
}

}  // namespace wrap
