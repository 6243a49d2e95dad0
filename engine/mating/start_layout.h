// The start of a plan judged from the meshes: parts that overlap where they rest on the table.
#pragma once

#include <vector>

#include "core/pose.h"
#include "mating/assembly_geometry.h"

namespace wrap {

/// Two parts that overlap in their initial poses.
struct StartOverlap {
  int a = -1;            ///< The first part (a < b).
  int b = -1;            ///< The second part.
  double depth_m = 0.0;  ///< How deep the deepest point of one lies inside the other [m].
};

/// The pairs of parts that overlap by more than `touch_depth_m` with part p at X_WP[p]: of the
/// pairs whose boxes overlap, the depth is that of the deepest vertex, surface sample or point a
/// little inside the surface of either inside the other (PenetrationDepth both ways).
std::vector<StartOverlap> StartOverlaps(AssemblyGeometry& geometry, const std::vector<Iso3>& X_WP,
                                        double touch_depth_m);

/// How deep part `a` at X_a reaches into part `b` at X_b [m]: the deepest of a's vertices, surface
/// samples and points 0.5 and 2 mm inside its surface inside b (0 when none is).
double PenetrationDepth(AssemblyGeometry& geometry, int a, const Iso3& X_a, int b,
                        const Iso3& X_b);

}  // namespace wrap
