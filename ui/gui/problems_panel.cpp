// The Problems panel: why the last planner run found no plan (the CLI's words, each failed check
// on its own row, blocker first, with "Show" to put the viewport into the failing state), and
// the live validation's errors and warnings by entity name (a click selects the entity).
#include <imgui.h>

#include <algorithm>
#include <cmath>

#include "gui/panels.h"
#include "model/entity_path.h"

namespace wrap::gui {

namespace {

const ImVec4 kError(1.0f, 0.45f, 0.4f, 1.0f);
const ImVec4 kWarning(1.0f, 0.8f, 0.35f, 1.0f);
const ImVec4 kDim(0.6f, 0.62f, 0.66f, 1.0f);

/// Where the failure happened, in words.
std::string WhereWords(const RunFailure& rf) {
  const PlanFailure& f = *rf.failure;
  std::string where;
  if (f.stage == "motion") {
    where = "motion: action " + std::to_string(f.action + 1) + ", " + f.segment + " segment";
    if (!f.robots.empty() && rf.project) {
      where += " (";
      for (size_t i = 0; i < f.robots.size(); ++i) {
        const int r = f.robots[i];
        if (r < 0 || r >= static_cast<int>(rf.project->robots.size())) continue;
        where += (i ? ", '" : "'") + rf.project->robots[r].name + "'";
      }
      where += ")";
    }
  } else if (f.milestone >= 0) {
    where = "task: milestone " + std::to_string(f.milestone + 1);
  } else {
    where = "task";
  }
  if (const std::string step = rf.StepName(); !step.empty()) where += ", step '" + step + "'";
  return where;
}

}  // namespace

void ShowFailureCase(AppState& app, int index) {
  if (!app.run_failure || !app.run_failure->failure) return;
  const RunFailure& rf = *app.run_failure;
  const PlanFailure& f = *rf.failure;
  if (index < 0 || index >= static_cast<int>(f.cases.size())) {
    app.showing_case = -1;
    return;
  }
  app.showing_case = index;
  app.playback.playing = false;
  const FailureCase& c = f.cases[index];
  // Select what failed: the object's (first) part, the robot, the step.
  if (c.object >= 0 && c.object < static_cast<int>(rf.node_parts.size()) &&
      !rf.node_parts[c.object].empty()) {
    app.selection.part = rf.node_parts[c.object].front();
  }
  if (c.robot >= 0 && c.robot < static_cast<int>(rf.project->robots.size())) {
    app.selection.robot = rf.project->robots[c.robot].name;
  }
  if (const std::string step = rf.StepName(); !step.empty()) app.selection.step = step;
}

void SelectEntity(AppState& app, const EntityRef& entity) {
  switch (entity.kind) {
    case EntityKind::kPart:
      app.selection.part = entity.name;
      break;
    case EntityKind::kStep:
      app.selection.step = entity.name;
      break;
    case EntityKind::kRobot:
      app.selection.robot = entity.name;
      break;
    default:
      break;
  }
}

std::string ProblemsPanel::Title(const AppState& app) {
  const ValidationResult v = app.validation.result();
  const int errors = v.diagnostics.error_count();
  const int warnings = v.diagnostics.warning_count() + static_cast<int>(app.run_warnings.size());
  std::string title = "Problems";
  if (app.run_failure) title += " (no plan";
  if (errors + warnings > 0) {
    title += app.run_failure ? ", " : " (";
    title += std::to_string(errors) + " error" + (errors == 1 ? "" : "s") + ", " +
             std::to_string(warnings) + " warning" + (warnings == 1 ? "" : "s");
  }
  if (app.run_failure || errors + warnings > 0) title += ")";
  return title;
}

void ProblemsPanel::Contents(AppState& app) {
  ImGui::BeginChild("problems", ImVec2(0, 0), false);
  // ---- The planner's last run.
  if (app.run_failure) {
    const RunFailure& rf = *app.run_failure;
    ImGui::TextColored(kError, "Planner");
    ImGui::SameLine();
    if (rf.failure) ImGui::TextDisabled("%s", WhereWords(rf).c_str());
    if (rf.project && !(*rf.project == app.doc.project())) {
      ImGui::SameLine();
      ImGui::TextDisabled("(the project has changed since this run)");
    }
    ImGui::PushStyleColor(ImGuiCol_Text, kError);
    ImGui::TextWrapped("%s", rf.headline.c_str());
    ImGui::PopStyleColor();
    if (rf.failure && !rf.failure->cases.empty()) {
      const std::vector<FailureCase>& cases = rf.failure->cases;
      if (ImGui::BeginTable("cases", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerH)) {
        ImGui::TableSetupColumn("show", ImGuiTableColumnFlags_WidthFixed, 64.0f);
        ImGui::TableSetupColumn("reason", ImGuiTableColumnFlags_WidthStretch);
        for (size_t i = 0; i < cases.size(); ++i) {
          ImGui::TableNextRow();
          ImGui::TableNextColumn();
          ImGui::PushID(static_cast<int>(i));
          const bool on = app.showing_case == static_cast<int>(i);
          if (ImGui::SmallButton(on ? "Showing" : "Show")) {
            ShowFailureCase(app, on ? -1 : static_cast<int>(i));
          }
          if (ImGui::IsItemHovered()) {
            ImGui::SetTooltip(
                "Put the viewport into this failure: the cell as the check saw it, the robot "
                "and the bodies that collided in red, the object tried in amber, the grasp "
                "tried as a magenta arrow. Click again to go back.");
          }
          ImGui::PopID();
          ImGui::TableNextColumn();
          if (i == 0) {
            ImGui::TextColored(kError, "blocker:");
            ImGui::SameLine();
          }
          ImGui::TextWrapped("%s", cases[i].text.c_str());
        }
        ImGui::EndTable();
      }
    }
    if (app.showing_case >= 0 && ImGui::SmallButton("Back to the cell")) app.showing_case = -1;
    ImGui::Separator();
  }

  // ---- The last run's preprocessing warnings (`wrap plan` prints them too).
  if (!app.run_warnings.empty()) {
    ImGui::TextUnformatted("Planner");
    ImGui::SameLine();
    ImGui::TextDisabled("warnings of the last run's preprocessing");
    for (const std::string& w : app.run_warnings) {
      ImGui::TextColored(kWarning, "warning");
      ImGui::SameLine();
      ImGui::TextWrapped("%s", w.c_str());
    }
    ImGui::Separator();
  }

  // ---- Live validation.
  const ValidationResult v = app.validation.result();
  ImGui::TextUnformatted("Validation");
  ImGui::SameLine();
  if (app.validation.pending()) {
    ImGui::TextDisabled("checking...");
  } else if (v.revision != 0) {
    ImGui::TextDisabled("%d error(s), %d warning(s) (the check took %.2f s)",
                        v.diagnostics.error_count(), v.diagnostics.warning_count(), v.seconds);
  }
  if (v.revision != 0 && v.diagnostics.items.empty()) {
    ImGui::TextDisabled("No problems: the project is valid.");
  }
  const Project& checked = v.project ? *v.project : app.doc.project();
  // Errors first, then warnings, each in the order found.
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 0; i < v.diagnostics.items.size(); ++i) {
      const Diagnostic& d = v.diagnostics.items[i];
      if ((d.severity == Severity::kError) != (pass == 0)) continue;
      const EntityRef entity = EntityOfPath(checked, d.path);
      ImGui::PushID(static_cast<int>(i));
      const bool error = d.severity == Severity::kError;
      ImGui::TextColored(error ? kError : kWarning, error ? "error  " : "warning");
      ImGui::SameLine();
      std::string where = entity.Label();
      if (!entity.field.empty()) where += " / " + entity.field;
      const bool selectable = entity.kind == EntityKind::kPart ||
                              entity.kind == EntityKind::kStep || entity.kind == EntityKind::kRobot;
      ImGui::PushStyleColor(ImGuiCol_Text, kDim);
      if (ImGui::Selectable(where.c_str(), false, ImGuiSelectableFlags_None,
                            ImVec2(ImGui::CalcTextSize(where.c_str()).x, 0)) &&
          selectable) {
        SelectEntity(app, entity);
      }
      ImGui::PopStyleColor();
      if (selectable && ImGui::IsItemHovered()) ImGui::SetTooltip("Select %s", where.c_str());
      ImGui::SameLine();
      ImGui::TextWrapped("%s", d.message.c_str());
      ImGui::PopID();
    }
  }
  ImGui::EndChild();
}

}  // namespace wrap::gui
