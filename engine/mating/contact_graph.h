// The contact graph: which parts touch in their assembled poses, where, and with which normals.
#pragma once

#include <vector>

#include "core/pose.h"
#include "geometry/mesh.h"
#include "mating/assembly_geometry.h"

namespace wrap {

/// One direction of a contact's surface, with the area that faces it.
struct ContactNormal {
  Vec3 n_A = Vec3::UnitZ();  ///< Unit normal in the assembly frame, out of part b into part a.
  double area_m2 = 0.0;      ///< Contact area facing it [m^2].
};

/// Two parts that touch (surfaces within the contact tolerance) in their assembled poses.
struct Contact {
  int a = -1;                          ///< The first part (a < b).
  int b = -1;                          ///< The second part.
  double distance_m = 0.0;             ///< Closest distance of the surfaces, 0 when they meet [m].
  double area_m2 = 0.0;                ///< Estimated area of the surfaces within the tolerance.
  Vec3 centroid_A = Vec3::Zero();      ///< Centre of that area, assembly frame [m].
  Aabb extent_A;                       ///< Its bounding box, assembly frame [m].
  std::vector<ContactNormal> normals;  ///< Distinct normals, largest area first.
};

/// Every touching pair of parts.
struct ContactGraph {
  double tolerance_m = 1e-3;      ///< Surfaces this close touch.
  std::vector<Contact> contacts;  ///< Ordered by (a, b).

  /// The contact of parts p and q (either order), or nullptr.
  const Contact* Find(int p, int q) const;
  /// The parts that touch part p, ascending.
  std::vector<int> Neighbours(int p) const;
};

/// Options of ComputeContactGraph.
struct ContactOptions {
  double tolerance_m = 1e-3;  ///< Surfaces this close touch [m].
};

/// The contact graph of the parts in their assembled poses. A pair touches when the meshes come
/// within the tolerance (FCL's exact distance); its area, centre, extent and normals come from
/// the surface samples of each part that lie within 0.1 mm of the closest distance of the other
/// (at most the tolerance): the surfaces that meet, not a strip along their edges.
ContactGraph ComputeContactGraph(AssemblyGeometry& geometry, const ContactOptions& options = {});

/// Closest distance between two sets of parts in their assembled poses (0 when they touch or
/// overlap), with the nearest pair; +inf when a set has no mesh.
struct SetDistance {
  double distance_m = 0.0;  ///< [m].
  int part_a = -1;          ///< Nearest part of the first set.
  int part_b = -1;          ///< Nearest part of the second set.
};
SetDistance DistanceBetween(AssemblyGeometry& geometry, const std::vector<int>& parts_a,
                            const std::vector<int>& parts_b);

}  // namespace wrap
