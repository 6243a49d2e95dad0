// PlanAssembly: the first task plan, then the queue of task plans waiting for their motion
// (MotionQueue: NextTaskPlan, SelectFairly, suspension with more effort); and PlanProject, the
// preprocessing and PlanAssembly in one call.
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

// The high-level search of Algorithm 1 after the first task plan: the queue of task plans waiting
// for their motion, with their effort levels, and what the run has spent so far.
class MotionQueue {
 public:
  MotionQueue(const Project& project, const ProjectCheck& check, const Preprocessed& pre,
              const PipelineOptions& options, const TaskWorld& world, RunContext& ctx)
      : project_(project), check_(check), pre_(pre), options_(options), world_(world), ctx_(ctx) {
    motion_ = options.motion;
    // One meaning of the skill lengths and the robots' clearance: the task planner's.
    motion_.skills = options.task.skills;
    keyframes_ = options.keyframes;
    keyframes_.min_clearance_m = options.task.skills.robot_clearance_m;
    motion_.segment_checks = std::max(1LL, std::llround(motion_.segment_checks * options.budget));
    motion_.carry_edges =
        std::max(1, static_cast<int>(std::lround(motion_.carry_edges * options.budget)));
  }

  bool empty() const { return queue_.empty(); }

  // Optimises the keyframes of a task plan (when asked) and queues it for its motion.
  Result<void> Enqueue(Plan plan);

  // NextTaskPlan is due: the queue is empty, or every queued plan has been suspended at least
  // once and there is room for another. New plans and more effort take turns: while the least
  // effort in the queue is e, up to 4 + 4 e task plans are made before the suspended ones get
  // more effort.
  bool WantsTaskPlan() const {
    bool all_suspended = !queue_.empty();
    int least_effort = motion_.max_effort;
    for (const Candidate& c : queue_) {
      all_suspended = all_suspended && c.effort > 0;
      least_effort = std::min(least_effort, c.effort);
    }
    const bool room = made_ < std::min(options_.max_task_plans, 4 + 4 * least_effort);
    return (queue_.empty() || (all_suspended && room)) && made_ < options_.max_task_plans;
  }

  // NextTaskPlan: another task plan, around the edges banned or stuck so far, queued unless
  // the queue has the same one. Fails only when cancelled.
  Result<void> AddTaskPlan();

  // SelectFairly and motion planning: the queued plan with the least effort so far (the oldest
  // first) gets its motion tried; returns it when solved, else suspends it (more effort later)
  // or drops it and bans the edge it failed at.
  Result<std::optional<Plan>> TryMotion();

  // The first task plan without motion, its failure saying why none was found.
  Plan Unsolved();

 private:
  // Copies the run's totals into a plan's stats.
  void StampStats(Plan& plan) const {
    plan.stats.t_kf_s = t_kf_;
    plan.stats.t_mp_s = t_mp_;
    plan.stats.t_retime_s = t_retime_;
    plan.stats.motion_suspensions = suspensions_;
    plan.stats.task_plans = made_;
  }
  // Records a failed motion attempt of queue entry `pick` and suspends or drops it.
  void MotionFailed(std::size_t pick, const MotionFailure& f);

  const Project& project_;
  const ProjectCheck& check_;
  const Preprocessed& pre_;
  const PipelineOptions& options_;
  const TaskWorld& world_;
  RunContext& ctx_;
  MotionOptions motion_;
  KeyframeOptOptions keyframes_;  // options.keyframes with the task planner's clearance
  std::vector<Candidate> queue_;
  int made_ = 1;
  int suspensions_ = 0;
  double t_kf_ = 0.0;
  double t_mp_ = 0.0;
  double t_retime_ = 0.0;
  std::optional<Plan> fallback_;  // the first task plan, returned when no motion is found
  std::string last_failure_;
  std::optional<PlanFailure> last_detail_;  // the same as data
  // Motion feedback: the edges of the task plans whose motion failed for good (a skill that
  // collides, a goal in collision, or every effort spent) are not taken by later task plans;
  // without it a task search that does not depend on its seed would make the same plan again.
  std::set<std::uint64_t> banned_;
  // The motion scene of every attempt: its collision cells are built once for the run.
  std::optional<MotionScene> scene_;
};

