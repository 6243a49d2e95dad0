// What the panels of the GUI share: the document, the selection, the planner job, the plan on
// show and its playback, the viewport's cell. Owned by the App, passed to every panel's Draw.
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gui/authoring_job.h"
#include "gui/document.h"
#include "gui/planner_job.h"
#include "gui/validation_job.h"
#include "render/window_renderer.h"
#include "task/plan.h"

namespace wrap::gui {

using render::DrawQuality;
using render::SceneArrow;
using render::SceneHighlight;
using render::SceneMarker;
using render::ViewportRenderer;

/// What is selected, shared by the viewport, the DAG canvas and the editors.
struct Selection {
  std::string part;   ///< Selected part name (empty: none).
  std::string step;   ///< Selected step name (empty: none).
  std::string robot;  ///< Selected robot name (empty: none).
};

/// The plan timeline's playback.
struct Playback {
  double t = 0.0;        ///< Time on the timeline [s] (keyframe index for plans without motion).
  bool playing = false;  ///< Advancing with the clock.
  double speed = 1.0;    ///< Timeline seconds per wall second.
  bool loop = true;      ///< Start again at the end.
};

/// How the viewport chooses its drawing quality.
enum class QualityMode {
  kAuto,  ///< Fine, except fast while something moves (planner running, playback, a drag) on a
          ///< machine where fine frames take longer than 1/20 s (software GL).
  kFine,  ///< Always antialiased with shadows.
  kFast,  ///< Always plain.
};

/// Frame times of the recent frames, for the frame rate shown and reported.
class FrameStats {
 public:
  /// Records one frame that ended at `now` [s] and took `seconds` from the previous one.
  void Add(double seconds, double now = 0.0);
  /// Median frame rate over the recent frames [1/s] (0 before any frame).
  double MedianFps() const;
  /// Frames drawn per second over the last second before `now` (what the eye sees: a burst of
  /// quick frames after an input does not read as thousands per second) [1/s].
  double RecentFps(double now) const;
  /// Forgets the recorded frames.
  void Clear() {
    seconds_.clear();
    ends_.clear();
  }
  size_t size() const { return seconds_.size(); }

 private:
  std::deque<double> seconds_;  // the last kKept
  std::deque<double> ends_;     // when each of them ended
  static constexpr size_t kKept = 60;
};

/// The last planner run that found no plan, as the Problems panel shows it: the CLI's words and
/// the failure record, with the names of the project as it was planned (the document may have
/// changed since).
struct RunFailure {
  std::string headline;  ///< The CLI's line, e.g. "No plan found in 12.3 s: milestone 2/4 ...".
  std::shared_ptr<const PlanFailure> failure;        ///< The record (null: the run failed earlier).
  std::shared_ptr<const Project> project;            ///< The project as planned.
  std::vector<std::string> nodes;                    ///< DAG node names by node id (parts, steps).
  std::vector<std::vector<std::string>> node_parts;  ///< Part names of each node.
  /// The step the failure is about (a name of `project`), or "".
  std::string StepName() const;
};

/// How the viewport's gizmo edits the selected part's or robot's pose.
enum class GizmoMode { kTranslate, kRotate };

/// Green at no load, through yellow (70%), to red at the limit and beyond (r, g, b in [0, 1]).
Rgba UtilisationColour(double utilisation);

/// The shared state of the GUI.
struct AppState {
  Document doc;                            ///< The project being edited.
  Selection selection;                     ///< Shared selection.
  PlannerJob job;                          ///< The planner run (at most one).
  PlannerRequest request;                  ///< Options of the next run.
  std::shared_ptr<const Plan> plan;        ///< The plan on show (null: none).
  std::string plan_origin;                 ///< Where it came from ("planned", a file name).
  /// The project the plan was made for (the run's snapshot, or the document when a plan file
  /// was opened): the plan is current while the document equals it, else out of date.
  std::shared_ptr<const Project> plan_project;
  std::optional<RunFailure> run_failure;  ///< The last run's failure (none after a solve).
  std::vector<std::string> run_warnings;  ///< The last run's preprocessing warnings.
  int showing_case = -1;      ///< Failure case the viewport shows ("Show"), -1: the cell as it is.
  LiveValidation validation;  ///< Checks the document after each edit.
  /// Out-of-range values typed into fields, by field key (e.g. "mating.seat+leg1.force_N"):
  /// the message shown under the field; cleared by the next valid value.
  std::map<std::string, std::string> field_errors;
  std::map<std::string, JointVector> jog;   ///< Robot name -> joints set with its sliders.
  GizmoMode gizmo = GizmoMode::kTranslate;  ///< The viewport gizmo's mode.
  bool focus_problems = false;              ///< Bring the Problems tab to the front once.
  std::string canvas_marked;  ///< Step the DAG canvas drew as failing in the last frame ("").
  Playback playback;                       ///< Timeline.
  ViewportRenderer viewport;               ///< The cell in the viewport.
  unsigned long viewport_revision = ~0ul;  ///< Document revision the cell was built from.
  std::string viewport_error;        ///< Why the cell could not be rebuilt ("" when it could).
  std::deque<std::string> messages;  ///< Recent messages for the status bar and log, newest last.
  std::vector<std::string> recent_files;  ///< Recently opened projects, newest first.
  QualityMode quality = QualityMode::kAuto;  ///< Viewport drawing quality.
  bool show_utilisation = true;  ///< Tint grippers by wrench utilisation during playback.
  /// View > Assembled view: the parts at their assembled poses on the table's centre, and the
  /// selected step's insertion path (its moved input at the approach pose, the swept outline
  /// green where free, red from where it is blocked).
  bool show_assembled = false;
  /// View > Contacts: the contact graph drawn in the assembled view (a ball at each contact's
  /// centre, its normal, a line between the touching parts' centres).
  bool show_contacts = false;
  AuthoringJob authoring;  ///< Import assembly, suggest order, lay out (at most one at a time).
  /// The last authoring edit: what it did or why it did not ("Changes" window, scripts).
  struct AuthoringLog {
    std::string title;               ///< E.g. "Suggest assembly order: 4 changes".
    std::vector<std::string> lines;  ///< What changed, then its decisions.
    std::string error;               ///< Why nothing was applied ("" when applied).
  } authoring_log;
  bool show_authoring_log = false;  ///< The "Changes" window is open.
  /// The next rebuilt cell is framed anew (after an edit that replaces what is on the table,
  /// e.g. Import assembly); otherwise a rebuild keeps the user's camera.
  bool frame_next_cell = false;
  FrameStats frames;                       ///< Recent frame times.

  /// True when a plan is on show and the document has changed since it was made (a plan for
  /// another project state: shown greyed, not played as current).
  bool PlanStale() const;

  /// Adds a message (kept: the last 200).
  void Notify(std::string message) {
    messages.push_back(std::move(message));
    while (messages.size() > 200) messages.pop_front();
  }
  /// Runs a command on the document; a refusal becomes a message. True when it was done.
  bool Do(const Command& command) {
    auto done = doc.Execute(command);
    if (!done) Notify("Refused: " + done.error().message);
    return done.has_value();
  }
  /// The plan's timeline length: the makespan with motion, else the last keyframe's index.
  double Duration() const;
  /// Index of the plan's action under timeline time `t` (its motion from start to end, or the
  /// keyframe interval before its keyframe), or -1 (no plan, or between actions).
  int ActionAt(double t) const;
  /// The timeline time of each action's (last) keyframe.
  std::vector<double> KeyframeTimes() const;
};

}  // namespace wrap::gui
