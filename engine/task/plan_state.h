// What an action of a plan does to the cell (the semantics of task/plan.h as code): the plan
// state (which objects exist, where they are, which rest on the table, which robot holds which
// object with which grasp) before and after each action. The one meaning of an action's effect
// for everything that replays a plan: the motion planner's scene, the keyframe optimisation, the
// keyframe replay and the physics run of the simulation, the renderer. (The plan validator and
// the motion stage's trajectory check keep replays of their own on purpose: they check plans
// against the semantics independently of this code.)
//
// An action happens in two moments. At its keyframe (and its approach) the grasps it closes are
// closed and every robot it names has the grasp it lists for it; then the grasps it opens open
// and an assemble joins its two inputs. StateAtKeyframe is the first, ApplyAction both.
#pragma once

#include <map>
#include <vector>

#include "task/plan.h"

namespace wrap {

/// What exists and who holds what at one moment of a plan.
struct PlanState {
  /// The objects that exist, by node id: pose of the assembly frame, resting on the table or not.
  /// The pose is where the last action that acted on the object had it at its keyframe (or the
  /// initial keyframe): exact for an object nobody holds; a held object moves with its holders
  /// between keyframes.
  std::map<int, PlanObject> objects;
  std::vector<int> held;         ///< Per robot: node id of the object it holds, -1 none.
  std::vector<PlanGrasp> grasp;  ///< Per robot: its grasp while `held[r] >= 0`.

  /// The robots holding `node`, in robot order.
  std::vector<int> Holders(int node) const;
};

/// The state at `initial`: its objects, `n_robots` robots holding nothing.
PlanState InitialPlanState(const Keyframe& initial, int n_robots);

/// The state at the keyframe of `action` (and at its approach), from the state `before` it:
/// - the objects it acts on (PlanAction::objects) that exist take the poses its keyframe gives
///   them; the others do not move (plan.h: only an action's objects move);
/// - every robot it names has the grasp it lists for it (PlanAction::grasps, same order);
/// - the grasp it closes is closed: pick and add_grasp: robots[0] holds objects[0]; handover:
///   the receiver robots[1] holds it too (the giver still does).
/// Nothing is let go yet. What an action lacks (robots, grasps, objects; robot indices outside
/// the state) is skipped: a malformed plan replays without a crash, as far as it goes.
[[nodiscard]] PlanState StateAtKeyframe(const PlanState& before, const PlanAction& action);

/// The state after `action`, from the state `before` it: StateAtKeyframe, then
/// - pick: the object is in the air (not resting);
/// - place: robots[0] lets go, the object rests;
/// - release: robots[0] lets go (the object stays supported: resting, or held by another);
/// - handover: the giver robots[0] lets go (the receiver holds the object);
/// - add_grasp: nothing more (a braced object keeps resting);
/// - assemble (M, B -> S): S replaces M and B, with B's pose and B's resting, held by every
///   robot that held M or B (with its grasp).
/// A robot that lets go holds nothing. Malformed actions as StateAtKeyframe.
[[nodiscard]] PlanState ApplyAction(const PlanState& before, const PlanAction& action);

/// The state before the first action (states[0], from plan.initial with one robot per
/// plan.robots) and after each action i (states[i + 1]), in plan order.
std::vector<PlanState> ReplayPlanStates(const Plan& plan);

}  // namespace wrap
