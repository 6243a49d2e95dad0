#include "gui/app.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <ostream>
#include <sstream>
#include <thread>

#include "core/file_io.h"
#include "gui/commands.h"
#include "gui/panels.h"
#include "gui/script.h"
#include "model/assembly.h"
#include "platform/window.h"
#include "render/image.h"
#include "render/render_job.h"
#include "task/plan_json.h"

namespace wrap::gui {

namespace fs = std::filesystem;

namespace {

// The recovery file follows the document: written once edits have paused for a second, and at
// least every 30 s during a long run of edits (a drag).
constexpr double kAutosaveQuietS = 1.0;
constexpr double kAutosavePeriodS = 30.0;

/// The file that lists recent projects (one per line, newest first).
fs::path RecentFilesPath() {
  if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return fs::path(x) / "wrap/recent";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".config/wrap/recent";
  return {};
}

bool IsMeshFile(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  for (const char* m :
       {".stl", ".obj", ".ply", ".off", ".glb", ".gltf", ".3mf", ".dae", ".step", ".stp"}) {
    if (ext == m) return true;
  }
  return false;
}

class App {
 public:
  App(platform::Window& window, bool interactive)
      : win_(window), interactive_(interactive), autosave_(interactive) {
    if (interactive_) LoadRecent();
  }

  AppState& state() { return s_; }

  /// Opens `path`, offering recovery when a recovery file is newer than it.
  bool Open(const fs::path& path) {
    auto doc = Document::Open(path);
    if (!doc) {
      s_.Notify("Open failed: " + doc.error().message);
      return false;
    }
    s_.job.Cancel();
    s_.doc = std::move(*doc);
    s_.selection = {};
    s_.plan.reset();
    s_.playback = {};
    graph_.pos.clear();
    s_.Notify("Opened " + path.string());
    offer_recovery_ = interactive_ && Document::HasRecovery(path);
    if (interactive_) AddRecent(fs::absolute(path).string());
    return true;
  }

  /// One frame: input, panels, the cell, and the window shown (read into `capture` if given).
  void Frame(render::Image* capture) {
    win_.BeginFrame();
    const double now = win_.time();
    const double dt = std::clamp(now - last_time_, 0.0, 0.2);
    if (last_time_ > 0.0) {
      s_.frames.Add(now - last_time_);
      if (last_frame_fine_) fine_frame_s_ = now - last_time_;
    }
    last_time_ = now;
    for (const std::string& f : win_.TakeDroppedFiles()) {
      if (IsMeshFile(f)) {
        parts_.Import(s_, f);
      } else if (fs::path(f).extension() == ".json") {
        RequestOpen(f);
      } else if (fs::path(f).extension() == ".urdf") {
        robots_.AddUrdf(s_, f);
      } else {
        s_.Notify("Dropped file not recognised (a mesh or STEP file, a robot .urdf or a project "
                  ".json): " + f);
      }
    }
    TakePlan();
    if (s_.playback.playing && s_.plan) {
      s_.playback.t += dt * s_.playback.speed;
      const double d = s_.Duration();
      if (s_.playback.t > d) {
        s_.playback.t = s_.playback.loop ? 0.0 : d;
        if (!s_.playback.loop) s_.playback.playing = false;
      }
    }
    Shortcuts();
    const float W = static_cast<float>(win_.width()), H = static_cast<float>(win_.height());
    const float menu_h = MenuBar();
    const float status_h = ImGui::GetFrameHeight() + 4;
    const float body_h = H - menu_h - status_h;
    const float left_w = std::round(0.23f * W), right_w = std::round(0.27f * W);
    const float centre_w = W - left_w - right_w;
    const float top = menu_h;
    parts_.Draw(s_, {0, top, left_w, std::round(0.62f * body_h)});
    robots_.Draw(
        s_, {0, top + std::round(0.62f * body_h), left_w, body_h - std::round(0.62f * body_h)});
    const float view_h = std::round(0.66f * body_h);
    viewport_panel_.Draw(s_, {left_w, top, centre_w, view_h});
    plan_.Draw(s_, {left_w, top + view_h, centre_w, body_h - view_h});
    const float g_h = std::round(0.40f * body_h), m_h = std::round(0.30f * body_h);
    graph_.Draw(s_, {left_w + centre_w, top, right_w, g_h});
    mating_.Draw(s_, {left_w + centre_w, top + g_h, right_w, m_h});
    planner_.Draw(s_, {left_w + centre_w, top + g_h + m_h, right_w, body_h - g_h - m_h});
    StatusBar({0, H - status_h, W, status_h});
    Popups();
    UpdateViewport();
    ChooseQuality();
    UpdateTitle();
    if (autosave_) {
      if (s_.doc.revision() != autosave_revision_) {
        autosave_revision_ = s_.doc.revision();
        last_edit_ = now;
      }
      const bool quiet = now - last_edit_ >= kAutosaveQuietS;
      if ((quiet || now - last_autosave_ > kAutosavePeriodS) &&
          autosave_failed_ != autosave_revision_) {
        last_autosave_ = now;
        if (auto wrote = s_.doc.WriteRecovery(); !wrote) {
          autosave_failed_ = autosave_revision_;  // not again until the next edit
          s_.Notify("Autosave failed: " + wrote.error().message);
        }
      }
    }

    // The cell under the panels: MuJoCo draws into the viewport's rectangle (GL: from below).
    const PanelRect vr = viewport_panel_.rect;
    win_.EndFrame(
        [&] {
          if (!s_.viewport.ready()) return;
          s_.viewport.Draw(static_cast<int>(vr.x), static_cast<int>(H - vr.y - vr.h),
                           static_cast<int>(vr.w), static_cast<int>(vr.h));
        },
        capture);
  }

