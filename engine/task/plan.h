// A task plan (paper §IV-D): the multi-robot action sequence with its keyframes, as the planner
// produces it, the validator replays it, the renderer draws it and the plan JSON stores it.
//
// Semantics (the contract between planner, validator and renderer). The world holds *objects*:
// the subassemblies that currently exist as separate rigid bodies (DAG node ids; at the start
// every part is one). Each object has a pose X_WA of its assembly frame A (every part P of it at
// X_WA * X_AP, X_AP from the project's assembled poses), is either resting on the table or in the
// air, and has holders: robots gripping it, each with a grasp (part, X_PG). A robot holds at most
// one object. Free robots wait at their home configuration; a holding robot keeps the
// configuration of its last keyframe until an action moves it. Actions:
//
// - pick (robot r, object o, grasp g): r free; o resting, no holders. o does not move; r grasps it
//   and lifts it: o is in the air, held by r.
// - place (r, o, placement): r the only holder of o, o in the air. o is set down at the placement
//   pose and r lets go: o rests, no holders; r goes home.
// - handover (giver r1, receiver r2, o, g2): r1 the only holder of o, o in the air, r2 free. o may
//   be moved to any pose (both arms reach it there); r2 grasps with g2, r1 lets go and goes home.
// - add_grasp (r, o, g): r free, o resting or held. A resting o does not move (a brace); an o in
//   the air may be moved by its holders to a new pose where r can also grasp it.
// - release (r, o): r holds o, and o stays supported: it rests on the table or another robot still
//   holds it. Nothing moves; r goes home.
// - assemble (moved M, base B -> result S): M in the air, held; B resting or held. A resting B
//   does not move; a B in the air may be moved by its holders. M is brought to its mating pose
//   relative to B (X_WM = X_WB: both frames are the assembly frame) from an approach pose
//   `approach_m` back along the insertion axis. S replaces M and B, with B's pose, resting if B
//   rested, held by every robot that held M or B (the grasps carry over).
//
// An object in the air that an action moves is carried by all its holders (they all move). The
// keyframe of an action is the moment of contact (pick, add_grasp, handover: the new grasp is
// closed; place: the object touches the table; release: just before opening; assemble: mated);
// it lists every robot's joints and every object's pose at that moment.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/pose.h"
#include "core/run_context.h"
#include "grasp/grasp_type.h"
#include "robot/kinematics.h"
#include "task/failure.h"

