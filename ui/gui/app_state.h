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
};

}  // namespace wrap::gui
