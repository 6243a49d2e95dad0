// Joint keyframe optimisation (paper §IV-D): the example plans re-optimised keep the validator's
// approval, every TCP pose and the stage structure, never raise the objective, are deterministic;
// a stage pushed onto a worse IK branch comes back; a cancelled run leaves the plan alone.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <stop_token>
#include <string>
#include <vector>

#include "motion/keyframe_opt.h"
#include "motion_fixture.h"
#include "robot/ik.h"
#include "robot/kinematics.h"

namespace wrap {
namespace {

// A project task-planned once (seed 1), shared by the tests of this binary.
struct Planned : PreparedProject {
  Plan plan;
  void Solve(const std::string& name) {
    RunContext ctx(1);
    ctx.set_time_limit_s(120.0);
    TaskPlannerOptions options;
    options.project_file = file;
    auto planned = PlanTask(*lp.project, lp.check, *pre, options, ctx);
    if (!planned) {
      error = planned.error().message;
    } else if (!planned->stats.solved) {
      error = name + ": not solved: " + planned->stats.failure;
    } else {
      plan = std::move(*planned);
    }
  }
};

const Planned& PlanOnce(const std::string& name) { return PrepareOnce<Planned>(name); }

PlanValidation Validate(const Planned& p, const Plan& plan) {
  auto v = ValidatePlan(*p.lp.project, p.lp.check, plan, PlanValidationOptions{}, p.file);
  EXPECT_TRUE(v.has_value()) << v.error().message;
  return v ? *v : PlanValidation{};
}

// Every keyframe of a plan in order: the initial one, then per action its approach and keyframe.
std::vector<Keyframe*> Sequence(Plan& plan) {
  std::vector<Keyframe*> out = {&plan.initial};
  for (PlanAction& a : plan.actions) {
    if (a.approach) out.push_back(&*a.approach);
    out.push_back(&a.keyframe);
  }
  return out;
}

bool SameJoints(const JointVector& a, const JointVector& b, double tolerance) {
  return a.size() == b.size() && (a - b).cwiseAbs().maxCoeff() <= tolerance;
}

class KeyframeOpt : public ::testing::TestWithParam<std::string> {};

TEST_P(KeyframeOpt, KeepsThePlanValidAndTheTcpPoses) {
  const Planned& p = PlanOnce(GetParam());
  ASSERT_EQ(p.error, "");
  const TaskWorld& world = *p.world;
  const PlanValidation before = Validate(p, p.plan);
  ASSERT_TRUE(before.valid) << "the planner's plan: " << Issues(before);

  Plan plan = p.plan;
  RunContext ctx(1);
  auto report = OptimizeKeyframes(world, plan, KeyframeOptOptions{}, ctx);
  ASSERT_TRUE(report.has_value()) << report.error().message;
  std::cout << GetParam() << ": stages " << report->stages << ", candidates " << report->candidates
            << ", changed " << report->changed << ", branch changes "
            << report->branch_changes_before << " -> " << report->branch_changes_after
            << ", joint motion " << report->joint_motion_before << " -> "
            << report->joint_motion_after << " rad, min clearance "
            << report->min_clearance_before_m << " -> " << report->min_clearance_after_m
            << " m, cost " << report->cost_before << " -> " << report->cost_after << "\n";

  const PlanValidation after = Validate(p, plan);
  EXPECT_TRUE(after.valid) << Issues(after);
  EXPECT_LE(report->cost_after, report->cost_before);
  EXPECT_TRUE(report->branch_changes_after <= report->branch_changes_before ||
              report->joint_motion_after < report->joint_motion_before);
  EXPECT_GT(report->stages, 0);
  EXPECT_GE(report->candidates, report->stages);
  EXPECT_GE(report->min_clearance_after_m, 0.005 - 1e-9);

  // Same actions, objects and grasps; every TCP where it was; joint runs and homes kept.
  Plan original = p.plan;
  const std::vector<Keyframe*> a = Sequence(original);
  const std::vector<Keyframe*> b = Sequence(plan);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(original.actions.size(), plan.actions.size());
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    EXPECT_EQ(original.actions[i].type, plan.actions[i].type);
    EXPECT_EQ(original.actions[i].robots, plan.actions[i].robots);
    EXPECT_EQ(original.actions[i].objects, plan.actions[i].objects);
  }
  int changed_keyframes = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k]->objects.size(), b[k]->objects.size());
    for (size_t o = 0; o < a[k]->objects.size(); ++o) {
      EXPECT_EQ(a[k]->objects[o].node, b[k]->objects[o].node);
      EXPECT_TRUE(a[k]->objects[o].X_WA.isApprox(b[k]->objects[o].X_WA, 0.0));
    }
    for (size_t r = 0; r < world.robots.size(); ++r) {
      const TaskRobot& robot = world.robots[r];
      const Iso3 X_a = TcpPose(robot.chain, robot.X_WB, a[k]->q[r], robot.end_effector.X_FT);
      const Iso3 X_b = TcpPose(robot.chain, robot.X_WB, b[k]->q[r], robot.end_effector.X_FT);
      EXPECT_LE((X_a.translation() - X_b.translation()).norm(), 1e-4) << "keyframe " << k;
      EXPECT_LE(Eigen::AngleAxisd(X_a.linear().transpose() * X_b.linear()).angle(), 1e-3);
      if (!SameJoints(a[k]->q[r], b[k]->q[r], 0.0)) ++changed_keyframes;
      if (k == 0 || SameJoints(a[k]->q[r], robot.home, 1e-9)) {
        EXPECT_TRUE(SameJoints(a[k]->q[r], b[k]->q[r], 0.0)) << "keyframe " << k << " robot " << r;
      }
      if (k > 0 && SameJoints(a[k]->q[r], a[k - 1]->q[r], 1e-9)) {
        EXPECT_TRUE(SameJoints(b[k]->q[r], b[k - 1]->q[r], 1e-9))
            << "keyframe " << k << " robot " << r;
      }
    }
  }
  EXPECT_EQ(changed_keyframes > 0, report->changed > 0);

  // Deterministic: a second run gives the same joints.
  Plan again = p.plan;
  RunContext ctx2(1);
  auto report2 = OptimizeKeyframes(world, again, KeyframeOptOptions{}, ctx2);
  ASSERT_TRUE(report2.has_value());
  EXPECT_EQ(report2->cost_after, report->cost_after);
  const std::vector<Keyframe*> c = Sequence(again);
  for (size_t k = 0; k < b.size(); ++k) {
    for (size_t r = 0; r < world.robots.size(); ++r) {
      EXPECT_TRUE(SameJoints(b[k]->q[r], c[k]->q[r], 0.0)) << "keyframe " << k << " robot " << r;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Projects, KeyframeOpt,
                         ::testing::Values("stool", "cross", "cross_openarm"),
                         [](const auto& param_info) { return param_info.param; });

// A stage of the stool plan moved onto another IK branch that the validator accepts but that costs
// more joint motion: the optimiser takes it back to something at least as good.
TEST(KeyframeOptPerturbed, AWorseBranchIsUndone) {
  const Planned& p = PlanOnce("stool");
  ASSERT_EQ(p.error, "");
  const TaskWorld& world = *p.world;
  Plan original = p.plan;
  const std::vector<Keyframe*> seq = Sequence(original);
  auto motion = [&](Plan& plan, int r) {
    double sum = 0.0;
    const std::vector<Keyframe*> s = Sequence(plan);
    for (size_t k = 1; k < s.size(); ++k) sum += (s[k]->q[r] - s[k - 1]->q[r]).cwiseAbs().sum();
    return sum;
  };

  std::optional<Plan> perturbed;
  int tries = 0;
  for (size_t k = 1; k < seq.size() && !perturbed && tries < 30; ++k) {
    for (size_t r = 0; r < world.robots.size() && !perturbed && tries < 30; ++r) {
      const TaskRobot& robot = world.robots[r];
      const JointVector& q = seq[k]->q[r];
      if (!robot.ur || SameJoints(q, robot.home, 1e-9) || SameJoints(q, seq[k - 1]->q[r], 1e-9)) {
        continue;  // not the start of a free stage of a UR arm
      }
      size_t end = k + 1;
      while (end < seq.size() && SameJoints(seq[end]->q[r], q, 1e-9)) ++end;
      const Iso3 X_BT = robot.X_BW * TcpPose(robot.chain, robot.X_WB, q, robot.end_effector.X_FT);
      const UrIkSolutions solutions = robot.ur->SolveTcp(X_BT, robot.end_effector.X_FT);
      for (int i = 0; i < solutions.count && !perturbed && tries < 30; ++i) {
        const JointVector other = NearestEquivalent(robot.chain, solutions.q[i], q);
        if (SameJoints(other, q, 1e-6) || !WithinLimits(robot.chain, other)) continue;
        Plan candidate = p.plan;
        const std::vector<Keyframe*> s = Sequence(candidate);
        for (size_t j = k; j < end; ++j) s[j]->q[r] = other;
        if (motion(candidate, static_cast<int>(r)) <= motion(original, static_cast<int>(r))) {
          continue;
        }
        ++tries;
        if (Validate(p, candidate).valid) perturbed = std::move(candidate);
      }
    }
  }
  ASSERT_TRUE(perturbed.has_value()) << "no valid worse branch found in " << tries << " tries";

  RunContext ctx_original(1);
  Plan reference = p.plan;
  auto original_report = OptimizeKeyframes(world, reference, KeyframeOptOptions{}, ctx_original);
  ASSERT_TRUE(original_report.has_value());

  RunContext ctx(1);
  auto report = OptimizeKeyframes(world, *perturbed, KeyframeOptOptions{}, ctx);
  ASSERT_TRUE(report.has_value()) << report.error().message;
  std::cout << "perturbed stool: cost " << report->cost_before << " -> " << report->cost_after
            << " (the planner's plan: " << original_report->cost_before << " -> "
            << original_report->cost_after << "), branch changes " << report->branch_changes_before
            << " -> " << report->branch_changes_after << "\n";
  EXPECT_LT(report->cost_after, report->cost_before);
  EXPECT_LE(report->cost_after, original_report->cost_before + 1e-9);
  EXPECT_GE(report->changed, 1);
  const PlanValidation v = Validate(p, *perturbed);
  EXPECT_TRUE(v.valid) << Issues(v);
}

// A cancelled run fails with kCancelled and leaves the plan as it was.
TEST(KeyframeOptStop, CancelledLeavesThePlanAlone) {
  const Planned& p = PlanOnce("cross");
  ASSERT_EQ(p.error, "");
  Plan plan = p.plan;
  std::stop_source stop;
  stop.request_stop();
  RunContext ctx(1);
  ctx.set_stop_token(stop.get_token());
  auto report = OptimizeKeyframes(*p.world, plan, KeyframeOptOptions{}, ctx);
  ASSERT_FALSE(report.has_value());
  EXPECT_EQ(report.error().code, ErrorCode::kCancelled);
  const std::vector<Keyframe*> a = Sequence(plan);
  Plan original = p.plan;
  const std::vector<Keyframe*> b = Sequence(original);
  for (size_t k = 0; k < a.size(); ++k) {
    for (size_t r = 0; r < a[k]->q.size(); ++r) EXPECT_TRUE(SameJoints(a[k]->q[r], b[k]->q[r], 0));
  }
}

// Past the deadline before the first robot: the plan stays as it is and the report says so.
TEST(KeyframeOptStop, PastTheDeadlineKeepsThePlan) {
  const Planned& p = PlanOnce("cross");
  ASSERT_EQ(p.error, "");
  Plan plan = p.plan;
  RunContext ctx(1);
  ctx.set_deadline(RunContext::Clock::now() - std::chrono::seconds(1));
  auto report = OptimizeKeyframes(*p.world, plan, KeyframeOptOptions{}, ctx);
  ASSERT_TRUE(report.has_value()) << report.error().message;
  EXPECT_EQ(report->changed, 0);
  EXPECT_EQ(report->cost_after, report->cost_before);
  EXPECT_EQ(report->branch_changes_after, report->branch_changes_before);
  const std::vector<Keyframe*> a = Sequence(plan);
  Plan original = p.plan;
  const std::vector<Keyframe*> b = Sequence(original);
  for (size_t k = 0; k < a.size(); ++k) {
    for (size_t r = 0; r < a[k]->q.size(); ++r) EXPECT_TRUE(SameJoints(a[k]->q[r], b[k]->q[r], 0));
  }
}

// Weights out of range are refused.
TEST(KeyframeOptOptions, NegativeWeightsAreRefused) {
  const Planned& p = PlanOnce("cross");
  ASSERT_EQ(p.error, "");
  Plan plan = p.plan;
  KeyframeOptOptions options;
  options.joint_motion_weight = -1.0;
  RunContext ctx(1);
  auto report = OptimizeKeyframes(*p.world, plan, options, ctx);
  ASSERT_FALSE(report.has_value());
  EXPECT_EQ(report.error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace wrap
