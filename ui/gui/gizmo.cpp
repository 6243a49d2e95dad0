#include "gui/gizmo.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace wrap::gui {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr float kHandlePx = 90.0f;  // arrow length and ring radius on screen [px]
constexpr float kPickPx = 7.0f;     // a handle is hit within this distance [px]
constexpr int kRingSegments = 48;

// Camera frame of MuJoCo's free camera (mjv_updateCamera): forward, up, right, position.
struct Frame {
  Vec3 forward, up, right, pos;
};

Frame CameraFrame(const CameraView& v) {
  const double ca = std::cos(v.azimuth_deg * kDeg), sa = std::sin(v.azimuth_deg * kDeg);
  const double ce = std::cos(v.elevation_deg * kDeg), se = std::sin(v.elevation_deg * kDeg);
  Frame f;
  f.forward = Vec3(ce * ca, ce * sa, se);
  f.up = Vec3(-se * ca, -se * sa, ce);
  f.right = f.forward.cross(f.up);
  f.pos = v.lookat - v.distance_m * f.forward;
  return f;
}

ImU32 AxisColour(int axis, bool bright) {
  const int a = bright ? 255 : 200;
  switch (axis % 3) {
    case 0:
      return bright ? IM_COL32(255, 120, 110, a) : IM_COL32(220, 60, 50, a);
    case 1:
      return bright ? IM_COL32(140, 255, 140, a) : IM_COL32(60, 190, 60, a);
    default:
      return bright ? IM_COL32(140, 170, 255, a) : IM_COL32(60, 100, 230, a);
  }
}

float SegmentDistance(ImVec2 p, ImVec2 a, ImVec2 b) {
  const float dx = b.x - a.x, dy = b.y - a.y;
  const float len2 = dx * dx + dy * dy;
  float t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0f;
  t = std::clamp(t, 0.0f, 1.0f);
  const float x = a.x + t * dx - p.x, y = a.y + t * dy - p.y;
  return std::sqrt(x * x + y * y);
}

// The ring about world axis `axis` through the pivot, of world radius r: point k of n.
Vec3 RingPoint(const Vec3& pivot, int axis, double r, int k, int n) {
  const double a = 2.0 * std::numbers::pi * k / n;
  const Vec3 u = Vec3::Unit((axis + 1) % 3), w = Vec3::Unit((axis + 2) % 3);
  return pivot + r * (std::cos(a) * u + std::sin(a) * w);
}

}  // namespace

bool ScreenCamera::Project(const Vec3& p_W, ImVec2& out) const {
  const Frame f = CameraFrame(view);
  const Vec3 v = p_W - f.pos;
  const double z = v.dot(f.forward);
  if (z <= 1e-6) return false;
  const double t = std::tan(0.5 * fovy_deg * kDeg);
  const double aspect = size.x / std::max(1.0f, size.y);
  const double nx = v.dot(f.right) / (z * t * aspect), ny = v.dot(f.up) / (z * t);
  out = ImVec2(origin.x + static_cast<float>(0.5 * (nx + 1.0) * size.x),
               origin.y + static_cast<float>(0.5 * (1.0 - ny) * size.y));
  return true;
}

double ScreenCamera::MetresPerPixel(const Vec3& p_W) const {
  const Frame f = CameraFrame(view);
  const double z = std::max(1e-3, (p_W - f.pos).dot(f.forward));
  return 2.0 * z * std::tan(0.5 * fovy_deg * kDeg) / std::max(1.0f, size.y);
}

int GizmoHandleAt(const ScreenCamera& cam, const Vec3& pivot_W, bool rotate, ImVec2 mouse) {
  const double L = kHandlePx * cam.MetresPerPixel(pivot_W);
  ImVec2 o;
  if (!cam.Project(pivot_W, o)) return -1;
  int best = -1;
  float best_d = kPickPx;
  for (int axis = 0; axis < 3; ++axis) {
    if (!rotate) {
      ImVec2 e;
      if (!cam.Project(pivot_W + L * Vec3::Unit(axis), e)) continue;
      const float d = SegmentDistance(mouse, o, e);
      if (d < best_d) {
        best_d = d;
        best = axis;
      }
      continue;
    }
    ImVec2 prev;
    bool have = cam.Project(RingPoint(pivot_W, axis, 0.8 * L, 0, kRingSegments), prev);
    for (int k = 1; k <= kRingSegments; ++k) {
      ImVec2 p;
      const bool ok = cam.Project(RingPoint(pivot_W, axis, 0.8 * L, k, kRingSegments), p);
      if (ok && have) {
        const float d = SegmentDistance(mouse, prev, p);
        if (d < best_d) {
          best_d = d;
          best = 3 + axis;
        }
      }
      prev = p;
      have = ok;
    }
  }
  return best;
}

