// The independent plan validator on hand-made plans for the stool project: a two-finger UR5e picks
// 'leg1' with a side grasp (real UR closed-form IK) and sets it down elsewhere; then the same plan
// corrupted one way at a time must give the matching issue at the matching action.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "model/validate.h"
#include "robot/catalog.h"
#include "robot/home.h"
#include "robot/ik.h"
#include "robot/kinematics.h"
#include "task/plan_validator.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

const fs::path kStool = fs::path(WRAP_SOURCE_DIR) / "projects/stool.json";
constexpr int kRobotA = 0;  // ur5e_a: two-finger gripper
constexpr int kRobotC = 2;  // ur5e_c
constexpr int kLeg1 = 1;    // node id = part index of 'leg1'
constexpr int kLeg2 = 2;
constexpr double kLegWidth = 0.025;

Iso3 Translation(double x, double y, double z) {
  Iso3 X = Iso3::Identity();
  X.translation() = Vec3(x, y, z);
  return X;
}

std::string Issues(const PlanValidation& v) {
  std::string s;
  for (const PlanIssue& i : v.issues) s += FormatIssue(i) + "\n";
  return s;
}

class PlanValidatorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    loaded_ = new LoadedProject(LoadProject(kStool));
    ASSERT_TRUE(loaded_->ok());
  }
  static void TearDownTestSuite() {
    delete loaded_;
    loaded_ = nullptr;
  }

  void SetUp() override {
    ASSERT_TRUE(loaded_ && loaded_->ok());
    project_ = *loaded_->project;
    const AssemblyTree& tree = *loaded_->check.tree;
    auto chain = LoadRobotModel("ur5e");
    ASSERT_TRUE(chain) << chain.error().message;
    chain_ = *chain;
    auto ee = LoadEndEffector("robotiq_2f85");
    ASSERT_TRUE(ee) << ee.error().message;
    X_FT_ = ee->X_FT;
    const Vec3 table_center(project_.table.center_xy.x(), project_.table.center_xy.y(),
                            project_.table.height);
    for (const Robot& r : project_.robots) {
      plan_.robots.push_back(r.name);
      home_.push_back(FacingHomeConfiguration(chain_, RobotBaseInWorld(project_, r), table_center));
    }
    for (const Part& p : project_.parts) plan_.parts.push_back(p.name);
    for (const AssemblyNode& n : tree.nodes) plan_.nodes.push_back(n.name);
    plan_.project = project_.name;
    plan_.initial.q = home_;
    for (size_t p = 0; p < project_.parts.size(); ++p) {
      plan_.initial.objects.push_back(
          {static_cast<int>(p), InitialX_WA(static_cast<int>(p)), true});
    }

    place_X_WA_ = Translation(-0.14, 0.14, 0.0) * InitialX_WA(kLeg1);
    ASSERT_TRUE(ChooseGrasp({InitialX_WA(kLeg1), place_X_WA_}));
  }

  // A side grasp of leg1, 10 cm up its axis, approaching horizontally at its initial pose.
  // Straight from robot A the wrist would come too near its base (UR shoulder offset): approach
  // from the side, the first direction (turned from the radial one) that the arm reaches with
  // leg1 at every pose of `X_WA`.
  bool ChooseGrasp(const std::vector<Iso3>& X_WA) {
    const Iso3 X_WB = RobotBaseInWorld(project_, project_.robots[kRobotA]);
    const Vec3 leg = ToIsometry(project_.parts[kLeg1].initial_pose).translation();
    Vec3 radial = leg - X_WB.translation();
    radial.z() = 0.0;
    radial.normalize();
    grasp_.subassembly = kLeg1;
    grasp_.index = 0;
    grasp_.part = kLeg1;
    grasp_.width_m = kLegWidth;
    for (double turn_deg : {90.0, 60.0, 120.0, -90.0, -60.0, -120.0}) {
      const Vec3 d = Eigen::AngleAxisd(turn_deg * std::acos(-1.0) / 180.0, Vec3::UnitZ()) * radial;
      grasp_.X_PG.linear().col(0) = Vec3(-d.y(), d.x(), 0.0);  // closing axis, horizontal
      grasp_.X_PG.linear().col(1) = Vec3::UnitZ();
      grasp_.X_PG.linear().col(2) = d;  // approach, towards the leg's axis
      grasp_.X_PG.translation() = Vec3(0, 0, 0.10);
      bool all = true;
      for (const Iso3& X : X_WA) all = all && Ik(kRobotA, kLeg1, X, grasp_).has_value();
      if (all) return true;
    }
    return false;
  }

  Iso3 X_AP(int part) const { return ToIsometry(project_.parts[part].assembled_pose); }
  Iso3 InitialX_WA(int part) const {
    return ToIsometry(project_.parts[part].initial_pose) * X_AP(part).inverse();
  }

  // The UR closed-form solution nearest home that puts robot r's TCP on the grasp of `part`
  // whose assembly frame is at X_WA.
  std::optional<JointVector> Ik(int r, int part, const Iso3& X_WA, const PlanGrasp& g) const {
    auto ik = UrAnalyticIk::FromChain(chain_);
    EXPECT_TRUE(ik) << ik.error().message;
    if (!ik) return std::nullopt;
    const Iso3 X_WB = RobotBaseInWorld(project_, project_.robots[r]);
    const Iso3 X_WG = X_WA * X_AP(part) * g.X_PG;
    const UrIkSolutions sols = ik->SolveTcp(X_WB.inverse() * X_WG, X_FT_);
    std::optional<JointVector> best;
    double best_d = 1e9;
    for (int k = 0; k < sols.count; ++k) {
      const JointVector q = NearestEquivalent(chain_, sols.q[k], home_[r]);
      const double dist = (q - home_[r]).norm();
      if (dist < best_d) {
        best_d = dist;
        best = q;
      }
    }
    return best;
  }

  PlanAction Action(ActionType type, int robot, int object, const Keyframe& kf) const {
    PlanAction a;
    a.type = type;
    a.robots = {robot};
    a.objects = {object};
    a.grasps = {PlanHold{robot, grasp_}};
    a.keyframe = kf;
    return a;
  }

  // Robot A picks leg1 where it stands and sets it down 14 cm further along -x, +y.
  void BuildPickPlace() {
    auto q_pick = Ik(kRobotA, kLeg1, InitialX_WA(kLeg1), grasp_);
    ASSERT_TRUE(q_pick.has_value());
    Keyframe pick = plan_.initial;
    pick.q[kRobotA] = *q_pick;
    plan_.actions.push_back(Action(ActionType::kPick, kRobotA, kLeg1, pick));

    auto q_place = Ik(kRobotA, kLeg1, place_X_WA_, grasp_);
    ASSERT_TRUE(q_place.has_value());
    Keyframe place = pick;
    place.q[kRobotA] = *q_place;
    place.objects[kLeg1].X_WA = place_X_WA_;
    plan_.actions.push_back(Action(ActionType::kPlace, kRobotA, kLeg1, place));
  }

  PlanValidation Validate(const PlanValidationOptions& options = Partial()) const {
    auto v = ValidatePlan(project_, loaded_->check, plan_, options, kStool);
    EXPECT_TRUE(v) << v.error().message;
    return v ? *v : PlanValidation{};
  }
  static PlanValidationOptions Partial() {
    PlanValidationOptions o;
    o.require_complete = false;
    return o;
  }

  static LoadedProject* loaded_;
  Project project_;
  Chain chain_;
  Iso3 X_FT_ = Iso3::Identity();
  std::vector<JointVector> home_;
  PlanGrasp grasp_;
  Iso3 place_X_WA_ = Iso3::Identity();
  Plan plan_;
};