  /// The viewport's drawing quality for this frame. Auto: fine, unless something moves (the
  /// planner runs, the plan plays, a mouse drag) and the last fine frame took longer than 1/20 s;
  /// a still scene is drawn fine again.
  void ChooseQuality() {
    bool fine = s_.quality != QualityMode::kFast;
    if (s_.quality == QualityMode::kAuto) {
      const bool moving = s_.job.running() || s_.playback.playing || ImGui::IsAnyItemActive();
      fine = !(moving && fine_frame_s_ > 1.0 / 20.0);
    }
    s_.viewport.set_quality(fine ? DrawQuality::kFine : DrawQuality::kFast);
    last_frame_fine_ = fine;
  }

  /// The interactive loop's pacing, so that the window leaves the CPU to the planner: while
  /// nothing changes (no run, no playback, no drag, no edit waiting for the recovery file) it
  /// sleeps until the next input, after drawing a few frames past the last one (ImGui settles
  /// hover and focus); while something moves it draws at most 30 frames per second.
  void Pace() {
    const bool moving = s_.job.running() || s_.playback.playing || ImGui::IsAnyItemActive() ||
                        (autosave_ && s_.doc.revision() != autosave_revision_) ||
                        (autosave_ && win_.time() - last_edit_ < kAutosaveQuietS + 0.1);
    if (moving) {
      settle_frames_ = 0;
      const double left = 1.0 / 30.0 - (win_.time() - last_time_);
      if (left > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(left));
      return;
    }
    // Input (or a resize) in this frame: a few more frames before sleeping.
    const ImGuiIO& io = ImGui::GetIO();
    bool input = io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f || io.MouseWheel != 0.0f ||
                 io.MouseWheelH != 0.0f || io.InputQueueCharacters.Size > 0 ||
                 ImGui::IsAnyMouseDown() || io.DisplaySize.x != last_size_.x ||
                 io.DisplaySize.y != last_size_.y;
    for (bool down : io.KeysDown) input = input || down;
    last_size_ = io.DisplaySize;
    if (input) settle_frames_ = 0;
    if (++settle_frames_ < 3) return;
    win_.WaitEvents(2.0);  // and at least every 2 s
    last_time_ = win_.time();  // a wait is not a slow frame
  }

  bool quit() const { return quit_; }
  /// Writes the recovery file as edits pause (on in the interactive window).
  void set_autosave(bool on) { autosave_ = on; }

