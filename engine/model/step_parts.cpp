#include "model/step_parts.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "geometry/convex_hull.h"
#include "geometry/stable_placement.h"
#include "model/validate.h"

namespace wrap {

namespace {

constexpr double kGap_m = 0.03;     // between neighbouring parts on the table
constexpr double kMargin_m = 0.05;  // from the table edge

/// The rotation that rests `mesh` on a table in its most stable placement, its lowest point at
/// z = 0 and its centre of mass over the origin; the mesh as modelled (lowest point at 0) when
/// no placement rests.
Iso3 RestingPose(const TriangleMesh& mesh) {
  Iso3 X = Iso3::Identity();
  const MassProperties mp = ComputeMassProperties(mesh);
  if (auto hull = ComputeConvexHull(mesh)) {
    const auto placements = ComputeStablePlacements(*hull, mp.com);
    if (!placements.empty()) return placements.front().X_TA;
  }
  const Aabb box = ComputeAabb(mesh);
  X.translation() = Vec3(-mp.com.x(), -mp.com.y(), -box.min.z());
  return X;
}

/// Axis-aligned footprint of `mesh` posed by `X` in the table plane: lower and upper corners.
std::pair<Eigen::Vector2d, Eigen::Vector2d> Footprint(const TriangleMesh& mesh, const Iso3& X) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  for (const Vec3& v : mesh.vertices) {
    const Vec3 w = X * v;
    lo = lo.cwiseMin(w.head<2>());
    hi = hi.cwiseMax(w.head<2>());
  }
  return {lo, hi};
}

}  // namespace

Rgba NewPartColor(size_t index) {
  static const Rgba kPalette[] = {{0.949, 0.557, 0.169, 1}, {0.306, 0.475, 0.655, 1},
                                  {0.463, 0.718, 0.698, 1}, {0.349, 0.631, 0.310, 1},
                                  {0.690, 0.478, 0.631, 1}, {0.882, 0.341, 0.349, 1}};
  return kPalette[index % std::size(kPalette)];
}

std::vector<Part> PartsFromStep(const StepAssembly& assembly, const Project& project,
                                const StepPartsOptions& options) {
  std::set<std::string> taken;
  for (const Part& p : project.parts) taken.insert(p.name);
  for (const Step& s : project.steps) taken.insert(s.name);
  // Spots already used on the table: the parts there (discs of 5 cm around their origins) and
  // the robots' bases (15 cm).
  struct Disc {
    Eigen::Vector2d centre;
    double radius = 0.0;
  };
  std::vector<Disc> occupied;
  for (const Part& p : project.parts) occupied.push_back({p.initial_pose.xyz.head<2>(), 0.05});
  for (const Robot& r : project.robots) {
    occupied.push_back({RobotBaseInWorld(project, r).translation().head<2>(), 0.15});
  }

  const Table& table = project.table;
  const Eigen::Vector2d corner =
      table.center_xy.head<2>() - 0.5 * table.size.head<2>() + Eigen::Vector2d::Constant(kMargin_m);
  const double row_end = table.center_xy.x() + 0.5 * table.size.x() - kMargin_m;
  double x = corner.x(), y = corner.y(), row_depth = 0.0;

  std::vector<Part> parts;
  std::vector<Iso3> rest(assembly.solids.size());
  std::vector<bool> rested(assembly.solids.size(), false);
  for (const StepInstance& inst : assembly.instances) {
    const auto s = static_cast<size_t>(inst.solid);
    const TriangleMesh& mesh = assembly.solids[s].mesh;
    if (!rested[s]) rest[s] = RestingPose(mesh), rested[s] = true;
    Part part;
    part.name = inst.name.empty() ? assembly.solids[s].name : inst.name;
    for (int k = 2; taken.contains(part.name); ++k) {
      part.name =
          (inst.name.empty() ? assembly.solids[s].name : inst.name) + "_" + std::to_string(k);
    }
    taken.insert(part.name);
    part.mesh = options.mesh;
    part.solid = assembly.solids[s].name;
    part.density_kg_m3 = options.density_kg_m3;
    part.assembled_pose = FromIsometry(inst.X_AS);
    part.color = inst.color ? Rgba(*inst.color) : NewPartColor(project.parts.size() + parts.size());

    // The next free spot of the rows, clear of the parts and robots already on the table.
    const auto [lo, hi] = Footprint(mesh, rest[s]);
    const Eigen::Vector2d size = hi - lo;
    for (int tries = 0; tries < 1000; ++tries) {
      if (x + size.x() > row_end && x > corner.x()) {
        x = corner.x();
        y += row_depth + kGap_m;
        row_depth = 0.0;
      }
      const Eigen::Vector2d centre(x + 0.5 * size.x(), y + 0.5 * size.y());
      const bool clear = std::none_of(occupied.begin(), occupied.end(), [&](const Disc& o) {
        return (o.centre - centre).norm() < 0.5 * size.norm() + o.radius + kGap_m;
      });
      if (clear) break;
      x += 0.5 * size.x() + kGap_m;
    }
    Iso3 X_WP = rest[s];
    X_WP.translation() += Vec3(x - lo.x(), y - lo.y(), table.height);
    part.initial_pose = FromIsometry(X_WP);
    occupied.push_back({Eigen::Vector2d(x + 0.5 * size.x(), y + 0.5 * size.y()), 0.0});
    x += size.x() + kGap_m;
    row_depth = std::max(row_depth, size.y());
    parts.push_back(std::move(part));
  }
  return parts;
}

}  // namespace wrap
