#include "mating/start_layout.h"

#include <algorithm>

namespace wrap {

namespace {

constexpr double kDepthCap_m = 1.0;  // deeper than a metre: report a metre

}  // namespace

double PenetrationDepth(AssemblyGeometry& g, int a, const Iso3& X_a, int b, const Iso3& X_b) {
  if (!g.has_mesh(a) || !g.has_mesh(b)) return 0.0;
  const Iso3 X_ba = X_b.inverse() * X_a;
  const MeshQuery& target = g.query(b);
  const Aabb box = g.Box(b, Iso3::Identity());
  double deepest = 0.0;
  auto probe = [&](const Vec3& p_a) {
    const Vec3 p = X_ba * p_a;
    if ((p.array() < box.min.array()).any() || (p.array() > box.max.array()).any()) return;
    deepest = std::max(deepest, target.Depth(p, kDepthCap_m));
  };
  for (const Vec3& v : g.mesh(a).vertices) probe(v);
  for (const Vec3& s : g.samples(a)) probe(s);
  return deepest;
}

std::vector<StartOverlap> StartOverlaps(AssemblyGeometry& g, const std::vector<Iso3>& X_WP,
                                        double touch_depth_m) {
  std::vector<StartOverlap> out;
  CollisionWorld& world = g.world(0.0);
  const int n = g.num_parts();
  for (int p = 0; p < n; ++p) world.SetPose(BodyId{p}, X_WP[p]);
  for (int a = 0; a < n; ++a) {
    if (!g.has_mesh(a)) continue;
    const Aabb box_a = g.Box(a, X_WP[a]);
    for (int b = a + 1; b < n; ++b) {
      if (!g.has_mesh(b)) continue;
      const Aabb box_b = g.Box(b, X_WP[b]);
      if ((box_a.max.array() < box_b.min.array()).any() ||
          (box_b.max.array() < box_a.min.array()).any()) {
        continue;
      }
      // Surfaces that do not meet overlap only when one solid holds the other.
      if (!world.Collide(BodyId{a}, BodyId{b}) &&
          !g.query(b).Contains(X_WP[b].inverse() * X_WP[a] * g.mesh(a).vertices[0]) &&
          !g.query(a).Contains(X_WP[a].inverse() * X_WP[b] * g.mesh(b).vertices[0])) {
        continue;
      }
      const double depth = std::max(PenetrationDepth(g, a, X_WP[a], b, X_WP[b]),
                                    PenetrationDepth(g, b, X_WP[b], a, X_WP[a]));
      if (depth > touch_depth_m) out.push_back({a, b, depth});
    }
  }
  return out;
}

}  // namespace wrap
