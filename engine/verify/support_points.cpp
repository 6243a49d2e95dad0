// Where the physics run's parts bear on the table: the points of each part the plan rests it on,
// chosen as the wrench LP's table supports are (task/world.cpp TableContacts), so that MuJoCo's
// contacts of a resting part lie where the LP's friction pyramids do (sim/mjcf.h), and the
// switch that lets only the spheres of the orientation a part is in meet the table.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "geometry/convex_hull.h"
#include "task/plan_state.h"
#include "verify/detail/simulator.h"

namespace wrap::detail {

std::vector<std::vector<SupportSet>> RestingSupportSets(const CellScene& scene,
                                                        const AssemblyTree& tree,
                                                        const Plan& plan) {
  const int np = static_cast<int>(scene.parts.size());
  std::vector<std::vector<SupportSet>> out(np);
  std::map<const TriangleMesh*, std::vector<Vec3>> hulls;  // Hull vertices per distinct mesh.
  const double top = scene.table.top_center.z();
  auto add = [&](int p, const Iso3& X_WP) {
    auto [it, fresh] = hulls.try_emplace(scene.parts[p].mesh.get());
    if (fresh) {
      auto hull = ComputeConvexHull(*scene.parts[p].mesh);
      if (hull) it->second = std::move(hull->mesh.vertices);
    }
    // The vertices the part touches the table with: within kRestReach_m of the table top, as
    // the LP counts them, and within kTouchReach_m of the lowest (a chamfered edge's vertices
    // 0.8 mm up widen the LP's polygon a little; as spheres they would carry nothing and
    // crowd the face's corners out).
    double lowest = std::numeric_limits<double>::infinity();
    for (const Vec3& v : it->second) lowest = std::min(lowest, (X_WP * v).z());
    if (!(lowest <= top + kRestReach_m)) return;
    std::vector<Vec3> low;  // Those vertices, part frame.
    std::vector<Eigen::Vector2d> xy;
    for (const Vec3& v : it->second) {
      const Vec3 w = X_WP * v;
      if (w.z() > lowest + kTouchReach_m) continue;
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
    const Vec3 up_P = X_WP.linear().transpose() * Vec3::UnitZ();
    auto set = std::find_if(out[p].begin(), out[p].end(), [&](const SupportSet& s) {
      return s.up_P.dot(up_P) > std::cos(kSameOrientation_rad);
    });
    if (set == out[p].end()) set = out[p].insert(out[p].end(), SupportSet{up_P, {}});
    // The sphere on a vertex touches the table where the vertex does: its centre is raised by
    // its radius along the table's normal.
    for (int c : corners) {
      const Vec3 v = low[c] + kSupportSphereRadius_m * set->up_P;
      const bool seen = std::any_of(
          set->centres_P.begin(), set->centres_P.end(),
          [&](const Vec3& u) { return (u - v).squaredNorm() < kSamePoint_m * kSamePoint_m; });
      if (!seen) set->centres_P.push_back(v);
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

// Lets the support spheres of the orientation each part is in meet the table, and no others: a
// sphere raised for one orientation stands up to its radius proud of the corner in another (a
// cube set down on another face: its cup met 126 N).
void Simulator::SwitchSupports() {
  const double cos_tilt = std::cos(kSupportTilt_rad);
  for (size_t p = 0; p < supports_.size(); ++p) {
    if (supports_[p].empty()) continue;
    const Vec3 up_P = PartPose(static_cast<int>(p)).linear().transpose() * Vec3::UnitZ();
    for (const SupportGeoms& s : supports_[p]) {
      const bool on = up_P.dot(s.up_P) >= cos_tilt;
      for (int g : s.geoms) {
        model_->geom_contype[g] = on ? kPartContype : 0;
        model_->geom_conaffinity[g] = on ? kPartConaffinity : 0;
      }
    }
  }
}

}  // namespace wrap::detail
