// Timing a task plan without motion for the simulation (verify/): the keyframes replayed one
// action at a time, robots moving in joint space between consecutive keyframes. Not a motion
// planner: nothing avoids collisions, so a simulation of such a plan judges support, welds and
// wrenches, not collisions.
#pragma once

#include <string>
#include <vector>

#include "core/result.h"
#include "model/assembly.h"
#include "sim/scene.h"
#include "task/plan.h"

namespace wrap::detail {

/// Options of TimeKeyframes (the motion stage's skill defaults, motion/motion_options.h).
struct KeyframeReplayOptions {
  double lift_m = 0.05;            ///< Straight lift after a pick, descent before a place [m].
  double skill_speed_mps = 0.05;   ///< TCP speed of a lift or descent [m/s].
  double insert_speed_mps = 0.02;  ///< TCP speed of an insertion [m/s].
  double grip_s = 0.4;             ///< Robots hold still this long before each action's moment.
};

/// Gives `plan` (whose keyframes fit `scene`, checked by the caller) trajectories, segments and
/// action times: per action, in plan order, every robot whose joints differ from the action's
/// keyframe (an assemble: its approach keyframe) moves there along a straight line in joint
/// space, all of them in step, with a trapezoidal profile within each joint's velocity and
/// acceleration limits ("free"); a place ends with a straight descent of `lift_m` ("descend"),
/// an assemble with its insertion from the approach keyframe ("insert"); the robots then hold
/// still for `grip_s` ("grip") and the action happens (end_s); a pick of a resting object is
/// followed by a straight lift ("lift"), after which the robot stays lifted while the keyframes
/// keep it at the pick (they have the object on the table until it moves). Straight moves are straight in joint space between
/// their ends (IK of the shifted TCP pose). At the end every robot returns to its initial
/// joints. `notes` receives what was approximated (a lift without IK).
Result<void> TimeKeyframes(const CellScene& scene, const AssemblyTree& tree, Plan& plan,
                           const KeyframeReplayOptions& options, std::vector<std::string>& notes);

}  // namespace wrap::detail
