#include "grasp/detail/gripper_collision.h"

#include <algorithm>
#include <string>

namespace wrap::detail {

namespace {

constexpr int kPartGroup = 0;

// Pose of a shape in the flange frame as the catalog places it at `opening_m`.
Iso3 FingerPoseAt(const EndEffector& ee, int k, double opening_m) {
  return EndEffectorShapesAt(ee, opening_m)[ee.finger_shapes[k]].X_LS;
}

}  // namespace

Result<GripperCollision> GripperCollision::Build(std::span<const TriangleMesh* const> part_meshes,
                                                 std::span<const Iso3> X_AP,
                                                 std::span<const EndEffector> end_effectors,
                                                 const RunContext& ctx) {
  GripperCollision gc;
  for (size_t i = 0; i < part_meshes.size(); ++i) {
    if (ctx.ShouldStop()) {
      return Fail(ctx.cancelled() ? ErrorCode::kCancelled : ErrorCode::kTimeout,
                  "grasp collision world: stopped");
    }
    BodyDef def;
    def.name = "part" + std::to_string(i);
    def.group = kPartGroup;
    Shape mesh;
    mesh.type = Shape::Type::kMesh;
    mesh.mesh = *part_meshes[i];
    mesh.name = def.name;
    def.shapes.push_back(std::move(mesh));
    def.X_WB = X_AP[i];
    auto id = gc.world_.AddBody(def);
    if (!id) return std::unexpected(id.error());
    gc.parts_.push_back(*id);
  }
  gc.world_.SetGroupPairAllowed(kPartGroup, kPartGroup, true);
  const int n_ee = static_cast<int>(end_effectors.size());
  if (n_ee + 1 > kMaxCollisionGroups) {
    return Fail(ErrorCode::kInvalidInput, "preprocess: too many end effectors");
  }
  for (int e = 0; e < n_ee; ++e) {
    const EndEffector& ee = end_effectors[e];
    Effector eff;
    eff.group = 1 + e;
    eff.X_TF = ee.X_FT.inverse();
    eff.stroke_m = ee.stroke_m;
    const bool two_finger = ee.kind == EndEffectorKind::kTwoFinger && ee.finger_shapes[0] >= 0 &&
                            ee.finger_shapes[1] >= 0;
    BodyDef palm;
    palm.name = ee.name + "/palm";
    palm.group = eff.group;
    for (int s = 0; s < static_cast<int>(ee.collision.size()); ++s) {
      if (two_finger && (s == ee.finger_shapes[0] || s == ee.finger_shapes[1])) continue;
      palm.shapes.push_back(ee.collision[s]);
    }
    auto palm_id = gc.world_.AddBody(palm);
    if (!palm_id) return std::unexpected(palm_id.error());
    eff.palm = *palm_id;
    if (two_finger) {
      for (int k = 0; k < 2; ++k) {
        BodyDef finger;
        finger.name = ee.name + "/finger" + std::to_string(k);
        finger.group = eff.group;
        Shape box = ee.collision[ee.finger_shapes[k]];
        box.X_LS = Iso3::Identity();  // the body frame is the box: posed per query
        finger.shapes.push_back(box);
        auto id = gc.world_.AddBody(finger);
        if (!id) return std::unexpected(id.error());
        eff.fingers[k] = *id;
        // The catalog moves each finger linearly with the opening: sample two openings.
        eff.X_FS_closed[k] = FingerPoseAt(ee, k, 0.0);
        if (ee.stroke_m > 0.0) {
          eff.slide_F[k] =
              (FingerPoseAt(ee, k, ee.stroke_m).translation() - eff.X_FS_closed[k].translation()) /
              ee.stroke_m;
        }
      }
    }
    for (int g = 1; g <= e + 1; ++g) gc.world_.SetGroupPairAllowed(eff.group, g, true);
    gc.effectors_.push_back(eff);
  }
  return gc;
}

void GripperCollision::EnableOnly(std::span<const int> parts) {
  for (BodyId b : parts_) world_.SetEnabled(b, false);
  for (int p : parts) world_.SetEnabled(parts_[p], true);
}

bool GripperCollision::Collides(int ee, const Iso3& X_AT, double opening_m) {
  Effector& eff = effectors_[ee];
  const Iso3 X_AF = X_AT * eff.X_TF;
  world_.SetPose(eff.palm, X_AF);
  for (int k = 0; k < 2; ++k) {
    if (!eff.fingers[k].valid()) continue;
    Iso3 X_FS = eff.X_FS_closed[k];
    X_FS.translation() += std::clamp(opening_m, 0.0, eff.stroke_m) * eff.slide_F[k];
    world_.SetPose(eff.fingers[k], X_AF * X_FS);
  }
  CollisionRequest request;
  request.group_mask = std::uint64_t{1} << eff.group;
  return world_.AnyCollision(request, &scratch_);
}

}  // namespace wrap::detail
