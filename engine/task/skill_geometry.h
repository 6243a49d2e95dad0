// The lengths and clearances that the task planner and the motion stage must agree on. The task
// planner checks at every keyframe that the straight moves the motion stage will make there (a
// gripper's approach to its grasp, a placement's descent, a freed gripper's retreat) are clear,
// and keeps the robots apart; the motion stage makes those moves and keeps the same clearance.
// One struct, read by both (TaskPlannerOptions::skills, MotionOptions::skills; PlanAssembly gives
// the motion stage and the keyframe optimisation the task planner's).
#pragma once

namespace wrap {

/// Skill lengths and clearances shared by the task and motion stages.
struct SkillGeometry {
  /// A gripper's straight approach to (and retreat from) a grasp, as the motion stage makes it
  /// where it can; shorter (down to an eighth) where the scene is tight [m]. Default 0.04.
  double approach_m = 0.04;
  /// The least straight approach to a grasp, and descent onto the table, that the task planner
  /// requires clear at a keyframe [m]. Default 0.02.
  double min_straight_m = 0.02;
  /// The least straight retreat a freed gripper needs: a release is permanent, and a gripper near
  /// the table still backs off a centimetre where two would hit it [m]. Default 0.01.
  double min_retreat_m = 0.01;
  /// Straight lift off (and descent onto) the table [m]. Default 0.02.
  double lift_m = 0.02;
  /// Least distance between two robots at a keyframe [m]. Default 0.005. (The independent plan
  /// validator checks 4 mm: PlanValidationOptions::min_clearance_m.)
  double robot_clearance_m = 0.005;
};

}  // namespace wrap
