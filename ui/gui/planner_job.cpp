#include "gui/planner_job.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <exception>

#include "core/run_context.h"
#include "grasp/preprocess.h"
#include "mating/project_check.h"
#include "model/validate.h"
#include "pipeline/pipeline.h"
#include "task/planner.h"

namespace wrap::gui {

const char* ToString(JobState state) {
  switch (state) {
    case JobState::kIdle:
      return "idle";
    case JobState::kRunning:
      return "running";
    case JobState::kSolved:
      return "solved";
    case JobState::kNoPlan:
      return "no plan";
    case JobState::kFailed:
      return "failed";
    case JobState::kCancelled:
      return "cancelled";
  }
  return "?";
}

PlannerJob::~PlannerJob() {
  Cancel();
  Wait();
}

bool PlannerJob::Start(Project project, std::filesystem::path project_file,
                       PlannerRequest request) {
  if (running()) return false;
  if (worker_.joinable()) worker_.join();
  auto snapshot = std::make_shared<const Project>(std::move(project));
  {
    std::lock_guard lock(mutex_);
    progress_ = JobProgress{};
    progress_.state = JobState::kRunning;
    progress_.stage = "validate";
    progress_.stages.push_back({"validate", 0.0});
    plan_.reset();
    snapshot_ = snapshot;
    ++run_id_;
    started_ = std::chrono::steady_clock::now();
  }
  worker_ = std::jthread([this, p = *snapshot, f = std::move(project_file),
                          r = std::move(request)](std::stop_token stop) mutable {
    Run(stop, std::move(p), std::move(f), std::move(r));
  });
  return true;
}

std::shared_ptr<const Project> PlannerJob::snapshot() const {
  std::lock_guard lock(mutex_);
  return snapshot_;
}

unsigned long PlannerJob::run_id() const {
  std::lock_guard lock(mutex_);
  return run_id_;
}

void PlannerJob::Cancel() {
  if (worker_.joinable()) worker_.request_stop();
}

bool PlannerJob::running() const {
  std::lock_guard lock(mutex_);
  return progress_.state == JobState::kRunning;
}

void PlannerJob::Wait() {
  if (worker_.joinable()) worker_.join();
}

JobProgress PlannerJob::progress() const {
  std::lock_guard lock(mutex_);
  JobProgress p = progress_;
  if (p.state == JobState::kRunning) {
    p.elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  }
  return p;
}

std::shared_ptr<const Plan> PlannerJob::TakePlan() {
  std::lock_guard lock(mutex_);
  return std::exchange(plan_, nullptr);
}

void PlannerJob::Log(const std::string& line) {
  std::lock_guard lock(mutex_);
  progress_.log.push_back(line);
}

void PlannerJob::Finish(JobState state, std::string error, std::shared_ptr<const Plan> plan) {
  std::lock_guard lock(mutex_);
  progress_.state = state;
  progress_.error = std::move(error);
  progress_.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  if (!progress_.error.empty()) progress_.log.push_back(progress_.error);
  progress_.log.push_back(std::string("run ended: ") + ToString(state));
  plan_ = std::move(plan);
}

// The catch barrier of the worker: whatever happens inside ends as a state and a message.
void PlannerJob::Run(std::stop_token stop, Project project, std::filesystem::path file,
                     PlannerRequest request) {
  // The GUI thread draws while this one plans: on a machine with few cores, planning at a lower
  // priority keeps the window responsive (Linux: nice is per thread; threads this one starts,
  // e.g. the parallel grasp sampling, inherit it). Nice 15: at 5 the chair's window drew 18 fps
  // on two cores under llvmpipe, at 15 34 fps, with planning 6-16% slower (BENCHMARKS.md).
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 15);
  try {
    RunContext ctx(request.seed);
    ctx.set_stop_token(stop);
    ctx.set_time_limit_s(request.time_limit_s);
    ctx.set_progress([this](const std::string& stage, double fraction, const std::string& msg) {
      std::lock_guard lock(mutex_);
      if (progress_.stages.empty() || progress_.stages.back().name != stage) {
        progress_.stages.push_back(
            {stage,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count()});
      }
      progress_.stage = stage;
      progress_.fraction = fraction;
      progress_.message = msg;
      progress_.log.push_back(stage + ": " + msg);
      // The log is copied to the GUI every frame: keep its last kMaxLog lines.
      constexpr size_t kMaxLog = 1000;
      if (progress_.log.size() > 2 * kMaxLog) {
        progress_.log.erase(progress_.log.begin(),
                            progress_.log.end() - static_cast<long>(kMaxLog));
      }
    });
    auto stage = [&](const char* name, const std::string& message) {
      ctx.Progress(name, -1.0, message);
    };
    auto stopped = [&]() {
      if (!ctx.cancelled()) return false;
      Finish(JobState::kCancelled, "", nullptr);
      return true;
    };

    stage("validate", "checking '" + project.name + "' (meshes, DAG, robots)");
    ProjectCheck check = CheckProject(project, file);
    if (check.diagnostics.has_errors()) {
      std::string message = "the project is not valid:";
      int shown = 0;
      for (const Diagnostic& d : check.diagnostics.items) {
        if (d.severity != Severity::kError) continue;
        if (++shown > 8) break;
        message += "\n  " + (d.path.empty() ? "" : d.path + ": ") + d.message;
      }
      Finish(JobState::kFailed, message, nullptr);
      return;
    }
    if (stopped()) return;

    const Result<PlannerVariant> variant = ParsePlannerVariant(request.planner);
    if (!variant) {
      Finish(JobState::kFailed, variant.error().message, nullptr);
      return;
    }
    const Result<PlanObjective> objective = ParsePlanObjective(request.objective);
    if (!objective) {
      Finish(JobState::kFailed, objective.error().message, nullptr);
      return;
    }
    TaskPlannerOptions task;
    task.project_file = file;
    task.planner = *variant;
    task.optimize = request.optimize;
    task.objective = *objective;
    task.force_scale = request.force_scale;
    task.wrench_mode = request.wrench == "gravity" ? MatingWrenchMode::kGravityOnly
                       : request.wrench == "none"  ? MatingWrenchMode::kNone
                                                   : MatingWrenchMode::kFull;
    ProjectPlanOptions run;
    run.preprocess.project_file = file;
    run.preprocess.grasps = request.grasps;
    run.pipeline.task = task;
    run.pipeline.task_only = request.task_only;
    run.pipeline.seed = request.seed;
    run.pipeline.budget = request.budget;
    run.on_preprocessed = [this](const Preprocessed& pre) {
      for (const std::string& w : pre.warnings) {
        Log("warning: " + w);
        std::lock_guard lock(mutex_);
        progress_.warnings.push_back(w);
      }
    };
    // Reports the stages "preprocess" and "task" as it goes.
    auto made = PlanProject(project, check, run, ctx);
    if (stopped()) return;
    if (!made) {
      const Error& e = made.error().error;
      if (made.error().stage == ProjectPlanError::Stage::kPreprocess) {
        Finish(JobState::kFailed, "preprocessing: " + e.message, nullptr);
      } else {
        Finish(e.code == ErrorCode::kCancelled ? JobState::kCancelled : JobState::kFailed,
               e.message, nullptr);
      }
      return;
    }
    Plan& plan = made->plan;
    plan.stats.seed = request.seed;
    // The plan moves into the shared one: its stats are read from there (reading them through
    // the moved-from plan gave an empty failure, "no plan found", where the CLI said why).
    auto shared = std::make_shared<const Plan>(std::move(plan));
    const PlanStats& st = shared->stats;
    Log("cost " + std::to_string(st.cost) + ", " + std::to_string(shared->actions.size()) +
        " actions" + (st.motion ? ", makespan " + std::to_string(st.makespan_s) + " s" : ""));
    if (st.solved) {
      Finish(JobState::kSolved, "", shared);
    } else {
      // A task plan without motion still has keyframes worth showing.
      if (st.failure_detail) {
        std::lock_guard lock(mutex_);
        progress_.failure = std::make_shared<const PlanFailure>(*st.failure_detail);
      }
      Finish(JobState::kNoPlan, st.failure.empty() ? "no plan found" : st.failure,
             shared->actions.empty() ? nullptr : shared);
    }
  } catch (const std::exception& e) {
    Finish(JobState::kFailed, std::string("internal error: ") + e.what(), nullptr);
  } catch (...) {
    Finish(JobState::kFailed, "internal error: unknown exception", nullptr);
  }
}

}  // namespace wrap::gui
