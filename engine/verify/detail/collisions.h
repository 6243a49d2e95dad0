// Collision detection during a simulation (verify/, paper §V-B "collision"): the robots at their
// simulated joints and the parts where MuJoCo has them, in the robot stage's collision cell
// (robot/cell.h: FCL on the robots' primitive shapes and the parts' own meshes; MuJoCo would
// collide the parts as convex hulls, which swallow a gripper inside a pocket). Which contacts are
// allowed at a moment (a gripper and the object it grasps, the two inputs of an insertion) is the
// simulation's business; this file answers "what touches what that must not".
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "robot/cell.h"
#include "robot/kinematics.h"
#include "sim/scene.h"

namespace wrap::detail {

/// Contacts allowed at one moment, besides a robot's own bodies with each other.
struct ContactRules {
  /// robot_part_ok[r][p]: robot r (any link or its end effector) may touch part p.
  std::vector<std::vector<char>> robot_part_ok;
  /// part_pair_ok[p][q] (p < q): parts p and q may touch.
  std::vector<std::vector<char>> part_pair_ok;
  /// held[p]: part p is held by a robot; its lowest hull point may then not sink below the table
  /// top by more than the tolerance (resting parts are the table's own business).
  std::vector<char> held;
};

/// A contact that must not be.
struct CollisionHit {
  std::string body_a;  ///< e.g. "ur5e_a/robotiq_2f85", "leg1", "table".
  std::string body_b;  ///< The other body.
  int robot_a = -1;    ///< Robot owning body_a, or -1.
  int robot_b = -1;    ///< Robot owning body_b, or -1.
  int part_a = -1;     ///< Part that is body_a, or -1.
  int part_b = -1;     ///< Part that is body_b, or -1.
  double depth_m = 0.0;  ///< Table contacts: how deep the part sinks [m]; 0 otherwise (unknown).
};

/// The cell of a scene with every robot shape shrunk by the penetration tolerance, so that only
/// contacts deeper than it count (a part into a robot shape: the tolerance; two robots: twice it).
/// Robot meshes (URDF robots) are not shrunk. Cells are built per set of finger openings and kept.
class SimCollisions {
 public:
  /// Fails with kInvalidInput when the cell does not build (a bad shape).
  static Result<SimCollisions> Build(const CellScene& scene, double tolerance_m);

  /// Poses the robots at `q` with fingers at `openings` (per robot, -1 fully open) and the parts
  /// at `X_WP`, then looks for a contact that `rules` do not allow: robot with robot, robot with
  /// a part, part with part, a robot link (not the base) with the table, and a held part sunk
  /// into the table. The first one found, or nothing.
  Result<std::optional<CollisionHit>> Check(const std::vector<JointVector>& q,
                                            const std::vector<double>& openings,
                                            const std::vector<Iso3>& X_WP,
                                            const ContactRules& rules);

 private:
  const CellScene* scene_ = nullptr;
  double tolerance_m_ = 0.0;
  std::vector<std::vector<Vec3>> hull_;  // per part, its hull's vertices in the part frame
  std::map<std::vector<long long>, Cell> cells_;
  std::vector<std::vector<Iso3>> frames_;  // per robot, scratch link frames
};

/// A shape shrunk by `by_m` on every side (radii and box half extents, a cylinder's ends), kept at
/// least a quarter of its size; meshes unchanged.
Shape ShrinkShape(const Shape& shape, double by_m);

}  // namespace wrap::detail