LoadedProject* PlanValidatorTest::loaded_ = nullptr;

TEST_F(PlanValidatorTest, InitialStateAloneIsValidButIncomplete) {
  const PlanValidation partial = Validate();
  EXPECT_TRUE(partial.valid) << Issues(partial);
  EXPECT_EQ(partial.keyframes, 1);
  const PlanValidation full = Validate(PlanValidationOptions{});
  EXPECT_FALSE(full.valid);
  EXPECT_TRUE(full.HasIssue("incomplete")) << Issues(full);
}

TEST_F(PlanValidatorTest, PickAndPlaceValidates) {
  BuildPickPlace();
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.valid) << Issues(v);
  EXPECT_EQ(v.actions, 2);
  EXPECT_EQ(v.keyframes, 3);
  // Transport after the pick; at the place, rest and the leg carried down to it alone.
  EXPECT_EQ(v.wrench_checks, 3);
  EXPECT_GE(v.collision_checks, 3);
  // The whole stool is not built: incomplete when the plan must be complete.
  const PlanValidation full = Validate(PlanValidationOptions{});
  EXPECT_TRUE(full.HasIssue("incomplete", 1)) << Issues(full);
}

// The gripper utilisation the validator reports: only the robot that holds the leg carries a load
// after the pick; alone in the air the leg's wrench on the gripper is fixed by equilibrium, so
// doubling every limit of the gripper halves its utilisation exactly.
TEST_F(PlanValidatorTest, UtilisationOfTheHoldingGripperScalesWithItsLimits) {
  BuildPickPlace();
  WrenchLimits limits;
  limits.two_finger = WrenchBox{Vec3::Constant(40.0), Vec3::Constant(4.0)};
  project_.robots[kRobotA].wrench_limits = limits;
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.valid) << Issues(v);
  ASSERT_GE(v.utilisation.size(), 1u);
  ASSERT_EQ(v.utilisation[0].size(), 1u);
  ASSERT_TRUE(v.utilisation[0].count(kRobotA));
  const double u = v.utilisation[0].at(kRobotA);
  EXPECT_GT(u, 0.0);
  EXPECT_LT(u, 1.0);
  limits.two_finger = WrenchBox{Vec3::Constant(80.0), Vec3::Constant(8.0)};
  project_.robots[kRobotA].wrench_limits = limits;
  const PlanValidation doubled = Validate();
  ASSERT_TRUE(doubled.utilisation.size() >= 1u && doubled.utilisation[0].count(kRobotA));
  EXPECT_NEAR(doubled.utilisation[0].at(kRobotA), u / 2, 1e-9 * u);
}

