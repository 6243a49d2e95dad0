// The independent plan validator: replays a task plan (paper §IV-D) from the project's initial
// state and checks every rule of the semantics contract in task/plan.h with its own code, not
// the search's: the preconditions and effects of every action, the poses of the objects an action
// may not move, forward kinematics of every grasp at every keyframe (the IK witnesses), joint
// limits, collisions and the robots' clearance in a cell of its own, and every wrench gate
// (assembly, transport, release, rest; paper §IV-A) re-solved from scratch with a fresh checker.
// Tests and `wrap plan --validate` use it to catch a planner that fools itself.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.h"
#include "model/project.h"
#include "model/validate.h"
#include "task/plan.h"
#include "wrench/wrench.h"

namespace wrap {

/// Options of ValidatePlan: tolerances and which checks run.
struct PlanValidationOptions {
  /// Largest distance between a holding robot's TCP (FK of its keyframe joints) and its grasp
  /// pose X_WA * X_AP * X_PG, and between an object's pose and the pose it must keep [m].
  double position_tolerance_m = 2e-3;
  /// Same for the rotation angle between the two frames [rad].
  double rotation_tolerance_rad = 2e-2;
  /// A robot that may not move (it holds an object that stays put, or it idles) keeps each joint
  /// within this of its previous value [rad or m].
  double joint_tolerance = 1e-6;
  /// Least distance between two robots (links and end effectors) at every keyframe [m]. The
  /// planner keeps 5 mm; the default leaves it 1 mm of slack.
  double min_clearance_m = 0.004;
  /// A resting object's lowest point lies within this of the table top, and its vertices this
  /// close to the top are its table supports in the wrench checks [m].
  double table_tolerance_m = 2e-3;
  /// Check collisions and clearance at every keyframe (the expensive part).
  bool check_collisions = true;
  /// Re-solve every wrench gate.
  bool check_wrench = true;
  /// How the mating wrench enters the gates (kNone: the wrench gates are skipped).
  MatingWrenchMode wrench_mode = MatingWrenchMode::kFull;
  /// Lambda on the mating force and torque, >= 0.
  double force_scale = 1.0;
  /// The plan must build the whole assembly: after the last action the root exists, rests on the
  /// table and every robot is free (else an "incomplete" issue). False for partial plans.
  bool require_complete = true;
};

/// One thing wrong with a plan.
struct PlanIssue {
  /// Index of the action whose keyframe or preconditions fail; -1 for the initial keyframe and the
  /// plan as a whole (e.g. names that do not match the project).
  int action = -1;
  /// Which check failed: "plan" (names, counts), "precondition" (an action not allowed in the
  /// state, or malformed), "pose" (an object where it may not be, the keyframe's object list, the
  /// mating or approach pose, a resting object off the table), "insertion" (the moved input's
  /// straight path from its approach pose into its mating pose cuts into the base beyond the
  /// geometry's allowance), "joints" (a robot that may not move did), "fk" (a TCP away from its
  /// grasp pose), "joint_limits", "collision", "clearance", "wrench_assembly",
  /// "wrench_transport", "wrench_release", "wrench_rest" (an infeasible gate, with the checker's
  /// reason), "incomplete" (the plan does not end with the root assembled, resting and every
  /// robot free).
  std::string gate;
  std::string message;  ///< What was seen and what was expected, with the project's names.
};

/// What ValidatePlan found.
struct PlanValidation {
  bool valid = false;             ///< No issue at all.
  std::vector<PlanIssue> issues;  ///< Every issue, in replay order.
  int actions = 0;                ///< Actions replayed (the replay stops at a malformed one).
  int keyframes = 0;              ///< Keyframes checked (initial, action and approach keyframes).
  int collision_checks = 0;       ///< Collision queries run.
  int wrench_checks = 0;          ///< Wrench gates solved.
  /// Per action (Plan::actions' order): each holding gripper's peak utilisation over the wrench
  /// gates solved at that action (robot index -> max_i |w_i| / limit_i, worst case over the
  /// uncertainty set; above 1 where a gate fails). Empty where no gate ran.
  std::vector<std::map<int, double>> utilisation;

  /// True when some issue has `gate`, at `action` unless `action` is kAnyAction.
  bool HasIssue(std::string_view gate, int action = kAnyAction) const;
  /// Wildcard for HasIssue's action.
  static constexpr int kAnyAction = -2;
};

/// One line for a person: "action 3: fk: ..." or "initial: collision: ...".
std::string FormatIssue(const PlanIssue& issue);

/// Replays `plan` on the validated project (`check` from LoadProject: meshes, masses, the DAG) and
/// checks it against the contract of task/plan.h: per action its preconditions (holders, resting
/// or in the air, one object per robot, a release leaving the object supported, an assemble of a
/// step's two inputs with the moved one held in the air) and its effects; per keyframe (the
/// initial one, each action's, each assemble's approach) the object list, the poses of objects
/// that may not move, the mating pose X_WM = X_WB and the approach pose `approach_m` back along the
/// insertion axis, resting objects on the table top, idle robots keeping their joints (a robot
/// freed by an action may park anywhere), FK of every grasp, joint limits, collisions (allowed: a
/// holding gripper with its part, parts of one object, the mated inputs at an assemble, objects at
/// rest with the table) and the robots' clearance; per action its wrench gate re-solved (pick and
/// handover: transport; place: rest; release and add_grasp: release, or rest when nothing holds
/// it any more; assemble: assembly). `project_file` resolves URDF robots.
/// Everything wrong with the plan is an issue (valid = false). Fails with kInvalidInput only when
/// the plan cannot be interpreted: a robot, part or node index out of range, a keyframe without
/// one joint vector of the right size per robot, a project without a DAG or a mesh, a robot model
/// or end effector that does not load; and with kInvalidInput for options out of range.
[[nodiscard]] Result<PlanValidation> ValidatePlan(const Project& project, const ProjectCheck& check,
                                                  const Plan& plan,
                                                  const PlanValidationOptions& options,
                                                  const std::filesystem::path& project_file);

/// Fills every action's PlanAction::utilisation: the wrench gates of the full model at the
/// plan's lambda (stats.force_scale), solved at each action's keyframe, whatever model the plan
/// was made with (so a plan made without the wrench model shows where it asks too much);
/// collisions are not checked and the plan is not judged. Fails like ValidatePlan.
Result<void> AnnotateUtilisation(const Project& project, const ProjectCheck& check, Plan& plan,
                                 const std::filesystem::path& project_file = {});

}  // namespace wrap
