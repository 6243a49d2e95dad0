#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <map>
#include <memory>
#include <random>
#include <string>

#include "../task/planning_fixture.h"
#include "pipeline/pipeline.h"
#include "robot/ik.h"
#include "robot/kinematics.h"
#include "sim/mujoco_model.h"
#include "sim/scene.h"
#include "task/plan_json.h"
#include "task/plan_state.h"
#include "task/plan_validator.h"
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

// The tests' common set-up: an example project's plan (planned once per binary), simulations of
// it or of a changed copy, and the actions they look for.
class Sim : public ::testing::Test {
 protected:
  // Plans `name` (once) and keeps it as the test's project; false (with a failure) when it has
  // no plan with motion.
  bool Use(const std::string& name) {
    p_ = &PlanOnce(name);
    EXPECT_TRUE(p_->error.empty()) << p_->error;
    return p_->error.empty();
  }
  const Plan& plan() const { return *p_->plan; }
  const Project& project() const { return *p_->lp.project; }
  const AssemblyTree& tree() const { return *p_->lp.check.tree; }

  // Simulates `plan` of the project (or of `changed`, the project edited after planning).
  Result<SimReport> Simulate(const Plan& plan, const SimOptions& options = {},
                             const Project* changed = nullptr) const {
    RunContext ctx(0);
    return SimulatePlan(changed ? *changed : project(), p_->lp.check, p_->file, plan, options, ctx);
  }

  // The first action of `type` in plan order, or -1.
  static int First(const Plan& plan, ActionType type) {
    for (size_t i = 0; i < plan.actions.size(); ++i) {
      if (plan.actions[i].type == type) return static_cast<int>(i);
    }
    return -1;
  }

  // The assemble that happens first in time, or -1.
  static int FirstAssembleInTime(const Plan& plan) {
    int assemble = -1;
    for (size_t i = 0; i < plan.actions.size(); ++i) {
      const PlanAction& a = plan.actions[i];
      if (a.type != ActionType::kAssemble) continue;
      if (assemble < 0 || a.end_s < plan.actions[assemble].end_s) assemble = static_cast<int>(i);
    }
    return assemble;
  }

  // "reason at action i: detail" of a report that failed, "holds" otherwise.
  static std::string Verdict(const SimReport& r) {
    if (!r.failure) return "holds";
    return r.failure->reason + " at action " + std::to_string(r.failure->action) + ": " +
           r.failure->detail;
  }

  const Planned* p_ = nullptr;
};

TEST_F(Sim, FullModelPlanHolds) {
  if (!Use("half_stool")) return;
  auto report = Simulate(plan());
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_TRUE(report->success) << Verdict(*report);
  EXPECT_FALSE(report->failure.has_value());
  EXPECT_EQ(report->tasks_total, static_cast<int>(plan().actions.size()));
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
  // Collisions were looked for along the whole run, and none was found.
  EXPECT_EQ(report->motion, "trajectories");
  EXPECT_TRUE(report->collisions_judged);
  EXPECT_GT(report->collision_checks, 100);
  // The report as JSON says the same.
  const std::string json = SerializeSimReport(*report);
  EXPECT_NE(json.find("\"success\": true"), std::string::npos);
  EXPECT_NE(json.find("\"failure\": null"), std::string::npos);
  EXPECT_NE(json.find("\"motion\": \"trajectories\""), std::string::npos);
}

