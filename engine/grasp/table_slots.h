// Table positions: where on the table the robots can set subassemblies down (paper §IV-B:
// placements at discretised positions the robots reach).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "core/run_context.h"
#include "geometry/stable_placement.h"
#include "model/project.h"

namespace wrap {

/// Options of ComputeTableSlots.
struct TableSlotOptions {
  int num_slots = 9;            ///< Slots to keep. Default 9.
  double grid_step_m = 0.05;    ///< Spacing of the candidate grid on the table top [m].
  double edge_margin_m = 0.06;  ///< Candidates keep this far from the table's edges [m].
  /// Candidates keep this far (horizontally) from every robot base: the arm's base link and
  /// shoulder stand there [m]. Default 0.2.
  double base_clearance_m = 0.2;
  /// IK target: the TCP this high above the table top, pointing straight down (a top grasp of a
  /// small part) [m]. Default 0.05.
  double probe_height_m = 0.05;
  int probe_yaws = 8;  ///< TCP rotations about the vertical tried until one is reachable.
  /// A slot must be reachable by this many robots (handovers through the table need two);
  /// when no candidate is, the best-reached ones are kept instead. Default 2.
  int min_robots = 2;
  /// Yaw angles per slot at which a placement may be set down, evenly spaced from 0. Default 4.
  int yaws = 4;
  /// Random restarts of the numeric IK (arms without a closed form). Default 4.
  int numeric_ik_restarts = 4;
  /// Test the robots on parallel threads (the result does not depend on it). Default true.
  bool parallel = true;
};

/// A position on the table top where a placement can be set down.
struct TableSlot {
  Vec3 p_W = Vec3::Zero();  ///< Slot centre in the world, on the table top (z = table height) [m].
  std::vector<int> robots;  ///< Indices into Project::robots of the robots that reach it.
};

/// The slots and the yaws a placement may take at each of them.
struct TableSlots {
  std::vector<TableSlot> slots;  ///< Spread over the reachable table (farthest-point order).
  std::vector<double> yaws_rad;  ///< Rotations about the vertical at every slot [rad].
  int candidates = 0;            ///< Grid points tried (statistics).
  int reachable = 0;             ///< ... of which reached by at least min_robots robots.
};

/// The slots: a grid over the table top (less edge and base margins), each point tested with
/// IK from above for every robot (UR closed form, else damped least squares with restarts),
/// then `num_slots` of the points reached by at least `min_robots` robots chosen by
/// farthest-point selection starting from the best-reached point nearest the table centre.
/// Deterministic for a seed. `project_file` resolves URDF robots. Checks `ctx.ShouldStop()`
/// between grid rows. Fails with kInvalidInput when a robot's model or end effector cannot be
/// loaded, kCancelled / kTimeout when stopped.
Result<TableSlots> ComputeTableSlots(const Project& project,
                                     const std::filesystem::path& project_file,
                                     const TableSlotOptions& options, std::uint64_t seed,
                                     RunContext& ctx);

/// Pose of a subassembly frame A in the world when `placement` is set down at `slot` turned by
/// `yaw_rad` about the vertical: X_WA = Trans(p_W) * Rz(yaw) * X_TA.
Iso3 PlacementPose(const TableSlot& slot, double yaw_rad, const StablePlacement& placement);

}  // namespace wrap
