// The panels of the GUI: small structs with a Draw(AppState&) that draw one ImGui window each
// inside the rectangle the App's layout gives them.
#pragma once

#include <map>
#include <string>

#include <imgui.h>

#include "gui/app_state.h"

namespace wrap::gui {

/// Where a panel goes on screen [px].
struct PanelRect {
  float x = 0, y = 0, w = 100, h = 100;
};

/// Sets the next window's rectangle (every frame: the layout is the App's).
void PlaceNextWindow(const PanelRect& r);

/// Project settings, the parts list with import, and the selected part's properties.
/// A small in-app file browser: a folder's subfolders and the files with one of `extensions`
/// (lower case, with the dot), in a child window of the given height; a click on a file puts
/// its path in `path`.
struct FileBrowser {
  std::string dir;    ///< Folder shown.
  bool open = false;  ///< Shown.
  /// Draws the "Browse..." toggle (starting in `start_dir`) and, when open, the list.
  void Draw(const char* id, const std::vector<std::string>& extensions, const std::string& start_dir,
            std::string& path);
};

struct PartsPanel {
  std::string import_path;    ///< Path field of the import.
  int import_unit = 2;        ///< Index into MeshUnits() (mm by default).
  FileBrowser browser;        ///< Mesh files.
  /// Imports `path` with the chosen unit; messages say how it went.
  void Import(AppState& app, const std::string& path);
  void Draw(AppState& app, const PanelRect& r);
};

/// The assembly DAG as a node canvas: parts and steps, drag from a node's port onto a step to
/// make an input, right-click an edge to remove it, automatic layout.
struct GraphPanel {
  std::map<std::string, ImVec2> pos;   ///< Node positions on the canvas (canvas units).
  std::string drag_from;               ///< Node a link is dragged from ("" none).
  std::string moving;                  ///< Node being moved.
  std::string new_step_name = "step";  ///< Name field of "New step".
  std::string rename_to;               ///< Rename field.
  ImVec2 scroll{20, 20};               ///< Canvas offset [px].
  std::string signature;               ///< Nodes and edges the layout was made for.
  float canvas_width = 400.0f;         ///< Width of the canvas last drawn [px].
  /// Places every node: parts in column 0, each step one column right of its deepest input,
  /// the columns fitted to the canvas width.
  void AutoLayout(const Project& project);
  /// The nodes and edges of `project` as a string: the layout is redone when it changes.
  static std::string Signature(const Project& project);
  void Draw(AppState& app, const PanelRect& r);
};

/// The selected step's mating: moved and base input, insertion axis, force and torque,
/// uncertainty, approach, final poses, connection limits.
struct MatingPanel {
  void Draw(AppState& app, const PanelRect& r);
};

/// Robots: add from the catalog, remove, base pose, end effector, wrench-limit tables.
struct RobotsPanel {
  int add_model = 0;  ///< Index into RobotModels().
  int add_ee = 0;     ///< Index into EndEffectors().
  std::string urdf_path, urdf_root, urdf_tip;  ///< Fields of "Add from URDF".
  FileBrowser browser;                         ///< URDF files.
  /// Adds the robot of the URDF `path` with the chosen end effector and the root and tip
  /// fields; messages say how it went.
  void AddUrdf(AppState& app, const std::string& path);
  void Draw(AppState& app, const PanelRect& r);
};

/// Planner options, Run / Cancel, progress, log, errors.
struct PlannerPanel {
  void Draw(AppState& app, const PanelRect& r);
};

/// The plan: actions in words (click to jump), timeline with play/pause/speed/loop and a
/// scrubber, per-robot lanes.
struct PlanPanel {
  void Draw(AppState& app, const PanelRect& r);
};

/// The viewport: the cell drawn by MuJoCo under a transparent ImGui window; mouse orbit (left),
/// pan (right or middle), zoom (wheel), click to select a part, reset view.
struct ViewportPanel {
  PanelRect rect;         ///< Where the cell was drawn this frame (window coordinates).
  bool dragging = false;  ///< A camera drag is under way.
  ImVec2 press{0, 0};     ///< Where the mouse went down.
  void Draw(AppState& app, const PanelRect& r);
};

}  // namespace wrap::gui
