// Where the physics run's parts bear on the table: the points of each part the plan rests it on,
// chosen as the wrench LP's table supports are (task/world.cpp TableContacts), so that MuJoCo's
// contacts of a resting part lie where the LP's friction pyramids do (sim/mjcf.h).
#include <algorithm>
#include <map>

#include "geometry/convex_hull.h"
#include "task/plan_state.h"
#include "verify/detail/simulator.h"

namespace wrap::detail {

std::vector<std::vector<Vec3>> RestingSupportPoints(const CellScene& scene,
                                                    const AssemblyTree& tree, const Plan& plan) {
  const int np = static_cast<int>(scene.parts.size());
  std::vector<std::vector<Vec3>> out(np);
  std::map<const TriangleMesh*, std::vector<Vec3>> hulls;  // Hull vertices per distinct mesh.
  const double top = scene.table.top_center.z();
  auto add = [&](int p, const Iso3& X_WP) {
    auto [it, fresh] = hulls.try_emplace(scene.parts[p].mesh.get());
    if (fresh) {
      auto hull = ComputeConvexHull(*scene.parts[p].mesh);
      if (hull) it->second = std::move(hull->mesh.vertices);
    }
    // The sphere on a vertex touches the table where the vertex does: its centre is raised by
    // its radius along the table's normal (world z, in P).
    const Vec3 up_P = X_WP.linear().transpose() * Vec3::UnitZ() * kSupportSphereRadius_m;
    std::vector<Vec3> low;  // Hull vertices on the table, part frame.
    std::vector<Eigen::Vector2d> xy;
    for (const Vec3& v : it->second) {
      const Vec3 w = X_WP * v;
      if (w.z() > top + kRestReach_m) continue;
      low.push_back(v);
      xy.emplace_back(w.x(), w.y());
    }
    // The corners of the support polygon, at most kMaxSupportPoints spread along it.
    std::vector<int> corners = ConvexHull2d(xy);
    if (corners.size() > kMaxSupportPoints) {
      std::vector<int> kept;
      for (size_t i = 0; i < kMaxSupportPoints; ++i) {
        kept.push_back(corners[i * corners.size() / kMaxSupportPoints]);
      }
      corners = std::move(kept);
    }
    for (int c : corners) {
      const Vec3 v = low[c] + up_P;
      const bool seen = std::any_of(out[p].begin(), out[p].end(), [&](const Vec3& u) {
        return (u - v).squaredNorm() < kSamePoint_m * kSamePoint_m;
      });
      if (!seen) out[p].push_back(v);
    }
  };
  for (const PlanState& state : ReplayPlanStates(plan)) {
    for (const auto& [node, o] : state.objects) {
      if (!o.resting || node < 0 || node >= static_cast<int>(tree.nodes.size())) continue;
      for (int p : tree.nodes[node].parts) {
        if (p >= 0 && p < np) add(p, o.X_WA * scene.parts[p].X_AP);
      }
    }
  }
  return out;
}

}  // namespace wrap::detail