TEST_F(PlanValidatorTest, CorruptedJointsGiveFk) {
  BuildPickPlace();
  plan_.actions[1].keyframe.q[kRobotA][0] += 0.2;
  const PlanValidation v = Validate();
  EXPECT_FALSE(v.valid);
  EXPECT_TRUE(v.HasIssue("fk", 1)) << Issues(v);
  EXPECT_FALSE(v.HasIssue("fk", 0)) << Issues(v);
}

TEST_F(PlanValidatorTest, ReleaseInTheAirGivesPrecondition) {
  BuildPickPlace();
  plan_.actions[1] = Action(ActionType::kRelease, kRobotA, kLeg1, plan_.actions[0].keyframe);
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.HasIssue("precondition", 1)) << Issues(v);
  EXPECT_FALSE(v.HasIssue("precondition", 0)) << Issues(v);
}

TEST_F(PlanValidatorTest, RobotThroughTheTableGivesCollision) {
  BuildPickPlace();
  // ur5e_c, idle, points its straight arm 34 degrees below the horizontal: into the table top.
  JointVector q = home_[kRobotC];
  q[1] = 0.6;
  q[2] = 0.0;
  plan_.actions[0].keyframe.q[kRobotC] = q;
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.HasIssue("collision", 0)) << Issues(v);
  EXPECT_TRUE(v.HasIssue("joints", 0)) << Issues(v);  // an idle robot may not move either
}

TEST_F(PlanValidatorTest, TinyGripperLimitsGiveWrenchIssue) {
  BuildPickPlace();
  WrenchLimits tiny;
  tiny.two_finger = WrenchBox{Vec3::Constant(0.01), Vec3::Constant(0.001)};
  project_.robots[kRobotA].wrench_limits = tiny;
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.HasIssue("wrench_transport", 0)) << Issues(v);
  // Carried down to the table by the same gripper, then the table alone holds it.
  EXPECT_TRUE(v.HasIssue("wrench_transport", 1)) << Issues(v);
  EXPECT_FALSE(v.HasIssue("wrench_rest")) << Issues(v);
  // Without wrench checks the same plan passes.
  PlanValidationOptions no_wrench = Partial();
  no_wrench.wrench_mode = MatingWrenchMode::kNone;
  const PlanValidation w = Validate(no_wrench);
  EXPECT_TRUE(w.valid) << Issues(w);
  EXPECT_EQ(w.wrench_checks, 0);
}

