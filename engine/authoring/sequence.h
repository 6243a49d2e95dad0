// An assembly sequence from geometry: assembly by disassembly over the contact graph. Parts (or
// touching pairs, for subassemblies) that can leave the rest along a free direction are taken
// off one at a time; the order reversed is the DAG, each step's axis the direction found.
#pragma once

#include <string>
#include <vector>

#include "core/pose.h"
#include "grasp/grasp_probe.h"
#include "mating/assembly_geometry.h"
#include "mating/contact_graph.h"

namespace wrap {

/// One assembly step proposed: `moved` travels along `axis_A` onto `base`.
struct ProposedStep {
  std::vector<int> moved;        ///< Parts of the moved input.
  std::vector<int> base;         ///< Parts of the base input.
  Vec3 axis_A = -Vec3::UnitZ();  ///< Insertion direction of the moved input (frame A).
  int moved_grasps = 0;          ///< Grasps of the moved input clear of the base when mated.
  int base_grasps = 0;           ///< Grasps of the base input clear of the moved one.
  bool swapped = false;          ///< Roles swapped: the disassembled unit is the base.
  std::string why;               ///< One line: the choice and its reason.
};

/// The sequence found, in assembly order (steps whose inputs are built by earlier steps).
struct ProposedSequence {
  std::vector<ProposedStep> steps;  ///< Assembly order.
  std::vector<int> interlocked;     ///< When no sequence exists: the parts none of which (nor
                                    ///< any touching pair) can leave the others.
  bool ok() const { return interlocked.empty(); }
};

/// Options of ProposeSequence.
struct SequenceOptions {
  double touch_depth_m = 2e-4;  ///< Overlap read as touching (the project's geometry tolerance).
  int sphere = 32;              ///< Directions over the sphere tried after the axes and normals.
  int end_effector = 0;         ///< End effector of the probe the grasp counts use.
};

/// Grasps of `unit` (parts) for end effector `ee` of `probe` that leave the gripper clear of
/// `rest` (and of the unit's other parts) where mated: full-pad ones, else (none) reduced ones,
/// which the planner's grasp sets hold too (a wheel by its tire's edge, a pipe by its collar).
/// The one count behind the roles of `wrap new` and `wrap suggest`; 0 without a probe.
int ClearGrasps(GraspProbe* probe, int ee, const std::vector<int>& unit,
                const std::vector<int>& rest);

/// Assembly by disassembly. Each round tries every remaining part that touches the rest and
/// leaves the rest connected, along the frame's axes and the contact normals (then the sphere),
/// swept until it clears the rest; it takes off the best by, in order: not the largest part (by
/// area: it stays to the end as the base), a grasp that clears the rest where it is mated, an
/// insertion from above, the highest centre, the smallest, the first.
/// When no single part can leave, touching pairs are tried (a subassembly made first). The last
/// part left is the base of the whole assembly. Roles: a step whose moved input has no grasp
/// clear of the base but whose base has one is swapped. Deterministic.
ProposedSequence ProposeSequence(AssemblyGeometry& geometry, const ContactGraph& contacts,
                                 GraspProbe* probe, const SequenceOptions& options = {});

}  // namespace wrap