Result<void> MotionQueue::Enqueue(Plan plan) {
  if (options_.optimize_keyframes) {
    ctx_.Progress("keyframes", -1.0,
                  "optimising the joint keyframes of task plan " + std::to_string(made_) + " (" +
                      std::to_string(plan.actions.size()) + " actions)");
    const auto t0 = std::chrono::steady_clock::now();
    auto report = OptimizeKeyframes(world_, plan, keyframes_, ctx_);
    t_kf_ += Since(t0);
    if (!report) {
      if (report.error().code == ErrorCode::kCancelled) return std::unexpected(report.error());
      // Keep the keyframes as planned: they are valid.
    }
  }
  if (!fallback_) fallback_ = plan;
  Candidate c;
  c.plan = std::move(plan);
  c.order = static_cast<int>(queue_.size());
  queue_.push_back(std::move(c));
  return {};
}

Result<void> MotionQueue::AddTaskPlan() {
  const std::uint64_t seed = options_.seed;
  TaskPlannerOptions task = options_.task;
  task.optimize = false;
  task.banned_edges.insert(banned_.begin(), banned_.end());
  // A new plan goes around the places where the queued ones are stuck (they keep their turn
  // with more effort); otherwise a search that does not depend on its seed would make one of
  // them again.
  for (const Candidate& c : queue_) {
    if (c.stuck != 0) task.banned_edges.insert(c.stuck);
  }
  RunContext sub(seed + 7919ULL * static_cast<std::uint64_t>(made_));
  sub.set_deadline(ctx_.deadline());
  sub.set_stop_token(ctx_.stop_token());
  sub.set_log_from(ctx_);
  ++made_;
  sub.set_progress([&ctx = ctx_, n = made_](const std::string& stage, double fraction,
                                            const std::string& message) {
    ctx.Progress(stage, fraction, "task plan " + std::to_string(n) + ": " + message);
  });
  auto next = PlanTask(project_, check_, pre_, task, sub);
  if (!next) {
    if (next.error().code == ErrorCode::kCancelled) return std::unexpected(next.error());
  } else if (next->stats.solved) {
    next->stats.seed = seed + 7919ULL * static_cast<std::uint64_t>(made_ - 1);
    const std::uint64_t sig = Signature(*next);
    const bool known = std::any_of(queue_.begin(), queue_.end(),
                                   [&](const Candidate& c) { return Signature(c.plan) == sig; });
    if (!known) {
      if (auto ok = Enqueue(std::move(*next)); !ok) return std::unexpected(ok.error());
    }
  }
  return {};
}

Result<std::optional<Plan>> MotionQueue::TryMotion() {
  // SelectFairly: the least effort so far, the oldest first.
  size_t pick = 0;
  for (size_t k = 1; k < queue_.size(); ++k) {
    if (queue_[k].effort < queue_[pick].effort) pick = k;
  }
  Candidate& c = queue_[pick];
  ctx_.Progress("motion", 0.0,
                "task plan " + std::to_string(c.order + 1) + " of " + std::to_string(made_) +
                    ", effort " + std::to_string(c.effort) + " (" + std::to_string(suspensions_) +
                    " suspensions so far)");
  // The path searches are seeded by the task plan's seed, xor "MP" (motion planning).
  const MotionRequest request{.effort = c.effort, .seed = c.plan.stats.seed ^ 0x4d50ULL};
  auto attempt = PlanMotion(world_, c.plan, motion_, request, c.cache, ctx_, &scene_);
  if (!attempt) return std::unexpected(attempt.error());
  t_mp_ += attempt->t_mp_s;
  t_retime_ += attempt->t_retime_s;
  if (attempt->solved) {
    Plan plan = std::move(c.plan);
    StampStats(plan);
    return plan;
  }
  MotionFailed(pick, attempt->failure);
  return std::nullopt;
}

