// The cell at any moment of a task plan, for motion planning (paper §IV-E): which objects exist,
// where the resting ones are, which robot carries which object with which grasp, the fingers'
// openings, and the contacts a motion may make (a held part with its gripper, the parts of one
// object, the two inputs of an insertion, an object on the table during a lift or a descent).
// The plan state it is posed at (who holds what, where the objects are) is task/plan_state.h's.
#pragma once

#include <map>
#include <span>
#include <utility>
#include <vector>

#include "core/result.h"
#include "geometry/mesh.h"
#include "robot/cell.h"
#include "task/plan.h"
#include "task/plan_state.h"
#include "task/world.h"

namespace wrap {

/// The finger opening a robot uses with `grasp`: its width plus the grasp sampler's clearance on
/// each side (two-finger), -1 (fully open, or vacuum) otherwise.
double GraspOpening(const TaskRobot& robot, const PlanGrasp& grasp);

/// The planner's collision cell posed at one state of a plan. Robots are set one by one; objects
/// held by a robot follow its TCP. Cells are built per set of finger openings and kept.
class MotionScene {
 public:
  /// A scene of `world` (robots, parts, table). Fails with kInvalidInput when a cell does not
  /// build.
  static Result<MotionScene> Build(const TaskWorld& world);

  /// Poses the scene at `state`: resting objects at their poses, held objects attached to their
  /// first holder at the grasp, finger openings `openings` (per robot, -1 fully open), robots at
  /// `q`. Contacts allowed besides a holder's gripper with its object and the parts of one
  /// object: between the objects of each pair in `mating` (node ids), between `table_ok`
  /// objects and the table (resting objects always may touch it), and between robot r's
  /// gripper and object `gripper_ok[k].second` for each pair in `gripper_ok`.
  Result<void> Set(const PlanState& state, std::span<const double> openings,
                   std::span<const JointVector> q,
                   const std::vector<std::pair<int, int>>& mating = {},
                   const std::vector<int>& table_ok = {},
                   const std::vector<std::pair<int, int>>& gripper_ok = {});

  /// Moves robot r (and what it carries).
  void SetRobot(int robot, const JointVector& q);
  /// True when anything collides (or comes closer than `margin_m`); with `robots` given only
  /// pairs that involve one of these robots or an object are tested.
  bool Collides(std::span<const int> robots = {}, double margin_m = 0.0);
  /// World boxes of robot r's bodies (links, gripper) and of the parts it carries, appended.
  void AppendBoxes(int robot, std::vector<Aabb>& out);
  /// World boxes of the parts of `node` where they are now.
  void AppendObjectBoxes(int node, std::vector<Aabb>& out);
  /// The current cell (after Set).
  Cell& cell() { return *cell_; }
  /// The world.
  const TaskWorld& world() const { return *world_; }

 private:
  const TaskWorld* world_ = nullptr;
  std::map<std::vector<long long>, Cell> cells_;
  Cell* cell_ = nullptr;
  std::vector<std::vector<Iso3>> frames_;  // scratch FK per robot
  std::vector<int> carried_parts_;         // scratch
  std::vector<int> object_of_part_;        // node of each part at the current state, -1 gone
};

}  // namespace wrap
