// The viewport: a window without background over the rectangle where MuJoCo draws the cell; the
// overlay (reset view, the gizmo's mode and target, the failure on show) is submitted before the
// scene's mouse area so that its buttons take their clicks.
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "gui/commands.h"
#include "gui/gizmo.h"
#include "gui/panels.h"
#include "model/validate.h"

namespace wrap::gui {

namespace {

const Part* FindPart(const Project& p, const std::string& name) {
  for (const Part& part : p.parts) {
    if (part.name == name) return &part;
  }
  return nullptr;
}

const Robot* FindRobot(const Project& p, const std::string& name) {
  for (const Robot& r : p.robots) {
    if (r.name == name) return &r;
  }
  return nullptr;
}

/// Shift + drag: the selected part's initial pose slides on the table, along the screen's
/// directions projected onto the table plane (one undo entry per drag).
void DragPart(AppState& app, double dx, double dy) {
  const Part* found = FindPart(app.doc.project(), app.selection.part);
  if (!found || (dx == 0.0 && dy == 0.0)) return;
  const CameraView cam = app.viewport.camera();
  const double az = cam.azimuth_deg * std::numbers::pi / 180.0;
  // World metres per viewport height at the look-at distance.
  const double scale =
      2.0 * cam.distance_m * std::tan(0.5 * app.viewport.fovy_deg() * std::numbers::pi / 180.0);
  const Vec3 right(std::sin(az), -std::cos(az), 0.0), ahead(std::cos(az), std::sin(az), 0.0);
  Part part = *found;
  part.initial_pose.xyz += scale * (dx * right - dy * ahead);
  app.Do(SetPart(part.name, part, "drag:" + part.name));
}

/// What the gizmo moves: the selected part (about the middle of its mesh) or, without one, the
/// selected robot's base. False when nothing is selected.
struct GizmoTarget {
  bool robot = false;
  std::string name;
  Iso3 X_WO = Iso3::Identity();  // the pose edited, in the world
  Vec3 pivot_W = Vec3::Zero();
};

bool FindGizmoTarget(const AppState& app, GizmoTarget& t) {
  const Project& p = app.doc.project();
  if (const Part* part = FindPart(p, app.selection.part)) {
    t.robot = false;
    t.name = part->name;
    t.X_WO = ToIsometry(part->initial_pose);
    t.pivot_W = t.X_WO.translation();
    if (app.viewport.ready()) {
      for (const ScenePart& sp : app.viewport.scene().parts) {
        if (sp.name == part->name && sp.mesh) {
          const Aabb box = ComputeAabb(*sp.mesh);
          t.pivot_W = t.X_WO * (0.5 * (box.min + box.max));
        }
      }
    }
    return true;
  }
  if (const Robot* robot = FindRobot(p, app.selection.robot)) {
    t.robot = true;
    t.name = robot->name;
    t.X_WO = RobotBaseInWorld(p, *robot);
    t.pivot_W = t.X_WO.translation();
    return true;
  }
  return false;
}

/// Applies a gizmo motion to the target (one undo entry per drag).
void MoveTarget(AppState& app, const GizmoTarget& t, const GizmoMotion& motion) {
  const Iso3 X_new = ApplyGizmo(t.X_WO, t.pivot_W, motion);
  const Project& p = app.doc.project();
  if (!t.robot) {
    Part part = *FindPart(p, t.name);
    part.initial_pose = FromIsometry(X_new);
    app.Do(SetPart(part.name, part, "gizmo:" + part.name));
    return;
  }
  Robot robot = *FindRobot(p, t.name);
  // A mounted robot's base pose is in its mount's frame: X_WM = X_WR X_MR^-1.
  const Iso3 X_WM = t.X_WO * ToIsometry(robot.base_pose).inverse();
  robot.base_pose = FromIsometry(X_WM.inverse() * X_new);
  app.Do(SetRobot(robot.name, robot, "gizmo:" + robot.name));
}

/// The overlay's line about a failure on show.
void FailureBanner(AppState& app, const PanelRect& rect) {
  if (app.showing_case < 0 || !app.run_failure || !app.run_failure->failure) return;
  const auto& cases = app.run_failure->failure->cases;
  if (app.showing_case >= static_cast<int>(cases.size())) return;
  ImGui::SetCursorScreenPos(ImVec2(rect.x + 6, rect.y + rect.h - 58));
  ImGui::PushStyleColor(ImGuiCol_ChildBg, ImVec4(0.25f, 0.05f, 0.05f, 0.85f));
  ImGui::BeginChild("failure_banner", ImVec2(rect.w - 12, 52), true, ImGuiWindowFlags_NoScrollbar);
  if (ImGui::SmallButton("Back to the cell")) app.showing_case = -1;
  ImGui::SameLine();
  ImGui::PushTextWrapPos(0.0f);
  ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.7f, 1.0f), "Showing why: %s",
                     cases[std::max(0, app.showing_case)].text.c_str());
  ImGui::PopTextWrapPos();
  ImGui::EndChild();
  ImGui::PopStyleColor();
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
  const ImGuiIO& io = ImGui::GetIO();