  /// The window's close button: confirm when there are unsaved edits.
  void HandleCloseRequest() {
    if (!win_.close_requested()) return;
    if (s_.doc.dirty() && interactive_) {
      win_.set_close_requested(false);
      confirm_close_ = true;
    } else {
      quit_ = true;
    }
  }

  /// Takes the plan of a finished run.
  void TakePlan() {
    if (auto plan = s_.job.TakePlan()) {
      s_.plan = std::move(plan);
      s_.plan_origin = "planned";
      s_.playback = Playback{};
      plan_states_.clear();
      s_.Notify(std::string("Planner: ") + (s_.plan->stats.solved ? "solved" : "no plan") +
                ", cost " + std::to_string(s_.plan->stats.cost));
    }
  }

 private:
  void RequestOpen(const std::string& path) {
    if (s_.doc.dirty() && interactive_) {
      pending_open_ = path;
      confirm_open_ = true;
    } else {
      Open(path);
    }
  }

  void Shortcuts() {
    const ImGuiIO& io = ImGui::GetIO();
    if (!io.KeyCtrl || io.WantTextInput) return;
    if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Z))) {
      if (io.KeyShift)
        s_.doc.Redo();
      else
        s_.doc.Undo();
    }
    if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Y))) s_.doc.Redo();
  }

  float MenuBar() {
    float h = 0;
    if (!ImGui::BeginMainMenuBar()) return h;
    h = ImGui::GetWindowSize().y;
    if (ImGui::BeginMenu("File")) {
      if (ImGui::MenuItem("New")) {
        if (s_.doc.dirty()) {
          confirm_new_ = true;
        } else {
          NewDocument();
        }
      }
      if (ImGui::MenuItem("Open...")) {
        path_field_ = s_.doc.path().string();
        open_dialog_ = true;
      }
      if (ImGui::BeginMenu("Open recent", !s_.recent_files.empty())) {
        for (const std::string& f : s_.recent_files) {
          if (ImGui::MenuItem(f.c_str())) RequestOpen(f);
        }
        ImGui::EndMenu();
      }
      if (ImGui::MenuItem("Save", "Ctrl+S")) Save();
      if (ImGui::MenuItem("Save as...")) {
        path_field_ = s_.doc.path().string();
        save_as_dialog_ = true;
      }
      if (ImGui::MenuItem("Open plan...")) {
        path_field_.clear();
        open_plan_dialog_ = true;
      }
      ImGui::Separator();
      if (ImGui::MenuItem("Quit")) win_.set_close_requested(true);
      ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("Edit")) {
      const std::string undo = "Undo " + s_.doc.UndoLabel();
      const std::string redo = "Redo " + s_.doc.RedoLabel();
      if (ImGui::MenuItem(undo.c_str(), "Ctrl+Z", false, s_.doc.CanUndo())) s_.doc.Undo();
      if (ImGui::MenuItem(redo.c_str(), "Ctrl+Y", false, s_.doc.CanRedo())) s_.doc.Redo();
      ImGui::EndMenu();
    }
    if (ImGui::BeginMenu("View")) {
      if (ImGui::MenuItem("Reset camera")) s_.viewport.ResetCamera();
      ImGui::Separator();
      ImGui::TextDisabled("Drawing");
      if (ImGui::MenuItem("Auto (fast while moving on slow GL)", nullptr,
                          s_.quality == QualityMode::kAuto)) {
        s_.quality = QualityMode::kAuto;
      }
      if (ImGui::MenuItem("Fine (antialiased, shadows)", nullptr,
                          s_.quality == QualityMode::kFine)) {
        s_.quality = QualityMode::kFine;
      }
      if (ImGui::MenuItem("Fast", nullptr, s_.quality == QualityMode::kFast)) {
        s_.quality = QualityMode::kFast;
      }
      ImGui::MenuItem("Grippers coloured by wrench utilisation", nullptr, &s_.show_utilisation);
      ImGui::Separator();
      if (ImGui::MenuItem("Auto layout of the graph")) graph_.AutoLayout(s_.doc.project());
      ImGui::EndMenu();
    }
    ImGui::EndMainMenuBar();
    if (ImGui::GetIO().KeyCtrl && !ImGui::GetIO().WantTextInput &&
        ImGui::IsKeyPressed('S')) {  // GLFW_KEY_S: the GLFW backend indexes keys by GLFW code
      Save();
    }
    return h;
  }

  void NewDocument() {
    s_.job.Cancel();
    s_.doc = Document();
    s_.selection = {};
    s_.plan.reset();
    graph_.pos.clear();
    s_.Notify("New project");
  }

  void Save() {
    if (s_.doc.path().empty()) {
      path_field_ = (fs::current_path() / "untitled.json").string();
      save_as_dialog_ = true;
      return;
    }
    if (auto saved = s_.doc.Save(); !saved) {
      s_.Notify("Save failed: " + saved.error().message);
    } else {
      s_.Notify("Saved " + s_.doc.path().string());
    }
  }

  /// A modal with a path field; true when confirmed.
  bool PathDialog(const char* title, bool& open, const char* action) {
    if (open) {
      ImGui::OpenPopup(title);
      open = false;
    }
    bool confirmed = false;
    if (ImGui::BeginPopupModal(title, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
      ImGui::SetNextItemWidth(520);
      const bool enter =
          ImGui::InputText("file", &path_field_, ImGuiInputTextFlags_EnterReturnsTrue);
      if (ImGui::Button(action) || enter) {
        confirmed = !path_field_.empty();
        ImGui::CloseCurrentPopup();
      }
      ImGui::SameLine();
      if (ImGui::Button("Cancel")) ImGui::CloseCurrentPopup();
      ImGui::EndPopup();
    }
    return confirmed;
  }

  /// A yes/no/cancel modal; returns 1 (first), 2 (second), 0 (cancel) or -1 (still open).
  int Choice(const char* title, bool& open, const std::string& text, const char* first,
             const char* second) {
    if (open) {
      ImGui::OpenPopup(title);
      open = false;
    }
    int result = -1;
    if (ImGui::BeginPopupModal(title, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
      ImGui::TextUnformatted(text.c_str());
      if (ImGui::Button(first)) result = 1;
      ImGui::SameLine();
      if (second && ImGui::Button(second)) result = 2;
      ImGui::SameLine();
      if (ImGui::Button("Cancel")) result = 0;
      if (result >= 0) ImGui::CloseCurrentPopup();
      ImGui::EndPopup();
    }
    return result;
  }

  void Popups() {
    if (PathDialog("Open project", open_dialog_, "Open")) RequestOpen(path_field_);
    if (PathDialog("Save project as", save_as_dialog_, "Save")) {
      if (auto saved = s_.doc.SaveAs(path_field_); !saved) {
        s_.Notify("Save failed: " + saved.error().message);
      } else {
        s_.Notify("Saved " + path_field_);
        if (interactive_) AddRecent(fs::absolute(path_field_).string());
      }
    }
    if (PathDialog("Open plan", open_plan_dialog_, "Open")) {
      auto plan = ReadPlanFile(path_field_);
      if (!plan) {
        s_.Notify("Plan not read: " + plan.error().message);
      } else if (auto match = MatchPlan(*plan); !match) {
        s_.Notify("Plan not shown: " + match.error().message);
      } else {
        s_.plan = std::make_shared<const Plan>(std::move(*plan));
        s_.plan_origin = path_field_;
        s_.playback = Playback{};
        plan_states_.clear();
      }
    }
    const std::string unsaved = "The project has unsaved changes.";
    const int close = Choice("Close Wrap?", confirm_close_, unsaved, "Save and quit", "Discard");
    if (close == 1) {
      Save();
      if (!s_.doc.dirty()) quit_ = true;
    } else if (close == 2) {
      s_.doc.RemoveRecovery();
      quit_ = true;
    }
    const int open =
        Choice("Open another project?", confirm_open_, unsaved, "Discard changes", nullptr);
    if (open == 1) Open(pending_open_);
    const int fresh = Choice("New project?", confirm_new_, unsaved, "Discard changes", nullptr);
    if (fresh == 1) NewDocument();
    const int recover = Choice("Recover unsaved edits?", offer_recovery_,
                               "A recovery file newer than the project was found:\n" +
                                   s_.doc.RecoveryPath().string() +
                                   "\n(Wrap was closed without saving, or crashed.)",
                               "Recover", "Discard it");
    if (recover == 1) {
      if (auto r = s_.doc.Recover(); !r) s_.Notify("Recovery failed: " + r.error().message);
    } else if (recover == 2) {
      s_.doc.RemoveRecovery();
    }
  }

  /// Whether `plan` is a plan of the project as it stands.
  Result<void> MatchPlan(const Plan& plan) {
    Diagnostics diags;
    AssemblyTree tree;
    if (!BuildAssemblyTree(s_.doc.project(), s_.doc.ResolvePath().string(), diags, tree)) {
      return Fail(ErrorCode::kInvalidInput, "the project's assembly graph is not complete");
    }
    return CheckPlanMatchesProject(plan, s_.doc.project(), tree, path_field_);
  }

  void StatusBar(const PanelRect& r) {
    PlaceNextWindow(r);
    ImGui::Begin(
        "##status", nullptr,
        ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings);
    ImGui::Text("%s%s", s_.doc.dirty() ? "* unsaved  " : "", s_.doc.path().string().c_str());
    ImGui::SameLine();
    ImGui::TextDisabled("|  %.0f fps%s", s_.frames.MedianFps(),
                        s_.viewport.quality() == DrawQuality::kFast ? ", fast drawing" : "");
    if (!s_.messages.empty()) {
      ImGui::SameLine();
      ImGui::TextDisabled("|  %s", s_.messages.back().c_str());
    }
    ImGui::End();
  }

  void UpdateTitle() {
    std::string title = "Wrap - " + (s_.doc.project().name.empty() ? std::string("untitled")
                                                                   : s_.doc.project().name);
    if (s_.doc.dirty()) title += " *";
    if (title != title_) {
      win_.SetTitle(title);
      title_ = title;
    }
  }

  /// Rebuilds the cell after an edit (not while a field is being dragged), then poses it.
  void UpdateViewport() {
    if (s_.viewport_revision != s_.doc.revision() && !ImGui::IsAnyItemActive()) {
      s_.viewport_revision = s_.doc.revision();
      auto built = s_.viewport.Build(s_.doc.project(), s_.doc.ResolvePath());
      s_.viewport_error = built ? "" : built.error().message;
      plan_states_.clear();
    }
    if (!s_.viewport.ready()) return;
    const CellScene& scene = s_.viewport.scene();
    const SceneState state = CurrentState();
    (void)s_.viewport.SetState(state);
    int selected = -1;
    for (size_t i = 0; i < scene.parts.size(); ++i) {
      if (scene.parts[i].name == s_.selection.part) selected = static_cast<int>(i);
    }
    s_.viewport.set_selected_part(selected);
    std::vector<SceneArrow> arrows;
    if (auto arrow = StepArrow()) arrows.push_back(*arrow);
    std::vector<SceneMarker> markers;
    PlanMarks(state, selected, arrows, markers);
    s_.viewport.set_arrows(std::move(arrows));
    s_.viewport.set_markers(std::move(markers));
    s_.viewport.set_gripper_tints(GripperTints(scene));
  }

  /// During playback, each gripper that carries a load in the action under the cursor tinted by
  /// its wrench utilisation (the plan panel's colours); the others keep their colours.
  std::vector<std::optional<Rgba>> GripperTints(const CellScene& scene) const {
    std::vector<std::optional<Rgba>> tints(scene.robots.size());
    if (!s_.show_utilisation || !s_.plan) return tints;
    const int under = s_.ActionAt(s_.playback.t);
    if (under < 0) return tints;
    for (const auto& [robot, u] : s_.plan->actions[under].utilisation) {
      if (robot < 0 || robot >= static_cast<int>(s_.plan->robots.size())) continue;
      for (size_t r = 0; r < scene.robots.size(); ++r) {
        if (scene.robots[r].name == s_.plan->robots[robot]) tints[r] = UtilisationColour(u);
      }
    }
    return tints;
  }

  /// With a plan of this cell on show: the grasps it uses on the selected part (arrows along
  /// each grasp's approach axis, ending at the TCP, on the part where it is now) and where its
  /// place actions set objects down (discs on the table).
  void PlanMarks(const SceneState& state, int selected, std::vector<SceneArrow>& arrows,
                 std::vector<SceneMarker>& markers) {
    const CellScene& scene = s_.viewport.scene();
    if (!s_.plan || s_.plan->parts.size() != scene.parts.size()) return;
    const Plan& plan = *s_.plan;
    if (selected >= 0 && selected < static_cast<int>(state.X_WP.size())) {
      std::vector<std::pair<int, int>> seen;  // (subassembly, index) of each grasp drawn
      for (const PlanAction& a : plan.actions) {
        for (const PlanHold& h : a.grasps) {
          const PlanGrasp& g = h.grasp;
          if (g.part != selected) continue;
          const std::pair<int, int> key{g.subassembly, g.index};
          if (std::find(seen.begin(), seen.end(), key) != seen.end()) continue;
          seen.push_back(key);
          const Iso3 X_WG = state.X_WP[selected] * g.X_PG;
          const Vec3 tcp = X_WG.translation();
          const Vec3 approach = X_WG.linear().col(2);
          arrows.push_back(SceneArrow{tcp - 0.08 * approach, tcp, {0.1, 0.75, 0.85, 1.0}, 0.006});
        }
      }
    }
    const double top = s_.doc.project().table.height + 0.001;
    for (const PlanAction& a : plan.actions) {
      if (a.type != ActionType::kPlace || a.objects.empty()) continue;
      for (const PlanObject& o : a.keyframe.objects) {
        if (o.node != a.objects[0]) continue;
        Vec3 at = o.X_WA.translation();
        const auto& tree = s_.viewport.check().tree;
        if (tree && o.node >= 0 && o.node < static_cast<int>(tree->nodes.size()) &&
            !tree->nodes[o.node].parts.empty()) {
          at.setZero();
          for (int part : tree->nodes[o.node].parts) {
            at += (o.X_WA * scene.parts[part].X_AP).translation();
          }
          at /= static_cast<double>(tree->nodes[o.node].parts.size());
        }
        markers.push_back(SceneMarker{Vec3(at.x(), at.y(), top), 0.035, {0.1, 0.6, 0.9, 0.55}});
      }
    }
  }

  /// The scene at the timeline's time, or the initial scene without a plan of this cell.
  SceneState CurrentState() {
    const CellScene& scene = s_.viewport.scene();
    const auto& tree = s_.viewport.check().tree;
    if (s_.plan && tree && s_.plan->robots.size() == scene.robots.size() &&
        s_.plan->parts.size() == scene.parts.size()) {
      const Plan& plan = *s_.plan;
      if (plan.stats.motion && !plan.trajectories.empty()) {
        if (auto st = render::MotionState(scene, *tree, plan, s_.playback.t)) return *st;
      } else {
        if (plan_states_.empty()) {
          if (auto states = render::PlanStates(scene, *tree, plan)) plan_states_ = *states;
        }
        if (!plan_states_.empty()) {
          const int k = std::clamp(static_cast<int>(std::lround(s_.playback.t)), 0,
                                   static_cast<int>(plan_states_.size()) - 1);
          return plan_states_[k];
        }
      }
    }
    // Initial poses as the document has them now (a drag or a typed pose shows before the
    // cell is rebuilt).
    SceneState state = InitialState(scene);
    const Project& p = s_.doc.project();
    for (size_t i = 0; i < scene.parts.size(); ++i) {
      for (const Part& part : p.parts) {
        if (part.name == scene.parts[i].name) state.X_WP[i] = ToIsometry(part.initial_pose);
      }
    }
    return state;
  }

  /// The insertion axis of the selected step, drawn at its moved input's first part where it
  /// starts on the table.
  std::optional<SceneArrow> StepArrow() {
    const CellScene& scene = s_.viewport.scene();
    const auto& tree = s_.viewport.check().tree;
    if (!tree || s_.selection.step.empty() || s_.plan) return std::nullopt;
    const Project& p = s_.doc.project();
    auto step = std::find_if(p.steps.begin(), p.steps.end(),
                             [&](const Step& st) { return st.name == s_.selection.step; });
    if (step == p.steps.end()) return std::nullopt;
    const int moved = tree->Find(step->mating.moved);
    if (moved < 0 || tree->nodes[moved].parts.empty()) return std::nullopt;
    const int part = tree->nodes[moved].parts.front();
    if (part >= static_cast<int>(scene.parts.size()) || step->mating.axis.norm() < 1e-9) {
      return std::nullopt;
    }
    // From the middle of the part (where it is now) along the direction it travels, out past
    // its far side.
    const ScenePart& sp = scene.parts[part];
    Iso3 X_WP = sp.X_WP_initial;
    for (const Part& q : p.parts) {
      if (q.name == sp.name) X_WP = ToIsometry(q.initial_pose);
    }
    const Iso3 X_WA = X_WP * sp.X_AP.inverse();
    const Vec3 axis_W = X_WA.linear() * step->mating.axis.normalized();
    const Aabb box = sp.mesh ? ComputeAabb(*sp.mesh) : Aabb{};
    const Vec3 centre_W = X_WP * (0.5 * (box.min + box.max));
    const Vec3 axis_P = X_WP.linear().transpose() * axis_W;
    const double half = 0.5 * axis_P.cwiseAbs().dot(box.size());  // centre to the far side
    const Vec3 tail = centre_W + (half + 0.01) * axis_W;
    return SceneArrow{tail, tail + 0.15 * axis_W, {0.95, 0.2, 0.15, 1.0}};
  }

  void LoadRecent() {
    std::ifstream in(RecentFilesPath());
    for (std::string line; std::getline(in, line);) {
      if (!line.empty()) s_.recent_files.push_back(line);
    }
  }

  void AddRecent(const std::string& file) {
    std::erase(s_.recent_files, file);
    s_.recent_files.insert(s_.recent_files.begin(), file);
    if (s_.recent_files.size() > 10) s_.recent_files.resize(10);
    const fs::path path = RecentFilesPath();
    if (path.empty()) return;
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    std::string text;
    for (const std::string& f : s_.recent_files) text += f + "\n";
    (void)WriteFileAtomic(path, text);
  }

  platform::Window& win_;
  bool interactive_;
  AppState s_;
  PartsPanel parts_;
  GraphPanel graph_;
  MatingPanel mating_;
  RobotsPanel robots_;
  PlannerPanel planner_;
  PlanPanel plan_;
  ViewportPanel viewport_panel_;
  std::vector<SceneState> plan_states_;
  std::string path_field_, pending_open_, title_;
  bool open_dialog_ = false, save_as_dialog_ = false, open_plan_dialog_ = false;
  bool confirm_close_ = false, confirm_open_ = false, confirm_new_ = false;
  bool offer_recovery_ = false;
  bool quit_ = false;
  double last_time_ = 0.0, last_autosave_ = 0.0, last_edit_ = 0.0;
  double fine_frame_s_ = 0.0;  // how long the last frame drawn fine took
  int settle_frames_ = 0;      // frames drawn since the last input while nothing moves
  ImVec2 last_size_{0.0f, 0.0f};
  bool last_frame_fine_ = true;
  bool autosave_ = false;
  unsigned long autosave_revision_ = 0;
  unsigned long autosave_failed_ = ~0UL;
};

int WriteScreenshot(const render::Image& image, const fs::path& file, std::ostream& out,
                    std::ostream& err) {
  if (auto written = render::WritePng(image, file); !written) {
    err << file.string() << ": " << written.error().message << "\n";
    return 2;
  }
  out << "Wrote " << file.string() << " (" << image.width << "x" << image.height << ")\n";
  return 0;
}

}  // namespace

