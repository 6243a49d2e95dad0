// What the panels of the GUI share: the document, the selection, the planner job, the plan on
// show and its playback, the viewport's cell. Owned by the App, passed to every panel's Draw.
#pragma once

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "gui/document.h"
#include "gui/planner_job.h"
#include "render/window_renderer.h"
#include "task/plan.h"

namespace wrap::gui {

using render::SceneArrow;
using render::SceneMarker;
using render::DrawQuality;
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
  /// Records one frame's duration [s].
  void Add(double seconds);
  /// Median frame rate over the recent frames [1/s] (0 before any frame).
  double MedianFps() const;
  /// Forgets the recorded frames.
  void Clear() { seconds_.clear(); }
  size_t size() const { return seconds_.size(); }

 private:
  std::deque<double> seconds_;  // the last kKept
  static constexpr size_t kKept = 60;
};

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
  Playback playback;                       ///< Timeline.
  ViewportRenderer viewport;               ///< The cell in the viewport.
  unsigned long viewport_revision = ~0ul;  ///< Document revision the cell was built from.
  std::string viewport_error;        ///< Why the cell could not be rebuilt ("" when it could).
  std::deque<std::string> messages;  ///< Recent messages for the status bar and log, newest last.
  std::vector<std::string> recent_files;  ///< Recently opened projects, newest first.
  QualityMode quality = QualityMode::kAuto;  ///< Viewport drawing quality.
  bool show_utilisation = true;  ///< Tint grippers by wrench utilisation during playback.
  FrameStats frames;                       ///< Recent frame times.

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
