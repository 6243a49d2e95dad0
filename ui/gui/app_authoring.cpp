// Authoring from geometry in the window: the Assembly menu (Import assembly..., Suggest assembly
// order, Lay out parts on the table), the import dialog, the progress of a run and the "Changes"
// window listing what the last one changed. The runs themselves: gui/authoring_job.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <sstream>

#include "gui/app_impl.h"

namespace wrap::gui {

namespace fs = std::filesystem;

bool StartAuthoring(AppState& app, AuthoringKind kind, std::vector<fs::path> meshes,
                    LengthUnit unit) {
  if (app.authoring.running()) {
    app.Notify(std::string(ToString(kind)) + ": wait for " + ToString(app.authoring.kind()) +
               " to finish");
    return false;
  }
  AuthoringRequest r;
  r.kind = kind;
  r.project = app.doc.project();
  r.revision = app.doc.revision();
  r.project_file = app.doc.ResolvePath();
  r.meshes = std::move(meshes);
  r.unit = unit;
  app.Notify(std::string(ToString(kind)) + ": started");
  return app.authoring.Start(std::move(r));
}

bool TakeAuthoring(AppState& app) {
  auto outcome = app.authoring.Take();
  if (!outcome) return false;
  AppState::AuthoringLog& log = app.authoring_log;
  log = {};
  const std::string what = ToString(outcome->kind);
  if (!outcome->project) {
    log.error = outcome->error;
  } else if (app.doc.revision() != outcome->revision) {
    log.error = "the project changed while it ran; nothing applied (run it again)";
  } else {
    const Project before = app.doc.project();
    if (auto done = app.doc.Execute(ApplyAuthoring(*outcome)); !done) {
      log.error = done.error().message;
    } else {
      log.lines = DescribeChanges(before, app.doc.project());
      // A new assembly: look at the whole cell again (the old view framed other parts).
      if (outcome->kind == AuthoringKind::kImportAssembly) app.frame_next_cell = true;
    }
  }
  char secs[32];
  std::snprintf(secs, sizeof secs, " (%.1f s)", outcome->seconds);
  if (!log.error.empty()) {
    log.title = what + ": not done" + secs;
    app.Notify(what + ": " + log.error);
  } else {
    log.title = what + ": " + std::to_string(log.lines.size()) + " change(s)" + secs +
                ", undo with Ctrl+Z";
    app.Notify(log.title);
    for (const std::string& l : log.lines) app.Notify("  " + l);
  }
  for (const std::string& d : outcome->decisions) log.lines.push_back("decided: " + d);
  app.show_authoring_log = true;
  return true;
}

void App::AssemblyMenu() {
  if (!ImGui::BeginMenu("Assembly")) return;
  const bool idle = !s_.authoring.running();
  if (ImGui::MenuItem("Import assembly...", nullptr, false, idle)) import_open_ = true;
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip(
        "Meshes of an assembly as CAD exports them (one file per part, each where it sits in\n"
        "the assembly): parts, a DAG with free insertion axes, robots and a layout on the\n"
        "table, as `wrap new` makes them. Replaces the project; one undoable edit.");
  }
  const bool parts = s_.doc.project().parts.size() >= 2;
  if (ImGui::MenuItem("Suggest assembly order", nullptr, false, idle && parts)) {
    StartAuthoring(s_, AuthoringKind::kSuggestOrder);
  }
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip(
        "Replaces the DAG and the matings by an order found from the meshes (assembly by\n"
        "disassembly: parts taken off along free directions). Undoable.");
  }
  if (ImGui::MenuItem("Lay out parts on the table", nullptr, false,
                      idle && parts && !s_.doc.project().robots.empty())) {
    StartAuthoring(s_, AuthoringKind::kLayOut);
  }
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip(
        "Sets every part's initial pose: a stable placement a robot can pick, apart from the\n"
        "others, within the robots' reach. Undoable.");
  }
  ImGui::Separator();
  ImGui::MenuItem("Show last changes", nullptr, &s_.show_authoring_log,
                  !s_.authoring_log.title.empty());
  ImGui::EndMenu();
}