TEST_F(PlanValidatorTest, AssembleOfNonStepInputsGivesPrecondition) {
  BuildPickPlace();
  PlanAction assemble = Action(ActionType::kAssemble, kRobotA, kLeg1, plan_.actions[0].keyframe);
  const int seat_leg1 = loaded_->check.tree->Find("seat+leg1");
  assemble.objects = {kLeg1, kLeg2, seat_leg1};
  plan_.actions[1] = assemble;
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.HasIssue("precondition", 1)) << Issues(v);
  EXPECT_EQ(v.actions, 1);  // the replay stops at an assemble it cannot interpret
}

TEST_F(PlanValidatorTest, MovingAnUninvolvedObjectGivesPose) {
  BuildPickPlace();
  plan_.actions[1].keyframe.objects[kLeg2].X_WA =
      Translation(0.0, 0.0, 0.01) * plan_.actions[1].keyframe.objects[kLeg2].X_WA;
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.HasIssue("pose", 1)) << Issues(v);
}

TEST_F(PlanValidatorTest, PlaceInTheAirGivesPose) {
  BuildPickPlace();
  // Set leg1 down 2 cm above the table top, with the arm following it.
  const Iso3 X_WA = Translation(0, 0, 0.02) * place_X_WA_;
  auto q = Ik(kRobotA, kLeg1, X_WA, grasp_);
  ASSERT_TRUE(q.has_value());
  plan_.actions[1].keyframe.q[kRobotA] = *q;
  plan_.actions[1].keyframe.objects[kLeg1].X_WA = X_WA;
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.HasIssue("pose", 1)) << Issues(v);
  EXPECT_FALSE(v.HasIssue("fk", 1)) << Issues(v);
}

// The seat lies upside down on the table (a changed initial pose); robot A picks leg1, turns it
// over and pushes it down into the seat's pocket (the step's axis, +z in A, points down in the
// world), then lets go of the new subassembly resting on the table.
class PlanValidatorAssembleTest : public PlanValidatorTest {
 protected:
  void SetUp() override {
    PlanValidatorTest::SetUp();
    if (HasFatalFailure()) return;
    project_.parts[kSeat].initial_pose.xyz = Vec3(-0.1, 0.2, 0.775);
    project_.parts[kSeat].initial_pose.rpy = Vec3(std::acos(-1.0), 0.0, 0.0);
    plan_.initial.objects[kSeat].X_WA = InitialX_WA(kSeat);
    const AssemblyTree& tree = *loaded_->check.tree;
    step_ = tree.Find("seat+leg1");
    const Iso3 X_WS = InitialX_WA(kSeat);  // the seat's assembly frame: the mated pose
    Iso3 X_approach = X_WS;
    X_approach.translation() += 0.03 * Vec3::UnitZ();  // 30 mm back along the axis (world -z)
    ASSERT_TRUE(ChooseGrasp({InitialX_WA(kLeg1), X_approach, X_WS}));

    Keyframe pick = plan_.initial;
    pick.q[kRobotA] = *Ik(kRobotA, kLeg1, InitialX_WA(kLeg1), grasp_);
    plan_.actions.push_back(Action(ActionType::kPick, kRobotA, kLeg1, pick));

    PlanAction assemble = Action(ActionType::kAssemble, kRobotA, kLeg1, pick);
    assemble.objects = {kLeg1, kSeat, step_};
    Keyframe approach = pick;
    approach.q[kRobotA] = *Ik(kRobotA, kLeg1, X_approach, grasp_);
    approach.objects[kLeg1].X_WA = X_approach;
    assemble.approach = approach;
    assemble.keyframe.q[kRobotA] = *Ik(kRobotA, kLeg1, X_WS, grasp_);
    assemble.keyframe.objects[kLeg1].X_WA = X_WS;
    plan_.actions.push_back(assemble);

    Keyframe release = assemble.keyframe;
    release.objects.clear();
    for (int p : {kLeg2, kLeg2 + 1, kLeg2 + 2}) release.objects.push_back(plan_.initial.objects[p]);
    release.objects.push_back({step_, X_WS, true});
    plan_.actions.push_back(Action(ActionType::kRelease, kRobotA, step_, release));
  }

  static constexpr int kSeat = 0;
  int step_ = -1;
};