void DrawGizmo(ImDrawList* dl, const ScreenCamera& cam, const Vec3& pivot_W, bool rotate,
               int active, int hovered) {
  const double L = kHandlePx * cam.MetresPerPixel(pivot_W);
  ImVec2 o;
  if (!cam.Project(pivot_W, o)) return;
  for (int axis = 0; axis < 3; ++axis) {
    const int handle = rotate ? 3 + axis : axis;
    const bool bright = handle == active || handle == hovered;
    const ImU32 col = AxisColour(axis, bright);
    const float thick = bright ? 4.0f : 2.5f;
    if (!rotate) {
      ImVec2 e;
      if (!cam.Project(pivot_W + L * Vec3::Unit(axis), e)) continue;
      dl->AddLine(o, e, col, thick);
      dl->AddCircleFilled(e, bright ? 7.0f : 5.5f, col);
      continue;
    }
    ImVec2 prev;
    bool have = cam.Project(RingPoint(pivot_W, axis, 0.8 * L, 0, kRingSegments), prev);
    for (int k = 1; k <= kRingSegments; ++k) {
      ImVec2 p;
      const bool ok = cam.Project(RingPoint(pivot_W, axis, 0.8 * L, k, kRingSegments), p);
      if (ok && have) dl->AddLine(prev, p, col, thick);
      prev = p;
      have = ok;
    }
  }
  dl->AddCircleFilled(o, 4.0f, IM_COL32(255, 255, 255, 230));
}

GizmoMotion GizmoDrag(const ScreenCamera& cam, const Vec3& pivot_W, int handle, ImVec2 mouse,
                      ImVec2 delta) {
  GizmoMotion m;
  if (handle < 0 || (delta.x == 0.0f && delta.y == 0.0f)) return m;
  const double L = kHandlePx * cam.MetresPerPixel(pivot_W);
  ImVec2 o;
  if (!cam.Project(pivot_W, o)) return m;
  if (handle < 3) {
    // Along the axis: the mouse's motion projected onto the axis's screen direction.
    const Vec3 axis = Vec3::Unit(handle);
    ImVec2 e;
    if (!cam.Project(pivot_W + L * axis, e)) return m;
    const double dx = e.x - o.x, dy = e.y - o.y;
    const double len2 = dx * dx + dy * dy;
    if (len2 < 4.0) return m;  // the axis points at the camera: no sensible drag
    const double along = (delta.x * dx + delta.y * dy) / len2;
    m.translation_W = along * L * axis;
    return m;
  }
  // About the axis: the mouse's motion along the ring's tangent where it was grabbed, over the
  // ring's radius on screen.
  const int axis = handle - 3;
  m.axis_W = Vec3::Unit(axis);
  int nearest = 0;
  float best = 1e9f;
  std::vector<ImVec2> pts(kRingSegments + 1);
  for (int k = 0; k <= kRingSegments; ++k) {
    if (!cam.Project(RingPoint(pivot_W, axis, 0.8 * L, k, kRingSegments), pts[k])) return m;
    const float d = std::hypot(pts[k].x - mouse.x, pts[k].y - mouse.y);
    if (d < best) {
      best = d;
      nearest = k;
    }
  }
  const ImVec2 a = pts[nearest], b = pts[(nearest + 1) % kRingSegments];
  const double tx = b.x - a.x, ty = b.y - a.y;
  const double seg = std::hypot(tx, ty);
  if (seg < 1e-3) return m;
  const double along = (delta.x * tx + delta.y * ty) / seg;  // pixels along the tangent
  const double step_world = 2.0 * std::numbers::pi * 0.8 * L / kRingSegments;
  m.angle_rad = along / seg * step_world / (0.8 * L);
  return m;
}

Iso3 ApplyGizmo(const Iso3& X_WO, const Vec3& pivot_W, const GizmoMotion& motion) {
  Iso3 X = X_WO;
  if (motion.angle_rad != 0.0) {
    const Mat3 R = Eigen::AngleAxisd(motion.angle_rad, motion.axis_W).toRotationMatrix();
    X.linear() = R * X_WO.linear();
    X.translation() = pivot_W + R * (X_WO.translation() - pivot_W);
  }
  X.translation() += motion.translation_W;
  return X;
}

}  // namespace wrap::gui
