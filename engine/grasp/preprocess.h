// The preprocessing stage (paper §IV-B "Preprocessing", Alg. 1 line 1: (O, G) <- Preprocess(A)):
// for every subassembly of the dependency DAG its convex hull, stable placements and grasp sets
// per end effector, and the table positions the robots reach. The front door of engine/grasp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/result.h"
#include "core/run_context.h"
#include "geometry/convex_hull.h"
#include "geometry/stable_placement.h"
#include "grasp/grasp.h"
#include "grasp/subassembly.h"
#include "grasp/table_slots.h"
#include "model/project.h"
#include "model/validate.h"

namespace wrap {

/// Options of Preprocess. The defaults are the planner's.
struct PreprocessOptions {
  /// Grasp-set size per subassembly and end effector; 0 or less: the project's
  /// `planner.grasps` (the paper: 20, and 64 for the Fabrica meshes).
  int grasps = 0;
  /// Friction coefficient at the finger pads, which sets the antipodal friction cone; absent:
  /// the project's `table.friction` (the one friction coefficient of project format v1).
  std::optional<double> friction;
  /// Candidates sampled per part and end effector, as a multiple of the set size; the sets of
  /// the part's subassemblies are selected from them. Default 4.
  int candidate_factor = 4;
  /// Surface samples tried per part and end effector before giving up, as a multiple of the
  /// candidates wanted. Default 30.
  int sample_factor = 30;
  /// End effectors to sample for (catalog names); empty: those of the project's robots.
  std::vector<std::string> end_effectors;
  ConvexHullOptions hull;             ///< Facet merging.
  StablePlacementOptions placements;  ///< Margins and symmetry classes.
  TableSlotOptions table_slots;       ///< Table positions.
  TwoFingerGraspOptions two_finger;   ///< Antipodal sampler.
  VacuumGraspOptions vacuum;          ///< Vacuum sampler.
  bool compute_table_slots = true;    ///< False: skip the IK of the table positions.
  /// Spread the per-part and per-subassembly work over threads (TBB). Results do not depend on
  /// it: every task has its own generator seeded from the run's. Default true.
  bool parallel = true;
  /// The project file, for resolving URDF robots (relative paths); may be empty.
  std::filesystem::path project_file;
};

/// What preprocessing produced.
struct Preprocessed {
  /// One per DAG node in node id order (parts first, then steps): the leaves are the parts.
  std::vector<Subassembly> subassemblies;
  TableSlots table_slots;                  ///< Where placements can be set down.
  std::vector<std::string> end_effectors;  ///< End effectors grasps were sampled for.
  int grasps_per_set = 0;                  ///< The set size asked for.
  double friction = 0.0;                   ///< Friction coefficient of the friction cone.
  std::uint64_t seed = 0;                  ///< Seed drawn from the run's generator.
  /// Wall-clock seconds per part of the stage: "subassemblies", "hulls", "placements",
  /// "table_slots", "grasp_candidates", "grasp_sets", "reduced_grasps" (the reduced pass and the
  /// sets it changes), and "total" (the paper's t_grasp).
  StageTimes times;
  /// Things the planner should know, e.g. a subassembly that no end effector can grasp.
  std::vector<std::string> warnings;

  /// The subassembly named `name` (a part or step name), or nullptr.
  const Subassembly* Find(const std::string& name) const;
};

/// Runs the preprocessing of a validated project: subassemblies of every DAG vertex (parts in
/// their final relative poses, mass, COM, convex hull), their stable placements, the table
/// positions (IK), and per end effector a spread grasp set: antipodal two-finger grasps (both
/// contacts inside the friction cone, within the stroke, pads touching the part over the
/// minimum area) and vacuum grasps (cup on a flat patch that carries the whole disc), none
/// colliding with its subassembly. `check` is the project's validation (meshes in metres, masses,
/// the DAG). Deterministic for a given state of ctx's generator (one draw seeds everything).
/// Checks ctx.ShouldStop() in every loop; adds its wall time to ctx's stage "grasp".
/// Fails with kInvalidInput (no DAG, a mesh missing, an unknown end effector, a non-positive
/// grasp count or friction), kCancelled / kTimeout when stopped, kInternal on a qhull failure.
[[nodiscard]] Result<Preprocessed> Preprocess(const Project& project, const ProjectCheck& check,
                                              const PreprocessOptions& options, RunContext& ctx);

}  // namespace wrap