TEST_F(PlanValidatorAssembleTest, InsertionValidates) {
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.valid) << Issues(v);
  EXPECT_EQ(v.actions, 3);
  EXPECT_EQ(v.keyframes, 5);      // initial, pick, approach, assemble, release
  EXPECT_EQ(v.wrench_checks, 3);  // transport, assembly, rest of the subassembly
}

TEST_F(PlanValidatorAssembleTest, MatingPoseOffGivesPose) {
  // leg1 5 mm beside its pocket, the arm following it.
  const Iso3 X_WM = Translation(0.005, 0.0, 0.0) * InitialX_WA(kSeat);
  auto q = Ik(kRobotA, kLeg1, X_WM, grasp_);
  ASSERT_TRUE(q.has_value());
  plan_.actions[1].keyframe.q[kRobotA] = *q;
  plan_.actions[1].keyframe.objects[kLeg1].X_WA = X_WM;
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.HasIssue("pose", 1)) << Issues(v);
  EXPECT_FALSE(v.HasIssue("fk", 1)) << Issues(v);
}

TEST_F(PlanValidatorAssembleTest, ApproachFromTheWrongSideGivesPose) {
  Iso3 X_WM = InitialX_WA(kSeat);
  X_WM.translation() -= 0.03 * Vec3::UnitZ();  // inside the seat instead of above it
  plan_.actions[1].approach->objects[kLeg1].X_WA = X_WM;
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.HasIssue("pose", 1)) << Issues(v);
  EXPECT_TRUE(v.HasIssue("fk", 1)) << Issues(v);  // the arm stayed at the right approach
}

TEST_F(PlanValidatorAssembleTest, StrongMatingForceGivesWrenchAssembly) {
  PlanValidationOptions strong = Partial();
  strong.force_scale = 20.0;  // 200 N: beyond the two-finger gripper's 50 N along any axis
  const PlanValidation v = Validate(strong);
  EXPECT_TRUE(v.HasIssue("wrench_assembly", 1)) << Issues(v);
  EXPECT_FALSE(v.HasIssue("wrench_transport")) << Issues(v);
  PlanValidationOptions gravity = strong;
  gravity.wrench_mode = MatingWrenchMode::kGravityOnly;
  const PlanValidation g = Validate(gravity);
  EXPECT_TRUE(g.valid) << Issues(g);
}

TEST_F(PlanValidatorAssembleTest, MissingResultGivesIncomplete) {
  PlanValidationOptions full;
  const PlanValidation v = Validate(full);
  EXPECT_TRUE(v.HasIssue("incomplete", 2)) << Issues(v);
}

TEST_F(PlanValidatorTest, PlaceBesideTheTableGivesPose) {
  BuildPickPlace();
  // Set leg1 down just beyond the table's +y edge (y = 0.5), at the table top's height.
  const Vec3 at = ToIsometry(project_.parts[kLeg1].initial_pose).translation();
  const Iso3 X_WA = Translation(0.0, 0.53 - at.y(), 0.0) * InitialX_WA(kLeg1);
  auto q = Ik(kRobotA, kLeg1, X_WA, grasp_);
  ASSERT_TRUE(q.has_value());
  plan_.actions[1].keyframe.q[kRobotA] = *q;
  plan_.actions[1].keyframe.objects[kLeg1].X_WA = X_WA;
  const PlanValidation v = Validate();
  EXPECT_TRUE(v.HasIssue("pose", 1)) << Issues(v);
  EXPECT_TRUE(v.HasIssue("wrench_rest", 1)) << Issues(v);
}

TEST_F(PlanValidatorTest, UninterpretablePlansFail) {
  BuildPickPlace();
  Plan bad = plan_;
  bad.actions[0].robots = {7};
  auto v = ValidatePlan(project_, loaded_->check, bad, Partial(), kStool);
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(v.error().message.find("robot index 7"), std::string::npos) << v.error().message;

  bad = plan_;
  bad.actions[1].keyframe.q.pop_back();
  v = ValidatePlan(project_, loaded_->check, bad, Partial(), kStool);
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error().code, ErrorCode::kInvalidInput);

  bad = plan_;
  bad.actions[0].objects = {99};
  v = ValidatePlan(project_, loaded_->check, bad, Partial(), kStool);
  ASSERT_FALSE(v);
  EXPECT_NE(v.error().message.find("node 99"), std::string::npos) << v.error().message;
}

}  // namespace
}  // namespace wrap
