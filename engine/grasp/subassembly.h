// Subassemblies: every vertex of the dependency DAG as one rigid body (paper §III, §IV-B).
#pragma once

#include <string>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "geometry/convex_hull.h"
#include "geometry/stable_placement.h"
#include "grasp/grasp.h"
#include "model/validate.h"

namespace wrap {

/// One DAG vertex as a rigid body: its parts fixed in their final relative poses. Its frame A
/// is the assembly frame (every part P at its assembled pose X_AP), so a pose in A means the
/// same in every subassembly.
struct Subassembly {
  std::string name;                         ///< Part or step name.
  int node = -1;                            ///< AssemblyTree node id.
  std::vector<int> parts;                   ///< Indices into Project::parts, ascending.
  std::vector<Iso3> X_AP;                   ///< Each part's frame in A, in the order of `parts`.
  double mass_kg = 0.0;                     ///< Sum of the parts' masses [kg].
  Vec3 com_A = Vec3::Zero();                ///< Centre of mass in A [m].
  Aabb aabb_A;                              ///< Bounding box of the parts' vertices in A [m].
  ConvexHull hull;                          ///< Convex hull of all its parts in A.
  std::vector<StablePlacement> placements;  ///< Resting classes, most stable first.
  std::vector<GraspSet> grasp_sets;         ///< One per end effector of the project.
};

/// The subassemblies of every DAG node (node id order: parts, then steps) with their parts,
/// poses, mass, centre of mass and bounding box; hulls, placements and grasps are left empty.
/// Fails with kInvalidInput when the check has no DAG or a part's mesh is not loaded.
Result<std::vector<Subassembly>> BuildSubassemblies(const Project& project,
                                                    const ProjectCheck& check);

}  // namespace wrap
