#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <map>
#include <memory>
#include <string>

#include "../task/planning_fixture.h"
#include "pipeline/pipeline.h"
#include "sim/mujoco_model.h"
#include "verify/simulate.h"

namespace wrap {
namespace {

// An example project planned with motion once per test binary.
struct Planned {
  fs::path file;
  LoadedProject lp;
  std::optional<Plan> plan;
  std::string error;
};

const Planned& PlanOnce(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Planned>> cache;
  auto& slot = cache[name];
  if (slot) return *slot;
  slot = std::make_unique<Planned>();
  Planned& p = *slot;
  p.file = ProjectFile(name);
  p.lp = LoadProject(p.file);
  if (!p.lp.ok()) {
    p.error = name + ": does not load";
    return p;
  }
  auto pre = PreprocessProject(p.lp, p.file);
  if (!pre) {
    p.error = pre.error().message;
    return p;
  }
  RunContext ctx(0);
  ctx.set_time_limit_s(300.0);
  PipelineOptions options;
  options.task.project_file = p.file;
  auto plan = PlanAssembly(*p.lp.project, p.lp.check, *pre, options, ctx);
  if (!plan) {
    p.error = plan.error().message;
  } else if (!plan->stats.solved || !plan->stats.motion) {
    p.error = name + ": no plan with motion: " + plan->stats.failure;
  } else {
    p.plan = std::move(*plan);
  }
  return p;
}

Result<SimReport> Simulate(const Planned& p, const Plan& plan, const SimOptions& options = {}) {
  RunContext ctx(0);
  return SimulatePlan(*p.lp.project, p.lp.check, p.file, plan, options, ctx);
}

// The first pick of the plan, its index.
int FirstPick(const Plan& plan) {
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    if (plan.actions[i].type == ActionType::kPick) return static_cast<int>(i);
  }
  return -1;
}

TEST(Sim, FullModelPlanHolds) {
  const Planned& p = PlanOnce("half_stool");
  ASSERT_TRUE(p.error.empty()) << p.error;
  auto report = Simulate(p, *p.plan);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_TRUE(report->success) << report->failure->reason << " at action "
                               << report->failure->action << ": " << report->failure->detail;
  EXPECT_FALSE(report->failure.has_value());
  EXPECT_EQ(report->tasks_total, static_cast<int>(p.plan->actions.size()));
  EXPECT_EQ(report->tasks_completed, report->tasks_total);
  for (const SimActionStatus& a : report->actions) EXPECT_EQ(a.status, "completed");
  // Some gripper carried something, within its limits; the assembly came out in one piece.
  const SimUtilisation& u = report->peak;
  const double peak_transport = std::max(u.two_finger_transport, u.vacuum_transport);
  EXPECT_GT(peak_transport, 0.0);
  EXPECT_LE(peak_transport, 1.0);
  EXPECT_LE(std::max(u.two_finger_insertion, u.vacuum_insertion), 1.0);
  EXPECT_LT(report->final_position_error_m, SimOptions{}.misalign_tolerance_m);
  // Connections were made and held within their limits.
  EXPECT_GE(u.connection, 0.0);
  EXPECT_LE(u.connection, 1.0);
  // The report as JSON says the same.
  const std::string json = SerializeSimReport(*report);
  EXPECT_NE(json.find("\"success\": true"), std::string::npos);
  EXPECT_NE(json.find("\"failure\": null"), std::string::npos);
}

// A part released in mid-air: a release inserted just after the first pick, while the part is
// being lifted, drops it; the failure is "no support" at the inserted release.
TEST(Sim, ReleaseInMidAirFailsWithNoSupport) {
  const Planned& p = PlanOnce("half_stool");
  ASSERT_TRUE(p.error.empty()) << p.error;
  Plan broken = *p.plan;
  const int pick = FirstPick(broken);
  ASSERT_GE(pick, 0);
  // Half way through the carry that follows the picking robot's lift: the part is high up.
  const int robot = broken.actions[pick].robots[0];
  double lifted_s = -1.0;
  bool after_lift = false;
  for (const MotionSegment& s : broken.segments) {
    const bool mine = std::find(s.robots.begin(), s.robots.end(), robot) != s.robots.end();
    if (!mine || s.start_s < broken.actions[pick].end_s - 1e-9) continue;
    if (s.kind == "lift") {
      after_lift = true;
      lifted_s = s.end_s;
    } else if (after_lift) {
      if (s.kind == "free" || s.kind == "carry") lifted_s = 0.5 * (s.start_s + s.end_s);
      break;
    }
  }
  ASSERT_GT(lifted_s, 0.0) << "no lift after the first pick";
  PlanAction release = broken.actions[pick];
  release.type = ActionType::kRelease;
  release.start_s = release.end_s = lifted_s;
  broken.actions.insert(broken.actions.begin() + pick + 1, release);

  auto report = Simulate(p, broken);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_FALSE(report->success);
  ASSERT_TRUE(report->failure.has_value());
  EXPECT_EQ(report->failure->reason, "no support") << report->failure->detail;
  EXPECT_EQ(report->failure->action, pick + 1) << report->failure->detail;
  EXPECT_EQ(report->actions[pick].status, "completed");
  EXPECT_EQ(report->actions[pick + 1].status, "failed");
  EXPECT_LT(report->tasks_completed, report->tasks_total);
  EXPECT_NE(SerializeSimReport(*report).find("\"reason\": \"no support\""), std::string::npos);
}

// An insertion pressed against a vacuum gripper sideways: the cube's plan (vacuum grippers
// only) simulated with the first assembled step's insertion axis turned by 90 degrees, so the
// mating force pushes across the suction cup, which holds no lateral force while mating.
TEST(Sim, SidewaysInsertionOnVacuumFailsWithVacuumLimit) {
  const Planned& p = PlanOnce("cube");
  ASSERT_TRUE(p.error.empty()) << p.error;
  const Plan& plan = *p.plan;
  const AssemblyTree& tree = *p.lp.check.tree;
  int assemble = -1;
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    const PlanAction& a = plan.actions[i];
    if (a.type != ActionType::kAssemble) continue;
    if (assemble < 0 || a.end_s < plan.actions[assemble].end_s) assemble = static_cast<int>(i);
  }
  ASSERT_GE(assemble, 0);
  Project sideways = *p.lp.project;
  Mating& mating = sideways.steps[tree.nodes[plan.actions[assemble].objects[2]].step].mating;
  const Vec3 axis = mating.axis.normalized();
  const Vec3 other = std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  mating.axis = axis.cross(other).normalized();

