// Joint keyframe optimisation (paper §IV-D "Joint Keyframe Optimization"): the task planner picks
// one IK solution per keyframe as it validates an edge, greedily, so that consecutive keyframes of
// a robot may sit on different IK branches (the elbow flips between a pick and the next assembly)
// or far apart in joint space. Once the task sequence is fixed, every robot's TCP pose at every
// keyframe is known, and the joint configurations can be chosen again jointly: per robot a
// dynamic programme (Viterbi) over its keyframes, with the IK solutions of each keyframe's TCP
// pose as candidates, trading branch changes and joint motion against clearance to the other
// robots; the robots take turns (coordinate descent) so that every choice stays collision-free
// against the others' current choices.
#pragma once

#include "core/result.h"
#include "core/run_context.h"
#include "task/plan.h"
#include "task/world.h"

namespace wrap {

/// Weights and limits of OptimizeKeyframes.
struct KeyframeOptOptions {
  /// Cost of one IK-branch change between consecutive stages of a robot.
  double branch_change_cost = 1.0;
  /// Cost per radian of joint motion (sum over the joints of |dq|) between consecutive stages.
  double joint_motion_weight = 0.2;
  /// Reward per metre of clearance to the other robots at a stage, capped: the reward is
  /// `clearance_weight * min(clearance, clearance_cap_m)`.
  double clearance_weight = 2.0;
  /// Clearance beyond which more clearance earns nothing [m].
  double clearance_cap_m = 0.10;
  /// A candidate must keep at least this clearance to the other robots at every keyframe of its
  /// stage [m] (the planner's minimum clearance).
  double min_clearance_m = 0.005;
  /// Random restarts of the numeric IK (arms without the UR closed form, e.g. 7-DoF arms) when
  /// looking for alternative branches.
  int numeric_candidates = 8;
  /// Coordinate-descent sweeps over the robots.
  int sweeps = 2;
};

/// What OptimizeKeyframes did, with the metrics before and after.
struct KeyframeOptReport {
  int stages = 0;      ///< (robot, stage) pairs optimised (fixed ones excluded).
  int candidates = 0;  ///< Candidates generated in total (within limits, on the stage's TCP pose).
  int changed = 0;     ///< Stages whose configuration changed.
  int branch_changes_before = 0;  ///< IK-branch changes between consecutive stages, all robots.
  int branch_changes_after = 0;   ///< ... after the optimisation.
  /// Joint motion, summed over the robots and their consecutive stages (sum of |dq|) [rad].
  double joint_motion_before = 0.0;
  double joint_motion_after = 0.0;  ///< ... after the optimisation [rad].
  /// Smallest robot-robot clearance over all keyframes [m] (+inf with fewer than two robots).
  double min_clearance_before_m = 0.0;
  double min_clearance_after_m = 0.0;  ///< ... after the optimisation [m].
  double cost_before = 0.0;            ///< The objective (see OptimizeKeyframes) before.
  double cost_after = 0.0;             ///< ... and after; never above `cost_before`.
};

/// Re-chooses the joint configurations of `plan`'s keyframes (every action's keyframe and each
/// assemble's approach; the initial keyframe is fixed) without changing anything else: the task
/// sequence, the objects' poses, the grasps and every robot's TCP pose at every keyframe stay as
/// they are.
///
/// Stages: walking the keyframes in order (initial, then per action its approach, if any, and its
/// keyframe), a robot whose joints do not change (within 1e-6, the validator's joint tolerance)
/// stays in one stage; a stage gets one configuration for all its keyframes. Stages at the
/// robot's home configuration (TaskWorld::robots[r].home) and the one holding the initial keyframe
/// are fixed. Candidates of a free stage: its current configuration and the other IK solutions of
/// its TCP pose (UR arms: every closed-form solution; other arms: the numeric IK's distinct
/// branches from the current configuration and `numeric_candidates` random restarts, seeded
/// deterministically from one draw of `ctx.rng()` and the stage), each (the current one too) as
/// its 2 pi equivalents nearest the current configuration, the neighbouring stages' and home
/// (where the limits allow), kept when within the joint limits and within 1e-4 m / 1e-3 rad of
/// the stage's TCP pose. A candidate is chosen only when it is collision-free (links, end
/// effector with the fingers at the held grasp's opening, against the table, the objects and the
/// other robots; the held part may touch its holder's end effector) and keeps `min_clearance_m`
/// to the other robots at every keyframe of its stage, with the other robots at their current
/// choices. The current configuration is always allowed.
///
/// Branch of a configuration: UR arms, the closed form's branch id of the solution nearest to it
/// (shoulder, wrist, elbow); other arms, the signs of q[1], q[3] and q[5] (shoulder, elbow and
/// wrist pitch of the usual alternating roll-pitch 7-DoF layout; joints beyond the chain ignored).
///
/// Objective, summed over the robots' chains of stages (fixed ones included):
/// `branch_change_cost * [branch changes] + joint_motion_weight * sum |dq|` over consecutive
/// stages, minus `clearance_weight * min(clearance, clearance_cap_m)` per stage (the robot's
/// least distance to the others over the stage's keyframes). The approach and the keyframe of an
/// assemble (a straight insertion) must keep the branch and turn no joint by more than pi, unless
/// the plan already breaks this there. Each robot in turn, `sweeps` times, gets
/// the Viterbi-optimal chain against the others' current choices; the new chain is kept only when
/// the whole objective decreases, so the result is never worse than the input and, with no better
/// choice, `plan` is unchanged. Deterministic.
///
/// Between robots: a cancelled `ctx` fails with kCancelled and leaves `plan` unchanged; past the
/// deadline the best choices so far are written. Fails with kInvalidInput when the plan does not
/// match the world (robot count, joint vector sizes, robot, part or node indices) and with
/// kInternal when the collision cell cannot be built.
[[nodiscard]] Result<KeyframeOptReport> OptimizeKeyframes(const TaskWorld& world, Plan& plan,
                                                          const KeyframeOptOptions& options,
                                                          RunContext& ctx);

}  // namespace wrap