void App::ImportAssemblyDialog() {
  if (import_open_) {
    ImGui::OpenPopup("Import assembly");
    import_open_ = false;
    if (import_paths_.empty()) import_dir_.dir = s_.doc.ResolvePath().parent_path().string();
  }
  ImGui::SetNextWindowSize(ImVec2(620, 0), ImGuiCond_Appearing);
  if (!ImGui::BeginPopupModal("Import assembly", nullptr)) return;
  ImGui::TextWrapped(
      "Mesh files (STL, OBJ, PLY...) in their assembled positions, or a folder of them: one "
      "per line. Replaces the project's parts, steps, robots and table (undoable).");
  ImGui::InputTextMultiline("##paths", &import_paths_, ImVec2(-1, 90));
  std::string picked;
  import_dir_.Draw("import_assembly", {".stl", ".obj", ".ply", ".off", ".dae", ".glb", ".gltf"},
                   s_.doc.ResolvePath().parent_path().string(), picked);
  if (!picked.empty()) {
    if (!import_paths_.empty() && import_paths_.back() != '\n') import_paths_ += "\n";
    import_paths_ += picked + "\n";
  }
  if (import_dir_.open && ImGui::SmallButton("Use this folder")) {
    import_paths_ = import_dir_.dir + "\n";
  }
  const char* units[] = {"auto", "mm", "cm", "m"};
  ImGui::Combo("unit", &import_unit_, units, 4);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("auto: the unit that makes the assembly about 20 cm across (said in the log)");
  }
  std::vector<fs::path> meshes;
  std::istringstream lines(import_paths_);
  for (std::string l; std::getline(lines, l);) {
    while (!l.empty() && (l.back() == ' ' || l.back() == '\r')) l.pop_back();
    if (!l.empty()) meshes.emplace_back(l);
  }
  ImGui::BeginDisabled(meshes.empty());
  if (ImGui::Button("Import")) {
    const LengthUnit unit = import_unit_ == 1   ? LengthUnit::kMillimetre
                            : import_unit_ == 2 ? LengthUnit::kCentimetre
                            : import_unit_ == 3 ? LengthUnit::kMetre
                                                : LengthUnit::kAuto;
    StartAuthoring(s_, AuthoringKind::kImportAssembly, meshes, unit);
    ImGui::CloseCurrentPopup();
  }
  ImGui::EndDisabled();
  ImGui::SameLine();
  if (ImGui::Button("Cancel")) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
}

void App::AuthoringWindows() {
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  if (s_.authoring.running()) {
    ImGui::SetNextWindowPos(ImVec2(size.x * 0.5f, size.y * 0.5f), ImGuiCond_Always,
                            ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSize(ImVec2(420, 0), ImGuiCond_Always);
    ImGui::Begin("Working", nullptr,
                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoResize |
                     ImGuiWindowFlags_NoSavedSettings);
    ImGui::Text("%s", ToString(s_.authoring.kind()));
    const std::string stage = s_.authoring.stage() + "...";
    ImGui::ProgressBar(static_cast<float>(s_.authoring.fraction()), ImVec2(-1, 0), stage.c_str());
    ImGui::End();
  }
  if (!s_.show_authoring_log || s_.authoring_log.title.empty()) return;
  ImGui::SetNextWindowPos(ImVec2(size.x * 0.5f, size.y * 0.45f), ImGuiCond_Appearing,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(size.x * 0.45f, size.y * 0.4f), ImGuiCond_Appearing);
  if (ImGui::Begin("Changes", &s_.show_authoring_log, ImGuiWindowFlags_NoCollapse)) {
    const AppState::AuthoringLog& log = s_.authoring_log;
    ImGui::TextUnformatted(log.title.c_str());
    if (!log.error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.45f, 0.4f, 1.0f), "%s", log.error.c_str());
    ImGui::Separator();
    ImGui::BeginChild("changes", ImVec2(0, -ImGui::GetFrameHeightWithSpacing()));
    for (const std::string& l : log.lines) {
      const bool decision = l.starts_with("decided: ");
      if (decision) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.65f, 0.65f, 0.7f, 1.0f));
      ImGui::TextWrapped("%s", l.c_str());
      if (decision) ImGui::PopStyleColor();
    }
    ImGui::EndChild();
    if (ImGui::Button("Close")) s_.show_authoring_log = false;
    if (s_.doc.CanUndo()) {
      ImGui::SameLine();
      const std::string undo = "Undo " + s_.doc.UndoLabel();
      if (ImGui::Button(undo.c_str())) s_.doc.Undo();
    }
  }
  ImGui::End();
}

}  // namespace wrap::gui
