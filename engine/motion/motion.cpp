#include "motion/motion.h"

#include <algorithm>
#include <chrono>
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
  MotionAttempt out;
  auto t0 = std::chrono::steady_clock::now();
  Plan work = plan;  // keyframes may be rebranched: only a plan with motion keeps them
  auto segments = PlanGeometricMotion(world, work, options, effort, seed, cache, ctx, &out.failure);
  out.t_mp_s = Since(t0);
  ctx.AddTime("mp", out.t_mp_s);
  if (!segments) return std::unexpected(segments.error());
  if (segments->empty()) return out;
  t0 = std::chrono::steady_clock::now();
  plan.actions = std::move(work.actions);
  auto timing = Retime(world, plan, *segments);
  out.t_retime_s = Since(t0);
  ctx.AddTime("retime", out.t_retime_s);
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
  if (options.self_check) {
    t0 = std::chrono::steady_clock::now();
    auto check = CheckTrajectories(world, plan, TrajectoryCheckOptions{});
    out.t_mp_s += Since(t0);
    if (!check) return std::unexpected(check.error());
    if (!check->valid) {
      // The action under way at the first issue's moment.
      const TrajectoryIssue& issue = check->issues.front();
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
      if (const char* dump = std::getenv("WRAP_MOTION_DUMP")) {
        // Debugging: keep the refused plan (a folder; one file per refusal).
        static int dumped = 0;
        (void)SavePlan(
            plan, std::filesystem::path(dump) / ("refused_" + std::to_string(dumped++) + ".json"));
      }
      plan.trajectories.clear();
      plan.segments.clear();
      plan.stats.motion = false;
      return out;
    }
  }
  out.solved = true;
  return out;
}

}  // namespace wrap
