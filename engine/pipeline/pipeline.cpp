#include "pipeline/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "motion/motion.h"
#include "task/plan_validator.h"
#include "task/world.h"

namespace wrap {

namespace {

double Since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A task plan waiting for its motion.
struct Candidate {
  Plan plan;
  MotionCache cache;
  int effort = 0;
  int order = 0;            // arrival
  std::uint64_t stuck = 0;  // edge of the action where its motion was last suspended
};

// The sequence of the task search's edges of a plan (two plans with the same one are the same).
std::uint64_t Signature(const Plan& plan) {
  std::uint64_t h = 0x5157;
  for (const PlanAction& a : plan.actions) h = (h ^ a.edge) * 0x100000001b3ULL + 0x9e37;
  return h;
}

// The motion stage's failure record of `plan`'s motion failure `f` (the words: `words`).
PlanFailure MotionFailureRecord(const Plan& plan, const MotionFailure& f,
                                const std::string& words) {
  PlanFailure d;
  d.stage = "motion";
  d.action = f.action;
  d.segment = f.segment;
  d.start = f.scene;
  FailureCase c;
  c.check = f.segment + " segment";
  c.count = 1;
  c.text = words;
  c.example = f.message;
  c.scene = f.scene;
  if (f.action >= 0 && f.action < static_cast<int>(plan.actions.size())) {
    const PlanAction& a = plan.actions[f.action];
    d.robots = a.robots;
    d.milestone = a.milestone;
    if (a.milestone >= 0 && a.milestone < static_cast<int>(plan.milestone_steps.size())) {
      d.step = plan.milestone_steps[a.milestone];
    }
    c.example += " (action " + std::to_string(f.action + 1) + ": " + DescribeAction(plan, a) + ")";
    c.robot = a.robots.empty() ? -1 : a.robots.front();
    c.object = a.objects.empty() ? -1 : a.objects.front();
    if (!a.grasps.empty() && a.grasps.front().grasp.part >= 0) {
      c.grasp_part = a.grasps.front().grasp.part;
      c.X_PG = a.grasps.front().grasp.X_PG;
      c.grasp_index = a.grasps.front().grasp.index;
    }
  }
  d.cases = {std::move(c)};
  return d;
}

}  // namespace

Result<Plan> PlanAssembly(const Project& project, const ProjectCheck& check,
                          const Preprocessed& pre, const PipelineOptions& options,
                          RunContext& ctx) {
  // A solved plan carries each gripper's utilisation per action (for the GUI and reports); a
  // failure to compute it leaves the plan as it is.
  auto annotate = [&](Plan& plan) {
    if (plan.stats.solved)
      (void)AnnotateUtilisation(project, check, plan, options.task.project_file);
  };
  auto first = PlanTask(project, check, pre, options.task, ctx);
  if (!first) return first;
  if (options.task_only || !first->stats.solved) {
    annotate(*first);
    return first;
  }
  auto world = BuildTaskWorld(project, check, pre, options.task.project_file);
  if (!world) return std::unexpected(world.error());
  MotionOptions motion = options.motion;
  motion.segment_checks = std::max(1LL, std::llround(motion.segment_checks * options.budget));
  motion.carry_edges =
      std::max(1, static_cast<int>(std::lround(motion.carry_edges * options.budget)));

  std::vector<Candidate> queue;
  int made = 1;
  int suspensions = 0;
  double t_kf = 0.0;
  double t_mp = 0.0;
  double t_retime = 0.0;
  std::optional<Plan> fallback;  // the first task plan, returned when no motion is found
  std::string last_failure;
  std::optional<PlanFailure> last_detail;  // the same as data
  // Motion feedback: the edges of the task plans whose motion failed for good (a skill that
  // collides, a goal in collision, or every effort spent) are not taken by later task plans;
  // without it a task search that does not depend on its seed would make the same plan again.
  std::set<std::uint64_t> banned;
  const std::uint64_t seed = options.seed;
  first->stats.seed = seed;

  auto enqueue = [&](Plan plan) -> Result<void> {
    if (options.optimize_keyframes) {
      ctx.Progress("keyframes", -1.0,
                   "optimising the joint keyframes of task plan " + std::to_string(made) + " (" +
                       std::to_string(plan.actions.size()) + " actions)");
      const auto t0 = std::chrono::steady_clock::now();
      auto report = OptimizeKeyframes(*world, plan, options.keyframes, ctx);
      t_kf += Since(t0);
      if (!report) {
        if (report.error().code == ErrorCode::kCancelled) return std::unexpected(report.error());
        // Keep the keyframes as planned: they are valid.
      }
    }
    if (!fallback) fallback = plan;
    Candidate c;
    c.plan = std::move(plan);
    c.order = static_cast<int>(queue.size());
    queue.push_back(std::move(c));
    return {};
  };
  if (auto ok = enqueue(std::move(*first)); !ok) return std::unexpected(ok.error());

  while (!ctx.ShouldStop()) {
    // NextTaskPlan: another task plan once every queued plan has been suspended at least once.
    // New plans and more effort take turns: while the least effort in the queue is e, up to
    // 4 + 4 e task plans are made before the suspended ones get more effort.
    bool all_suspended = !queue.empty();
    int least_effort = motion.max_effort;
    for (const Candidate& c : queue) {
      all_suspended = all_suspended && c.effort > 0;
      least_effort = std::min(least_effort, c.effort);
    }
    const bool room = made < std::min(options.max_task_plans, 4 + 4 * least_effort);
    if ((queue.empty() || (all_suspended && room)) && made < options.max_task_plans) {
      TaskPlannerOptions task = options.task;
      task.optimize = false;
      task.banned_edges.insert(banned.begin(), banned.end());
      // A new plan goes around the places where the queued ones are stuck (they keep their
      // turn with more effort); otherwise a search that does not depend on its seed would
      // make one of them again.
      for (const Candidate& c : queue) {
        if (c.stuck != 0) task.banned_edges.insert(c.stuck);
      }
      RunContext sub(seed + 7919ULL * static_cast<std::uint64_t>(made));
      sub.set_deadline(ctx.deadline());
      sub.set_stop_token(ctx.stop_token());
      sub.set_log_from(ctx);
      ++made;
      sub.set_progress(
          [&ctx, n = made](const std::string& stage, double fraction, const std::string& message) {
            ctx.Progress(stage, fraction, "task plan " + std::to_string(n) + ": " + message);
          });
      auto next = PlanTask(project, check, pre, task, sub);
      if (!next) {
        if (next.error().code == ErrorCode::kCancelled) return std::unexpected(next.error());
      } else if (next->stats.solved) {
        next->stats.seed = seed + 7919ULL * static_cast<std::uint64_t>(made - 1);
        const std::uint64_t sig = Signature(*next);
        const bool known = std::any_of(queue.begin(), queue.end(), [&](const Candidate& c) {
          return Signature(c.plan) == sig;
        });
        if (!known) {
          if (auto ok = enqueue(std::move(*next)); !ok) return std::unexpected(ok.error());
        }
      }
      continue;
    }
    if (queue.empty()) break;
    // SelectFairly: the least effort so far, the oldest first.
    size_t pick = 0;
    for (size_t k = 1; k < queue.size(); ++k) {
      if (queue[k].effort < queue[pick].effort) pick = k;
    }
    Candidate& c = queue[pick];
    ctx.Progress("motion", 0.0,
                 "task plan " + std::to_string(c.order + 1) + " of " + std::to_string(made) +
                     ", effort " + std::to_string(c.effort) + " (" + std::to_string(suspensions) +
                     " suspensions so far)");
    auto attempt = PlanMotion(*world, c.plan, motion, c.effort,
                              c.plan.stats.seed ^ 0x4d50ULL, c.cache, ctx);
    if (!attempt) {
      if (attempt.error().code == ErrorCode::kCancelled) return std::unexpected(attempt.error());
      return std::unexpected(attempt.error());
    }
    t_mp += attempt->t_mp_s;
    t_retime += attempt->t_retime_s;
    if (attempt->solved) {
      Plan plan = std::move(c.plan);
      plan.stats.t_kf_s = t_kf;
      plan.stats.t_mp_s = t_mp;
      plan.stats.t_retime_s = t_retime;
      plan.stats.motion_suspensions = suspensions;
      plan.stats.task_plans = made;
      annotate(plan);
      return plan;
    }
    const MotionFailure& f = attempt->failure;
    last_failure =
        "action " + std::to_string(f.action + 1) + ", " + f.segment + " segment: " + f.message;
    last_detail = MotionFailureRecord(c.plan, f, last_failure);
    ctx.Progress("motion", -1.0,
                 (f.suspend && c.effort < motion.max_effort ? "suspended: " : "failed: ") +
                     last_failure);
    if (ctx.Logs("motion")) {
      ctx.Log("motion", StrFormat("plan %d effort %d: %s%s", c.order, c.effort,
                                  last_failure.c_str(), f.suspend ? " (suspended)" : ""));
    }
    const int blame = f.blame >= 0 ? f.blame : f.action;
    const std::uint64_t edge = blame >= 0 && blame < static_cast<int>(c.plan.actions.size())
                                   ? c.plan.actions[blame].edge
                                   : 0;
    if (f.suspend && c.effort < motion.max_effort) {
      ++c.effort;  // Suspend: more effort later
      ++suspensions;
      c.stuck = edge;
    } else {
      if (edge != 0) banned.insert(edge);
      queue.erase(queue.begin() + static_cast<long>(pick));
    }
  }
  if (ctx.cancelled()) return Fail(ErrorCode::kCancelled, "planning cancelled");
  Plan plan = std::move(*fallback);
  plan.stats.solved = false;
  plan.stats.t_kf_s = t_kf;
  plan.stats.t_mp_s = t_mp;
  plan.stats.t_retime_s = t_retime;
  plan.stats.motion_suspensions = suspensions;
  plan.stats.task_plans = made;
  plan.stats.failure = "no motion for the task plan" + std::string(made > 1 ? "s" : "") +
                       " found (" + std::to_string(made) + " tried" +
                       (ctx.timed_out() ? ", time limit reached before the work budgets were spent"
                                        : ", work budgets spent; --budget gives more") +
                       "); last: " + (last_failure.empty() ? "none planned" : last_failure);
  if (last_detail) {
    last_detail->text = plan.stats.failure;
    plan.stats.failure_detail = std::move(last_detail);
  } else {
    plan.stats.failure_detail.reset();
  }
  return plan;
}

}  // namespace wrap
