// Selecting a subassembly's grasp set from its parts' candidates (paper §IV-B): candidates that
// hit another part are dropped, the rest scored and tiered (clear of the mating partner, pickable
// from the table) and spread by farthest-point order. Internal to Preprocess.
#pragma once

#include <optional>
#include <vector>

#include "core/pose.h"
#include "core/run_context.h"
#include "grasp/detail/grasp_sampler.h"
#include "grasp/detail/gripper_collision.h"
#include "grasp/grasp.h"
#include "grasp/preprocess.h"
#include "grasp/subassembly.h"
#include "model/project.h"
#include "model/validate.h"
#include "robot/catalog.h"

namespace wrap::detail {

/// What a subassembly's grasps are checked against besides its own parts, per subassembly (in
/// Preprocessed::subassemblies order).
struct SelectionScene {
  /// The parts of the other input of the step that consumes it (none for the root).
  std::vector<std::vector<int>> partner;
  /// The insertion direction (unit, in A) of a moved input: a vacuum cup inserts it only when it
  /// pushes along it (its assembly box allows force along the cup axis alone).
  std::vector<std::optional<Vec3>> insertion;
  /// Rest frames X_TA (table top at z = 0) in which a grasp must clear the table to count as
  /// pickable: a part's initial pose, then the subassembly's most stable placements.
  std::vector<std::vector<Iso3>> rest_frames;
  /// Index of the table among the collision world's parts.
  int table_body = -1;
};

/// The scene of `subs` (`X_AP`: each part's assembled pose), the table being body `table_body`
/// of the collision world.
SelectionScene BuildSelectionScene(const Project& project, const ProjectCheck& check,
                                   const std::vector<Subassembly>& subs,
                                   const std::vector<Iso3>& X_AP, int table_body);

/// The grasp set of subassembly `s` for end effector `e` (`ee`), `grasps_per_set` grasps at most,
/// chosen from `candidates` (index part * num_ee + end effector). Half of the set (every other
/// grasp, from the first) are assembly grasps, clear of the partner; within each half, grasps
/// pickable from the table come first. `world` is copied (one copy per call). Empty when ctx
/// says stop.
std::optional<GraspSet> SelectGraspSet(const Subassembly& sub, int s, int e, const EndEffector& ee,
                                       const std::vector<std::vector<GraspCandidate>>& candidates,
                                       int num_ee, const SelectionScene& scene,
                                       const GripperCollision& world,
                                       const PreprocessOptions& options, int grasps_per_set,
                                       const RunContext& ctx);

}  // namespace wrap::detail
