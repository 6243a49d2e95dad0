#include "geometry/convex_hull.h"

#include "geometry/detail/qhull_adapter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <utility>

namespace wrap {

namespace {

// Runs qhull (through the C++17 adapter) and returns the hull triangles as indices into
// `points`, counter-clockwise seen from outside.
Result<std::vector<Eigen::Vector3i>> QhullTriangles(std::span<const Vec3> points) {
  std::vector<double> coords;
  coords.reserve(3 * points.size());
  for (const Vec3& p : points) coords.insert(coords.end(), {p.x(), p.y(), p.z()});
  const detail::QhullOutput out =
      detail::RunQhull3d(coords.data(), static_cast<int>(points.size()));
  if (!out.ok) {
    return Fail(out.flat ? ErrorCode::kInvalidInput : ErrorCode::kInternal,
                "convex hull: qhull failed on " + std::to_string(points.size()) +
                    " points: " + out.error +
                    (out.flat ? " (the points span no volume: a flat or degenerate mesh)" : ""));
  }
  std::vector<Eigen::Vector3i> triangles;
  triangles.reserve(out.triangles.size());
  for (const auto& t : out.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  return triangles;
}

// Groups hull triangles into planar facets: region growing over edge neighbours from the
// largest unassigned triangle, accepting neighbours parallel to and on the seed's plane.
void MergeCoplanar(const ConvexHullOptions& options, ConvexHull& hull) {
  const TriangleMesh& mesh = hull.mesh;
  const int nt = static_cast<int>(mesh.triangles.size());
  std::vector<Vec3> normals(nt);
  std::vector<double> areas(nt);
  for (int i = 0; i < nt; ++i) {
    const Eigen::Vector3i& t = mesh.triangles[i];
    const Vec3 c = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                       .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    areas[i] = 0.5 * c.norm();
    normals[i] = areas[i] > 0.0 ? Vec3(c.normalized()) : Vec3::Zero();
  }
  // Edge -> the triangles that use it (two on a closed hull).
  std::map<std::pair<int, int>, std::vector<int>> edges;
  for (int i = 0; i < nt; ++i) {
    for (int k = 0; k < 3; ++k) {
      int a = mesh.triangles[i][k], b = mesh.triangles[i][(k + 1) % 3];
      if (a > b) std::swap(a, b);
      edges[{a, b}].push_back(i);
    }
  }
  std::vector<int> order(nt);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return areas[a] > areas[b]; });

  const double cos_tol = std::cos(options.coplanar_angle_rad);
  hull.triangle_facet.assign(nt, -1);
  std::vector<int> queue;
  for (int seed : order) {
    if (hull.triangle_facet[seed] >= 0) continue;
    const int facet = static_cast<int>(hull.facets.size());
    HullFacet f;
    const Vec3 n0 = normals[seed];
    const double d0 = n0.dot(mesh.vertices[mesh.triangles[seed][0]]);
    hull.triangle_facet[seed] = facet;
    queue.assign(1, seed);
    for (size_t qi = 0; qi < queue.size(); ++qi) {
      const int cur = queue[qi];
      f.triangles.push_back(cur);
      for (int k = 0; k < 3; ++k) {
        int a = mesh.triangles[cur][k], b = mesh.triangles[cur][(k + 1) % 3];
        if (a > b) std::swap(a, b);
        for (int nb : edges[{a, b}]) {
          if (hull.triangle_facet[nb] >= 0) continue;
          // A zero-area sliver has no normal of its own: its corners decide.
          if (areas[nb] > 0.0 && normals[nb].dot(n0) < cos_tol) continue;
          if (areas[seed] == 0.0) continue;
          bool on_plane = true;
          for (int c = 0; c < 3; ++c) {
            on_plane = on_plane && std::abs(n0.dot(mesh.vertices[mesh.triangles[nb][c]]) - d0) <=
                                       options.coplanar_distance_m;
          }
          if (!on_plane) continue;
          hull.triangle_facet[nb] = facet;
          queue.push_back(nb);
        }
      }
    }
    // Normal: area-weighted mean; offset: the supporting plane through the outermost corner.
    Vec3 sum = Vec3::Zero();
    std::vector<int> corners;
    for (int t : f.triangles) {
      sum += areas[t] * normals[t];
      f.area_m2 += areas[t];
      for (int c = 0; c < 3; ++c) corners.push_back(mesh.triangles[t][c]);
    }
    f.normal = sum.norm() > 0.0 ? Vec3(sum.normalized()) : n0;
    if (f.normal.isZero()) f.normal = Vec3::UnitZ();
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    f.offset = -std::numeric_limits<double>::infinity();
    for (int c : corners) f.offset = std::max(f.offset, f.normal.dot(mesh.vertices[c]));
    // Boundary: the 2-D hull of the corners in a basis (e1, e2) with e1 x e2 = normal, so that
    // counter-clockwise in the plane is counter-clockwise seen from outside.
    const Vec3 e1 = f.normal.unitOrthogonal();
    const Vec3 e2 = f.normal.cross(e1);
    std::vector<Eigen::Vector2d> flat;
    flat.reserve(corners.size());
    for (int c : corners) flat.emplace_back(e1.dot(mesh.vertices[c]), e2.dot(mesh.vertices[c]));
    for (int k : ConvexHull2d(flat)) f.polygon.push_back(corners[k]);
    hull.facets.push_back(std::move(f));
  }
}

}  // namespace

