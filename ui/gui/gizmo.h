// A translate/rotate gizmo drawn over the viewport with ImGui: three arrows along the world axes
// (drag: move along that axis) or three rings about them (drag: turn about that axis), at a
// pivot in the cell. The projection follows MuJoCo's free camera, so the handles sit on the
// drawn scene. Plain math plus ImGui drawing; the caller applies the motion to the document.
#pragma once

#include <imgui.h>

#include "core/pose.h"
#include "sim/mjcf.h"

namespace wrap::gui {

/// The viewport's camera as a pinhole projection into a screen rectangle.
struct ScreenCamera {
  CameraView view;       ///< MuJoCo free camera (look-at, azimuth, elevation, distance).
  double fovy_deg = 45;  ///< Vertical field of view [deg].
  ImVec2 origin{0, 0};   ///< Top-left corner of the viewport [px].
  ImVec2 size{1, 1};     ///< Its size [px].
  /// The screen point of world point p_W; false when it is behind the camera.
  bool Project(const Vec3& p_W, ImVec2& out) const;
  /// World metres per pixel at the depth of p_W.
  double MetresPerPixel(const Vec3& p_W) const;
};

/// What a gizmo drag gives this frame: a translation or a rotation about the pivot (world).
struct GizmoMotion {
  Vec3 translation_W = Vec3::Zero();  ///< [m].
  Vec3 axis_W = Vec3::UnitZ();        ///< Rotation axis.
  double angle_rad = 0.0;             ///< About axis_W through the pivot.
  bool any() const { return translation_W.squaredNorm() > 0.0 || angle_rad != 0.0; }
};

/// The handle under `mouse` (0-2: move along x, y, z; 3-5: turn about x, y, z), or -1.
int GizmoHandleAt(const ScreenCamera& cam, const Vec3& pivot_W, bool rotate, ImVec2 mouse);
/// Draws the gizmo; `active` (a handle index, or -1) and `hovered` drawn brighter.
void DrawGizmo(ImDrawList* dl, const ScreenCamera& cam, const Vec3& pivot_W, bool rotate,
               int active, int hovered);
/// The motion that dragging handle `handle` by `delta` pixels (this frame) from `mouse` makes.
GizmoMotion GizmoDrag(const ScreenCamera& cam, const Vec3& pivot_W, int handle, ImVec2 mouse,
                      ImVec2 delta);
/// X_WO moved by `motion` (a turn about the pivot, then the translation).
Iso3 ApplyGizmo(const Iso3& X_WO, const Vec3& pivot_W, const GizmoMotion& motion);

}  // namespace wrap::gui