// A part released in mid-air: a release inserted just after the first pick, while the part is
// being lifted, drops it; the failure is "no support" at the inserted release.
TEST_F(Sim, ReleaseInMidAirFailsWithNoSupport) {
  if (!Use("half_stool")) return;
  Plan broken = plan();
  const int pick = First(broken, ActionType::kPick);
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

  auto report = Simulate(broken);
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
TEST_F(Sim, SidewaysInsertionOnVacuumFailsWithVacuumLimit) {
  if (!Use("cube")) return;
  const int assemble = FirstAssembleInTime(plan());
  ASSERT_GE(assemble, 0);
  Project sideways = project();
  Mating& mating = sideways.steps[tree().nodes[plan().actions[assemble].objects[2]].step].mating;
  const Vec3 axis = mating.axis.normalized();
  const Vec3 other = std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  mating.axis = axis.cross(other).normalized();

  auto report = Simulate(plan(), {}, &sideways);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_FALSE(report->success);
  ASSERT_TRUE(report->failure.has_value());
  EXPECT_EQ(report->failure->reason, "vacuum limit") << report->failure->detail;
  EXPECT_EQ(report->failure->action, assemble) << report->failure->detail;
  EXPECT_GT(report->peak.vacuum_insertion, 1.0);

  // The same plan with the project's own axis holds through that insertion.
  auto nominal = Simulate(plan());
  ASSERT_TRUE(nominal) << nominal.error().message;
  EXPECT_TRUE(nominal->success) << Verdict(*nominal);
  EXPECT_LE(nominal->peak.vacuum_insertion, 1.0);
}

// A moved part that does not meet its base where the assembly has it: the project's assembled
// pose of the first assemble's moved part is shifted 2 cm across the insertion axis after
// planning, so the plan mates it off by that much.
TEST_F(Sim, OffsetMatingFailsWithMisalignment) {
  if (!Use("half_stool")) return;
  const int assemble = FirstAssembleInTime(plan());
  ASSERT_GE(assemble, 0);
  const int moved = plan().actions[assemble].objects[0];
  ASSERT_EQ(tree().nodes[moved].parts.size(), 1u) << "expected a single part moved first";
  Project shifted = project();
  Part& part = shifted.parts[tree().nodes[moved].parts.front()];
  const Mating& mating =
      shifted.steps[tree().nodes[plan().actions[assemble].objects[2]].step].mating;
  const Vec3 axis = mating.axis.normalized();
  const Vec3 across = axis.cross(std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY());
  const Iso3 X_AP = ToIsometry(part.assembled_pose);
  part.assembled_pose.xyz += 0.02 * across.normalized();
  // The part starts where it did (the plan's initial objects are frames A, parts sit at
  // X_WA X_AP): only where the assembly wants it differs.
  Plan same_start = plan();
  for (PlanObject& o : same_start.initial.objects) {
    if (o.node == moved) o.X_WA = o.X_WA * X_AP * ToIsometry(part.assembled_pose).inverse();
  }

  auto report = Simulate(same_start, {}, &shifted);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_FALSE(report->success);
  ASSERT_TRUE(report->failure.has_value());
  EXPECT_EQ(report->failure->reason, "misalignment") << report->failure->detail;
  EXPECT_EQ(report->failure->action, assemble) << report->failure->detail;
}

// A robot moved through the cell: while a pick's robot approaches its part, another robot, idle
// then, is put (by IK) where that gripper is. The run fails with "collision" then, naming a body
// of the moved robot (it meets the other robot, a part or the table on its way); the same run
// with collisions not judged holds.
TEST_F(Sim, RobotMovedThroughTheCellFailsWithCollision) {
  if (!Use("stool")) return;
  Plan broken = plan();
  // The first moment of an approach to a pick from which another robot, holding nothing, stays
  // idle for 0.3 s (robots move at the same time: not at every moment).
  auto idle_from = [&](int r, double t0) {
    PlanState state = InitialPlanState(broken.initial, static_cast<int>(broken.robots.size()));
    for (const PlanAction& a : broken.actions) {
      if (a.end_s <= t0) state = ApplyAction(state, a);  // (in plan order: one robot's are)
    }
    if (state.held[r] >= 0) return false;
    for (const MotionSegment& s : broken.segments) {
      if (std::find(s.robots.begin(), s.robots.end(), r) != s.robots.end() &&
          s.start_s < t0 + 0.3 && s.end_s > t0) {
        return false;  // (a grip keeps it still, but it is at work)
      }
    }
    const RobotTrajectory& tr = broken.trajectories[r];
    for (int k = 1; k <= 6; ++k) {
      if ((SampleTrajectory(tr, t0 + 0.05 * k) - SampleTrajectory(tr, t0)).cwiseAbs().maxCoeff() >
          1e-9) {
        return false;
      }
    }
    return true;
  };
  int pick = -1, picker = -1, other = -1;
  double t = -1.0;
  for (const MotionSegment& s : broken.segments) {
    if (s.kind != "approach" || s.action < 0 || t >= 0.0 ||
        broken.actions[s.action].type != ActionType::kPick) {
      continue;
    }
    for (int r = 0; r < static_cast<int>(broken.robots.size()) && t < 0.0; ++r) {
      if (r == s.robots[0]) continue;
      for (double t0 = s.start_s + 0.05; t0 < s.end_s - 0.05 && t < 0.0; t0 += 0.05) {
        if (idle_from(r, t0)) {
          t = t0;
          pick = s.action;
          picker = s.robots[0];
          other = r;
        }
      }
    }
  }
  ASSERT_GT(t, 0.0) << "no moment of an approach to a pick with the other robot idle";
  RobotTrajectory& tr = broken.trajectories[other];
  auto scene = BuildCellScene(project(), p_->lp.check, p_->file);
  ASSERT_TRUE(scene) << scene.error().message;
  const SceneRobot& a = scene->robots[picker];
  const SceneRobot& b = scene->robots[other];
  const JointVector idle = SampleTrajectory(tr, t);
  // The other robot's TCP onto the picker's, turned half way round (facing it).
  const Iso3 X_WT = TcpPose(a.chain, a.X_WB, SampleTrajectory(broken.trajectories[picker], t),
                            a.end_effector.X_FT);
  NumericIkRequest request;
  request.X_BT = b.X_WB.inverse() * X_WT * Eigen::AngleAxisd(M_PI, Vec3::UnitX());
  request.X_FT = b.end_effector.X_FT;
  request.seeds = {idle};
  std::mt19937_64 rng(1);
  NumericIkOptions ik_options;
  ik_options.restarts = 200;
  ik_options.position_tolerance_m = 1e-3;
  ik_options.rotation_tolerance_rad = 0.5;
  auto ik = SolveNumericIk(b.chain, request, rng, ik_options);
  ASSERT_TRUE(ik) << ik.error().message;
  // Knots (constant acceleration between them, here none): there from t to t + 0.3 s.
  std::vector<TrajectoryKnot> knots;
  for (const TrajectoryKnot& k : tr.knots) {
    if (k.t < t) knots.push_back(k);
  }
  const JointVector zero = JointVector::Zero(idle.size());
  knots.push_back({t, ik->q, zero, -1.0});
  knots.push_back({t + 0.3, idle, zero, -1.0});
  for (const TrajectoryKnot& k : tr.knots) {
    if (k.t > t + 0.3) knots.push_back(k);
  }
  tr.knots = knots;

  auto report = Simulate(broken);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_FALSE(report->success);
  ASSERT_TRUE(report->failure.has_value());
  EXPECT_EQ(report->failure->reason, "collision") << report->failure->detail;
  // Blamed on an action under way then (robots work at the same time: the pick, or another
  // robot's when the moved one meets nothing but the table).
  ASSERT_GE(report->failure->action, 0);
  const PlanAction& blamed = broken.actions[report->failure->action];
  EXPECT_TRUE(report->failure->action == pick ||
              (blamed.start_s <= report->failure->t_s && report->failure->t_s <= blamed.end_s))
      << report->failure->detail;
  EXPECT_GE(report->failure->t_s, t);
  EXPECT_LE(report->failure->t_s, t + 0.3);
  EXPECT_NE(report->failure->detail.find("'" + b.name + "/"), std::string::npos)
      << report->failure->detail;

  SimOptions blind;
  blind.check_collisions = false;
  auto unchecked = Simulate(broken, blind);
  ASSERT_TRUE(unchecked) << unchecked.error().message;
  EXPECT_TRUE(unchecked->success) << Verdict(*unchecked);
  EXPECT_FALSE(unchecked->collisions_judged);
}

// A part moved into a gripper's way: the part the first pick's robot does not grasp is put, on
// the table, where the grasped one stands, so the gripper meets it on its way in.
TEST_F(Sim, PartInTheGrippersWayFailsWithCollision) {
  if (!Use("half_stool")) return;
  Plan broken = plan();
  const int pick = First(broken, ActionType::kPick);
  ASSERT_GE(pick, 0);
  const int picked = broken.actions[pick].objects[0];
  // Another single part of the same shape that rests untouched until later (the other leg).
  int moved = -1;
  for (const PlanObject& o : broken.initial.objects) {
    if (o.node != picked && tree().nodes[o.node].parts.size() == 1 &&
        project().parts[tree().nodes[o.node].parts[0]].mesh ==
            project().parts[tree().nodes[picked].parts[0]].mesh) {
      moved = o.node;
    }
  }
  ASSERT_GE(moved, 0) << "no part like the first picked one";
  Iso3 X_W_picked = Iso3::Identity(), X_W_moved = Iso3::Identity();
  for (const PlanObject& o : broken.initial.objects) {
    if (o.node == picked) X_W_picked = o.X_WA * ToIsometry(project().parts[picked].assembled_pose);
    if (o.node == moved) X_W_moved = o.X_WA * ToIsometry(project().parts[moved].assembled_pose);
  }
  // Same height and orientation on the table, shifted sideways onto the picked part.
  Vec3 shift = X_W_picked.translation() - X_W_moved.translation();
  shift.z() = 0.0;
  for (PlanObject& o : broken.initial.objects) {
    if (o.node == moved) o.X_WA.translation() += shift;
  }

  auto report = Simulate(broken);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_FALSE(report->success);
  ASSERT_TRUE(report->failure.has_value());
  EXPECT_EQ(report->failure->reason, "collision") << report->failure->detail;
  // Blamed on an action under way then (robots work at the same time: the pick, or another
  // robot's when the moved one meets nothing but the table).
  ASSERT_GE(report->failure->action, 0);
  const PlanAction& blamed = broken.actions[report->failure->action];
  EXPECT_TRUE(report->failure->action == pick ||
              (blamed.start_s <= report->failure->t_s && report->failure->t_s <= blamed.end_s))
      << report->failure->detail;
  EXPECT_NE(report->failure->detail.find("'" + project().parts[moved].name + "'"),
            std::string::npos)
      << report->failure->detail;
}

// A plan without motion is replayed from its keyframes: it holds (the full wrench model), says
// so, and judges no collisions.
TEST_F(Sim, PlanWithoutMotionReplaysItsKeyframes) {
  if (!Use("half_stool")) return;
  Plan task_only = plan();
  task_only.trajectories.clear();
  task_only.segments.clear();
  for (PlanAction& a : task_only.actions) a.start_s = a.end_s = -1.0;
  auto report = Simulate(task_only);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->motion, "keyframes");
  EXPECT_FALSE(report->collisions_judged);
  EXPECT_TRUE(report->success) << Verdict(*report);
  EXPECT_EQ(report->tasks_completed, report->tasks_total);
  EXPECT_GT(report->peak.two_finger_transport, 0.0);
  EXPECT_GT(report->peak.two_finger_insertion, 0.0);
  ASSERT_FALSE(report->notes.empty());
  EXPECT_NE(report->notes.front().find("keyframes"), std::string::npos);
  EXPECT_NE(SerializeSimReport(*report).find("\"motion\": \"keyframes\""), std::string::npos);

  // Trajectories that do not fit the cell are still bad input.
  Plan wrong = plan();
  wrong.trajectories.pop_back();
  auto bad = Simulate(wrong);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(bad.error().message.find("trajectories"), std::string::npos);
}

