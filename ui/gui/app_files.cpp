// The App's menus and files: New, Open (with unsaved changes: Save, Discard or Cancel), Open
// recent, Save, Save As (the undo history kept), Open plan; the file dialogs with their folder
// listing filtered to projects or plans; the recent files list.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>

#include "core/file_io.h"
#include "gui/app_impl.h"
#include "model/assembly.h"
#include "task/plan_json.h"

namespace wrap::gui {

namespace fs = std::filesystem;

namespace {

/// The file that lists recent projects (one per line, newest first).
fs::path RecentFilesPath() {
  if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return fs::path(x) / "wrap/recent";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".config/wrap/recent";
  return {};
}

/// Whether the start of `file` holds `tag` (a project's or plan's "format").
bool HasFormatTag(const fs::path& file, const std::string& tag) {
  std::ifstream in(file, std::ios::binary);
  char buf[512] = {};
  in.read(buf, sizeof buf);
  return std::string(buf, static_cast<size_t>(in.gcount())).find(tag) != std::string::npos;
}

}  // namespace

// ---- The file dialog ----------------------------------------------------------------------------

void FileDialog::Request(const std::string& start_path) {
  path = start_path;
  std::error_code ec;
  fs::path d = start_path.empty() ? fs::current_path(ec) : fs::absolute(start_path, ec);
  if (!fs::is_directory(d, ec)) d = d.parent_path();
  if (!fs::is_directory(d, ec)) d = fs::current_path(ec);
  dir = d.string();
  requested_ = true;
  listed_dir_.clear();
}

void FileDialog::List() {
  entries_.clear();
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name[0] == '.') continue;
    if (e.is_directory(ec)) {
      entries_.push_back({name, true});
    } else if (e.path().extension() == ".json" && HasFormatTag(e.path(), format_tag)) {
      entries_.push_back({name, false});
    }
  }
  std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
    return a.folder != b.folder ? a.folder : a.name < b.name;
  });
  listed_dir_ = dir;
  listed_at_ = ImGui::GetTime();
}

bool FileDialog::Draw(const std::vector<std::string>& recent) {
  if (requested_) {
    ImGui::OpenPopup(title.c_str());
    requested_ = false;
  }
  bool confirmed = false;
  ImGui::SetNextWindowSize(ImVec2(620, 0), ImGuiCond_Appearing);
  if (!ImGui::BeginPopupModal(title.c_str(), nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    return false;
  }
  // The listing is read again when the folder changes, and every two seconds.
  if (listed_dir_ != dir || ImGui::GetTime() - listed_at_ > 2.0) List();
  ImGui::SetNextItemWidth(560);
  if (ImGui::IsWindowAppearing()) ImGui::SetKeyboardFocusHere();
  const bool enter = ImGui::InputText("file", &path, ImGuiInputTextFlags_EnterReturnsTrue);
  std::error_code ec;
  if (save && !path.empty() && fs::exists(path, ec)) {
    ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "%s exists and will be replaced",
                       fs::path(path).filename().string().c_str());
  }
  ImGui::TextDisabled("%s", dir.c_str());
  ImGui::BeginChild("listing", ImVec2(600, 220), true);
  if (ImGui::Selectable("../")) dir = fs::path(dir).parent_path().string();
  for (const Entry& e : entries_) {
    const fs::path full = fs::path(dir) / e.name;
    if (e.folder) {
      if (ImGui::Selectable((e.name + "/").c_str())) dir = full.string();
      continue;
    }
    if (ImGui::Selectable(e.name.c_str(), path == full.string(),
                          ImGuiSelectableFlags_AllowDoubleClick)) {
      path = full.string();
      if (ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) confirmed = true;
    }
  }
  if (entries_.empty()) ImGui::TextDisabled("(no %s files here)", format_tag.c_str());
  ImGui::EndChild();
  if (!save && !recent.empty()) {
    ImGui::TextDisabled("Recent");
    for (const std::string& f : recent) {
      if (ImGui::Selectable(f.c_str(), path == f, ImGuiSelectableFlags_AllowDoubleClick)) {
        path = f;
        if (ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) confirmed = true;
      }
    }
  }
  if (ImGui::Button(action.c_str(), ImVec2(90, 0)) || enter) confirmed = true;
  ImGui::SameLine();
  if (ImGui::Button("Cancel", ImVec2(90, 0))) ImGui::CloseCurrentPopup();
  if (confirmed && path.empty()) confirmed = false;
  if (confirmed && !save && fs::is_directory(path, ec)) {
    dir = path;  // Enter on a folder lists it
    confirmed = false;
  }
  if (confirmed) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
  return confirmed;
}

// ---- Menus and files ----------------------------------------------------------------------------

