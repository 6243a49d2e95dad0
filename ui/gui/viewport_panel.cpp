// The viewport: a window without background over the rectangle where MuJoCo draws the cell.
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "gui/commands.h"

#include "gui/panels.h"

namespace wrap::gui {

namespace {

/// Shift + drag: the selected part's initial pose slides on the table, along the screen's
/// directions projected onto the table plane (one undo entry per drag).
void DragPart(AppState& app, double dx, double dy) {
  const Project& p = app.doc.project();
  auto it = std::find_if(p.parts.begin(), p.parts.end(),
                         [&](const Part& q) { return q.name == app.selection.part; });
  if (it == p.parts.end() || (dx == 0.0 && dy == 0.0)) return;
  const CameraView cam = app.viewport.camera();
  const double az = cam.azimuth_deg * std::numbers::pi / 180.0;
  // World metres per viewport height at the look-at distance (fovy 40 degrees).
  const double scale = 2.0 * cam.distance_m * std::tan(20.0 * std::numbers::pi / 180.0);
  const Vec3 right(std::sin(az), -std::cos(az), 0.0), ahead(std::cos(az), std::sin(az), 0.0);
  Part part = *it;
  part.initial_pose.xyz += scale * (dx * right - dy * ahead);
  app.Do(SetPart(part.name, part, "drag:" + part.name));
}

}  // namespace

void ViewportPanel::Draw(AppState& app, const PanelRect& r) {
  PlaceNextWindow(r);
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
  const bool open =
      ImGui::Begin("Viewport", nullptr,
                   ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoBackground |
                       ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse);
  ImGui::PopStyleVar();
  if (!open) {
    ImGui::End();
    return;
  }
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  rect = PanelRect{p0.x, p0.y, std::max(1.0f, avail.x), std::max(1.0f, avail.y)};
  ImGui::InvisibleButton("scene", ImVec2(rect.w, rect.h),
                         ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                             ImGuiButtonFlags_MouseButtonMiddle);
  const ImGuiIO& io = ImGui::GetIO();
  if (ImGui::IsItemHovered()) {
    if (io.MouseWheel != 0.0f) app.viewport.Zoom(-0.05 * io.MouseWheel);
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) press = io.MousePos;
  }
  if (ImGui::IsItemActive()) {
    const double dx = io.MouseDelta.x / rect.h, dy = io.MouseDelta.y / rect.h;
    if (ImGui::IsMouseDown(ImGuiMouseButton_Left) && io.KeyShift && !app.plan &&
        !app.selection.part.empty()) {
      DragPart(app, dx, dy);
    } else if (ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
      app.viewport.Orbit(dx, dy);
    } else if (ImGui::IsMouseDown(ImGuiMouseButton_Right) ||
               ImGui::IsMouseDown(ImGuiMouseButton_Middle)) {
      app.viewport.Pan(dx, dy);
    }
  }
  if (ImGui::IsItemDeactivated()) app.doc.CloseMerge();
  // A click (press and release without moving) selects the part under the mouse.
  if (ImGui::IsItemDeactivated() &&
      std::hypot(io.MousePos.x - press.x, io.MousePos.y - press.y) < 3.0f &&
      ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
    const double rx = (io.MousePos.x - rect.x) / rect.w;
    const double ry = 1.0 - (io.MousePos.y - rect.y) / rect.h;
    const int part = app.viewport.Pick(rx, ry);
    const Project& p = app.doc.project();
    if (part >= 0 && part < static_cast<int>(p.parts.size())) {
      app.selection.part = p.parts[part].name;
    } else {
      app.selection.part.clear();
    }
  }
  // Overlay: reset button and messages.
  ImGui::SetCursorScreenPos(ImVec2(rect.x + 6, rect.y + 6));
  if (ImGui::SmallButton("Reset view")) app.viewport.ResetCamera();
  ImGui::SameLine();
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.25f, 0.27f, 0.3f, 1.0f));
  ImGui::TextUnformatted(
      "drag: orbit  right/middle: pan  wheel: zoom  click: select  shift+drag: move part");
  ImGui::PopStyleColor();
  if (!app.viewport_error.empty()) {
    ImGui::SetCursorScreenPos(ImVec2(rect.x + 6, rect.y + 28));
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.8f, 0.1f, 0.1f, 1.0f));
    ImGui::PushTextWrapPos(rect.x + rect.w - 10);
    ImGui::TextWrapped("Cell not updated: %s", app.viewport_error.c_str());
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
  }
  ImGui::End();
}

}  // namespace wrap::gui
