// Why a planner run found no plan, as data: the stage, the milestone (assembly step) or the
// action and motion segment where it stopped, and the checks that failed there, blocker first,
// each with one example that names the object, the pose, the grasp, the robot and the bodies
// that collided, so that a front end can put the cell back into the failing state (like MoveIt
// Task Constructor's introspection of failed stages). The words are the CLI's: `stats.failure`
// is `text`, and each case's `text` is the piece of it that names that check.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/pose.h"
#include "robot/kinematics.h"

namespace wrap {

/// The cell as a failed check saw it (any part may be missing: empty means unknown).
struct FailureScene {
  std::vector<JointVector> q;  ///< Every robot's joints, Project::robots order.
  std::vector<Iso3> X_WP;      ///< Every part's pose, Project::parts order.
  /// The two bodies that touched, by their collision-world names ("ROBOT/LINK", a part's name,
  /// "table"); empty when the check was not a collision.
  std::vector<std::string> bodies;
};

/// One kind of check that failed (a gate of the task planner, or a motion segment), with the
/// first example of it.
struct FailureCase {
  std::string check;         ///< The check in words: "IK", "collision", "wrench (assembly)", ...
  long long count = 0;       ///< How many distinct questions failed it (1 for motion).
  std::string text;          ///< The CLI's words for it, e.g. "IK failed 40x (e.g. ...)".
  std::string example;       ///< The example alone, in words.
  int object = -1;           ///< DAG node id of the object tried (-1: none named).
  std::optional<Iso3> X_WA;  ///< Where the object was tried (its assembly frame in the world).
  int robot = -1;            ///< The robot that could not reach, or whose gripper hit.
  int grasp_part = -1;       ///< Part the tried grasp is on (-1: no grasp named).
  Iso3 X_PG = Iso3::Identity();  ///< The tried grasp (TCP) in that part's frame.
  int grasp_index = -1;          ///< Its index in its grasp set (the words' "grasp N").
  /// The cell at the failure: the stage's start with the tried object moved to X_WA, or the
  /// cell as the failing check saw it (joints, bodies) when it was captured.
  FailureScene scene;
};

/// Why a run found no plan.
struct PlanFailure {
  std::string stage;        ///< "task" or "motion".
  std::string text;         ///< The whole reason, the CLI's words (= PlanStats::failure).
  int milestone = -1;       ///< Task: index of the milestone that failed (planning order).
  int step = -1;            ///< Task: DAG node id of its step; motion: the failing action's step.
  int action = -1;          ///< Motion: index of the action whose segment failed.
  std::string segment;      ///< Motion: the segment's kind ("free", "approach", ...).
  std::vector<int> robots;  ///< Motion: the robots of the segment.
  /// The cell where the failing stage started: task, the milestone's start (robots at home or
  /// holding, every object where it rests); motion, where the segment started.
  FailureScene start;
  std::vector<FailureCase> cases;  ///< The checks that failed, blocker (most failures) first.
};

}  // namespace wrap
