// Geometric motion of a task plan (paper §IV-E): the free-space paths between keyframes, planned
// in the composite space of the robots that move, and the contact-rich skills (approach and
// retreat along the gripper axis, lift and descent at the table, insertion along the mating axis,
// two-handed carries) as straight Cartesian moves. Untimed; retime.h times them.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/result.h"
#include "core/run_context.h"
#include "motion/scene.h"
#include "task/plan.h"
#include "task/world.h"

namespace wrap {

/// What a segment is.
enum class SegmentKind { kFree, kApproach, kRetreat, kLift, kDescend, kInsert, kCarry, kGrip };

/// "free", "approach", "retreat", "lift", "descend", "insert", "carry", "grip".
std::string_view ToString(SegmentKind kind);

/// Options of the geometric motion.
struct MotionOptions {
  /// Joint-space resolution of the path search's collision checks along a motion: consecutive
  /// checked states differ by at most this in every joint [rad]; skills and final paths are
  /// checked 4 times finer. (The trajectory check samples at 0.02 rad.)
  double resolution_rad = 0.01;
  /// Work budget of a free segment's path search at effort 0: collision checks (RRT-Connect's
  /// states and motions). Budgets count work, not time, so that the same project, options and
  /// seed give the same plan whatever the machine's load, its cores or a sanitizer's slowdown.
  long long segment_checks = 200000;
  /// Work budget of the search over a carried object's poses at effort 1 (it runs from effort
  /// 1 on): edges tried, each tracked by the holders' IK and checked for collisions.
  int carry_edges = 500;
  int max_effort = 3;  ///< Effort levels 0..max_effort; the budgets double per level.
  double approach_m = 0.04;         ///< Straight approach to (and retreat from) a grasp [m].
  double lift_m = 0.02;             ///< Straight lift off (and descent onto) the table [m].
  double cartesian_step_m = 0.004;  ///< Spacing of IK samples along a straight move [m].
  double skill_speed_mps = 0.05;    ///< TCP speed of approach, retreat, lift, descent [m/s].
  double insert_speed_mps = 0.02;   ///< TCP speed of an insertion [m/s].
  double carry_speed_mps = 0.10;    ///< Object speed of a two-handed carry [m/s].
  double grip_s = 0.4;              ///< A gripper closing or opening at a keyframe [s].
  /// Shortcut attempts per free path.
  int shortcut_attempts = 16;
  /// Along a free path, an object held by one robot may load its gripper (its weight, in the
  /// grasp frame, against the transport box of a vacuum cup or the two-finger box) up to this
  /// fraction of the limits, or up to the path's ends' load where that is higher: the task plan's
  /// wrench gates hold at the keyframes only, and an object turned on the way (a seat held by
  /// its edge) can hang on its gripper beyond the limits; the rest is kept for the accelerations.
  double transport_load_max = 0.8;
  /// Run the independent trajectory check on the timed result; a plan that fails it has no
  /// motion (its first issue is the failure), so no colliding trajectory leaves the planner.
  bool self_check = true;
  /// Debugging: every timed result the self-check refuses is saved here as a plan JSON
  /// (refused_N.json); empty: none (`wrap plan --dump-refused DIR`).
  std::filesystem::path dump_refused_dir;
};

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
  /// World boxes swept by its robots' bodies and what they carry, and of its objects, grown by
  /// the sampling bound, per body: [0] the whole sweep, then the sweeps of consecutive runs of
  /// samples. Two segments whose boxes do not meet can run at the same time.
  std::vector<std::vector<Aabb>> sweep;
};

/// Why the geometric motion of a plan could not be made.
struct MotionFailure {
  int action = -1;  ///< Action of the segment.
  /// The action whose keyframe made it fail (the task plan's edge to avoid): the segment's own,
  /// or, for a retreat, the action that let go.
  int blame = -1;
  std::string segment;   ///< Its kind.
  bool suspend = false;  ///< True when more effort may find it (a path search ran out of time).
  std::string message;   ///< The segment and the reason, in words.
  /// The cell at the collision the message names (robots where they hit, the two bodies), or
  /// where the segment starts.
  FailureScene scene;
};

/// Solved free paths of one plan, kept across effort levels (by free segment index).
struct MotionCache {
  struct Path {
    std::vector<int> robots;                          ///< Robots of the composite space.
    std::vector<std::vector<JointVector>> waypoints;  ///< Empty where not solved.
    /// The scene the path was solved in (every robot's joints, the objects, the holds and the
    /// finger openings): a path is reused only in the very same scene.
    std::vector<double> scene;
  };
  std::vector<Path> free_paths;  ///< By free segment index.
  /// Free paths to search again with another seed (free segment index -> how many times): the
  /// timed result grazed something between the path's checked states (see PlanMotion).
  std::map<int, int> reseed;
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

/// The geometric motion of `plan` at effort level `effort`. Keyframes stay, except where a straight
/// two-handed carry or an insertion reaches the keyframe's TCP pose on another IK solution that is
/// collision-free and clear of the other robots there: that solution replaces the robot's joints
/// at that keyframe and the following ones where it stood still (validate the plan again). On
/// success the segments in execution order (the plan's order; the schedule may overlap them);
/// otherwise `failure` says which segment failed. `cache` keeps solved free paths between calls
/// for the same plan. Deterministic for a given seed when no path search runs out of time.
/// Fails with kCancelled when ctx is cancelled and kInvalidInput when the plan does not fit the
/// world.
Result<std::vector<GeoSegment>> PlanGeometricMotion(const TaskWorld& world, Plan& plan,
                                                    const MotionOptions& options, int effort,
                                                    std::uint64_t seed, MotionCache& cache,
                                                    RunContext& ctx, MotionFailure* failure);

}  // namespace wrap
