// The geometry in the editors: the mating editor's insertion-path verdict and free directions
// (each with a button that makes it the axis), and the parts a selected part touches. Both read
// the live validation's geometry report: nothing is computed here.
#include <imgui.h>

#include "gui/geometry_view.h"
#include "gui/panels.h"
#include "mating/insertion.h"

namespace wrap::gui {

namespace {

const ImVec4 kRed(1.0f, 0.45f, 0.4f, 1.0f);
const ImVec4 kGreen(0.45f, 0.85f, 0.45f, 1.0f);

}  // namespace

bool StepGeometrySection(AppState& app, const Step& step_in) {
  const Step step = step_in;  // a copy: an edit below replaces the project it came from
  ImGui::Separator();
  ImGui::TextDisabled("Geometry");
  const ValidationResult v = app.validation.result();
  const auto verdict = FindStepVerdict(v, step);
  if (!verdict) {
    ImGui::TextDisabled(app.validation.pending() ? "Checking the insertion path..."
                                                 : "No geometry verdict (see Problems).");
    return false;
  }
  const StepGeometry& g = *verdict->geometry;
  const bool bad = g.blocked() || !g.touch;
  ImGui::PushTextWrapPos(0.0f);
  ImGui::TextColored(bad ? kRed : kGreen, "Insertion path %s",
                     PathVerdictText(*verdict, step).c_str());
  ImGui::PopTextWrapPos();
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip(
        "The moved input's straight path along the axis, from its approach pose to its mating\n"
        "pose, swept against the base input's meshes (the live validation's check). View >\n"
        "Assembled view draws it: green where free, red from where it hits.");
  }
  if (!g.blocked()) return false;
  const std::vector<Vec3> free = RankedFreeDirections(g);
  if (free.empty()) {
    ImGui::TextColored(kRed, "No free direction found among the axes, the contact normals and a "
                             "sphere of directions: try another order (Assembly menu).");
    return false;
  }
  ImGui::Text("Free directions (%zu), most natural first:", free.size());
  const size_t shown = std::min<size_t>(free.size(), 6);
  bool edited = false;
  for (size_t i = 0; i < shown && !edited; ++i) {
    ImGui::PushID(static_cast<int>(i));
    const std::string label = "Use " + FormatDirection(free[i]);
    if (ImGui::SmallButton(label.c_str())) {
      if (app.Do(UseInsertionAxis(step.name, free[i]))) {
        edited = true;
        app.Notify("Step '" + step.name + "': insertion axis set to " + FormatDirection(free[i]) +
                   " (undo: Ctrl+Z)");
      }
    }
    if (ImGui::IsItemHovered()) {
      ImGui::SetTooltip("Make this the insertion axis of '%s' (undoable).", step.name.c_str());
    }
    if (i + 1 < shown && (i + 1) % 3 != 0) ImGui::SameLine();
    ImGui::PopID();
  }
  if (free.size() > shown) ImGui::TextDisabled("... and %zu more", free.size() - shown);
  return edited;
}

void PartContactsSection(AppState& app, const std::string& part) {
  const ValidationResult v = app.validation.result();
  if (!v.geometry) return;
  const std::vector<std::string> touching = TouchingParts(v, part);
  ImGui::PushTextWrapPos(0.0f);
  if (touching.empty()) {
    ImGui::TextDisabled("Touches no part where assembled.");
  } else {
    std::string list;
    for (const std::string& t : touching) list += (list.empty() ? "" : ", ") + t;
    ImGui::Text("Touches (assembled): %s", list.c_str());
  }
  ImGui::PopTextWrapPos();
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip(
        "The contact graph: parts whose surfaces come within the project's contact tolerance\n"
        "in their assembled poses, with the area of the surfaces that meet. View > Contacts\n"
        "draws them.");
  }
}

}  // namespace wrap::gui
