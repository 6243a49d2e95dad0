// The task plan's makespan estimate (task/makespan_estimate.h) on hand-made action lists: actions
// of different robots on different objects overlap, a robot's or an object's actions keep their
// order, and an assembly's approach overlaps with the base's earlier work.
#include <gtest/gtest.h>

#include <vector>

#include "task/makespan_estimate.h"

namespace wrap {
namespace {

// Nodes of a three-part assembly: parts, then the steps (peg+block, then pin onto it).
constexpr int kPeg = 0, kBlock = 1, kPin = 2, kPegBlock = 3, kAll = 4;
constexpr int kNodes = 5;
constexpr int kR0 = 0, kR1 = 1, kR2 = 2;

PlanAction Act(ActionType type, std::vector<int> robots, std::vector<int> objects) {
  PlanAction a;
  a.type = type;
  a.robots = std::move(robots);
  a.objects = std::move(objects);
  return a;
}

double Pick() { return EstimatedDuration(ActionType::kPick); }
double Assemble() { return EstimatedDuration(ActionType::kAssemble); }
double Insertion() { return EstimatedInsertion(); }
double Release() { return EstimatedDuration(ActionType::kRelease); }

TEST(MakespanEstimate, TwoRobotsPickingTwoPartsOverlap) {
  const std::vector<PlanAction> actions = {Act(ActionType::kPick, {kR0}, {kPeg}),
                                           Act(ActionType::kPick, {kR1}, {kBlock})};
  const TaskClock clock = ClockAfter(actions, 2, kNodes);
  EXPECT_DOUBLE_EQ(clock.makespan_s(), Pick());
  EXPECT_DOUBLE_EQ(clock.completion_sum_s(), 2 * Pick());
}

TEST(MakespanEstimate, OneRobotDoesItsActionsInTurn) {
  const std::vector<PlanAction> actions = {Act(ActionType::kPick, {kR0}, {kPeg}),
                                           Act(ActionType::kRelease, {kR0}, {kPeg}),
                                           Act(ActionType::kPick, {kR0}, {kBlock})};
  EXPECT_DOUBLE_EQ(ClockAfter(actions, 2, kNodes).makespan_s(), 2 * Pick() + Release());
}

TEST(MakespanEstimate, AnObjectPassedOnKeepsTheOrder) {
  // r1 adds a grasp on the peg that r0 holds: it waits for r0's pick though it was free.
  const std::vector<PlanAction> actions = {Act(ActionType::kPick, {kR0}, {kPeg}),
                                           Act(ActionType::kAddGrasp, {kR1}, {kPeg})};
  const TaskClock clock = ClockAfter(actions, 2, kNodes);
  EXPECT_DOUBLE_EQ(clock.makespan_s(), Pick() + EstimatedDuration(ActionType::kAddGrasp));
  EXPECT_DOUBLE_EQ(clock.robot_free_s(kR0), Pick());
}

TEST(MakespanEstimate, TheNextPartApproachesWhileTheBaseIsBusy) {
  // r0 inserts the peg into the block that r1 holds; r2 picked the pin meanwhile and brings it
  // to its approach during that assembly, then inserts it once the first is done.
  const std::vector<PlanAction> actions = {
      Act(ActionType::kPick, {kR0}, {kPeg}), Act(ActionType::kPick, {kR1}, {kBlock}),
      Act(ActionType::kPick, {kR2}, {kPin}),
      Act(ActionType::kAssemble, {kR0, kR1}, {kPeg, kBlock, kPegBlock}),
      Act(ActionType::kAssemble, {kR2, kR0, kR1}, {kPin, kPegBlock, kAll})};
  const TaskClock clock = ClockAfter(actions, 3, kNodes);
  const double first = Pick() + Assemble();
  EXPECT_DOUBLE_EQ(clock.robot_free_s(kR2), first + Insertion());
  EXPECT_DOUBLE_EQ(clock.makespan_s(), first + Insertion());
  // One robot for both parts: its second part comes after its first assembly, whole.
  const std::vector<PlanAction> alone = {
      Act(ActionType::kPick, {kR1}, {kBlock}),
      Act(ActionType::kPick, {kR0}, {kPeg}),
      Act(ActionType::kAssemble, {kR0, kR1}, {kPeg, kBlock, kPegBlock}),
      Act(ActionType::kRelease, {kR0}, {kPegBlock}),
      Act(ActionType::kPick, {kR0}, {kPin}),
      Act(ActionType::kAssemble, {kR0, kR1}, {kPin, kPegBlock, kAll})};
  EXPECT_DOUBLE_EQ(ClockAfter(alone, 3, kNodes).makespan_s(),
                   2 * Pick() + 2 * Assemble() + Release());
}

TEST(MakespanEstimate, APlanWithoutActionsTakesNoTime) {
  Plan plan;
  plan.robots = {"a", "b"};
  plan.nodes = {"peg", "block", "pin", "peg+block", "all"};
  EXPECT_DOUBLE_EQ(EstimateMakespan(plan), 0.0);
  plan.actions = {Act(ActionType::kPick, {kR0}, {kPeg}), Act(ActionType::kPick, {kR1}, {kPin})};
  EXPECT_DOUBLE_EQ(EstimateMakespan(plan), Pick());
}

}  // namespace
}  // namespace wrap
