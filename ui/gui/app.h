// The GUI application: the window, the layout of the panels, the menus, the frame loop, and
// the headless hooks (--screenshot, --script) that tests and docs use.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>

namespace wrap::gui {

/// How `wrap [PROJECT] [options]` opens the GUI.
struct GuiOptions {
  std::string project;       ///< Project file to open; empty: a new project.
  std::string screenshot;    ///< Save the window to this PNG after a few frames and exit.
  bool run_plan = false;     ///< With --screenshot: plan first (the project's defaults).
  std::optional<double> at;  ///< With --screenshot: the timeline's time [s].
  int width = 1600;          ///< Window size [px].
  int height = 960;          ///< [px].
  std::string script;        ///< Run this script of UI commands, then exit.
};

/// Opens the GUI and runs it until the window closes (or the screenshot or script is done).
/// Returns the exit code: 0; 1 when --run-plan or a script's planner run found no plan, or a
/// script line failed; 2 bad input (unreadable project or script, no display); 3 internal.
int RunGui(const GuiOptions& options, std::ostream& out, std::ostream& err);

}  // namespace wrap::gui