// The half stool's seat with a plug in the hole of the first leg it takes: the plan (made for the
// open hole) now pushes that leg through the plug. The independent plan validator refuses the
// insertion at its assemble action, and the simulation fails with a collision naming both parts.
TEST_F(Sim, InsertionThroughThePluggedHoleIsRefusedAndCollides) {
  if (!Use("half_stool")) return;
  const int assemble = FirstAssembleInTime(plan());
  ASSERT_GE(assemble, 0);
  const PlanAction& a = plan().actions[assemble];
  const AssemblyNode& moved = tree().nodes[a.objects[0]];
  const AssemblyNode& base = tree().nodes[a.objects[1]];
  ASSERT_EQ(moved.parts.size(), 1u);
  const int leg = moved.parts[0];
  const int seat = base.parts[0];
  ProjectCheck plugged = p_->lp.check;
  // The plug: the leg's box (assembled) within the seat's box, in the seat's frame.
  const Iso3 X_seat = ToIsometry(project().parts[seat].assembled_pose);
  const Iso3 X_leg = ToIsometry(project().parts[leg].assembled_pose);
  ASSERT_TRUE(X_seat.linear().isIdentity(1e-12)) << "the seat is modelled in place";
  const Aabb leg_box = ComputeAabb(Transformed(plugged.parts[leg].mesh, X_seat.inverse() * X_leg));
  const Aabb seat_box = ComputeAabb(plugged.parts[seat].mesh);
  const Vec3 lo = leg_box.min.cwiseMax(seat_box.min), hi = leg_box.max.cwiseMin(seat_box.max);
  ASSERT_TRUE((lo.array() < hi.array()).all()) << "the leg does not reach into the seat";
  TriangleMesh& mesh = plugged.parts[seat].mesh;
  const TriangleMesh plug = BoxMesh(lo, hi);
  const int offset = static_cast<int>(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), plug.vertices.begin(), plug.vertices.end());
  for (const Eigen::Vector3i& t : plug.triangles) {
    mesh.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
  }
  const std::string leg_name = project().parts[leg].name;
  const std::string seat_name = project().parts[seat].name;

  PlanValidationOptions vo;
  vo.check_wrench = false;
  auto validation = ValidatePlan(project(), plugged, plan(), vo, p_->file);
  ASSERT_TRUE(validation) << validation.error().message;
  bool refused = false;
  for (const PlanIssue& i : validation->issues) {
    if (i.gate == "insertion" && i.action == assemble) {
      refused = true;
      EXPECT_NE(i.message.find("(part '" + leg_name + "') cuts"), std::string::npos) << i.message;
      EXPECT_NE(i.message.find("(part '" + seat_name + "')"), std::string::npos) << i.message;
    }
  }
  EXPECT_TRUE(refused) << "no insertion issue at action " << assemble;

  RunContext ctx(0);
  auto report = SimulatePlan(project(), plugged, p_->file, plan(), SimOptions{}, ctx);
  ASSERT_TRUE(report) << report.error().message;
  ASSERT_TRUE(report->failure.has_value()) << "holds";
  EXPECT_EQ(report->failure->reason, "collision") << Verdict(*report);
  EXPECT_EQ(report->failure->action, assemble) << Verdict(*report);
  EXPECT_NE(report->failure->detail.find("'" + leg_name + "' cuts into '" + seat_name + "'"),
            std::string::npos)
      << Verdict(*report);
}

