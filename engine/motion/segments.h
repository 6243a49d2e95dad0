// Geometric motion of a task plan (paper §IV-E): the free-space paths between keyframes, planned
// in the composite space of the robots that move, and the contact-rich skills (approach and
// retreat along the gripper axis, lift and descent at the table, insertion along the mating axis,
// two-handed carries) as straight Cartesian moves. Untimed; retime.h times them.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/result.h"
#include "core/run_context.h"
#include "motion/motion_options.h"
#include "motion/scene.h"
#include "task/plan.h"
#include "task/world.h"

namespace wrap {

/// What a segment is.
enum class SegmentKind { kFree, kApproach, kRetreat, kLift, kDescend, kInsert, kCarry, kGrip };

/// "free", "approach", "retreat", "lift", "descend", "insert", "carry", "grip".
std::string_view ToString(SegmentKind kind);

/// A segment of the geometric motion.
struct GeoSegment {
  SegmentKind kind = SegmentKind::kFree;
  int action = -1;           ///< Action it leads to (the last action for the final returns).
  bool main = false;         ///< Part of the action itself (not a robot returning home).
  std::vector<int> robots;   ///< Robots that move (or grip), ascending.
  std::vector<int> objects;  ///< Objects it carries, approaches, releases or inserts.
  /// Waypoints: waypoints[k][i] is robot robots[i] at waypoint k; straight joint motion between.
  std::vector<std::vector<JointVector>> waypoints;
  std::vector<double> openings;  ///< Every robot's finger opening during it (-1 fully open).
  double skill_length_m = 0.0;   ///< Cartesian length of a skill (sets its duration) [m].
  double skill_speed_mps = 0.0;  ///< Its TCP or object speed [m/s]; 0 for free paths.
  double hold_s = 0.0;           ///< Grip: how long the robots stay [s].
  int free_index = -1;           ///< A free path: its index in MotionCache::free_paths.
  /// At least this much slower than the fastest timing its limits allow (times x slow,
  /// velocities / slow, accelerations / slow^2): set where an object's inertia would load its
  /// gripper beyond the limits (see PlanMotion).
  double slow = 1.0;
  /// Scheduled only once everything before it has ended (the trajectory check refused it
  /// running beside others: see PlanMotion).
  bool after_all = false;
  /// World boxes swept by its robots' bodies and what they carry, and of its objects, grown by
  /// the sampling bound, per body: [0] the whole sweep, then the sweeps of consecutive runs of
  /// samples. Two segments whose boxes do not meet can run at the same time.
  std::vector<std::vector<Aabb>> sweep;
  /// Per chunk of `sweep` (sweep[b][c + 1]): the path parameter of its first sample, k + s on
  /// the straight piece from waypoint k to k + 1 (s in [0, 1]); a chunk lasts until the next
  /// one starts. The schedule tells from it when the chunk's boxes are swept.
  std::vector<double> sweep_u;
};

/// An object that one robot carries alone: its mass, its centre of mass in the grasp (TCP)
/// frame, and the gripper's limits while carrying (a vacuum cup's transport box, the two-finger
/// box).
struct SoleLoad {
  int robot = -1;
  double mass = 0.0;
  Vec3 com_G = Vec3::Zero();
  WrenchBox box;
};
/// What robot `robot` carries alone in `state`, if anything (nothing, or no mass: nullopt).
std::optional<SoleLoad> SoleLoadOf(const TaskWorld& world, const PlanState& state, int robot);
/// Largest ratio of a component of the wrench the gripper applies on `load` (weight, plus the
/// inertia of a centre of mass accelerating by `accel_W`), in the grasp frame whose world
/// orientation is R_WG, to its limit.
double LoadRatio(const SoleLoad& load, const Mat3& R_WG, const Vec3& accel_W = Vec3::Zero());

/// The geometric motion of `plan` at effort level request.effort. Keyframes stay, except where a
/// straight two-handed carry or an insertion reaches the keyframe's TCP pose on another IK solution
/// that is collision-free and clear of the other robots there: that solution replaces the robot's
/// joints at that keyframe and the following ones where it stood still (validate the plan again).
/// On success the segments in execution order (the plan's order; the schedule may overlap them);
/// otherwise `failure` says which segment failed. `cache` keeps solved free paths between calls
/// for the same plan. `scene` (may be null) keeps a motion scene of `world` between calls: built
/// on the first (when empty), its cells are not built again (MotionScene::Set poses it afresh
/// each time). Deterministic for a given request.seed when no path search runs out of time.
/// Fails with kCancelled when ctx is cancelled and kInvalidInput when the plan does not fit the
/// world.
Result<std::vector<GeoSegment>> PlanGeometricMotion(const TaskWorld& world, Plan& plan,
                                                    const MotionOptions& options,
                                                    const MotionRequest& request,
                                                    MotionCache& cache, RunContext& ctx,
                                                    MotionFailure* failure,
                                                    std::optional<MotionScene>* scene = nullptr);

}  // namespace wrap
