// Robot catalog: the embedded JSON loads, agrees with model/catalog.h and with the fact sheet,
// and broken documents fail with the JSON path of the problem.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "model/catalog.h"
#include "model/project.h"
#include "robot/catalog.h"
#include "robot/kinematics.h"
#include "test_util.h"

namespace wrap {
namespace {

using testing::LoadOrDie;

// Every name that a project may use (model/catalog.h) loads here, with the same facts.
TEST(Catalog, EveryModelCatalogNameLoadsWithMatchingFacts) {
  for (const RobotModelInfo& info : RobotModels()) {
    SCOPED_TRACE(info.name);
    Result<Chain> chain = LoadRobotModel(info.name);
    ASSERT_TRUE(chain.has_value()) << chain.error().message;
    EXPECT_EQ(chain->name, info.name);
    EXPECT_EQ(chain->dof(), info.dof);
    EXPECT_EQ(chain->links.size(), static_cast<std::size_t>(info.dof) + 1);
  }
  for (const EndEffectorInfo& info : EndEffectors()) {
    SCOPED_TRACE(info.name);
    Result<EndEffector> ee = LoadEndEffector(info.name);
    ASSERT_TRUE(ee.has_value()) << ee.error().message;
    EXPECT_EQ(ee->name, info.name);
    EXPECT_EQ(ee->kind, info.kind);
    // The TCP lies along the approach axis z at the model catalog's offset.
    EXPECT_NEAR(ee->X_FT.translation().z(), info.tcp_offset_m, 1e-9);
    EXPECT_TRUE(ee->X_FT.linear().isIdentity(1e-12));
  }
  for (const MobileBaseInfo& info : MobileBasePresets()) {
    SCOPED_TRACE(info.name);
    Result<MobileBaseModel> base = LoadMobileBase(info.name);
    ASSERT_TRUE(base.has_value()) << base.error().message;
    ASSERT_EQ(base->mounts.size(), info.mounts.size());
    for (std::size_t i = 0; i < info.mounts.size(); ++i) {
      EXPECT_EQ(base->mounts[i].name, info.mounts[i].name);
      EXPECT_TRUE(base->mounts[i].X_BM.isApprox(ToIsometry(info.mounts[i].X_BM), 1e-9));
    }
    EXPECT_NE(FindRobotModel(base->arm_model), nullptr);
    EXPECT_NE(FindEndEffector(base->end_effector), nullptr);
  }
  // And nothing embedded here is unknown to the model catalog.
  for (const std::string& name : CatalogRobotModelNames()) EXPECT_NE(FindRobotModel(name), nullptr);
  for (const std::string& name : CatalogEndEffectorNames()) {
    EXPECT_NE(FindEndEffector(name), nullptr) << name;
  }
  for (const std::string& name : CatalogMobileBaseNames()) {
    EXPECT_NE(FindMobileBasePreset(name), nullptr) << name;
  }
  EXPECT_EQ(CatalogRobotModelNames().size(), RobotModels().size());
  EXPECT_EQ(CatalogEndEffectorNames().size(), EndEffectors().size());
  EXPECT_EQ(CatalogMobileBaseNames().size(), MobileBasePresets().size());
}

TEST(Catalog, UnknownNamesFailListingTheKnownOnes) {
  Result<Chain> chain = LoadRobotModel("ur3e");
  ASSERT_FALSE(chain.has_value());
  EXPECT_EQ(chain.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(chain.error().message.find("ur3e"), std::string::npos);
  EXPECT_NE(chain.error().message.find("ur5e, ur10e, openarm"), std::string::npos);
  // A name of another kind is not a robot model.
  EXPECT_FALSE(LoadRobotModel("robotiq_2f85").has_value());
  EXPECT_FALSE(LoadEndEffector("ur5e").has_value());
  Result<MobileBaseModel> base = LoadMobileBase("warthog");
  ASSERT_FALSE(base.has_value());
  EXPECT_NE(base.error().message.find("husky_dual_ur5e"), std::string::npos);
}

TEST(Catalog, UrLimitsAndShapesFollowTheFactSheet) {
  const Chain ur5e = LoadOrDie("ur5e");
  ASSERT_EQ(ur5e.dof(), 6);
  for (const Joint& joint : ur5e.joints) {
    SCOPED_TRACE(joint.name);
    const double range = joint.name == "elbow" ? 3.141593 : 6.283185;
    EXPECT_DOUBLE_EQ(joint.lower, -range);
    EXPECT_DOUBLE_EQ(joint.upper, range);
    EXPECT_DOUBLE_EQ(joint.max_velocity, 3.141593);
    EXPECT_DOUBLE_EQ(joint.max_acceleration, 5.0);
  }
  EXPECT_DOUBLE_EQ(ur5e.joints[0].max_effort, 150.0);
  EXPECT_DOUBLE_EQ(ur5e.joints[5].max_effort, 28.0);
  const Chain ur10e = LoadOrDie("ur10e");
  EXPECT_DOUBLE_EQ(ur10e.joints[0].max_velocity, 2.094395);
  EXPECT_DOUBLE_EQ(ur10e.joints[2].max_velocity, 3.141593);
  EXPECT_DOUBLE_EQ(ur10e.joints[1].max_effort, 330.0);

  // Base cylinder, 9 arm shapes; visual = collision.
  int shapes = 0;
  for (const Link& link : ur5e.links) {
    shapes += static_cast<int>(link.collision.size());
    EXPECT_EQ(link.visual.size(), link.collision.size());
  }
  EXPECT_EQ(shapes, 10);
  EXPECT_EQ(ur5e.links[0].collision[0].type, Shape::Type::kCylinder);
  EXPECT_DOUBLE_EQ(ur5e.links[0].collision[0].radius, 0.0755);
  EXPECT_EQ(ur5e.links[6].collision[0].type, Shape::Type::kCylinder);

  // The capsules were given in DH frames: at q = 0 they land where the fact sheet says (its
  // p*_base_at_q0 values come from the menagerie's rounded lengths: within 2 mm).
  std::vector<Iso3> X_BL(7);
  ForwardKinematics(ur5e, Iso3::Identity(), ZeroConfiguration(ur5e), X_BL);
  const Shape& shoulder = ur5e.links[1].collision[0];
  EXPECT_LT((X_BL[1] * shoulder.p0 - Vec3(0.0, 0.0, 0.063)).norm(), 2e-3);
  EXPECT_LT((X_BL[1] * shoulder.p1 - Vec3(0.0, 0.0, 0.183)).norm(), 2e-3);
  const Shape& tube = ur5e.links[2].collision[1];
  EXPECT_LT((X_BL[2] * tube.p1 - Vec3(-0.4, -0.138, 0.163)).norm(), 2e-3);
  const Shape& wrist3 = ur5e.links[6].collision[0];
  EXPECT_LT((X_BL[6] * wrist3.p0 - Vec3(-0.817, -0.234, 0.063)).norm(), 2e-3);
}

TEST(Catalog, OpenArmLimitsAndCapsules) {
  const Chain arm = LoadOrDie("openarm");
  ASSERT_EQ(arm.dof(), 7);
  EXPECT_DOUBLE_EQ(arm.joints[3].lower, 0.0);
  EXPECT_DOUBLE_EQ(arm.joints[3].upper, 2.443461);
  EXPECT_TRUE(arm.joints[1].axis.isApprox(Vec3(-1.0, 0.0, 0.0)));
  for (const Joint& joint : arm.joints) EXPECT_DOUBLE_EQ(joint.max_acceleration, 3.0);
  for (const Link& link : arm.links) {
    ASSERT_EQ(link.collision.size(), 1u) << link.name;
    EXPECT_EQ(link.collision[0].type, Shape::Type::kCapsule);
  }
  EXPECT_DOUBLE_EQ(arm.links[0].collision[0].radius, 0.0581);
  EXPECT_TRUE(arm.X_LF.translation().isApprox(Vec3(1e-6, 0.0205, 0.0)));
}

// The defaults of the project format (paper table) are the catalog's end-effector limits.
TEST(Catalog, EndEffectorWrenchLimitsAreThePaperTable) {
  const WrenchLimits paper;
  const EndEffector two_finger = *LoadEndEffector("robotiq_2f85");
  EXPECT_EQ(two_finger.wrench_assembly, paper.two_finger);
  EXPECT_EQ(two_finger.wrench_transport, paper.two_finger);
  const EndEffector vacuum = *LoadEndEffector("vacuum_cup");
  EXPECT_EQ(vacuum.wrench_assembly, paper.vacuum_assembly);
  EXPECT_EQ(vacuum.wrench_transport, paper.vacuum_transport);
  EXPECT_DOUBLE_EQ(vacuum.cup_diameter_m, 0.04);
  EXPECT_EQ(vacuum.finger_shapes[0], -1);
  const EndEffector hand = *LoadEndEffector("openarm_hand");
  EXPECT_EQ(hand.wrench_assembly, paper.two_finger);
  EXPECT_TRUE(hand.X_FT.translation().isApprox(Vec3(0.0, -0.025, 0.1801)));
}

TEST(Catalog, RobotiqFingersMoveWithTheOpening) {
  const EndEffector ee = *LoadEndEffector("robotiq_2f85");
  EXPECT_DOUBLE_EQ(ee.stroke_m, 0.085);
  EXPECT_DOUBLE_EQ(ee.pad_width_m, 0.022);
  EXPECT_DOUBLE_EQ(ee.pad_length_m, 0.0375);
  ASSERT_EQ(ee.collision.size(), 3u);  // Body and two fingers, open.
  const Shape& open = ee.collision[ee.finger_shapes[0]];
  EXPECT_NEAR(open.X_LS.translation().x(), 0.0425 + 0.0158, 1e-12);

  const std::vector<Shape> half = EndEffectorShapesAt(ee, 0.04);
  const Shape& pos = half[ee.finger_shapes[0]];
  const Shape& neg = half[ee.finger_shapes[1]];
  // Inner faces at +-20 mm.
  EXPECT_NEAR(pos.X_LS.translation().x() - pos.half_extents.x(), 0.02, 1e-12);
  EXPECT_NEAR(neg.X_LS.translation().x() + neg.half_extents.x(), -0.02, 1e-12);
  EXPECT_NEAR(pos.X_LS.translation().z(), 0.108, 1e-12);
  // Openings beyond the stroke clamp.
  const std::vector<Shape> wide = EndEffectorShapesAt(ee, 1.0);
  EXPECT_NEAR(wide[ee.finger_shapes[0]].X_LS.translation().x(), 0.0583, 1e-12);
  const std::vector<Shape> closed = EndEffectorShapesAt(ee, -1.0);
  EXPECT_NEAR(closed[ee.finger_shapes[0]].X_LS.translation().x(), 0.0158, 1e-12);

  // The OpenArm hand closes along y, around the TCP's y.
  const EndEffector hand = *LoadEndEffector("openarm_hand");
  const std::vector<Shape> shut = EndEffectorShapesAt(hand, 0.0);
  EXPECT_NEAR(shut[hand.finger_shapes[0]].X_LS.translation().y(), -0.025 + 0.0175, 1e-12);
}

TEST(Catalog, HuskyMountsTiltOutward) {
  const MobileBaseModel husky = *LoadMobileBase("husky_dual_ur5e");
  ASSERT_EQ(husky.mounts.size(), 2u);
  const double s = std::numbers::sqrt2 / 2.0;
  EXPECT_TRUE(husky.mounts[0].X_BM.linear().col(2).isApprox(Vec3(0.0, s, s), 1e-5));
  EXPECT_TRUE(husky.mounts[1].X_BM.linear().col(2).isApprox(Vec3(0.0, -s, s), 1e-5));
  // Arm bases 0.490 m above the floor (ROBOTS.md 4.3), the chassis boxes on the wheels.
  EXPECT_NEAR(husky.mounts[0].X_BM.translation().z(), 0.48999, 1e-9);
  EXPECT_NEAR(husky.base_height_m, 0.13228, 1e-12);
  EXPECT_NEAR(husky.collision[0].X_LS.translation().z(), 0.13228 + 0.061875, 1e-12);
  EXPECT_NEAR(husky.collision[2].p0.z() - husky.collision[2].radius, 0.0, 1e-12);
  EXPECT_EQ(husky.collision.size(), 7u);
  EXPECT_DOUBLE_EQ(husky.tool_coupling_m, 0.01);
}

TEST(Catalog, BrokenDocumentsNameThePath) {
  const char* missing_limits = R"({
    "schema": "wrap.robot_model/1", "name": "bad", "kinematics": "urdf",
    "joints": [{"name": "j1", "origin": {"xyz": [0, 0, 0.1]}, "axis": [0, 0, 1]}],
    "links": [{"name": "l0"}, {"name": "l1"}], "flange": {}})";
  Result<Chain> chain = ParseRobotModel(missing_limits, "bad.json");
  ASSERT_FALSE(chain.has_value());
  EXPECT_EQ(chain.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(chain.error().message.find("bad.json"), std::string::npos);
  EXPECT_NE(chain.error().message.find("joints[0].limits"), std::string::npos);

  const char* bad_shape = R"({
    "schema": "wrap.robot_model/1", "name": "bad", "kinematics": "urdf",
    "joints": [{"name": "j1", "origin": {}, "axis": [0, 0, 1],
                "limits": {"lower": -1, "upper": 1, "velocity": 1, "acceleration": 1}}],
    "links": [{"name": "l0"}, {"name": "l1", "collision": [{"type": "cone", "radius": 1}]}],
    "flange": {}})";
  chain = ParseRobotModel(bad_shape, "bad.json");
  ASSERT_FALSE(chain.has_value());
  EXPECT_NE(chain.error().message.find("links[1].collision[0].type"), std::string::npos);

  chain = ParseRobotModel("{ not json", "x.json");
  ASSERT_FALSE(chain.has_value());
  EXPECT_NE(chain.error().message.find("not valid JSON"), std::string::npos);

  Result<EndEffector> ee = ParseEndEffector(R"({"schema": "wrap.robot_model/1"})", "y.json");
  ASSERT_FALSE(ee.has_value());
  EXPECT_NE(ee.error().message.find("schema"), std::string::npos);
}

}  // namespace
}  // namespace wrap