void MotionQueue::MotionFailed(std::size_t pick, const MotionFailure& f) {
  Candidate& c = queue_[pick];
  last_failure_ =
      "action " + std::to_string(f.action + 1) + ", " + f.segment + " segment: " + f.message;
  last_detail_ = MotionFailureRecord(c.plan, f, last_failure_);
  ctx_.Progress(
      "motion", -1.0,
      (f.suspend && c.effort < motion_.max_effort ? "suspended: " : "failed: ") + last_failure_);
  if (ctx_.Logs("motion")) {
    ctx_.Log("motion", StrFormat("plan %d effort %d: %s%s", c.order, c.effort,
                                 last_failure_.c_str(), f.suspend ? " (suspended)" : ""));
  }
  const int blame = f.blame >= 0 ? f.blame : f.action;
  const std::uint64_t edge = blame >= 0 && blame < static_cast<int>(c.plan.actions.size())
                                 ? c.plan.actions[blame].edge
                                 : 0;
  if (f.suspend && c.effort < motion_.max_effort) {
    ++c.effort;  // Suspend: more effort later
    ++suspensions_;
    c.stuck = edge;
  } else {
    if (edge != 0) banned_.insert(edge);
    queue_.erase(queue_.begin() + static_cast<long>(pick));
  }
}

Plan MotionQueue::Unsolved() {
  Plan plan = std::move(*fallback_);
  plan.stats.solved = false;
  StampStats(plan);
  plan.stats.failure =
      "no motion for the task plan" + std::string(made_ > 1 ? "s" : "") + " found (" +
      std::to_string(made_) + " tried" +
      (ctx_.timed_out() ? ", time limit reached before the work budgets were spent; "
                          "a longer time limit lets the search go on"
                        : ", work budgets spent; --budget gives more") +
      "); last: " + (last_failure_.empty() ? "none planned" : last_failure_);
  if (last_detail_) {
    last_detail_->text = plan.stats.failure;
    plan.stats.failure_detail = std::move(last_detail_);
  } else {
    plan.stats.failure_detail.reset();
  }
  return plan;
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
  MotionQueue queue(project, check, pre, options, *world, ctx);
  first->stats.seed = options.seed;
  if (auto ok = queue.Enqueue(std::move(*first)); !ok) return std::unexpected(ok.error());

  while (!ctx.ShouldStop()) {
    if (queue.WantsTaskPlan()) {
      if (auto ok = queue.AddTaskPlan(); !ok) return std::unexpected(ok.error());
      continue;
    }
    if (queue.empty()) break;
    Result<std::optional<Plan>> solved = queue.TryMotion();
    if (!solved) return std::unexpected(solved.error());
    if (*solved) {
      Plan plan = std::move(**solved);
      annotate(plan);
      return plan;
    }
  }
  if (ctx.cancelled()) return Fail(ErrorCode::kCancelled, "planning cancelled");
  return queue.Unsolved();
}

std::expected<ProjectPlan, ProjectPlanError> PlanProject(const Project& project,
                                                         const ProjectCheck& check,
                                                         const ProjectPlanOptions& options,
                                                         RunContext& ctx) {
  using Stage = ProjectPlanError::Stage;
  ctx.Progress("preprocess", -1.0, "placements, table slots and grasp sets");
  auto pre = Preprocess(project, check, options.preprocess, ctx);
  // A cancelled run stops here even when preprocessing finished (the GUI's cancel button).
  if (ctx.cancelled()) {
    return std::unexpected(
        ProjectPlanError{Stage::kPlan, Error{ErrorCode::kCancelled, "planning cancelled"}});
  }
  if (!pre) return std::unexpected(ProjectPlanError{Stage::kPreprocess, pre.error()});
  if (options.on_preprocessed) options.on_preprocessed(*pre);

  ctx.Progress(
      "task", -1.0,
      "searching for a task plan (" + std::string(ToString(options.pipeline.task.planner)) + ")");
  const auto t_plan = std::chrono::steady_clock::now();
  auto plan = PlanAssembly(project, check, *pre, options.pipeline, ctx);
  const double t_plan_s = Since(t_plan);
  if (!plan) return std::unexpected(ProjectPlanError{Stage::kPlan, plan.error()});
  return ProjectPlan{std::move(*pre), std::move(*plan), t_plan_s};
}

}  // namespace wrap