  // The overlay first: its buttons are submitted before the scene's mouse area, so they take
  // the clicks that land on them.
  ImGui::SetCursorScreenPos(ImVec2(rect.x + 6, rect.y + 6));
  if (ImGui::SmallButton("Reset view")) app.viewport.ResetCamera();
  GizmoTarget target;
  // The gizmo edits the document's poses: shown while the viewport draws the document (not a
  // current plan playing, not a failure on show).
  const bool has_target =
      FindGizmoTarget(app, target) && app.showing_case < 0 && !(app.plan && !app.PlanStale());
  ImGui::SameLine();
  if (ImGui::RadioButton("move", app.gizmo == GizmoMode::kTranslate)) {
    app.gizmo = GizmoMode::kTranslate;
  }
  ImGui::SameLine();
  if (ImGui::RadioButton("turn", app.gizmo == GizmoMode::kRotate)) app.gizmo = GizmoMode::kRotate;
  ImGui::SameLine();
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.25f, 0.27f, 0.3f, 1.0f));
  if (has_target) {
    ImGui::Text("gizmo: %s '%s'", target.robot ? "robot base" : "part", target.name.c_str());
  } else {
    ImGui::TextUnformatted("gizmo: select a part or a robot");
  }
  ImGui::SetCursorScreenPos(ImVec2(rect.x + 6, rect.y + 26));
  ImGui::TextUnformatted(
      "drag: orbit  right/middle: pan  wheel: zoom  click: select  shift+drag: move part");
  ImGui::PopStyleColor();
  if (!app.viewport_error.empty()) {
    ImGui::SetCursorScreenPos(ImVec2(rect.x + 6, rect.y + 46));
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.8f, 0.1f, 0.1f, 1.0f));
    ImGui::PushTextWrapPos(rect.x + rect.w - 10);
    ImGui::TextWrapped("Cell not drawn: %s", app.viewport_error.c_str());
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
  }
  FailureBanner(app, rect);

  // The scene's mouse area.
  ImGui::SetCursorScreenPos(p0);
  ImGui::InvisibleButton("scene", ImVec2(rect.w, rect.h),
                         ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                             ImGuiButtonFlags_MouseButtonMiddle);
  ScreenCamera cam;
  cam.view = app.viewport.camera();
  cam.fovy_deg = app.viewport.fovy_deg();
  cam.origin = p0;
  cam.size = ImVec2(rect.w, rect.h);
  const bool rotate = app.gizmo == GizmoMode::kRotate;
  const int hovered_handle = has_target && ImGui::IsItemHovered()
                                 ? GizmoHandleAt(cam, target.pivot_W, rotate, io.MousePos)
                                 : -1;
  if (ImGui::IsItemHovered() && io.MouseWheel != 0.0f) app.viewport.Zoom(-0.05 * io.MouseWheel);
  // What a drag does is decided when the mouse goes down.
  if (ImGui::IsItemActivated()) {
    press = io.MousePos;
    if (ImGui::IsMouseDown(ImGuiMouseButton_Left) && hovered_handle >= 0) {
      drag = Drag::kGizmo;
      gizmo_axis = hovered_handle;
    } else if (ImGui::IsMouseDown(ImGuiMouseButton_Left) && io.KeyShift &&
               FindPart(app.doc.project(), app.selection.part)) {
      drag = Drag::kMovePart;
    } else {
      drag = Drag::kCamera;
    }
  }
  if (ImGui::IsItemActive()) {
    const double dx = io.MouseDelta.x / rect.h, dy = io.MouseDelta.y / rect.h;
    if (drag == Drag::kGizmo && has_target) {
      const GizmoMotion m = GizmoDrag(cam, target.pivot_W, gizmo_axis, io.MousePos, io.MouseDelta);
      if (m.any()) MoveTarget(app, target, m);
    } else if (drag == Drag::kMovePart) {
      DragPart(app, dx, dy);
    } else if (ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
      app.viewport.Orbit(dx, dy);
    } else if (ImGui::IsMouseDown(ImGuiMouseButton_Right) ||
               ImGui::IsMouseDown(ImGuiMouseButton_Middle)) {
      app.viewport.Pan(dx, dy);
    }
  }
  if (ImGui::IsItemDeactivated()) {
    app.doc.CloseMerge();
    // A click (press and release without moving) selects the part under the mouse.
    if (drag == Drag::kCamera &&
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
    drag = Drag::kNone;
    gizmo_axis = -1;
  }
  if (has_target && app.viewport.ready()) {
    ImDrawList* dl = ImGui::GetWindowDrawList();
    dl->PushClipRect(p0, ImVec2(p0.x + rect.w, p0.y + rect.h), true);
    DrawGizmo(dl, cam, target.pivot_W, rotate, drag == Drag::kGizmo ? gizmo_axis : -1,
              hovered_handle);
    dl->PopClipRect();
  }
  ImGui::End();
}

}  // namespace wrap::gui