std::vector<int> ConvexHull2d(std::span<const Eigen::Vector2d> points) {
  const int n = static_cast<int>(points.size());
  std::vector<int> idx(n);
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](int a, int b) {
    return points[a].x() < points[b].x() ||
           (points[a].x() == points[b].x() && points[a].y() < points[b].y());
  });
  idx.erase(
      std::unique(idx.begin(), idx.end(), [&](int a, int b) { return points[a] == points[b]; }),
      idx.end());
  if (idx.size() < 3) return idx;
  // Collinear within a relative tolerance counts as collinear (float noise on merged facets).
  double scale = 0.0;
  for (int i : idx) scale = std::max(scale, points[i].cwiseAbs().maxCoeff());
  for (int i : idx) scale = std::max(scale, (points[i] - points[idx[0]]).norm());
  const double eps = 1e-12 * scale * scale;
  auto cross = [&](int o, int a, int b) {
    const Eigen::Vector2d u = points[a] - points[o], v = points[b] - points[o];
    return u.x() * v.y() - u.y() * v.x();
  };
  std::vector<int> h(2 * idx.size());
  size_t k = 0;
  for (int i : idx) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], i) <= eps) --k;
    h[k++] = i;
  }
  for (size_t j = idx.size() - 1, lower = k + 1; j-- > 0;) {
    const int i = idx[j];
    while (k >= lower && cross(h[k - 2], h[k - 1], i) <= eps) --k;
    h[k++] = i;
  }
  h.resize(k - 1);
  return h;
}

Result<ConvexHull> ComputeConvexHull(std::span<const Vec3> points,
                                     const ConvexHullOptions& options) {
  if (points.size() < 4) {
    return Fail(ErrorCode::kInvalidInput,
                "convex hull: needs at least 4 points, got " + std::to_string(points.size()));
  }
  for (const Vec3& p : points) {
    if (!p.allFinite()) {
      return Fail(ErrorCode::kInvalidInput, "convex hull: a point has a non-finite coordinate");
    }
  }
  auto triangles = QhullTriangles(points);
  if (!triangles) return std::unexpected(triangles.error());

  // Keep only the vertices the hull uses, in input order (deterministic numbering).
  ConvexHull hull;
  std::vector<int> remap(points.size(), -1);
  for (const Eigen::Vector3i& t : *triangles) {
    for (int c = 0; c < 3; ++c) remap[t[c]] = 0;
  }
  for (size_t i = 0; i < points.size(); ++i) {
    if (remap[i] < 0) continue;
    remap[i] = static_cast<int>(hull.mesh.vertices.size());
    hull.mesh.vertices.push_back(points[i]);
  }
  hull.mesh.triangles.reserve(triangles->size());
  for (const Eigen::Vector3i& t : *triangles) {
    hull.mesh.triangles.emplace_back(remap[t[0]], remap[t[1]], remap[t[2]]);
  }
  // qhull's facet order follows its internal lists: sort triangles for a stable numbering.
  for (Eigen::Vector3i& t : hull.mesh.triangles) {
    int m = 0;
    if (t[1] < t[m]) m = 1;
    if (t[2] < t[m]) m = 2;
    t = Eigen::Vector3i(t[m], t[(m + 1) % 3], t[(m + 2) % 3]);
  }
  std::sort(hull.mesh.triangles.begin(), hull.mesh.triangles.end(),
            [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
              return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
            });

  const MassProperties mp = ComputeMassProperties(hull.mesh);
  hull.volume_m3 = mp.volume_m3;
  hull.area_m2 = SurfaceArea(hull.mesh);
  // A joggled flat input has a sliver of a hull: below 1e-9 of its box diagonal cubed it is flat.
  const double diag = ComputeAabb(hull.mesh).size().norm();
  if (!(hull.volume_m3 > 1e-9 * diag * diag * diag)) {
    return Fail(ErrorCode::kInvalidInput,
                "convex hull: the points span no volume (a flat or degenerate mesh)");
  }
  MergeCoplanar(options, hull);
  // Largest facets first; renumber the triangle -> facet map accordingly.
  std::vector<int> order(hull.facets.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return hull.facets[a].area_m2 > hull.facets[b].area_m2; });
  std::vector<int> rank(order.size());
  std::vector<HullFacet> sorted;
  sorted.reserve(order.size());
  for (size_t r = 0; r < order.size(); ++r) {
    rank[order[r]] = static_cast<int>(r);
    sorted.push_back(std::move(hull.facets[order[r]]));
  }
  hull.facets = std::move(sorted);
  for (int& f : hull.triangle_facet) f = rank[f];
  return hull;
}

Result<ConvexHull> ComputeConvexHull(const TriangleMesh& mesh, const ConvexHullOptions& options) {
  return ComputeConvexHull(std::span<const Vec3>(mesh.vertices), options);
}

}  // namespace wrap
