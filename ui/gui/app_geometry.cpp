// The assembled view of the viewport (View > Assembled view, View > Contacts): the parts at their
// assembled poses over the table's centre; the contact graph of the live validation (a ball at
// each contact's centre, its main normal, a line between the touching parts' centres); and the
// selected step's insertion: its moved input drawn at the approach pose, its bounding box swept
// along the axis to the mating pose, green where the path is free, red from where the validation
// found it blocked.
#include <algorithm>

#include "gui/app_impl.h"
#include "gui/geometry_view.h"
#include "mating/check.h"

namespace wrap::gui {

namespace {

constexpr Rgba kFree = {0.15, 0.85, 0.3, 1.0};
constexpr Rgba kBlocked = {0.95, 0.15, 0.1, 1.0};
constexpr Rgba kOutline = {0.92, 0.92, 0.95, 1.0};
constexpr Rgba kContact = {1.0, 0.8, 0.1, 1.0};

// The box of part `i` of the scene at X (its mesh's box corners moved: cheap, conservative).
Aabb BoxAt(const ScenePart& part, const Iso3& X) {
  Aabb out;
  if (!part.mesh) {
    out.min = out.max = X.translation();
    return out;
  }
  const Aabb box = ComputeAabb(*part.mesh);
  out.min = Vec3::Constant(1e30);
  out.max = -out.min;
  for (int k = 0; k < 8; ++k) {
    const Vec3 c(k & 1 ? box.max.x() : box.min.x(), k & 2 ? box.max.y() : box.min.y(),
                 k & 4 ? box.max.z() : box.min.z());
    const Vec3 w = X * c;
    out.min = out.min.cwiseMin(w);
    out.max = out.max.cwiseMax(w);
  }
  return out;
}

}  // namespace

void App::AssembledView(SceneState& state, std::vector<render::SceneLine>& lines,
                        std::vector<render::SceneDot>& dots) {
  const CellScene& scene = s_.viewport.scene();
  const Project& p = s_.doc.project();
  std::vector<Aabb> boxes;
  for (const ScenePart& part : scene.parts) boxes.push_back(BoxAt(part, part.X_AP));
  const Iso3 X_WA = AssembledPlacement(p.table, boxes);
  for (size_t i = 0; i < scene.parts.size() && i < state.X_WP.size(); ++i) {
    state.X_WP[i] = X_WA * scene.parts[i].X_AP;
  }
  if (!assembled_framed_) {
    // Turning the view on looks at the assembly (Reset view goes back to the whole cell).
    Aabb all;
    all.min = Vec3::Constant(1e30);
    all.max = -all.min;
    for (const Aabb& b : boxes) {
      all.min = all.min.cwiseMin(X_WA * b.min);
      all.max = all.max.cwiseMax(X_WA * b.max);
    }
    if (all.min.x() <= all.max.x()) s_.viewport.FrameBounds(all);
    assembled_framed_ = true;
  }
  const ValidationResult v = s_.validation.result();
  auto part_index = [&](const std::string& name) {
    for (size_t i = 0; i < scene.parts.size(); ++i) {
      if (scene.parts[i].name == name) return static_cast<int>(i);
    }
    return -1;
  };
  if (s_.show_contacts && v.geometry && v.project) {
    for (const Contact& c : v.geometry->contacts.contacts) {
      if (c.a < 0 || c.b < 0 || c.a >= static_cast<int>(v.project->parts.size()) ||
          c.b >= static_cast<int>(v.project->parts.size())) {
        continue;
      }
      const int a = part_index(v.project->parts[c.a].name);
      const int b = part_index(v.project->parts[c.b].name);
      if (a < 0 || b < 0) continue;
      const Vec3 at = X_WA * c.centroid_A;
      dots.push_back({at, 0.008, kContact});
      if (!c.normals.empty()) {
        const Vec3 n = X_WA.linear() * c.normals.front().n_A;
        lines.push_back({at - 0.03 * n, at + 0.03 * n, kContact, 0.002});
      }
      const Vec3 ca = X_WA * (0.5 * (boxes[a].min + boxes[a].max));
      const Vec3 cb = X_WA * (0.5 * (boxes[b].min + boxes[b].max));
      lines.push_back({ca, cb, {1.0, 0.8, 0.1, 0.6}, 0.0015});
    }
  }
  // The selected step's insertion.
  const auto& tree = s_.viewport.check().tree;
  auto step = std::find_if(p.steps.begin(), p.steps.end(),
                           [&](const Step& st) { return st.name == s_.selection.step; });
  if (!tree || step == p.steps.end()) return;
  const int s = static_cast<int>(step - p.steps.begin());
  if (step->mating.axis.norm() < 1e-9 || tree->Find(step->mating.moved) < 0 ||
      tree->Find(step->mating.base) < 0) {
    return;
  }
  const InsertionPath path = StepInsertionPath(p, *tree, s, p.steps[s].mating.final_poses.empty() ? -1 : 0);
  double blocked_at = -1.0;
  if (const auto verdict = FindStepVerdict(v, *step)) {
    if (!verdict->geometry->paths.empty() && verdict->geometry->paths.front().blocked) {
      blocked_at = verdict->geometry->paths.front().at_m;
    }
  }
  Aabb moved;
  moved.min = Vec3::Constant(1e30);
  moved.max = -moved.min;
  const Vec3 back = -path.length_m * path.axis_A.normalized();
  for (int part : path.moved) {
    if (part < 0 || part >= static_cast<int>(scene.parts.size())) continue;
    const Iso3 X_AM = path.X_BM * scene.parts[part].X_AP;
    const Aabb b = BoxAt(scene.parts[part], X_AM);
    moved.min = moved.min.cwiseMin(b.min);
    moved.max = moved.max.cwiseMax(b.max);
    // The moved input waits at its approach pose.
    Iso3 X_approach = X_AM;
    X_approach.translation() += back;
    state.X_WP[part] = X_WA * X_approach;
  }
  if (!(moved.min.x() <= moved.max.x())) return;
  for (const SweepSegment& seg : InsertionSweep(moved, path.axis_A, path.length_m, blocked_at)) {
    const Rgba& colour = seg.kind == SweepSegment::Kind::kFree      ? kFree
                         : seg.kind == SweepSegment::Kind::kBlocked ? kBlocked
                                                                    : kOutline;
    const double width = seg.kind == SweepSegment::Kind::kOutline ? 0.0015 : 0.003;
    lines.push_back({X_WA * seg.from_A, X_WA * seg.to_A, colour, width});
  }
}

}  // namespace wrap::gui
