// Offsetting a closed surface inward: the geometry checks judge "touching" against "penetrating"
// by testing surfaces moved inward by half the allowed depth.
#pragma once

#include "geometry/mesh.h"

namespace wrap {

/// The closed surface `mesh` moved inward by `depth_m` [m] (outward for a negative depth): a
/// mitered vertex offset, in which each vertex moves so that every distinct face plane around it
/// moves by `depth_m` along its normal (least squares where three or more planes disagree; a
/// vertex moves at most 3 |depth_m|). Same triangles, same vertex order. Two such insets of
/// depth d/2 intersect where the original solids overlap by more than about d; features thinner
/// than 2 |depth_m| turn inside out. An inward-facing mesh (negative volume) is offset into its
/// solid all the same.
TriangleMesh InsetMesh(const TriangleMesh& mesh, double depth_m);

}  // namespace wrap
