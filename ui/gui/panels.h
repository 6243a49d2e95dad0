// The panels of the GUI: small structs with a Draw(AppState&) that draw one ImGui window each
// inside the rectangle the App's layout gives them.
#pragma once

#include <map>
#include <string>

#include <imgui.h>

#include "gui/app_state.h"
#include "model/entity_path.h"

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

/// The project's header (name, description, table), the import of a mesh or STEP file as new
/// parts, and the parts list: each part's name, mesh, initial and assembled poses.
struct PartsPanel {
  std::string import_path;    ///< Path field of the import.
  int import_unit = 2;        ///< Index into MeshUnits() (mm by default).
  FileBrowser browser;        ///< Mesh files.
  /// Imports `path` with the chosen unit; messages say how it went.
  void Import(AppState& app, const std::string& path);
  void Draw(AppState& app, const PanelRect& r);
};

/// The assembly DAG as a node canvas: parts and steps with their full names, drag from a node's
/// out port (yellow) onto a step to make an input, right-click an edge to remove it, automatic
/// layout that keeps every node in view (fit to view; wheel zooms, middle drag pans), hover a step
/// for its mating; the step where the last run failed is marked red.
struct GraphPanel {
  std::map<std::string, ImVec2> pos;   ///< Node positions on the canvas (canvas units).
  std::map<std::string, float> width;  ///< Node widths from their names (canvas units).
  std::string drag_from;               ///< Node a link is dragged from ("" none).
  std::string moving;                  ///< Node being moved.
  std::string new_step_name = "step";  ///< Name field of "New step".
  std::string rename_to;               ///< Rename field.
  std::string renaming;                ///< Step the rename field was filled for.
  ImVec2 scroll{20, 20};               ///< Canvas offset [px].
  float zoom = 1.0f;                   ///< Canvas pixels per canvas unit.
  bool fit_pending = true;             ///< Fit the whole graph into view at the next draw.
  std::string signature;               ///< Nodes and edges the layout was made for.
  float canvas_width = 400.0f;         ///< Width of the canvas last drawn [px].
  float canvas_height = 300.0f;        ///< Height of the canvas last drawn [px].
  std::string marked;                  ///< Node drawn as failing this frame ("" none).
  bool vertical = false;               ///< Levels as rows (flow downwards), else as columns.
  /// Places every node by level (a step one past its deepest input, a part one before the step
  /// that uses it), levels as columns or as rows, whichever shows the whole graph larger in the
  /// canvas; every node as wide as its name, none overlapping; then fits the view.
  void AutoLayout(const Project& project);
  /// Zoom and scroll that show every node inside the canvas (zoom at most 1).
  void FitToView();
  /// The nodes and edges of `project` as a string: the layout is redone when it changes.
  static std::string Signature(const Project& project);
  void Draw(AppState& app, const PanelRect& r);
};

/// The selected step's mating: moved and base input, insertion axis, force and torque,
/// uncertainty, approach, final poses, connection limits; each field with a tooltip (meaning,
/// unit) and its range enforced (an out-of-range value is refused with a message at the field).
struct MatingPanel {
  void Draw(AppState& app, const PanelRect& r);
};

/// The mating editor's geometry: the step's insertion-path verdict from the live validation and,
/// when blocked, its free directions, each with a button that makes it the axis (undoable).
/// True when it edited the project (references into the old one are then stale).
bool StepGeometrySection(AppState& app, const Step& step);
/// The parts `part` touches where assembled (the live validation's contact graph).
void PartContactsSection(AppState& app, const std::string& part);

/// Starts an authoring run on the document (Import assembly: `meshes` in `unit`); false with a
/// message when one is under way.
bool StartAuthoring(AppState& app, AuthoringKind kind,
                    std::vector<std::filesystem::path> meshes = {},
                    LengthUnit unit = LengthUnit::kAuto);
/// Takes a finished authoring run: applies its project as one undoable edit when the document
/// has not changed since it started (else says so), and fills the authoring log with what
/// changed. True when it took one.
bool TakeAuthoring(AppState& app);

/// Robots: add from the catalog, remove, base pose, end effector, wrench-limit tables.
struct RobotsPanel {
  int add_model = 0;  ///< Index into RobotModels().
  /// Joint sliders of the selected robot (jogging: the viewport shows it there; not saved).
  void JointSliders(AppState& app, const std::string& robot);
  int add_ee = 0;     ///< Index into EndEffectors().
  std::string urdf_path, urdf_root, urdf_tip;  ///< Fields of "Add from URDF".
  FileBrowser browser;                         ///< URDF files.
  /// Adds the robot of the URDF `path` with the chosen end effector and the root and tip
  /// fields; messages say how it went.
  void AddUrdf(AppState& app, const std::string& path);
  void Draw(AppState& app, const PanelRect& r);
};

/// Planner options, Run / Cancel, progress through every stage (its name and count), log, errors.
struct PlannerPanel {
  void Draw(AppState& app, const PanelRect& r);
};

/// Starts the planner on the document with the request's options (Run, Re-plan).
void StartRun(AppState& app);

/// The plan: actions in words (click to jump), timeline with play/pause/speed/loop and a
/// scrubber, per-robot lanes; a plan of another state of the project greyed, with "Re-plan".
/// Drawn as a tab of the bottom panel.
struct PlanPanel {
  void Contents(AppState& app);
};

/// The Problems tab: the last run's failure (the CLI's words, blocker first, "Show" per failed
/// check) and the live validation's diagnostics by entity name (click: select).
struct ProblemsPanel {
  /// "Problems (no plan, 1 error, 2 warnings)".
  static std::string Title(const AppState& app);
  void Contents(AppState& app);
};

/// Puts the viewport into failure case `index` of the last run (-1: back to the cell) and
/// selects what failed: the object's part, the robot, the step.
void ShowFailureCase(AppState& app, int index);
/// Selects the part, step or robot `entity` names (others: nothing).
void SelectEntity(AppState& app, const EntityRef& entity);

/// The viewport: the cell drawn by MuJoCo under a transparent ImGui window; mouse orbit (left),
/// pan (right or middle), zoom (wheel), click to select a part, shift+drag moves the selected
/// part on the table, a translate/rotate gizmo on the selected part or robot base; reset view.
struct ViewportPanel {
  PanelRect rect;      ///< Where the cell was drawn this frame (window coordinates).
  ImVec2 press{0, 0};  ///< Where the mouse went down.
  /// What the drag under way does, decided when the mouse went down: a drag that starts with
  /// shift held on a selected part moves it until the button is released, whatever the keys.
  enum class Drag { kNone, kCamera, kMovePart, kGizmo } drag = Drag::kNone;
  int gizmo_axis = -1;  ///< Gizmo handle being dragged (0-2 move x/y/z, 3-5 turn about x/y/z).
  void Draw(AppState& app, const PanelRect& r);
};

}  // namespace wrap::gui
