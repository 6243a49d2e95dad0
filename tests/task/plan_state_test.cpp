// What an action does to the plan state (task/plan_state.h): hand-made tiny plans, checking who
// holds what with which grasp, which objects rest, and where they are after each action type.
#include <gtest/gtest.h>

#include <vector>

#include "task/plan.h"
#include "task/plan_state.h"

namespace wrap {
namespace {

// Nodes of a two-part assembly: parts first, then the step that joins them.
constexpr int kPeg = 0, kBlock = 1, kPegBlock = 2;
constexpr int kR0 = 0, kR1 = 1, kR2 = 2;

Iso3 At(double x, double y, double z) {
  Iso3 X = Iso3::Identity();
  X.translation() = Vec3(x, y, z);
  return X;
}

PlanGrasp Grasp(int part, int index, double width_m) {
  PlanGrasp g;
  g.subassembly = part;
  g.index = index;
  g.part = part;
  g.X_PG = At(0.0, 0.0, 0.01 * (index + 1));
  g.width_m = width_m;
  return g;
}

PlanHold Hold(int robot, const PlanGrasp& g) { return PlanHold{robot, g}; }

Keyframe Objects(std::vector<PlanObject> objects) {
  Keyframe k;
  k.objects = std::move(objects);
  return k;
}

PlanAction Act(ActionType type, std::vector<int> robots, std::vector<int> objects,
               std::vector<PlanHold> grasps, Keyframe keyframe) {
  PlanAction a;
  a.type = type;
  a.robots = std::move(robots);
  a.objects = std::move(objects);
  a.grasps = std::move(grasps);
  a.keyframe = std::move(keyframe);
  return a;
}

// Peg and block resting on the table, three robots free.
PlanState Start() {
  return InitialPlanState(
      Objects({{kPeg, At(0.1, 0.0, 0.0), true}, {kBlock, At(-0.1, 0.0, 0.0), true}}), 3);
}

void ExpectPose(const PlanState& s, int node, const Iso3& X_WA) {
  ASSERT_TRUE(s.objects.count(node)) << "node " << node;
  EXPECT_TRUE(s.objects.at(node).X_WA.isApprox(X_WA, 0.0)) << "node " << node;
}

TEST(PlanState, InitialHasTheKeyframesObjectsAndFreeRobots) {
  const PlanState s = Start();
  EXPECT_EQ(s.held, (std::vector<int>{-1, -1, -1}));
  EXPECT_EQ(s.grasp.size(), 3u);
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_TRUE(s.objects.at(kPeg).resting);
  ExpectPose(s, kBlock, At(-0.1, 0.0, 0.0));
  EXPECT_TRUE(s.Holders(kPeg).empty());
}

TEST(PlanState, PickLiftsTheObjectInTheRobotsGrasp) {
  const PlanGrasp g = Grasp(kPeg, 3, 0.02);
  // The keyframe has the block elsewhere: only the action's object takes the keyframe's pose.
  const PlanAction pick =
      Act(ActionType::kPick, {kR1}, {kPeg}, {Hold(kR1, g)},
          Objects({{kPeg, At(0.1, 0.0, 0.0), true}, {kBlock, At(5.0, 5.0, 5.0), true}}));
  const PlanState at = StateAtKeyframe(Start(), pick);
  EXPECT_EQ(at.held[kR1], kPeg);
  EXPECT_TRUE(at.objects.at(kPeg).resting) << "lifted after the keyframe, not at it";

  const PlanState s = ApplyAction(Start(), pick);
  EXPECT_EQ(s.held, (std::vector<int>{-1, kPeg, -1}));
  EXPECT_EQ(s.grasp[kR1].index, 3);
  EXPECT_EQ(s.grasp[kR1].width_m, 0.02);
  EXPECT_FALSE(s.objects.at(kPeg).resting);
  EXPECT_TRUE(s.objects.at(kBlock).resting);
  ExpectPose(s, kBlock, At(-0.1, 0.0, 0.0));
  EXPECT_EQ(s.Holders(kPeg), (std::vector<int>{kR1}));
}

TEST(PlanState, PlaceSetsTheObjectDownAtTheKeyframesPoseAndFreesTheRobot) {
  const PlanGrasp g = Grasp(kPeg, 0, 0.02);
  const PlanState held =
      ApplyAction(Start(), Act(ActionType::kPick, {kR0}, {kPeg}, {Hold(kR0, g)}, Keyframe{}));
  const PlanAction place =
      Act(ActionType::kPlace, {kR0}, {kPeg}, {Hold(kR0, g)},
          Objects({{kPeg, At(0.3, 0.2, 0.0), true}, {kBlock, At(-0.1, 0.0, 0.0), true}}));
  const PlanState at = StateAtKeyframe(held, place);
  EXPECT_EQ(at.held[kR0], kPeg) << "the gripper opens after the keyframe";
  ExpectPose(at, kPeg, At(0.3, 0.2, 0.0));

  const PlanState s = ApplyAction(held, place);
  EXPECT_EQ(s.held[kR0], -1);
  EXPECT_TRUE(s.objects.at(kPeg).resting);
  ExpectPose(s, kPeg, At(0.3, 0.2, 0.0));
  EXPECT_TRUE(s.Holders(kPeg).empty());
}

TEST(PlanState, HandoverPassesTheObjectToTheReceiversGrasp) {
  const PlanGrasp g0 = Grasp(kPeg, 0, 0.02);
  const PlanGrasp g1 = Grasp(kPeg, 1, 0.03);
  const PlanState held =
      ApplyAction(Start(), Act(ActionType::kPick, {kR0}, {kPeg}, {Hold(kR0, g0)}, Keyframe{}));
  const PlanAction handover =
      Act(ActionType::kHandover, {kR0, kR2}, {kPeg}, {Hold(kR0, g0), Hold(kR2, g1)},
          Objects({{kPeg, At(0.0, 0.0, 0.3), false}, {kBlock, At(-0.1, 0.0, 0.0), true}}));
  const PlanState at = StateAtKeyframe(held, handover);
  EXPECT_EQ(at.Holders(kPeg), (std::vector<int>{kR0, kR2})) << "both hold at the keyframe";

  const PlanState s = ApplyAction(held, handover);
  EXPECT_EQ(s.held, (std::vector<int>{-1, -1, kPeg}));
  EXPECT_EQ(s.grasp[kR2].index, 1);
  EXPECT_EQ(s.grasp[kR2].width_m, 0.03);
  EXPECT_FALSE(s.objects.at(kPeg).resting);
  ExpectPose(s, kPeg, At(0.0, 0.0, 0.3));
}

TEST(PlanState, AddGraspOnARestingObjectBracesIt) {
  const PlanGrasp g = Grasp(kBlock, 2, 0.05);
  const PlanState s =
      ApplyAction(Start(), Act(ActionType::kAddGrasp, {kR2}, {kBlock}, {Hold(kR2, g)}, Keyframe{}));
  EXPECT_EQ(s.held[kR2], kBlock);
  EXPECT_EQ(s.grasp[kR2].index, 2);
  EXPECT_TRUE(s.objects.at(kBlock).resting) << "a brace does not lift it";
}

TEST(PlanState, ReleaseLetsOneHolderGoAndTheOtherKeepsIt) {
  const PlanGrasp g0 = Grasp(kPeg, 0, 0.02);
  const PlanGrasp g1 = Grasp(kPeg, 1, 0.02);
  PlanState s =
      ApplyAction(Start(), Act(ActionType::kPick, {kR0}, {kPeg}, {Hold(kR0, g0)}, Keyframe{}));
  s = ApplyAction(s, Act(ActionType::kAddGrasp, {kR1}, {kPeg}, {Hold(kR1, g1)}, Keyframe{}));
  EXPECT_EQ(s.Holders(kPeg), (std::vector<int>{kR0, kR1}));
  s = ApplyAction(s, Act(ActionType::kRelease, {kR0}, {kPeg}, {Hold(kR0, g0)}, Keyframe{}));
  EXPECT_EQ(s.Holders(kPeg), (std::vector<int>{kR1}));
  EXPECT_EQ(s.grasp[kR1].index, 1);
  EXPECT_FALSE(s.objects.at(kPeg).resting) << "still in the air, held by the other robot";
}

TEST(PlanState, AssembleJoinsTheInputsWithTheBasesPoseAndEveryHolder) {
  const PlanGrasp gp = Grasp(kPeg, 0, 0.02);
  const PlanGrasp gb = Grasp(kBlock, 1, 0.05);
  PlanState s =
      ApplyAction(Start(), Act(ActionType::kPick, {kR2}, {kPeg}, {Hold(kR2, gp)}, Keyframe{}));
  s = ApplyAction(s, Act(ActionType::kPick, {kR0}, {kBlock}, {Hold(kR0, gb)}, Keyframe{}));
  const Iso3 X_WB = At(0.0, 0.1, 0.4);
  const PlanAction assemble =
      Act(ActionType::kAssemble, {kR2, kR0}, {kPeg, kBlock, kPegBlock},
          {Hold(kR2, gp), Hold(kR0, gb)}, Objects({{kPeg, X_WB, false}, {kBlock, X_WB, false}}));
  const PlanState at = StateAtKeyframe(s, assemble);
  EXPECT_EQ(at.objects.size(), 2u) << "joined after the keyframe";

  const PlanState after = ApplyAction(s, assemble);
  ASSERT_EQ(after.objects.size(), 1u);
  const PlanObject& joined = after.objects.at(kPegBlock);
  EXPECT_EQ(joined.node, kPegBlock);
  EXPECT_FALSE(joined.resting);
  ExpectPose(after, kPegBlock, X_WB);
  EXPECT_EQ(after.Holders(kPegBlock), (std::vector<int>{kR0, kR2}));
  EXPECT_EQ(after.grasp[kR0].part, kBlock) << "each holder keeps its grasp";
  EXPECT_EQ(after.grasp[kR2].part, kPeg);
}

TEST(PlanState, AssembleOntoARestingBaseRests) {
  const PlanGrasp gp = Grasp(kPeg, 0, 0.02);
  const PlanState s =
      ApplyAction(Start(), Act(ActionType::kPick, {kR1}, {kPeg}, {Hold(kR1, gp)}, Keyframe{}));
  const PlanState after = ApplyAction(
      s, Act(ActionType::kAssemble, {kR1}, {kPeg, kBlock, kPegBlock}, {Hold(kR1, gp)},
             Objects({{kPeg, At(-0.1, 0.0, 0.0), false}, {kBlock, At(-0.1, 0.0, 0.0), true}})));
  EXPECT_TRUE(after.objects.at(kPegBlock).resting);
  ExpectPose(after, kPegBlock, At(-0.1, 0.0, 0.0));
  EXPECT_EQ(after.Holders(kPegBlock), (std::vector<int>{kR1}));
}

TEST(PlanState, TheGraspAnActionListsIsTheRobotsGraspAtItsKeyframe) {
  PlanGrasp g = Grasp(kPeg, 0, 0.02);
  const PlanState s =
      ApplyAction(Start(), Act(ActionType::kPick, {kR0}, {kPeg}, {Hold(kR0, g)}, Keyframe{}));
  g.width_m = 0.021;
  const PlanState at =
      StateAtKeyframe(s, Act(ActionType::kPlace, {kR0}, {kPeg}, {Hold(kR0, g)}, Keyframe{}));
  EXPECT_EQ(at.grasp[kR0].width_m, 0.021);
}

TEST(PlanState, MalformedActionsReplayWithoutACrash) {
  const PlanState start = Start();
  for (ActionType type : {ActionType::kPick, ActionType::kPlace, ActionType::kHandover,
                          ActionType::kAddGrasp, ActionType::kRelease, ActionType::kAssemble}) {
    // Nothing named.
    const PlanState s = ApplyAction(start, Act(type, {}, {}, {}, Keyframe{}));
    EXPECT_EQ(s.held, start.held);
    EXPECT_EQ(s.objects.size(), start.objects.size());
    // Robots outside the cell, no grasps, an object that does not exist.
    const PlanState t = ApplyAction(start, Act(type, {7, -1}, {kPegBlock}, {}, Keyframe{}));
    EXPECT_EQ(t.held, start.held);
  }
}

TEST(PlanState, ReplayGivesTheStateBeforeAndAfterEveryAction) {
  Plan plan;
  plan.robots = {"a", "b", "c"};
  plan.initial = Objects({{kPeg, At(0.1, 0.0, 0.0), true}, {kBlock, At(-0.1, 0.0, 0.0), true}});
  const PlanGrasp g = Grasp(kPeg, 0, 0.02);
  plan.actions.push_back(Act(ActionType::kPick, {kR0}, {kPeg}, {Hold(kR0, g)}, Keyframe{}));
  plan.actions.push_back(
      Act(ActionType::kAssemble, {kR0}, {kPeg, kBlock, kPegBlock}, {Hold(kR0, g)}, Keyframe{}));
  plan.actions.push_back(Act(ActionType::kRelease, {kR0}, {kPegBlock}, {Hold(kR0, g)}, Keyframe{}));
  const std::vector<PlanState> states = ReplayPlanStates(plan);
  ASSERT_EQ(states.size(), 4u);
  EXPECT_EQ(states[0].held, (std::vector<int>{-1, -1, -1}));
  EXPECT_EQ(states[1].held, (std::vector<int>{kPeg, -1, -1}));
  EXPECT_EQ(states[2].held, (std::vector<int>{kPegBlock, -1, -1}));
  EXPECT_EQ(states[3].held, (std::vector<int>{-1, -1, -1}));
  EXPECT_TRUE(states[3].objects.at(kPegBlock).resting);
}

}  // namespace
}  // namespace wrap
