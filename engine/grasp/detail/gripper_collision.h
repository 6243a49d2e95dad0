// Gripper-versus-subassembly collision checks for grasp sampling, on the robot stage's
// CollisionWorld: every part at its assembled pose, every end effector as a palm body and two
// finger bodies that slide with the opening.
#pragma once

#include <span>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "core/run_context.h"
#include "geometry/mesh.h"
#include "robot/catalog.h"
#include "robot/collision.h"

namespace wrap::detail {

/// The parts of a project and the end effectors that grasp them, in one collision world. Copy it
/// per thread (copies share the geometry).
class GripperCollision {
 public:
  /// Parts as mesh bodies at X_AP (assembly frame A), end effectors parked. Fails with
  /// kInvalidInput when a mesh or an end-effector shape is rejected by the collision world, and
  /// with kCancelled / kTimeout when ctx says stop (checked between parts).
  static Result<GripperCollision> Build(std::span<const TriangleMesh* const> part_meshes,
                                        std::span<const Iso3> X_AP,
                                        std::span<const EndEffector> end_effectors,
                                        const RunContext& ctx);

  /// Takes exactly the listed parts (indices into the parts given to Build) into the checks.
  void EnableOnly(std::span<const int> parts);

  /// True when end effector `ee` with its TCP at X_AT (in A) and its fingers `opening_m` apart
  /// (ignored for a vacuum gripper) touches an enabled part.
  bool Collides(int ee, const Iso3& X_AT, double opening_m);

 private:
  struct Effector {
    Iso3 X_TF = Iso3::Identity();  // flange in the TCP frame
    BodyId palm;
    std::array<BodyId, 2> fingers;
    std::array<Iso3, 2> X_FS_closed = {Iso3::Identity(), Iso3::Identity()};  // at opening 0
    std::array<Vec3, 2> slide_F = {Vec3::Zero(), Vec3::Zero()};  // finger motion per m opening
    double stroke_m = 0.0;
    int group = 0;
  };
  CollisionWorld world_;
  std::vector<BodyId> parts_;
  std::vector<Effector> effectors_;
  CollisionResult scratch_;
};

}  // namespace wrap::detail
