#include "mating/start_layout.h"

#include <algorithm>

namespace wrap {

namespace {

constexpr double kDepthCap_m = 1.0;    // deeper than a metre: report a metre
constexpr int kInnerProbes = 200;      // surface samples also probed a little inside
constexpr double kInnerProbe_m = 5e-4;  // how far inside

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
  const std::vector<Vec3>& samples = g.samples(a);
  for (const Vec3& s : samples) probe(s);
  // Points inside a: two solids that coincide (a part placed where another is) share every
  // surface point, which lies on b's surface at depth 0. Its centre of mass (when inside it) and
  // points a little inside its surface.
  const MeshQuery& own = g.query(a);
  const Vec3 com = ComputeMassProperties(g.mesh(a)).com;
  if (own.Contains(com)) probe(com);
  const int stride = std::max<int>(1, static_cast<int>(samples.size()) / kInnerProbes);
  for (size_t i = 0; i < samples.size(); i += stride) {
    const auto c = own.Closest(samples[i], 1e-9);
    if (!c) continue;
    for (double inset : {kInnerProbe_m, 4.0 * kInnerProbe_m}) {
      const Vec3 p = samples[i] - inset * own.normal(c->triangle);
      if (own.Contains(p)) probe(p);
    }
  }
  return deepest;
}

std::vector<StartOverlap> StartOverlaps(AssemblyGeometry& g, const std::vector<Iso3>& X_WP,
                                        double touch_depth_m) {
  std::vector<StartOverlap> out;
  const int n = g.num_parts();
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
      const double depth = std::max(PenetrationDepth(g, a, X_WP[a], b, X_WP[b]),
                                    PenetrationDepth(g, b, X_WP[b], a, X_WP[a]));
      if (depth > touch_depth_m) out.push_back({a, b, depth});
    }
  }
  return out;
}

}  // namespace wrap
