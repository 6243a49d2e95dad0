// Exact first contact of two triangle meshes when one of them translates along a line: for a pair
// of triangles the separating-axis test in the travel parameter (an interval per axis), and a box
// tree per mesh that finds the pairs worth testing in one traversal, with no step size.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "core/pose.h"
#include "geometry/mesh.h"

namespace wrap {

/// The travel parameters t at which triangle `a` translated by t d meets triangle `b` (closed
/// triangles: touching counts). The set is an interval, empty when lo > hi; unbounded ends are
/// infinite. Exact up to rounding, for any triangles (coplanar, parallel edges; a degenerate one
/// is treated as the segment or point it is, conservatively).
struct TravelInterval {
  double lo = 0.0;  ///< First t in contact.
  double hi = 0.0;  ///< Last t in contact.
  bool empty() const { return lo > hi; }
};

/// The interval of t in [t_min, t_max] where triangle a + t d intersects triangle b (frame of
/// all four arguments is the same; d in the units of the vertices per unit of t).
TravelInterval TriangleTravelInterval(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b,
                                      const Vec3& d, double t_min, double t_max);

/// A triangle mesh placed in a frame F, with a tree of axis-aligned boxes (of F) over its
/// triangles, ready for SweepContact. Immutable after construction: share it between threads.
class SweepMesh {
 public:
  /// `mesh` mapped through X_FM (mesh frame M to F). Splits at the middle of the longest
  /// extent (or the median), up to 2 triangles a leaf.
  SweepMesh(const TriangleMesh& mesh, const Iso3& X_FM);

  /// Number of triangles.
  int num_triangles() const { return static_cast<int>(triangles_.size()); }
  /// True when there is no triangle.
  bool empty() const { return triangles_.empty(); }
  /// Box of the whole mesh in F [m] (zero box when empty).
  Aabb box() const;

 private:
  friend class SweepTraversal;
  struct Triangle {
    std::array<Vec3, 3> v;  // vertices in F
  };
  struct Node {
    Vec3 lo = Vec3::Zero();
    Vec3 hi = Vec3::Zero();
    int first = -1;  // child index for an inner node (children first, first + 1); first
                     // triangle slot for a leaf
    int count = 0;   // triangles in a leaf, 0 for an inner node
  };
  struct BuildInput {  // per triangle (mesh index): its box and centroid in F
    std::vector<Vec3> lo, hi, centroid;
  };
  void Build(int node, int begin, int end, const BuildInput& in);

  std::vector<Triangle> triangles_;  // in leaf order
  std::vector<int> index_;           // the mesh's triangle index of each slot
  std::vector<Node> nodes_;
};

/// One query of SweepContact: `moving` is placed at t d_F (frame F of both meshes) for t in
/// [t_min, t_max]; the query wants the first t at which it meets `fixed`, or the last.
struct SweepQuery {
  Vec3 d_F = Vec3::UnitZ();  ///< Displacement per unit of t, frame F [m].
  double t_min = 0.0;        ///< Range of t.
  double t_max = 1.0;        ///< Range of t.
  bool last = false;         ///< False: the smallest t in contact; true: the largest.
};

/// Where two meshes meet.
struct SweepContactHit {
  double t = 0.0;            ///< Travel parameter at contact (the smallest or the largest).
  int moving_triangle = -1;  ///< A triangle of `moving` that meets `fixed` there (mesh index).
  int fixed_triangle = -1;   ///< The triangle of `fixed` it meets.
};

/// Work done by SweepContact (for benchmarks and tests).
struct SweepContactStats {
  long long box_tests = 0;       ///< Pairs of boxes whose travel interval was computed.
  long long triangle_tests = 0;  ///< Pairs of triangles whose travel interval was computed.
};

/// The smallest (or, with query.last, the largest) t in [t_min, t_max] at which some triangle of
/// `moving` translated by t d_F intersects some triangle of `fixed`, or none. Exact up to rounding:
/// nothing is stepped over, however thin. Surfaces only: a mesh wholly inside the other at every
/// t of the range meets nothing. Deterministic (ties: the first pair the traversal meets).
std::optional<SweepContactHit> SweepContact(const SweepMesh& moving, const SweepMesh& fixed,
                                            const SweepQuery& query,
                                            SweepContactStats* stats = nullptr);

}  // namespace wrap