int RunGui(const GuiOptions& options, std::ostream& out, std::ostream& err) {
  // Read the script first: a bad script is bad input before any window opens.
  std::vector<ScriptLine> script;
  fs::path script_dir;
  if (!options.script.empty()) {
    auto text = ReadFile(options.script);
    if (!text) {
      err << options.script << ": " << text.error().message << "\n";
      return 2;
    }
    auto parsed = ParseScript(*text);
    if (!parsed) {
      err << options.script << ": " << parsed.error().message << "\n";
      return 2;
    }
    script = std::move(*parsed);
    script_dir = fs::absolute(options.script).parent_path();
  }
  const bool headless = !options.screenshot.empty() || !options.script.empty();
  platform::WindowOptions wo;
  wo.width = options.width;
  wo.height = options.height;
  wo.vsync = !headless;
  auto window = platform::Window::Create(wo);
  if (!window) {
    err << "wrap: " << window.error().message << "\n";
    return 2;
  }
  App app(**window, !headless);
  AppState& s = app.state();
  if (!options.project.empty() && !app.Open(options.project)) {
    err << s.messages.back() << "\n";
    return 2;
  }

  if (!options.screenshot.empty() && options.script.empty()) {
    int code = 0;
    if (options.run_plan) {
      PlannerRequest q;
      q.time_limit_s = s.doc.project().planner.time_limit_s;
      q.seed = s.doc.project().planner.seed;
      s.job.Start(s.doc.project(), s.doc.ResolvePath(), q);
      // Frames keep drawing while the worker plans (the window stays responsive).
      int frames = 0;
      const auto start = std::chrono::steady_clock::now();
      while (s.job.running()) {
        app.Frame(nullptr);
        ++frames;
      }
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      app.TakePlan();
      const JobProgress prog = s.job.progress();
      out << "Planner " << ToString(prog.state) << " in " << seconds << " s; the window drew "
          << frames << " frames meanwhile (" << (seconds > 0 ? frames / seconds : 0.0)
          << " per second; median of the last " << s.frames.size() << ": "
          << s.frames.MedianFps() << " fps, drawing "
          << (s.viewport.quality() == DrawQuality::kFast ? "fast" : "fine") << ")\n";
      if (prog.state != JobState::kSolved) {
        err << "wrap: planner: " << ToString(prog.state)
            << (prog.error.empty() ? "" : ": " + prog.error) << "\n";
        code = 1;
      }
    }
    if (options.at) s.playback.t = std::clamp(*options.at, 0.0, s.Duration());
    for (int i = 0; i < 3; ++i) app.Frame(nullptr);
    render::Image image;
    app.Frame(&image);
    const int written = WriteScreenshot(image, options.screenshot, out, err);
    return written != 0 ? written : code;
  }

  if (!script.empty()) {
    int code = 0;
    app.Frame(nullptr);
    for (const ScriptLine& line : script) {
      auto effect = RunScriptLine(s, line, script_dir);
      if (!effect) {
        err << options.script << ": " << effect.error().message << "\n";
        code = 1;
        break;
      }
      if (effect->autosave) app.set_autosave(true);
      if (effect->wait_for_planner) {
        while (s.job.running()) app.Frame(nullptr);
        app.TakePlan();
      }
      if (effect->sleep_s > 0) {
        const auto until = std::chrono::steady_clock::now() +
                           std::chrono::duration<double>(effect->sleep_s);
        while (std::chrono::steady_clock::now() < until) app.Frame(nullptr);
      }
      app.Frame(nullptr);
      if (!effect->screenshot.empty()) {
        render::Image image;
        app.Frame(&image);
        if (WriteScreenshot(image, effect->screenshot, out, err) != 0) {
          code = 2;
          break;
        }
      }
      out << "ok " << line.number << ":";
      for (const std::string& w : line.words) out << " " << w;
      out << std::endl;  // flushed: a watching process sees each line as it is done
    }
    if (!options.screenshot.empty()) {
      render::Image image;
      app.Frame(&image);
      if (const int c = WriteScreenshot(image, options.screenshot, out, err); c != 0) return c;
    }
    s.job.Cancel();
    return code;
  }

  while (!app.quit()) {
    app.Frame(nullptr);
    app.HandleCloseRequest();
    app.Pace();
  }
  s.job.Cancel();
  return 0;
}

}  // namespace wrap::gui
