// Stable resting placements of a rigid body on a horizontal plane (paper §IV-B "Preprocessing":
// stable resting orientations O_A of every subassembly A).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/pose.h"
#include "geometry/convex_hull.h"

namespace wrap {

/// Options of ComputeStablePlacements.
struct StablePlacementOptions {
  /// The centre of mass must project at least this far inside the support polygon [m]. Default
  /// 0.5 mm: strictly inside, yet a 48-sided round leg (25 mm, facet half-width 0.82 mm) still
  /// rests on its side.
  double min_margin_m = 5e-4;
  /// Merge placements that differ by a small-step rotational symmetry of the body (below).
  /// Default true.
  bool merge_symmetric = true;
  /// Two stable facets are one class when a rotation of at most this angle, which maps the hull
  /// and its centre of mass onto themselves, carries one onto the other: the facets of a
  /// tessellated body of revolution lying on its side (one class, rolled about its axis), but
  /// not the faces of a cube (90 degrees apart: six classes) [rad]. Default 30 degrees.
  double max_symmetry_step_rad = 0.5236;
  /// Tolerance of that symmetry test, relative to the hull's bounding-box diagonal. Default 1e-3.
  double symmetry_tolerance = 1e-3;
};

/// One class of resting orientations on a horizontal table. Frames: A is the body (subassembly)
/// frame; T is the rest frame: its xy plane is the table top, z up, its origin under the centre
/// of mass. Any rotation about T's z gives the same class: a table position adds the yaw.
struct StablePlacement {
  int facet = -1;                 ///< Hull facet the body rests on (the class representative).
  Vec3 normal_A = Vec3::UnitZ();  ///< Outward normal of that facet in A (points down at rest).
  Iso3 X_TA = Iso3::Identity();   ///< The body frame A in the rest frame T.
  /// Support polygon (the facet's boundary) in A, counter-clockwise seen from above at rest.
  std::vector<Vec3> support_A;
  /// The same corners in T's xy plane (z = 0) [m], counter-clockwise seen from above: where
  /// the table's friction pyramids go.
  std::vector<Eigen::Vector2d> support_T;
  double area_m2 = 0.0;        ///< Support polygon area [m^2].
  double margin_m = 0.0;       ///< Distance from the COM's projection to the nearest support edge
                               ///< [m] (the stability margin, > options.min_margin_m).
  double com_height_m = 0.0;   ///< Height of the centre of mass above the table [m].
  double tip_angle_rad = 0.0;  ///< atan(margin / COM height): the tilt that tips it over [rad].
  std::vector<int> equivalent_facets;  ///< Every stable facet of the class, ascending (by
                                       ///< symmetry; just `facet` for most bodies).
};

/// Every resting class of a body with convex hull `hull` and centre of mass `com_A` (both in A):
/// hull facets (coplanar triangles already merged) whose support polygon holds the COM's
/// projection with the margin, one per orientation up to a rotation about the vertical, classes
/// related by a small-step symmetry merged (see the options). The representative of a class is
/// its lowest-numbered facet (the largest). Ordered most stable first (largest tip angle, then
/// facet index). Empty when none rests (e.g. a COM outside the hull).
std::vector<StablePlacement> ComputeStablePlacements(const ConvexHull& hull, const Vec3& com_A,
                                                     const StablePlacementOptions& options = {});

/// Signed distance from `p` to the boundary of the convex counter-clockwise polygon `polygon`:
/// positive inside [m]. -inf for fewer than 3 corners.
double PolygonMargin(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p);

}  // namespace wrap