  RunContext ctx(0);
  auto report = SimulatePlan(sideways, p.lp.check, p.file, plan, SimOptions{}, ctx);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_FALSE(report->success);
  ASSERT_TRUE(report->failure.has_value());
  EXPECT_EQ(report->failure->reason, "vacuum limit") << report->failure->detail;
  EXPECT_EQ(report->failure->action, assemble) << report->failure->detail;
  EXPECT_GT(report->peak.vacuum_insertion, 1.0);

  // The same plan with the project's own axis holds through that insertion.
  RunContext ctx2(0);
  auto nominal = SimulatePlan(*p.lp.project, p.lp.check, p.file, plan, SimOptions{}, ctx2);
  ASSERT_TRUE(nominal) << nominal.error().message;
  EXPECT_TRUE(nominal->success) << nominal->failure->reason << " at action "
                                << nominal->failure->action << ": " << nominal->failure->detail;
  EXPECT_LE(nominal->peak.vacuum_insertion, 1.0);
}

// A moved part that does not meet its base where the assembly has it: the project's assembled
// pose of the first assemble's moved part is shifted 2 cm across the insertion axis after
// planning, so the plan mates it off by that much.
TEST(Sim, OffsetMatingFailsWithMisalignment) {
  const Planned& p = PlanOnce("half_stool");
  ASSERT_TRUE(p.error.empty()) << p.error;
  const Plan& plan = *p.plan;
  const AssemblyTree& tree = *p.lp.check.tree;
  int assemble = -1;
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    const PlanAction& a = plan.actions[i];
    if (a.type != ActionType::kAssemble) continue;
    if (assemble < 0 || a.end_s < plan.actions[assemble].end_s) assemble = static_cast<int>(i);
  }
  ASSERT_GE(assemble, 0);
  const int moved = plan.actions[assemble].objects[0];
  ASSERT_EQ(tree.nodes[moved].parts.size(), 1u) << "expected a single part moved first";
  Project shifted = *p.lp.project;
  Part& part = shifted.parts[tree.nodes[moved].parts.front()];
  const Mating& mating = shifted.steps[tree.nodes[plan.actions[assemble].objects[2]].step].mating;
  const Vec3 axis = mating.axis.normalized();
  const Vec3 across = axis.cross(std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY());
  const Iso3 X_AP = ToIsometry(part.assembled_pose);
  part.assembled_pose.xyz += 0.02 * across.normalized();
  // The part starts where it did (the plan's initial objects are frames A, parts sit at
  // X_WA X_AP): only where the assembly wants it differs.
  Plan same_start = plan;
  for (PlanObject& o : same_start.initial.objects) {
    if (o.node == moved) o.X_WA = o.X_WA * X_AP * ToIsometry(part.assembled_pose).inverse();
  }

  RunContext ctx(0);
  auto report = SimulatePlan(shifted, p.lp.check, p.file, same_start, SimOptions{}, ctx);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_FALSE(report->success);
  ASSERT_TRUE(report->failure.has_value());
  EXPECT_EQ(report->failure->reason, "misalignment") << report->failure->detail;
  EXPECT_EQ(report->failure->action, assemble) << report->failure->detail;
}

TEST(Sim, PlanWithoutMotionIsBadInput) {
  const Planned& p = PlanOnce("half_stool");
  ASSERT_TRUE(p.error.empty()) << p.error;
  Plan task_only = *p.plan;
  task_only.trajectories.clear();
  auto report = Simulate(p, task_only);
  ASSERT_FALSE(report);
  EXPECT_EQ(report.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(report.error().message.find("trajectories"), std::string::npos);
}

// MuJoCo's errors (which exit the process by default) come back as messages.
TEST(Sim, MujocoErrorsBecomeMessages) {
  InstallMujocoHandlers();
  auto guarded = RunGuarded("a deliberate error", [] { mju_error_i("deliberate failure %d", 42); });
  ASSERT_FALSE(guarded);
  EXPECT_EQ(guarded.error().code, ErrorCode::kInternal);
  EXPECT_NE(guarded.error().message.find("deliberate failure"), std::string::npos);
  // An invalid model: the compiler's message, not an exit.
  MjcfDocument doc;
  doc.xml = "<mujoco><worldbody><body><joint type=\"hinge\"/></body></worldbody></mujoco>";
  auto model = CellModel::Compile(doc);
  EXPECT_FALSE(model);
}

}  // namespace
}  // namespace wrap
