#include "geometry/stable_placement.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <unordered_map>

namespace wrap {

namespace {

// The rotation that turns the outward normal `n` straight down (-z), the shortest one.
Mat3 RotationNormalDown(const Vec3& n) {
  if (n.z() > 1.0 - 1e-12)
    return Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()).toRotationMatrix();
  return Eigen::Quaterniond::FromTwoVectors(n, -Vec3::UnitZ()).toRotationMatrix();
}

// Points in a uniform hash grid, for "is there a point within tol of q?".
class PointGrid {
 public:
  PointGrid(const std::vector<Vec3>& points, double cell) : points_(points), cell_(cell) {
    for (int i = 0; i < static_cast<int>(points_.size()); ++i)
      cells_[Key(Cell(points_[i]))].push_back(i);
  }
  bool Contains(const Vec3& q, double tol) const {
    // With cells at least 2 tol wide, the ball of radius tol spans at most 2 cells per axis.
    const Eigen::Vector3i lo = Cell(q - Vec3::Constant(tol));
    const Eigen::Vector3i hi = Cell(q + Vec3::Constant(tol));
    for (int x = lo.x(); x <= hi.x(); ++x) {
      for (int y = lo.y(); y <= hi.y(); ++y) {
        for (int z = lo.z(); z <= hi.z(); ++z) {
          auto it = cells_.find(Key(Eigen::Vector3i(x, y, z)));
          if (it == cells_.end()) continue;
          for (int i : it->second) {
            if ((points_[i] - q).squaredNorm() <= tol * tol) return true;
          }
        }
      }
    }
    return false;
  }

 private:
  Eigen::Vector3i Cell(const Vec3& p) const {
    return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / cell_)),
                           static_cast<int>(std::floor(p.y() / cell_)),
                           static_cast<int>(std::floor(p.z() / cell_)));
  }
  static std::uint64_t Key(const Eigen::Vector3i& c) {
    const auto u = [](int v) {
      return static_cast<std::uint64_t>(static_cast<std::uint32_t>(v) & 0x1FFFFF);
    };
    return (u(c.x()) << 42) | (u(c.y()) << 21) | u(c.z());
  }
  std::vector<Vec3> points_;
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

// The cheap necessary conditions of SameUpToYaw.
bool MaybeSameUpToYaw(const StablePlacement& a, const StablePlacement& b, double tol) {
  return a.support_T.size() == b.support_T.size() &&
         std::abs(a.com_height_m - b.com_height_m) <= tol &&
         std::abs(a.margin_m - b.margin_m) <= tol &&
         std::abs(a.area_m2 - b.area_m2) <=
             tol * 4.0 * std::sqrt(std::max(a.area_m2, b.area_m2)) + tol * tol;
}

// True when rotating placement a about the vertical by some angle gives exactly placement b's
// geometry: then S = X_TA_b^-1 Rz(psi) X_TA_a maps the hull (and the COM, which both frames put
// on their z axis at the same height) onto itself. `grid` holds the hull vertices in A.
bool SameUpToYaw(const StablePlacement& a, const StablePlacement& b,
                 const std::vector<Vec3>& hull_A, const PointGrid& grid, double tol) {
  const int n = static_cast<int>(a.support_T.size());
  // Candidate yaws: a's farthest support corner onto each of b's corners at the same radius,
  // with the polygons' counter-clockwise orders aligned from there (linear per candidate).
  int far = 0;
  for (int k = 1; k < n; ++k) {
    if (a.support_T[k].norm() > a.support_T[far].norm() + 1e-15) far = k;
  }
  const Eigen::Vector2d r = a.support_T[far];
  if (r.norm() < 4.0 * tol) return false;
  for (int start = 0; start < n; ++start) {
    const Eigen::Vector2d& v = b.support_T[start];
    if (std::abs(v.norm() - r.norm()) > tol) continue;
    const double psi = std::atan2(v.y(), v.x()) - std::atan2(r.y(), r.x());
    const Eigen::Rotation2Dd R2(psi);
    bool polygon_ok = true;
    for (int m = 0; m < n && polygon_ok; ++m) {
      polygon_ok = (R2 * a.support_T[(far + m) % n] - b.support_T[(start + m) % n]).norm() <= tol;
    }
    if (!polygon_ok) continue;
    const Iso3 S = b.X_TA.inverse() * Eigen::AngleAxisd(psi, Vec3::UnitZ()) * a.X_TA;
    bool all = true;
    for (size_t k = 0; k < hull_A.size() && all; ++k) all = grid.Contains(S * hull_A[k], tol);
    if (all) return true;
  }
  return false;
}