bool App::Open(const fs::path& path) {
  auto doc = Document::Open(path);
  if (!doc) {
    s_.Notify("Open failed: " + doc.error().message);
    return false;
  }
  s_.job.Cancel();
  s_.doc = std::move(*doc);
  s_.selection = {};
  s_.plan.reset();
  s_.plan_project.reset();
  s_.run_failure.reset();
  s_.run_warnings.clear();
  s_.showing_case = -1;
  s_.playback = {};
  s_.field_errors.clear();
  s_.jog.clear();
  plan_states_.clear();
  graph_.pos.clear();
  // The old cell goes at once; the new one is built and framed from the default view.
  s_.viewport.Clear();
  built_key_.reset();
  s_.Notify("Opened " + path.string());
  offer_recovery_ = interactive_ && Document::HasRecovery(path);
  if (interactive_) AddRecent(fs::absolute(path).string());
  return true;
}

void App::NewDocument() {
  s_.job.Cancel();
  s_.doc = Document();
  s_.selection = {};
  s_.plan.reset();
  s_.plan_project.reset();
  s_.run_failure.reset();
  s_.run_warnings.clear();
  s_.showing_case = -1;
  s_.playback = {};
  s_.field_errors.clear();
  s_.jog.clear();
  plan_states_.clear();
  graph_.pos.clear();
  s_.viewport.Clear();
  built_key_.reset();
  s_.Notify("New project");
}

void App::RequestOpen(const std::string& path) {
  if (s_.doc.dirty() && interactive_) {
    pending_open_ = path;
    confirm_open_ = true;
  } else {
    Open(path);
  }
}

void App::Save() {
  if (s_.doc.path().empty()) {
    save_as_dialog_.Request((fs::current_path() / "untitled.json").string());
    return;
  }
  if (auto saved = s_.doc.Save(); !saved) {
    s_.Notify("Save failed: " + saved.error().message);
  } else {
    s_.Notify("Saved " + s_.doc.path().string());
  }
}

void App::SaveAs(const std::string& path) {
  if (auto saved = s_.doc.SaveAs(path); !saved) {
    s_.Notify("Save failed: " + saved.error().message);
    return;
  }
  s_.Notify("Saved " + path);
  if (interactive_) AddRecent(fs::absolute(path).string());
}

void App::OpenPlan(const std::string& path) {
  auto plan = ReadPlanFile(path);
  if (!plan) {
    s_.Notify("Plan not read: " + plan.error().message);
  } else if (auto match = MatchPlan(*plan, path); !match) {
    s_.Notify("Plan not shown: " + match.error().message);
  } else {
    s_.plan = std::make_shared<const Plan>(std::move(*plan));
    s_.plan_project = std::make_shared<const Project>(s_.doc.project());
    s_.plan_origin = path;
    s_.playback = Playback{};
    s_.showing_case = -1;
    plan_states_.clear();
  }
}

void App::Shortcuts() {
  const ImGuiIO& io = ImGui::GetIO();
  if (!io.KeyCtrl || io.WantTextInput) return;
  if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Z))) {
    if (io.KeyShift)
      s_.doc.Redo();
    else
      s_.doc.Undo();
  }
  if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Y))) s_.doc.Redo();
  // GLFW_KEY_S, _O, _N: the GLFW backend indexes keys by GLFW code.
  if (ImGui::IsKeyPressed('S')) {
    if (io.KeyShift) {
      save_as_dialog_.Request(s_.doc.ResolvePath().string());
    } else {
      Save();
    }
  }
  if (ImGui::IsKeyPressed('O')) open_dialog_.Request(s_.doc.ResolvePath().parent_path().string());
}