namespace wrap {

/// The actions of the task planner (paper §IV-D).
enum class ActionType { kPick, kPlace, kHandover, kAddGrasp, kRelease, kAssemble };

/// "pick", "place", "handover", "add_grasp", "release", "assemble".
std::string_view ToString(ActionType type);
/// Inverse of ToString; nullopt for an unknown word.
std::optional<ActionType> ActionTypeFromString(std::string_view word);

/// A grasp as a plan records it: where it came from and what it is.
struct PlanGrasp {
  int subassembly = -1;          ///< Node id of the subassembly whose grasp set it was drawn from.
  int index = -1;                ///< Index in that set (the set of the robot's end effector).
  int part = -1;                 ///< Held part (index into Project::parts).
  Iso3 X_PG = Iso3::Identity();  ///< Grasp (TCP) frame in the part frame.
  double width_m = 0.0;          ///< Two-finger: the width the fingers close to [m]; vacuum 0.
  GraspType type = GraspType::kFullPad;  ///< Full-pad, partial-pad or fingertip (grasp.h).
  /// The grasp's torque limits as fractions of the robot's box: GraspLimits(limits, scale).
  Vec3 torque_scale = Vec3::Ones();
};

/// A robot holding an object with a grasp.
struct PlanHold {
  int robot = -1;   ///< Index into Project::robots.
  PlanGrasp grasp;  ///< The grasp.
};

/// Where a place action sets an object down (indices into the preprocessing's placements of the
/// object's subassembly, its table slots and the slots' yaws).
struct PlanPlacement {
  int placement = -1;  ///< Stable placement class.
  int slot = -1;       ///< Table slot.
  int yaw = -1;        ///< Yaw index at the slot.
};

/// One object at a keyframe.
struct PlanObject {
  int node = -1;                 ///< DAG node id of the object (a part or a step's subassembly).
  Iso3 X_WA = Iso3::Identity();  ///< Pose of its assembly frame in the world.
  bool resting = false;          ///< Rests on the table (else in the air, held).
};

/// A snapshot of the cell.
struct Keyframe {
  std::vector<JointVector> q;       ///< Every robot's joints, in Project::robots order.
  std::vector<PlanObject> objects;  ///< Every object that exists at that moment, by node id.
};

/// One action of a plan.
struct PlanAction {
  ActionType type = ActionType::kPick;  ///< What happens.
  /// Robots that act: pick, place, add_grasp, release: {r}; handover: {giver, receiver};
  /// assemble: every robot holding M or B (M's holders first).
  std::vector<int> robots;
  /// Objects (node ids): {o} for every type but assemble, which has {M, B, S}.
  std::vector<int> objects;
  /// One per entry of `robots`, same order: the grasp that robot has at the keyframe (pick,
  /// add_grasp: the new one; handover: the giver's, then the receiver's new one; place, release:
  /// the one let go; assemble: each holder's).
  std::vector<PlanHold> grasps;
  std::optional<PlanPlacement> placement;  ///< Place: where.
  Keyframe keyframe;                       ///< The moment of the action (see the file comment).
  /// Assemble: the moment before insertion, M `approach_m` back along the insertion axis; the
  /// insertion is a straight move from here to `keyframe`.
  std::optional<Keyframe> approach;
  int milestone = -1;  ///< Index of the milestone (step in planning order) it belongs to.
  /// The task search's key of the edge that made it (symbolic state before it and the action),
  /// for the motion stage's feedback (TaskPlannerOptions::banned_edges); 0 when unknown (a plan
  /// read from a file). Not saved.
  std::uint64_t edge = 0;
  /// Once retimed: when the first motion toward this action starts [s]; -1 without motion.
  double start_s = -1.0;
  /// Once retimed: the moment of the keyframe (grasp closed, gripper about to open, mated), when
  /// every robot of `robots` is at its keyframe joints [s]; -1 without motion.
  double end_s = -1.0;
  /// Each holding gripper's peak wrench utilisation at this action (robot index -> max_i |w_i| /
  /// limit_i over the action's wrench gates of the full model; AnnotateUtilisation). Empty when
  /// not computed.
  std::map<int, double> utilisation;
};

/// A knot of a timed robot trajectory. Between two knots every joint moves with constant
/// acceleration, so q, qd at both ends define the stretch: q(t) = q0 + qd0 tau + a tau^2 / 2
/// with a = (qd1 - qd0) / (t1 - t0).
struct TrajectoryKnot {
  double t = 0.0;  ///< Time since the plan starts [s].
  JointVector q;   ///< Joint positions [rad or m].
  JointVector qd;  ///< Joint velocities [rad/s or m/s].
  /// Finger opening from this knot to the next [m] (two-finger grippers: the width the fingers are
  /// open to); -1: fully open (and for vacuum grippers).
  double opening_m = -1.0;
};

/// One robot's timed trajectory, from time 0 to the makespan.
struct RobotTrajectory {
  int robot = -1;                     ///< Index into Project::robots.
  std::vector<TrajectoryKnot> knots;  ///< Increasing times; the first at t = 0.
};

/// A stretch of motion as the motion planner made it: free-space paths planned in the composite
/// space of the robots that move, and skills (straight moves along an approach, lift or insertion
/// axis) with their own durations.
struct MotionSegment {
  /// "free" (planned path), "approach" (to a grasp along the gripper axis), "retreat" (away from
  /// a released grasp), "lift" (a picked object up off the table), "descend" (onto the table at a
  /// place), "insert" (along the insertion axis to the mating pose), "carry" (an object held by
  /// several robots moved along a straight line), "grip" (gripper closes or opens at the keyframe).
  std::string kind;
  int action = -1;          ///< Action it leads to (or, after the last, the last action).
  std::vector<int> robots;  ///< Robots that take part.
  /// Objects (node ids) it moves or touches: carried, approached, released, inserted.
  std::vector<int> objects;
  double start_s = 0.0;  ///< Start [s].
  double end_s = 0.0;    ///< End [s].
  /// What its start waited for: "none" (nothing: it starts at 0), "robot" (it starts when
  /// `wait_segment`, the previous segment of one of its robots, ends), "object" (when
  /// `wait_segment`, an earlier segment on one of its objects, ends), "collision" (it was ready
  /// earlier, but its timed motion, or its robots' rest afterwards, would have collided with
  /// `wait_segment`'s robots or with an object that segment moves); empty: not recorded (plans
  /// written before the schedule said).
  std::string wait;
  /// The segment waited for (index into Plan::segments), -1 for none.
  int wait_segment = -1;
};

/// Statistics of a planner run (the paper's breakdown table and search counters).
struct PlanStats {
  bool solved = false;                ///< A plan was found.
  int cost = 0;                       ///< Number of actions (the paper's cost).
  double t_init_s = 0.0;              ///< Time to the first task plan, without preprocessing [s].
  double t_grasp_s = 0.0;             ///< Preprocessing (grasps, placements, table slots) [s].
  double t_bwd_s = 0.0;               ///< Backward (heuristic) search [s].
  double t_lp_s = 0.0;                ///< Wrench LPs [s].
  double t_fwd_s = 0.0;               ///< Forward search, without IK and LP [s].
  double t_ik_s = 0.0;                ///< IK, collision and clearance checks of keyframes [s].
  std::string planner;                ///< Planner variant, e.g. "counting".
  std::uint64_t seed = 0;             ///< Seed of the run.
  std::string wrench_mode;            ///< "full", "gravity" or "none".
  double force_scale = 1.0;           ///< Lambda on the mating wrench.
  int grasps = 0;                     ///< Grasp-set size of the preprocessing.
  long long expansions = 0;           ///< Search nodes expanded.
  long long validations = 0;          ///< Edges validated (IK, collision, wrench).
  long long validation_failures = 0;  ///< ... that failed.
  long long lp_checks = 0;            ///< Wrench checks asked (cache hits included).
  long long lp_cache_hits = 0;        ///< ... answered from the cache.
  long long lp_solves = 0;            ///< LPs solved for the rest (one per vertex of U, ...).
  long long lp_pivots = 0;            ///< Their simplex pivots.
  long long ik_calls = 0;             ///< IK queries.
  long long collision_checks = 0;     ///< Cell collision queries.
  int milestones = 0;                 ///< Milestones (assembly steps) planned.
  int backtracks = 0;                 ///< Milestones re-planned after a later one failed.
  int widenings = 0;                  ///< Grasp and placement subsets widened.
  bool out_of_memory = false;         ///< Stopped at the memory limit (failure says so).
  int first_cost = 0;                 ///< Cost of the first plan (before --optimize).
  double t_opt_s = 0.0;               ///< Plan improvement (--optimize) [s].
  /// Cost over time (--optimize): (seconds since planning started, cost) at the first plan
  /// and at every improvement.
  std::vector<std::pair<double, int>> cost_history;
  /// What --optimize minimised: "actions" (the number of actions) or "makespan".
  std::string objective;
  /// The task plan's makespan estimate (makespan_estimate.h): actions of estimated durations by
  /// type, each as early as its robots and objects allow [s]; 0 when not solved.
  double makespan_est_s = 0.0;
  std::string failure;  ///< Empty when solved, else why not, in words.
  /// The same as data when not solved (where it failed and the checks that failed there, with
  /// the cell at each); absent when solved or when the planner could not say. Not saved.
  std::optional<PlanFailure> failure_detail;
  // Motion (paper §IV-D keyframe optimisation, §IV-E motion planning, §IV-F retiming).
  bool motion = false;                 ///< Trajectories were planned (false: task plan only).
  double t_kf_s = 0.0;                 ///< Joint keyframe optimisation [s].
  double t_mp_s = 0.0;                 ///< Motion planning of the plan that succeeded [s].
  double t_retime_s = 0.0;             ///< Retiming and scheduling [s].
  double makespan_s = 0.0;             ///< Execution time with robots moving concurrently [s].
  double makespan_sequential_s = 0.0;  ///< Same plan, one motion segment at a time [s].
  int motion_segments = 0;             ///< Segments (free paths and skills).
  int motion_suspensions = 0;          ///< Segments that timed out and were suspended.
  int task_plans = 0;                  ///< Task plans tried by the motion loop.
};

/// A plan of a project.
/// Two parts that touch in the assembly, as the geometry checks found them (the project's contact
/// graph, recorded with the plan for viewers).
struct PlanContact {
  int part_a = -1;                   ///< Part index (Plan::parts), a < b.
  int part_b = -1;                   ///< The other part.
  double distance_m = 0.0;           ///< Closest distance of the surfaces (0: they meet) [m].
  double area_m2 = 0.0;              ///< Area within the contact tolerance [m^2].
  Vec3 centroid_A = Vec3::Zero();    ///< Centre of that area, assembly frame [m].
  Vec3 extent_min_A = Vec3::Zero();  ///< Its bounding box, assembly frame [m].
  Vec3 extent_max_A = Vec3::Zero();
  std::vector<std::pair<Vec3, double>> normals;  ///< Unit normal out of b into a, with its area.
};

struct Plan {
  std::string project;               ///< Project name.
  std::vector<std::string> robots;   ///< Robot names, Project::robots order.
  std::vector<std::string> parts;    ///< Part names, Project::parts order.
  std::vector<std::string> nodes;    ///< DAG node names by node id (parts, then steps).
  std::vector<int> milestone_steps;  ///< Step node id of each milestone, in planning order.
  Keyframe initial;                  ///< Robots at home, parts at their initial poses.
  std::vector<PlanAction> actions;   ///< The action sequence.
  PlanStats stats;                   ///< How it was found.
  /// Timed trajectories, one per robot (Project::robots order); empty without motion.
  std::vector<RobotTrajectory> trajectories;
  std::vector<MotionSegment> segments;  ///< How the motion was made, by start time.
  std::vector<PlanContact> contacts;    ///< The assembly's contact graph (may be empty).
};

/// Joint positions (and velocities when `qd` is given) of a trajectory at time t, clamped to its
/// first and last knot. The trajectory must have knots.
JointVector SampleTrajectory(const RobotTrajectory& trajectory, double t,
                             JointVector* qd = nullptr);
/// Finger opening of a trajectory at time t (the opening of the last knot at or before t).
double OpeningAt(const RobotTrajectory& trajectory, double t);

/// The action in words, e.g. "r2 hands 'leg1' over to r3 (grasp 7 -> grasp 12)", with the
/// plan's names.
std::string DescribeAction(const Plan& plan, const PlanAction& action);

}  // namespace wrap