int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

double PolygonMargin(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  const size_t n = polygon.size();
  if (n < 3) return -std::numeric_limits<double>::infinity();
  double margin = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % n];
    const Eigen::Vector2d e = b - a;
    const double len = e.norm();
    if (len <= 0.0) continue;
    const Eigen::Vector2d d = p - a;
    margin = std::min(margin, (e.x() * d.y() - e.y() * d.x()) / len);
  }
  return margin;
}

std::vector<StablePlacement> ComputeStablePlacements(const ConvexHull& hull, const Vec3& com_A,
                                                     const StablePlacementOptions& options) {
  std::vector<StablePlacement> stable;
  for (int f = 0; f < static_cast<int>(hull.facets.size()); ++f) {
    const HullFacet& facet = hull.facets[f];
    if (facet.polygon.size() < 3) continue;
    const double height = facet.offset - facet.normal.dot(com_A);
    if (!(height > 0.0)) continue;
    StablePlacement s;
    s.facet = f;
    s.normal_A = facet.normal;
    // T: origin at the COM's projection onto the facet plane, facet normal straight down.
    const Mat3 R_TA = RotationNormalDown(facet.normal);
    const Vec3 foot_A = com_A + height * facet.normal;
    s.X_TA.linear() = R_TA;
    s.X_TA.translation() = -R_TA * foot_A;
    // Counter-clockwise seen from outside = from below at rest: reverse for "seen from above".
    for (auto it = facet.polygon.rbegin(); it != facet.polygon.rend(); ++it) {
      const Vec3& p_A = hull.mesh.vertices[*it];
      s.support_A.push_back(p_A);
      s.support_T.push_back((s.X_TA * p_A).head<2>());
    }
    s.area_m2 = facet.area_m2;
    s.margin_m = PolygonMargin(s.support_T, Eigen::Vector2d::Zero());
    s.com_height_m = height;
    if (!(s.margin_m >= options.min_margin_m) || !(s.margin_m > 0.0)) continue;
    s.tip_angle_rad = std::atan2(s.margin_m, height);
    s.equivalent_facets = {f};
    stable.push_back(std::move(s));
  }

  // Merge classes related by a small-step symmetry of the hull (union-find over close normals).
  const int n = static_cast<int>(stable.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  if (options.merge_symmetric && n > 1) {
    const Aabb box = ComputeAabb(hull.mesh);
    const double tol = std::max(1e-9, options.symmetry_tolerance * box.size().norm());
    const double cos_step = std::cos(options.max_symmetry_step_rad);
    const PointGrid grid(hull.mesh.vertices, 2.0 * tol);
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        if (Find(parent, i) == Find(parent, j)) continue;
        if (stable[i].normal_A.dot(stable[j].normal_A) < cos_step) continue;
        if (!MaybeSameUpToYaw(stable[i], stable[j], tol)) continue;
        if (SameUpToYaw(stable[i], stable[j], hull.mesh.vertices, grid, tol)) {
          parent[Find(parent, j)] = Find(parent, i);
        }
      }
    }
  }
  std::vector<StablePlacement> classes;
  std::vector<int> class_of(n, -1);
  for (int i = 0; i < n; ++i) {
    const int root = Find(parent, i);
    if (class_of[root] < 0) {
      // The first member met is the lowest facet index (facets were visited in order).
      class_of[root] = static_cast<int>(classes.size());
      classes.push_back(stable[i]);
    } else {
      classes[class_of[root]].equivalent_facets.push_back(stable[i].facet);
    }
  }
  std::stable_sort(classes.begin(), classes.end(),
                   [](const StablePlacement& a, const StablePlacement& b) {
                     if (a.tip_angle_rad != b.tip_angle_rad)
                       return a.tip_angle_rad > b.tip_angle_rad;
                     return a.facet < b.facet;
                   });
  return classes;
}

}  // namespace wrap
