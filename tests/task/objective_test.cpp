// The planner's objectives (TaskPlannerOptions::objective): under `makespan` the half stool's two
// legs go to its two robots, --optimize never lengthens the makespan estimate nor adds more than
// its few actions, the same seed gives the same plan; every plan reports its estimate.
#include <gtest/gtest.h>

#include <string>

#include "planning_fixture.h"
#include "task/makespan_estimate.h"
#include "task/plan_json.h"

namespace wrap {
namespace {

// The robot that holds `node` when it is assembled: the one that last picked it or took it in
// a handover before its assembly; -1 when none.
int InserterOf(const Plan& plan, const std::string& name) {
  int node = -1;
  for (size_t i = 0; i < plan.nodes.size(); ++i) {
    if (plan.nodes[i] == name) node = static_cast<int>(i);
  }
  int holder = -1;
  for (const PlanAction& a : plan.actions) {
    if (a.type == ActionType::kAssemble && a.objects.front() == node) return holder;
    if (a.objects.front() != node) continue;
    if (a.type == ActionType::kPick) holder = a.robots.front();
    if (a.type == ActionType::kHandover) holder = a.robots.back();
  }
  return -1;
}

PlanRun PlanProject(const std::string& project, std::uint64_t seed,
                    const TaskPlannerOptions& options, double time_limit_s = kNoTimeLimit) {
  const fs::path file = ProjectFile(project);
  const LoadedProject lp = LoadProject(file);
  EXPECT_TRUE(lp.ok()) << project;
  if (!lp.ok()) return {};
  return PlanAndValidate(*lp.project, lp.check, file, seed, time_limit_s, options);
}

TaskPlannerOptions ByMakespan() {
  TaskPlannerOptions options;
  options.objective = PlanObjective::kMakespan;
  return options;
}

// Two robots, two legs that go into the seat one after the other: under the makespan objective
// each robot inserts one of them, so one brings its leg while the other inserts; the plan is
// valid and its estimate shorter than the default objective's plan (where seed 2 has one robot
// insert both).
TEST(MakespanObjective, SpreadsTheHalfStoolsLegsOverBothRobots) {
  const PlanRun spread = PlanProject("half_stool", 2, ByMakespan());
  ASSERT_TRUE(spread.plan && spread.plan->stats.solved);
  ASSERT_TRUE(spread.validation);
  EXPECT_TRUE(spread.validation->valid) << Issues(*spread.validation);
  const int leg1 = InserterOf(*spread.plan, "leg1");
  const int leg2 = InserterOf(*spread.plan, "leg2");
  ASSERT_GE(leg1, 0);
  ASSERT_GE(leg2, 0);
  EXPECT_NE(leg1, leg2);
  const PlanRun actions = PlanProject("half_stool", 2, {});
  ASSERT_TRUE(actions.plan && actions.plan->stats.solved);
  EXPECT_LT(spread.plan->stats.makespan_est_s, actions.plan->stats.makespan_est_s);
  EXPECT_EQ(spread.plan->stats.objective, "makespan");
  EXPECT_EQ(actions.plan->stats.objective, "actions");
}

// Every solved plan reports its estimate: the actions' own.
TEST(MakespanObjective, ThePlanReportsItsEstimate) {
  const PlanRun run = PlanProject("half_stool", 0, {});
  ASSERT_TRUE(run.plan && run.plan->stats.solved);
  EXPECT_GT(run.plan->stats.makespan_est_s, 0.0);
  EXPECT_DOUBLE_EQ(run.plan->stats.makespan_est_s, EstimateMakespan(*run.plan));
}

// --optimize under the makespan objective: the estimate never grows from the first plan (the
// same seed's plan without --optimize), the action count by at most a couple, and the plan is
// valid.
TEST(MakespanObjective, OptimizeNeverLengthensTheEstimate) {
  const PlanRun first = PlanProject("stool", 0, ByMakespan());
  ASSERT_TRUE(first.plan && first.plan->stats.solved);
  TaskPlannerOptions options = ByMakespan();
  options.optimize = true;
  const PlanRun better = PlanProject("stool", 0, options, 10.0);
  ASSERT_TRUE(better.plan && better.plan->stats.solved) << better.plan->stats.failure;
  const PlanStats& st = better.plan->stats;
  EXPECT_EQ(st.first_cost, first.plan->stats.cost);
  EXPECT_LE(st.makespan_est_s, first.plan->stats.makespan_est_s + 1e-6);
  EXPECT_LE(st.cost, st.first_cost + 2);
  ASSERT_TRUE(better.validation);
  EXPECT_TRUE(better.validation->valid) << Issues(*better.validation);
}

// Same project, options and seed under the makespan objective: the same plan.
TEST(MakespanObjective, SameSeedSamePlan) {
  auto strip = [](Plan plan) {
    PlanStats& s = plan.stats;
    s.t_init_s = s.t_grasp_s = s.t_bwd_s = s.t_lp_s = s.t_fwd_s = s.t_ik_s = s.t_opt_s = 0.0;
    for (auto& [t, cost] : s.cost_history) t = 0.0;
    return SerializePlan(plan);
  };
  const PlanRun a = PlanProject("stool", 4, ByMakespan());
  const PlanRun b = PlanProject("stool", 4, ByMakespan());
  ASSERT_TRUE(a.plan && b.plan && a.plan->stats.solved);
  EXPECT_EQ(strip(*a.plan), strip(*b.plan));
}

TEST(MakespanObjective, NamesRoundTrip) {
  for (PlanObjective o : {PlanObjective::kActions, PlanObjective::kMakespan}) {
    const Result<PlanObjective> parsed = ParsePlanObjective(ToString(o));
    ASSERT_TRUE(parsed.has_value());
    EXPECT_EQ(*parsed, o);
  }
  const Result<PlanObjective> bad = ParsePlanObjective("speed");
  ASSERT_FALSE(bad.has_value());
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(bad.error().message.find("actions, makespan"), std::string::npos);
}

}  // namespace
}  // namespace wrap
