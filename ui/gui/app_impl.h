// The App behind RunGui: the window's frame loop and what it owns (the shared state, the panels,
// the dialogs). Internal to the GUI library, in three files: app.cpp (the frame loop, pacing,
// the layout, the status bar, RunGui), app_files.cpp (menus, file dialogs, recent files, new,
// open and save) and app_scene.cpp (what the viewport shows: the document's cell, the plan at
// the timeline's time, or a failure the Problems panel shows).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "gui/app_state.h"
#include "gui/panels.h"
#include "platform/window.h"
#include "render/image.h"

namespace wrap::gui {

/// A modal dialog that chooses a project or plan file: a path field, the folder's subfolders and
/// its files of one kind (recognised by their "format" tag), and the recent files. A click on a
/// file takes its path; a double-click or Enter confirms.
struct FileDialog {
  std::string title;   ///< Popup title, e.g. "Open project".
  std::string action;  ///< Confirm button, e.g. "Open".
  std::string
      format_tag;     ///< Files listed: .json files whose start holds this, e.g. "wrap-project".
  bool save = false;  ///< Saving: a file that exists is flagged as to be replaced.
  std::string path;   ///< The path field.
  std::string dir;    ///< Folder listed.
  /// Opens the dialog on the next frame, its field at `start_path` (its folder listed).
  void Request(const std::string& start_path);
  /// Draws it while open; true once when confirmed (then `path` holds the file).
  bool Draw(const std::vector<std::string>& recent);

 private:
  struct Entry {
    std::string name;
    bool folder = false;
  };
  void List();  // (re)reads `dir` into entries_
  bool requested_ = false;
  std::string listed_dir_;
  double listed_at_ = -1.0;
  std::vector<Entry> entries_;
};

class App {
 public:
  App(platform::Window& window, bool interactive);

  AppState& state() { return s_; }
  /// Opens `path`, offering recovery when a recovery file is newer than it. False (with a
  /// message) when it cannot be read.
  bool Open(const std::filesystem::path& path);
  /// File > New: an untitled empty project (the viewport and every panel follow at once).
  void NewDocument();
  /// One frame: input, panels, the cell, and the window shown (read into `capture` if given).
  void Frame(render::Image* capture);
  /// The interactive loop's pacing (see app.cpp).
  void Pace();
  bool quit() const { return quit_; }
  /// Writes the recovery file as edits pause (on in the interactive window).
  void set_autosave(bool on) { autosave_ = on; }
  /// The window's close button: confirm when there are unsaved edits.
  void HandleCloseRequest();
  /// Takes the outcome of a finished run, once: its plan (the plan on show, current for the
  /// project it was made of) or its failure (the Problems panel, the failing step marked).
  void TakeRun();

 private:
  // app.cpp
  void ChooseQuality();
  void StatusBar(const PanelRect& r);
  void BottomPanel(const PanelRect& r);
  void UpdateTitle();
  void Autosave(double now);
  // app_files.cpp
  void RequestOpen(const std::string& path);
  void Shortcuts();
  float MenuBar();
  void Save();
  void SaveAs(const std::string& path);
  void OpenPlan(const std::string& path);
  int Choice(const char* title, bool& open, const std::string& text, const char* first,
             const char* second, const char* third = nullptr);
  void Popups();
  Result<void> MatchPlan(const Plan& plan, const std::string& file);
  void LoadRecent();
  void AddRecent(const std::string& file);
  // app_authoring.cpp
  void AssemblyMenu();
  void ImportAssemblyDialog();
  void AuthoringWindows();
  // app_geometry.cpp
  /// The assembled view (parts at their assembled poses, the selected step's moved input at its
  /// approach pose) and what it draws: contacts, the insertion's swept outline.
  void AssembledView(SceneState& state, std::vector<render::SceneLine>& lines,
                     std::vector<render::SceneDot>& dots);
  // app_scene.cpp
  void UpdateViewport();
  std::vector<std::optional<Rgba>> GripperTints(const CellScene& scene) const;
  void PlanMarks(const SceneState& state, int selected, std::vector<SceneArrow>& arrows,
                 std::vector<SceneMarker>& markers);
  SceneState CurrentState();
  SceneState DocumentState();
  std::optional<SceneArrow> StepArrow();
  /// The failure case on show: its cell as the scene's state, and what to highlight.
  bool FailureState(SceneState& state, std::vector<SceneArrow>& arrows,
                    std::vector<SceneHighlight>& highlights);

  platform::Window& win_;
  bool interactive_;
  AppState s_;
  PartsPanel parts_;
  GraphPanel graph_;
  MatingPanel mating_;
  RobotsPanel robots_;
  PlannerPanel planner_;
  PlanPanel plan_;
  ProblemsPanel problems_;
  ViewportPanel viewport_panel_;
  FileDialog open_dialog_, save_as_dialog_, plan_dialog_;
  bool assembled_framed_ = false;  // the camera framed the assembly since the view went on
  bool import_open_ = false;  // open the Import assembly dialog at the next frame
  std::string import_paths_;  // its mesh files or folder, one per line
  int import_unit_ = 0;       // auto, mm, cm, m
  FileBrowser import_dir_;    // its browser
  std::vector<SceneState> plan_states_;
  std::string pending_open_, title_;
  bool confirm_close_ = false, confirm_open_ = false, confirm_new_ = false;
  bool offer_recovery_ = false;
  bool quit_ = false;
  double last_time_ = 0.0, last_autosave_ = 0.0, last_edit_ = 0.0;
  double fine_frame_s_ = 0.0;  // how long the last frame drawn fine took
  int settle_frames_ = 0;      // frames drawn since the last input while nothing moves
  ImVec2 last_size_{0.0f, 0.0f};
  std::size_t last_shapes_ = 0;  // what the last frame drew, in short (see Pace)
  int frames_since_input_ = 0;   // frames drawn since the last input
  bool last_frame_fine_ = true;
  bool autosave_ = false;
  unsigned long autosave_revision_ = 0;
  unsigned long autosave_failed_ = ~0UL;
  unsigned long taken_run_ = 0;       // run_id of the last run whose outcome was taken
  double last_build_ = -1.0;          // when the viewport's cell was last built [s]
  std::optional<Project> built_key_;  // the project it was built of, initial poses left out
  std::filesystem::path built_file_;  // and the file its paths resolved against
};

}  // namespace wrap::gui
