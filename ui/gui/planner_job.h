// A planner run on a worker thread over a snapshot of the project: validate, preprocess, plan
// (task and motion). The GUI starts it, reads its progress every frame and may cancel it; the
// document stays editable meanwhile (the job owns its own copy). No window, no GL.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "model/project.h"
#include "task/failure.h"
#include "task/plan.h"

namespace wrap::gui {

/// What the GUI asks of a run.
struct PlannerRequest {
  std::string planner = "wrap";  ///< Variant: wrap, optimistic, flat, counting, exact, fine.
  std::string wrench = "full";   ///< Wrench model: full, gravity, none.
  double force_scale = 1.0;      ///< Lambda on the mating force.
  double time_limit_s = 60.0;    ///< Time limit of the whole run (wall clock, an outer bound) [s].
  double budget = 1.0;           ///< Scale of the motion searches' work budgets (`--budget`).
  std::uint64_t seed = 0;        ///< Random seed.
  int grasps = 0;                ///< Grasp-set size; 0: the project's.
  bool optimize = false;         ///< Improve the first plan until the time limit.
  bool task_only = false;        ///< No motion (keyframes only).
  /// What the planner minimises: "actions" or "makespan" (`wrap plan --objective`).
  std::string objective = "actions";
};

/// Where a run is.
enum class JobState { kIdle, kRunning, kSolved, kNoPlan, kFailed, kCancelled };

/// "idle", "running", "solved", "no plan", "failed", "cancelled".
const char* ToString(JobState state);

/// A stage the run has entered, for the progress line ("validate 0.1 s > preprocess 2.3 s > ...").
struct JobStage {
  std::string name;      ///< "validate", "preprocess", "task", "keyframes", "motion", "retime", ...
  double start_s = 0.0;  ///< When the run entered it, since the start [s].
};

/// What the GUI reads each frame (a copy, taken under the job's lock).
struct JobProgress {
  JobState state = JobState::kIdle;  ///< Where the run is.
  std::string stage;                 ///< "validate", "preprocess", "task", "motion", ...
  double fraction = -1.0;            ///< Of the stage, in [0, 1]; negative: unknown.
  std::string message;               ///< Latest progress message.
  std::vector<std::string> log;      ///< Every message so far, oldest first.
  std::vector<JobStage> stages;      ///< The stages entered so far, in order.
  std::string error;                 ///< Why the run failed or found no plan (in words).
  std::vector<std::string> warnings;  ///< Preprocessing's warnings (as `wrap plan` prints them).
  /// The failure as data when the planner found no plan (the CLI's words in `text`, the checks
  /// that failed with the cell at each); null when it solved, or failed before planning.
  std::shared_ptr<const PlanFailure> failure;
  double elapsed_s = 0.0;            ///< Since the start [s].
};

/// One planner run at a time on a std::jthread. Destroying the job cancels and joins the run.
class PlannerJob {
 public:
  PlannerJob() = default;
  ~PlannerJob();
  PlannerJob(const PlannerJob&) = delete;
  PlannerJob& operator=(const PlannerJob&) = delete;

  /// Starts planning `project` (a snapshot; relative paths resolve against `project_file`).
  /// Returns false (and does nothing) while a run is under way.
  bool Start(Project project, std::filesystem::path project_file, PlannerRequest request);
  /// The project of the last run started (its snapshot; null before any run): a plan is
  /// current while the document still equals it.
  std::shared_ptr<const Project> snapshot() const;
  /// Counts the runs started (0: none yet): the GUI takes each run's outcome once.
  unsigned long run_id() const;
  /// Asks the run to stop: it ends with kCancelled within a fraction of a second.
  void Cancel();
  /// True while the worker runs.
  bool running() const;
  /// Waits for the worker to end (tests, --screenshot --run-plan).
  void Wait();
  /// The progress as it stands.
  JobProgress progress() const;
  /// The plan of the last run that produced one (solved, or keyframes without motion); taken
  /// once: later calls return null until the next run gives one.
  std::shared_ptr<const Plan> TakePlan();

 private:
  void Run(std::stop_token stop, Project project, std::filesystem::path file,
           PlannerRequest request);
  void Log(const std::string& line);
  void Finish(JobState state, std::string error, std::shared_ptr<const Plan> plan);

  mutable std::mutex mutex_;
  JobProgress progress_;
  std::shared_ptr<const Project> snapshot_;
  unsigned long run_id_ = 0;
  std::shared_ptr<const Plan> plan_;
  std::chrono::steady_clock::time_point started_;
  std::jthread worker_;
};

}  // namespace wrap::gui
