// Convex hulls of point sets: the one qhull adapter. Qhull is included only by convex_hull.cpp.
#pragma once

#include <span>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "geometry/mesh.h"

namespace wrap {

/// Options of ComputeConvexHull: when hull triangles count as one planar facet.
struct ConvexHullOptions {
  /// Neighbouring hull triangles whose normals differ from the facet's first (largest) triangle
  /// by at most this angle join its facet [rad]. Default 0.5 degrees: the 7.5 degree steps of a
  /// 48-sided cylinder stay apart, the float noise of a flat face is merged.
  double coplanar_angle_rad = 0.0087;
  /// ... and whose vertices lie within this distance of that triangle's plane [m]. Default 0.1 mm.
  double coplanar_distance_m = 1e-4;
};

/// A planar facet of a hull: one or more coplanar hull triangles merged.
struct HullFacet {
  Vec3 normal = Vec3::UnitZ();  ///< Outward unit normal (area-weighted mean of its triangles).
  double offset = 0.0;         ///< Supporting plane: normal . x <= offset for every hull point [m].
  std::vector<int> polygon;    ///< Boundary as hull vertex indices, convex, counter-clockwise
                               ///< seen from outside, collinear corners removed.
  std::vector<int> triangles;  ///< Indices into the hull mesh's triangles that form the facet.
  double area_m2 = 0.0;        ///< Area of its triangles [m^2].
};

/// The convex hull of a point set as a closed triangle mesh with its planar facets.
struct ConvexHull {
  TriangleMesh mesh;                ///< Hull vertices (a subset of the input) and triangles,
                                    ///< counter-clockwise seen from outside.
  std::vector<int> triangle_facet;  ///< Facet index of each mesh triangle.
  std::vector<HullFacet> facets;    ///< Coplanar triangles merged; largest first.
  double volume_m3 = 0.0;           ///< Enclosed volume [m^3].
  double area_m2 = 0.0;             ///< Surface area [m^2].
};

/// The convex hull of `points` (qhull, joggled triangulated output), with coplanar triangles merged
/// into facets by region growing from the largest triangle. Deterministic for a given input order.
/// Fails with kInvalidInput for fewer than 4 points, a non-finite coordinate or points that span
/// no volume (all on a plane or a line), and with kInternal for any other qhull failure; the
/// message carries qhull's own.
Result<ConvexHull> ComputeConvexHull(std::span<const Vec3> points,
                                     const ConvexHullOptions& options = {});

/// The convex hull of every vertex of `mesh` (see the overload on points).
Result<ConvexHull> ComputeConvexHull(const TriangleMesh& mesh,
                                     const ConvexHullOptions& options = {});

/// Indices of the convex hull of 2-D points, counter-clockwise, collinear points dropped
/// (Andrew's monotone chain). Fewer than 3 distinct points give them back in sorted order.
std::vector<int> ConvexHull2d(std::span<const Eigen::Vector2d> points);

}  // namespace wrap