// A recorded plan of the paper's cube (tests/sim/data/cube_seed10.plan.json: `wrap plan
// projects/cube.json --seed 10 --wrench full --time-limit 60`, 2026-12-02). Its action 14 slides
// cube2 along the table into cube1 with a cup on cube2's side: at the insertion's onset the rigid
// weld took the 10 N mating force sideways (985% of the cup's assembly box, whose lateral bound
// is 0), where the plan's LP has the cup press the cube onto the table so that friction takes it.
// Judged by the best split among the cube's supports, the plan holds, as every full-model plan of
// the ablation in BENCHMARKS.md does; some measurements went through that split.
TEST(SimRecorded, CubePlanWhoseCupSlidesACubeAlongTheTableHolds) {
  const fs::path file = ProjectFile("cube");
  const LoadedProject lp = LoadProject(file);
  ASSERT_TRUE(lp.ok());
  auto plan = ReadPlanFile(fs::path(WRAP_SOURCE_DIR) / "tests/sim/data/cube_seed10.plan.json");
  ASSERT_TRUE(plan) << plan.error().message;
  RunContext ctx(0);
  auto report = SimulatePlan(*lp.project, lp.check, file, *plan, SimOptions{}, ctx);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_TRUE(report->success) << (report->failure
                                       ? report->failure->reason + ": " + report->failure->detail
                                       : std::string());
  EXPECT_EQ(report->tasks_completed, report->tasks_total);
  EXPECT_GT(report->split_measurements, 0);
  EXPECT_GT(report->peak.vacuum_insertion, 0.0);
  EXPECT_LE(report->peak.vacuum_insertion, 1.0);
  EXPECT_LE(report->peak.vacuum_transport, 1.0);
}

// MuJoCo's errors (which exit the process by default) come back as messages.
TEST(SimMujoco, MujocoErrorsBecomeMessages) {
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
