// The paper's comparison rows as planner variants, and plan improvement: every variant solves the
// stool, the cross and the cube with plans the independent validator accepts, and gives the same
// plan for the same seed; Flat lazy stops at the memory limit and says so; the backward heuristic
// never overestimates a milestone's cost found by a search without heuristic; --optimize never
// returns a worse plan than its first one, and its plans pass the validator.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "planning_fixture.h"
#include "robot/cell.h"
#include "task/keyframes.h"
#include "task/plan_json.h"
#include "task/search.h"
#include "task/world.h"

namespace wrap {
namespace {

// "variant/project".
std::pair<std::string, std::string> SplitParam(const std::string& param) {
  const size_t slash = param.find('/');
  return {param.substr(0, slash), param.substr(slash + 1)};
}

std::string ParamName(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  std::replace(name.begin(), name.end(), '/', '_');
  return name;
}

// The variant named `name` (a test parameter's words).
PlannerVariant Variant(const std::string& name) {
  const Result<PlannerVariant> v = ParsePlannerVariant(name);
  EXPECT_TRUE(v.has_value()) << name;
  return v.value_or(PlannerVariant::kWrap);
}

// The plan as JSON without its times (which differ from run to run).
std::string WithoutTimes(Plan plan) {
  PlanStats& s = plan.stats;
  s.t_init_s = s.t_grasp_s = s.t_bwd_s = s.t_lp_s = s.t_fwd_s = s.t_ik_s = s.t_opt_s = 0.0;
  for (auto& [t, cost] : s.cost_history) t = 0.0;
  return SerializePlan(plan);
}

class VariantPlan : public ::testing::TestWithParam<std::string> {};

// The seed each variant/project plans with: 3, except where that seed is one of the variant's
// slow tails. The optimistic variant chooses the assembly's grasps first and searches for a way
// to them; on the cross its time varies with the seed (seeds 0-5 on dev-2c, user CPU: 1.7, 10.8,
// 13.9, 33.5, 47.9 s, and 60 s without a plan), and this test plans twice.
int SeedFor(const std::string& param) { return param == "optimistic/cross" ? 0 : 3; }

TEST_P(VariantPlan, IsSolvedValidAndDeterministic) {
  const auto [variant, project] = SplitParam(GetParam());
  const fs::path file = ProjectFile(project);
  const LoadedProject lp = LoadProject(file);
  ASSERT_TRUE(lp.ok()) << project;
  TaskPlannerOptions options;
  options.planner = Variant(variant);
  const int seed = SeedFor(GetParam());
  const PlanRun run = PlanAndValidate(*lp.project, lp.check, file, seed, kNoTimeLimit, options);
  ASSERT_TRUE(run.plan.has_value()) << run.plan.error().message;
  const PlanStats& st = run.plan->stats;
  ASSERT_TRUE(st.solved) << GetParam() << ": " << st.failure;
  EXPECT_EQ(st.planner, variant);
  EXPECT_EQ(st.cost, static_cast<int>(run.plan->actions.size()));
  EXPECT_EQ(st.first_cost, st.cost);
  ASSERT_EQ(st.cost_history.size(), 1u);
  EXPECT_EQ(st.cost_history[0].second, st.cost);
  // The backward abstraction runs for the variants that use it, and only for them.
  const bool backward = variant == "wrap" || variant == "exact" || variant == "fine";
  EXPECT_EQ(st.t_bwd_s > 0.0, backward) << st.t_bwd_s;
  ASSERT_TRUE(run.validation.has_value());
  EXPECT_TRUE(run.validation->valid) << Issues(*run.validation);
  // Milestones are in the plan even for Flat lazy (which finds them after the fact): each step
  // once, the actions' milestone indices non-decreasing and each milestone ending in its step.
  ASSERT_EQ(run.plan->milestone_steps.size(), lp.project->steps.size());
  int last = 0;
  for (const PlanAction& a : run.plan->actions) {
    EXPECT_GE(a.milestone, last);
    last = a.milestone;
    if (a.type == ActionType::kAssemble) {
      EXPECT_EQ(run.plan->milestone_steps[a.milestone], a.objects.back());
    }
  }
  // Same seed, same plan.
  const PlanRun again = PlanAndValidate(*lp.project, lp.check, file, seed, kNoTimeLimit, options);
  ASSERT_TRUE(again.plan.has_value());
  EXPECT_EQ(WithoutTimes(*run.plan), WithoutTimes(*again.plan));
}

INSTANTIATE_TEST_SUITE_P(Variants, VariantPlan,
                         ::testing::Values("wrap/stool", "wrap/cross", "wrap/cube",
                                           "optimistic/stool", "optimistic/cross",
                                           "optimistic/cube", "counting/stool", "counting/cross",
                                           "counting/cube", "exact/stool", "exact/cross",
                                           "exact/cube", "fine/stool", "fine/cross", "fine/cube",
                                           "flat/stool"),
                         ParamName);

// The backward variants on the larger projects they solve fast (the Fabrica ones when the meshes
// are beside the repository).
class WrapPlan : public ::testing::TestWithParam<std::string> {};

TEST_P(WrapPlan, IsSolvedAndValid) {
  const auto [variant, project] = SplitParam(GetParam());
  const fs::path file = ProjectFile(project);
  const LoadedProject lp = LoadProject(file);
  if (!lp.ok() && project.starts_with("fabrica")) {
    GTEST_SKIP() << "the Fabrica meshes are not beside the repository (../shared/fabrica)";
  }
  ASSERT_TRUE(lp.ok()) << project;
  TaskPlannerOptions options;
  options.planner = Variant(variant);
  const PlanRun run = PlanAndValidate(*lp.project, lp.check, file, 0, kNoTimeLimit, options);
  ASSERT_TRUE(run.plan.has_value()) << run.plan.error().message;
  ASSERT_TRUE(run.plan->stats.solved) << GetParam() << ": " << run.plan->stats.failure;
  ASSERT_TRUE(run.validation.has_value());
  EXPECT_TRUE(run.validation->valid) << Issues(*run.validation);
}

INSTANTIATE_TEST_SUITE_P(Projects, WrapPlan,
                         ::testing::Values("wrap/cube_2x2x3", "exact/chair", "fine/fabrica_beam"),
                         ParamName);

// Flat lazy searches the whole task at once; on the cross and the cube its search outgrows a
// memory limit, and the run stops saying "out of memory" (the paper's Flat lazy runs out of
// memory on every assembly but one).
TEST(FlatLazy, StopsAtTheMemoryLimitAndSaysSo) {
  for (const std::string project : {"cross", "cube"}) {
    const fs::path file = ProjectFile(project);
    const LoadedProject lp = LoadProject(file);
    ASSERT_TRUE(lp.ok());
    TaskPlannerOptions options;
    options.planner = PlannerVariant::kFlat;
    options.memory_limit_mb = 16;
    const PlanRun run = PlanAndValidate(*lp.project, lp.check, file, 0, kNoTimeLimit, options);
    ASSERT_TRUE(run.plan.has_value()) << run.plan.error().message;
    const PlanStats& st = run.plan->stats;
    EXPECT_FALSE(st.solved) << project;
    EXPECT_TRUE(st.out_of_memory) << project;
    EXPECT_NE(st.failure.find("out of memory"), std::string::npos) << st.failure;
    EXPECT_NE(st.failure.find("16 MiB"), std::string::npos) << st.failure;
  }
}

// The rig (planning_fixture.h) with one search per variant over the same tables (so that their
// states mean the same).
struct SearchRig : SolverRig {
  std::vector<TaskPlannerOptions> variant_options;
  std::optional<RunContext> ctx;
  std::vector<std::unique_ptr<TaskSearch>> searches;
  SymState s0;
  ContState c0;

