// The motion stage's options, per-attempt request, failure record and path cache: what PlanMotion
// (motion.h) takes and gives besides the plan. Apart from motion.h so that the stage's own parts
// (segments.h) use them without including the front door.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "robot/kinematics.h"
#include "task/failure.h"
#include "task/skill_geometry.h"

namespace wrap {

/// Options of the schedule that lets robots move at the same time (Retime, paper §IV-F).
struct RetimeOptions {
  /// Segments start as early as their robots, objects and timed conflicts allow. False: one at
  /// a time in plan order, each once everything before it has ended (the segments' own timing
  /// is the same either way).
  bool concurrent = true;
  /// The collision test of overlapping motions samples states no farther apart than this in any
  /// joint of any robot [rad]: no coarser than the trajectory check's 0.02 rad. The check
  /// samples other moments; where it meets a graze between the schedule's samples, PlanMotion
  /// schedules that segment after everything before it.
  double resolution_rad = 0.02;
  /// Bodies of a segment keep this far from what other robots move or leave meanwhile [m]
  /// (the motion planner's margin is 0; a positive one makes each test a distance query, about
  /// ten times dearer).
  double clearance_m = 0.0;
};

/// Options of the motion stage: the geometric motion, its timing and the self-check.
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
  /// Skill lengths (approach_m, lift_m) and the robots' clearance at keyframes: the task
  /// planner's (PlanAssembly sets them from TaskPlannerOptions::skills).
  SkillGeometry skills;
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
  RetimeOptions retime;  ///< The concurrent schedule.
  /// Run the independent trajectory check on the timed result; a plan that fails it has no
  /// motion (its first issue is the failure), so no colliding trajectory leaves the planner.
  bool self_check = true;
  /// Debugging: every timed result the self-check refuses is saved here as a plan JSON
  /// (refused_N.json); empty: none (`wrap plan --dump-refused DIR`).
  std::filesystem::path dump_refused_dir;
};

/// What varies between the motion attempts on one plan (the options are fixed for a run).
struct MotionRequest {
  /// Effort level 0..MotionOptions::max_effort: the searches' work budgets
  /// (MotionOptions::segment_checks and carry_edges) double per level.
  int effort = 0;
  std::uint64_t seed = 0;  ///< Seed of the path searches.
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

}  // namespace wrap
