// Queries against one triangle mesh through a bounding-volume hierarchy of boxes: ray casts,
// closest points, inside tests, and uniform sampling of its surface. What the grasp samplers ask of
// a part, and what the geometry checks (contacts, overlaps) ask of two.
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "core/pose.h"
#include "geometry/mesh.h"

namespace wrap {

/// A uniform double in [0, 1) from 53 random bits (the same sequence on every standard library).
inline double Uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

/// One ray hit.
struct RayHit {
  double t = 0.0;     ///< Distance along the (unit) direction [m].
  int triangle = -1;  ///< Triangle index.
};

/// The point of a mesh nearest to a query point.
struct ClosestPoint {
  double distance = 0.0;     ///< Unsigned distance to the surface [m].
  Vec3 point = Vec3::Zero();  ///< The nearest surface point [m].
  int triangle = -1;          ///< The triangle it lies on.
};

/// A mesh prepared for ray casts, closest points and surface sampling. Immutable after construction: share one
/// between threads.
class MeshQuery {
 public:
  /// Copies the mesh and builds the hierarchy (median splits, up to 4 triangles a leaf).
  explicit MeshQuery(const TriangleMesh& mesh);

  /// The nearest hit with t in (t_min, t_max) of the ray origin + t dir (`dir` unit), or none.
  std::optional<RayHit> Cast(const Vec3& origin, const Vec3& dir, double t_min, double t_max) const;

  /// The nearest surface point to `p` if it lies within `max_distance` [m], else none.
  std::optional<ClosestPoint> Closest(const Vec3& p, double max_distance) const;

  /// True when `p` lies inside the closed surface: the majority of three ray-parity counts along
  /// fixed skew directions (a ray grazing an edge miscounts one of them at most). Meaningless for
  /// an open mesh.
  bool Contains(const Vec3& p) const;

  /// How deep `p` lies inside the closed surface [m]: its distance to the surface when inside and
  /// within `max_depth`, 0 when outside (or deeper than `max_depth`: then `max_depth`).
  double Depth(const Vec3& p, double max_depth) const;

  /// A point drawn uniformly over the surface area, with its triangle.
  Vec3 SamplePoint(std::mt19937_64& rng, int* triangle) const;

  /// Outward unit normal of a triangle (zero for a degenerate one).
  const Vec3& normal(int triangle) const { return normals_[triangle]; }
  /// Total surface area [m^2].
  double area() const { return total_area_; }
  /// The mesh.
  const TriangleMesh& mesh() const { return mesh_; }

 private:
  struct Node {
    Vec3 lo = Vec3::Zero();
    Vec3 hi = Vec3::Zero();
    int left = -1;  // child index for an inner node, first triangle slot for a leaf
    int count = 0;  // triangles in a leaf, 0 for an inner node (children left, left + 1)
  };
  void Build(int begin, int end, std::vector<Vec3>& centroids);
  int CountCrossings(const Vec3& origin, const Vec3& dir) const;

  TriangleMesh mesh_;
  std::vector<Vec3> normals_;
  std::vector<double> cumulative_area_;
  double total_area_ = 0.0;
  std::vector<int> order_;  // triangle indices, leaves refer to ranges of it
  std::vector<Node> nodes_;
};

}  // namespace wrap