float App::MenuBar() {
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
    if (ImGui::MenuItem("Open...", "Ctrl+O")) {
      open_dialog_.Request(s_.doc.ResolvePath().parent_path().string());
    }
    if (ImGui::BeginMenu("Open recent", !s_.recent_files.empty())) {
      for (const std::string& f : s_.recent_files) {
        if (ImGui::MenuItem(f.c_str())) RequestOpen(f);
      }
      ImGui::EndMenu();
    }
    if (ImGui::MenuItem("Save", "Ctrl+S")) Save();
    if (ImGui::MenuItem("Save as...", "Ctrl+Shift+S")) {
      save_as_dialog_.Request(s_.doc.ResolvePath().string());
    }
    if (ImGui::MenuItem("Open plan...")) {
      plan_dialog_.Request(s_.doc.ResolvePath().parent_path().string());
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
  AssemblyMenu();
  if (ImGui::BeginMenu("View")) {
    if (ImGui::MenuItem("Reset camera")) s_.viewport.ResetCamera();
    ImGui::Separator();
    ImGui::TextDisabled("Drawing");
    if (ImGui::MenuItem("Auto (fast while moving on slow GL)", nullptr,
                        s_.quality == QualityMode::kAuto)) {
      s_.quality = QualityMode::kAuto;
    }
    if (ImGui::MenuItem("Fine (antialiased, shadows)", nullptr, s_.quality == QualityMode::kFine)) {
      s_.quality = QualityMode::kFine;
    }
    if (ImGui::MenuItem("Fast", nullptr, s_.quality == QualityMode::kFast)) {
      s_.quality = QualityMode::kFast;
    }
    ImGui::MenuItem("Grippers coloured by wrench utilisation", nullptr, &s_.show_utilisation);
    ImGui::Separator();
    ImGui::MenuItem("Assembled view (insertion path of the selected step)", nullptr,
                    &s_.show_assembled);
    ImGui::MenuItem("Contacts (assembled)", nullptr, &s_.show_contacts);
    ImGui::Separator();
    if (ImGui::MenuItem("Auto layout of the graph")) graph_.AutoLayout(s_.doc.project());
    if (ImGui::MenuItem("Problems")) s_.focus_problems = true;
    ImGui::EndMenu();
  }
  ImGui::EndMainMenuBar();
  return h;
}

int App::Choice(const char* title, bool& open, const std::string& text, const char* first,
                const char* second, const char* third) {
  if (open) {
    ImGui::OpenPopup(title);
    open = false;
  }
  int result = -1;
  if (ImGui::BeginPopupModal(title, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::TextUnformatted(text.c_str());
    if (ImGui::Button(first)) result = 1;
    if (second) {
      ImGui::SameLine();
      if (ImGui::Button(second)) result = 2;
    }
    if (third) {
      ImGui::SameLine();
      if (ImGui::Button(third)) result = 3;
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) result = 0;
    if (result >= 0) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
  }
  return result;
}

void App::Popups() {
  open_dialog_.title = "Open project";
  open_dialog_.action = "Open";
  open_dialog_.format_tag = "wrap-project";
  save_as_dialog_.title = "Save project as";
  save_as_dialog_.action = "Save";
  save_as_dialog_.format_tag = "wrap-project";
  save_as_dialog_.save = true;
  plan_dialog_.title = "Open plan";
  plan_dialog_.action = "Open";
  plan_dialog_.format_tag = "wrap-plan";
  if (open_dialog_.Draw(s_.recent_files)) RequestOpen(open_dialog_.path);
  if (save_as_dialog_.Draw({})) SaveAs(save_as_dialog_.path);
  if (plan_dialog_.Draw({})) OpenPlan(plan_dialog_.path);

  const std::string unsaved = "The project has unsaved changes.";
  const int close = Choice("Close Wrap?", confirm_close_, unsaved, "Save and quit", "Discard");
  if (close == 1) {
    Save();
    if (!s_.doc.dirty()) quit_ = true;
  } else if (close == 2) {
    s_.doc.RemoveRecovery();
    quit_ = true;
  }
  const int open = Choice("Open another project?", confirm_open_,
                          unsaved + "\nOpening " + pending_open_ + " replaces it.", "Save and open",
                          "Discard changes");
  if (open == 1) {
    Save();
    if (!s_.doc.dirty()) {
      Open(pending_open_);
    } else {
      s_.Notify("Not opened: save the project first (Save As for an untitled one)");
    }
  } else if (open == 2) {
    Open(pending_open_);
  }
  const int fresh =
      Choice("New project?", confirm_new_, unsaved, "Save, then new", "Discard changes");
  if (fresh == 1) {
    Save();
    if (!s_.doc.dirty()) NewDocument();
  } else if (fresh == 2) {
    NewDocument();
  }
  const int recover =
      Choice("Recover unsaved edits?", offer_recovery_,
             "A recovery file newer than the project was found:\n" +
                 s_.doc.RecoveryPath().string() + "\n(Wrap was closed without saving, or crashed.)",
             "Recover", "Discard it");
  if (recover == 1) {
    if (auto r = s_.doc.Recover(); !r) s_.Notify("Recovery failed: " + r.error().message);
  } else if (recover == 2) {
    s_.doc.RemoveRecovery();
  }
}

Result<void> App::MatchPlan(const Plan& plan, const std::string& file) {
  Diagnostics diags;
  AssemblyTree tree;
  if (!BuildAssemblyTree(s_.doc.project(), s_.doc.ResolvePath().string(), diags, tree)) {
    return Fail(ErrorCode::kInvalidInput, "the project's assembly graph is not complete");
  }
  return CheckPlanMatchesProject(plan, s_.doc.project(), tree, file);
}

void App::LoadRecent() {
  std::ifstream in(RecentFilesPath());
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) s_.recent_files.push_back(line);
  }
}

void App::AddRecent(const std::string& file) {
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

}  // namespace wrap::gui