  bool Build(const std::string& project, const std::vector<PlannerVariant>& variants) {
    if (!SolverRig::Build(project).empty()) return false;
    ctx.emplace(0);
    ctx->set_time_limit_s(kNoTimeLimit);
    variant_options.reserve(variants.size());  // searches keep references into it
    for (PlannerVariant v : variants) {
      variant_options.push_back(options);
      variant_options.back().planner = v;
      searches.push_back(std::make_unique<TaskSearch>(*world, tables, *solver,
                                                      variant_options.back(), *ctx, 11, true));
    }
    const int n_robots = static_cast<int>(world->robots.size());
    s0.loc.assign(world->num_nodes, kInactive);
    s0.held.assign(n_robots, -1);
    s0.grasp.assign(n_robots, -1);
    c0.X_WA.assign(world->num_nodes, Iso3::Identity());
    for (int part = 0; part < world->num_parts; ++part) {
      s0.loc[part] = static_cast<int16_t>(tables.InitialLocation(part, world->initial_X_WA[part]));
      c0.X_WA[part] = world->initial_X_WA[part];
    }
    for (const TaskRobot& r : world->robots) c0.q.push_back(r.home);
    return true;
  }
};

// Admissibility: along the cross's milestones, WRAP's backward heuristic (and the finer
// projection's) at a milestone's start is at most the cost of the cheapest plan of that
// milestone, as found by a uniform-cost lazy search (weight 0: no heuristic at all). The finer
// projection is at least as informed as the coarse one.
TEST(BackwardHeuristic, NeverOverestimatesAMilestone) {
  SearchRig rig;
  ASSERT_TRUE(rig.Build("cross",
                        {PlannerVariant::kCounting, PlannerVariant::kWrap, PlannerVariant::kFine}));
  TaskSearch& blind = *rig.searches[0];
  TaskSearch& coarse = *rig.searches[1];
  TaskSearch& fine = *rig.searches[2];
  const std::vector<int>& order = rig.world->tree->step_order;
  const int K = static_cast<int>(order.size());
  SymState s = rig.s0;
  ContState c = rig.c0;
  TaskClock t(static_cast<int>(rig.world->robots.size()), rig.world->num_nodes);
  FillLimits uniform;
  uniform.weight = 0;
  int informative = 0;
  for (int k = 0; k < K; ++k) {
    const int next = k + 1 < K ? order[k + 1] : -1;
    const MilestoneResult r = blind.Fill(k, order[k], next, s, c, t, {}, uniform);
    ASSERT_TRUE(r.ok) << "milestone " << k << ": " << r.failure;
    const int optimum = static_cast<int>(r.actions.size());
    const int h_coarse = coarse.StartHeuristic(order[k], next, s);
    const int h_fine = fine.StartHeuristic(order[k], next, s);
    EXPECT_LE(h_coarse, optimum) << "milestone " << k;
    EXPECT_LE(h_fine, optimum) << "milestone " << k;
    EXPECT_GE(h_fine, h_coarse) << "milestone " << k;
    informative += h_coarse >= 2 ? 1 : 0;
    s = r.end;
    c = r.end_c;
    t = r.end_clock;
  }
  EXPECT_GT(informative, 0);  // not the trivial heuristic
}

// --optimize: the plan is never worse than the first one, every improvement is strictly cheaper,
// and the improved plan passes the validator.
class OptimizedPlan : public ::testing::TestWithParam<std::string> {};

TEST_P(OptimizedPlan, IsNoWorseAndValid) {
  const auto [variant, project] = SplitParam(GetParam());
  const fs::path file = ProjectFile(project);
  const LoadedProject lp = LoadProject(file);
  ASSERT_TRUE(lp.ok());
  TaskPlannerOptions options;
  options.planner = Variant(variant);
  options.optimize = true;
  // Plan improvement runs until the time limit; on dev-2c the stool's and the cross's last
  // improvements come within 2 s of the start (seed 0), and 6 s leaves room on a loaded machine.
  const PlanRun run = PlanAndValidate(*lp.project, lp.check, file, 0, 6.0, options);
  ASSERT_TRUE(run.plan.has_value()) << run.plan.error().message;
  const PlanStats& st = run.plan->stats;
  ASSERT_TRUE(st.solved) << st.failure;
  ASSERT_FALSE(st.cost_history.empty());
  EXPECT_EQ(st.cost_history.front().second, st.first_cost);
  EXPECT_EQ(st.cost_history.back().second, st.cost);
  EXPECT_LE(st.cost, st.first_cost);
  for (size_t i = 1; i < st.cost_history.size(); ++i) {
    EXPECT_LT(st.cost_history[i].second, st.cost_history[i - 1].second);
    EXPECT_GE(st.cost_history[i].first, st.cost_history[i - 1].first);
  }
  EXPECT_EQ(st.cost, static_cast<int>(run.plan->actions.size()));
  ASSERT_TRUE(run.validation.has_value());
  EXPECT_TRUE(run.validation->valid) << Issues(*run.validation);
}

INSTANTIATE_TEST_SUITE_P(Variants, OptimizedPlan, ::testing::Values("wrap/stool", "counting/cross"),
                         ParamName);

}  // namespace
}  // namespace wrap
