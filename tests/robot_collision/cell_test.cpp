// The cell: hand-built arms that interlock and then separate by a known gap, default filters,
// grasped objects moving with the TCP, UR5e arms with grippers.
#include "robot/cell.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "scenes.h"

namespace wrap {
namespace {

using testing::Box;
using testing::BoxMesh;
using testing::Capsule;
using testing::Pose;
using testing::Sphere;
using testing::Translation;

constexpr double kPi = std::numbers::pi;

// A 2-joint arm: a sphere base, an upright column (link 1) and a horizontal boom (link 2) of
// 0.6 m along the link's x; the flange at the boom's end with a small box gripper.
CellRobot BoomArm(const std::string& name, const Iso3& X_WB) {
  CellRobot r;
  r.name = name;
  r.X_WB = X_WB;
  r.chain.name = "boom";
  r.chain.links = {Link{"base", {Sphere({0, 0, 0}, 0.05, "base")}, {}},
                   Link{"column", {Capsule({0, 0, 0.08}, {0, 0, 0.5}, 0.05, "column")}, {}},
                   Link{"boom", {Capsule({0, 0, 0}, {0.6, 0, 0}, 0.04, "boom")}, {}}};
  r.chain.joints = {Joint{.name = "j1"}, Joint{.name = "j2"}};
  r.chain.X_LF = Translation(0.6, 0, 0);
  r.end_effector.name = "hand";
  r.end_effector.collision = {Box({0.05, 0, 0}, {0.05, 0.03, 0.03}, "palm")};
  r.end_effector.X_FT = Translation(0.1, 0, 0);
  return r;
}

// Link frames X_BL given in the base frame, put into the world: the frames the cell takes.
std::vector<Iso3> InWorld(const Iso3& X_WB, std::vector<Iso3> X_BL) {
  for (Iso3& X : X_BL) X = X_WB * X;
  return X_BL;
}

// World link frames of a boom arm based at X_WB, the boom at height h.
std::vector<Iso3> BoomFrames(double h, const Iso3& X_WB = Iso3::Identity()) {
  return InWorld(X_WB, {Iso3::Identity(), Iso3::Identity(), Translation(0, 0, h)});
}

CellDef TwoBoomArms() {
  CellDef def;
  def.robots.push_back(BoomArm("a", Iso3::Identity()));
  // Robot b stands at x = 1 facing -x: the two booms overlap on x in [0.4, 0.6].
  def.robots.push_back(BoomArm("b", Pose({1.0, 0, 0}, {0, 0, kPi})));
  def.table.present = false;
  return def;
}

TEST(Cell, InterlockedArmsCollideThenSeparateByKnownClearance) {
  auto cell = Cell::Build(TwoBoomArms());
  ASSERT_TRUE(cell) << cell.error().message;
  const std::vector<double> q = {0.1, 0.2};
  cell->SetConfiguration(0, q, BoomFrames(0.5, cell->X_WB(0)));
  cell->SetConfiguration(1, q, BoomFrames(0.5, cell->X_WB(1)));

  CollisionResult result;
  ASSERT_TRUE(cell->InCollision(&result));
  const int ra = cell->robot_of(result.first.body_a);
  const int rb = cell->robot_of(result.first.body_b);
  EXPECT_NE(ra, rb);
  EXPECT_GE(ra, 0);
  EXPECT_GE(rb, 0);
  const std::string text = cell->Describe(result.first);
  EXPECT_NE(text.find("q=[0.1, 0.2]"), std::string::npos) << text;
  EXPECT_EQ(cell->MinRobotClearance().distance, 0.0);

  // Raise b's boom by 0.3: the booms are parallel, 0.3 apart on axis, radii 0.04 + 0.04.
  cell->SetConfiguration(1, q, BoomFrames(0.8, cell->X_WB(1)));
  EXPECT_FALSE(cell->InCollision());
  const DistanceResult d = cell->MinRobotClearance();
  EXPECT_NEAR(d.distance, 0.3 - 0.08, 1e-12);
  EXPECT_EQ(cell->world().shape_name(d.pair.body_a, d.pair.shape_a), "boom");
  EXPECT_EQ(cell->world().shape_name(d.pair.body_b, d.pair.shape_b), "boom");
  EXPECT_NEAR(d.p_A_W.z(), 0.54, 1e-12);
  EXPECT_NEAR(d.p_B_W.z(), 0.76, 1e-12);

  // The TCP follows: robot a's TCP at the boom's end + 0.1.
  EXPECT_TRUE(cell->X_WT(0).translation().isApprox(Vec3(0.7, 0, 0.5), 1e-12));
  EXPECT_TRUE(cell->X_WT(1).translation().isApprox(Vec3(0.3, 0, 0.8), 1e-12));
}

TEST(Cell, EndEffectorsCountInClearanceUnlessTurnedOff) {
  CellDef def = TwoBoomArms();
  // b's boom 0.3 higher and shifted so that only the palms face each other.
  CellOptions opt;
  auto with = Cell::Build(def, opt);
  opt.clearance_includes_end_effectors = false;
  auto without = Cell::Build(def, opt);
  ASSERT_TRUE(with && without);
  for (Cell* c : {&*with, &*without}) {
    c->SetConfiguration(0, {}, BoomFrames(0.5, c->X_WB(0)));
    // b's base moved to x = 1.5: booms' ends 0.3 apart on x; palms 0.1 apart.
    c->SetConfiguration(1, {},
                        InWorld(c->X_WB(1), {Iso3::Identity(), Translation(-0.5, 0, 0),
                                             Translation(-0.5, 0, 0.5)}));
  }
  EXPECT_NEAR(with->MinRobotClearance().distance, 0.1, 1e-9);
  EXPECT_NEAR(without->MinRobotClearance().distance, 0.3 - 0.08, 1e-12);
}

TEST(Cell, AdjacentLinksIgnoredByDefault) {
  CellDef def;
  def.robots.push_back(BoomArm("a", Iso3::Identity()));
  def.table.present = false;
  // The column and the boom overlap at their joint; the base sphere overlaps the column.
  auto cell = Cell::Build(def);
  ASSERT_TRUE(cell);
  cell->SetConfiguration(0, {}, BoomFrames(0.5, cell->X_WB(0)));
  EXPECT_FALSE(cell->InCollision());

  CellOptions none;
  none.adjacent_link_gap = 0;
  auto strict = Cell::Build(def, none);
  ASSERT_TRUE(strict);
  strict->SetConfiguration(0, {}, BoomFrames(0.5, strict->X_WB(0)));
  CollisionResult result;
  ASSERT_TRUE(strict->InCollision(&result));
  EXPECT_EQ(strict->robot_of(result.first.body_a), 0);
  EXPECT_EQ(strict->robot_of(result.first.body_b), 0);

  // Folding the boom down onto the base: links 0 and 2 are two apart, so that is a collision.
  cell->SetConfiguration(
      0, {}, InWorld(cell->X_WB(0), {Iso3::Identity(), Iso3::Identity(), Translation(0, 0, 0.02)}));
  ASSERT_TRUE(cell->InCollision(&result));
  EXPECT_EQ(result.first.body_a, cell->link_body(0, 0));
  EXPECT_EQ(result.first.body_b, cell->link_body(0, 2));
}

TEST(Cell, BaseOnTableAndObjectsOnTableAreAllowed) {
  CellDef def;
  def.robots.push_back(BoomArm("a", Translation(0, 0, 0.80)));  // base sphere dips into the top
  def.table.size = Vec3(2, 2, 0.05);
  def.table.top_center = Vec3(0, 0, 0.80);
  def.objects.push_back(CellObject{"part", BoxMesh({-0.02, -0.02, 0}, {0.02, 0.02, 0.04}),
                                   Translation(0.3, 0.3, 0.80)});
  auto cell = Cell::Build(def);
  ASSERT_TRUE(cell);
  cell->SetConfiguration(0, {}, BoomFrames(0.5, cell->X_WB(0)));
  EXPECT_FALSE(cell->InCollision());
  EXPECT_TRUE(cell->world().IsAllowed(cell->link_body(0, 0), cell->table_body()));
  EXPECT_TRUE(cell->world().IsAllowed(cell->object_body(0), cell->table_body()));

  CellOptions strict;
  strict.base_touches_table = false;
  strict.objects_touch_table = false;
  auto c2 = Cell::Build(def, strict);
  ASSERT_TRUE(c2);
  c2->SetConfiguration(0, {}, BoomFrames(0.5, c2->X_WB(0)));
  CollisionRequest all;
  all.all_pairs = true;
  CollisionResult result;
  EXPECT_TRUE(c2->InCollision(&result, all));
  EXPECT_EQ(result.pairs.size(), 2u);

  // The boom (a link two away from the base) swung into the table is caught.
  cell->SetConfiguration(
      0, {},
      InWorld(cell->X_WB(0), {Iso3::Identity(), Iso3::Identity(), Translation(0.1, 0, 0.0)}));
  ASSERT_TRUE(cell->InCollision(&result));
  EXPECT_EQ(result.first.body_b, cell->table_body());
}

TEST(Cell, GraspedObjectMovesWithTcpAndMayTouchItsGripper) {
  CellDef def = TwoBoomArms();
  // A 4 cm cube centred on robot a's TCP: half in its palm (x 0.6 to 0.7), half out.
  def.objects.push_back(CellObject{"cube", BoxMesh({-0.02, -0.02, -0.02}, {0.02, 0.02, 0.02}),
                                   Translation(0.7, 0, 0.5)});
  auto cell = Cell::Build(def);
  ASSERT_TRUE(cell);
  cell->SetConfiguration(0, {}, BoomFrames(0.5, cell->X_WB(0)));
  cell->SetConfiguration(1, {}, BoomFrames(1.2, cell->X_WB(1)));  // out of the way
  CollisionResult result;
  ASSERT_TRUE(cell->InCollision(&result));
  EXPECT_EQ(result.first.body_a, cell->end_effector_body(0));
  EXPECT_EQ(result.first.body_b, cell->object_body(0));

  cell->Attach(0, 0);
  EXPECT_EQ(cell->carrier(0), 0);
  EXPECT_FALSE(cell->InCollision());
  // Raise a's boom by 0.2: the cube follows.
  cell->SetConfiguration(0, {}, BoomFrames(0.7, cell->X_WB(0)));
  EXPECT_TRUE(cell->object_pose(0).translation().isApprox(Vec3(0.7, 0, 0.7), 1e-12));
  EXPECT_FALSE(cell->InCollision());
  // Robot b's palm (x 0.71 to 0.81) closes on the cube's free half: a collision with b (b does
  // not hold it), 1 cm clear of a's palm.
  cell->SetConfiguration(
      1, {},
      InWorld(cell->X_WB(1), {Iso3::Identity(), Iso3::Identity(), Translation(-0.41, 0, 0.7)}));
  ASSERT_TRUE(cell->InCollision(&result));
  EXPECT_EQ(cell->robot_of(result.first.body_a), 1);
  EXPECT_EQ(result.first.body_b, cell->object_body(0));
  // Handover: b grasps too; a still carries it; then a lets go and b carries it.
  cell->Attach(0, 1);
  EXPECT_EQ(cell->carrier(0), 0);
  EXPECT_FALSE(cell->InCollision());
  cell->Detach(0, 0);
  EXPECT_EQ(cell->carrier(0), 1);
  const Vec3 before = cell->object_pose(0).translation();
  cell->SetConfiguration(0, {},
                         BoomFrames(0.3, cell->X_WB(0)));  // a moves away: the cube stays with b
  EXPECT_TRUE(cell->object_pose(0).translation().isApprox(before, 1e-12));
  cell->SetConfiguration(
      1, {},
      InWorld(cell->X_WB(1), {Iso3::Identity(), Iso3::Identity(), Translation(-0.41, 0, 0.9)}));
  EXPECT_TRUE(cell->object_pose(0).translation().isApprox(before + Vec3(0, 0, 0.2), 1e-12));
  cell->Detach(0, 1);
  EXPECT_EQ(cell->carrier(0), -1);
  cell->SetConfiguration(1, {}, BoomFrames(1.2, cell->X_WB(1)));
  EXPECT_TRUE(cell->object_pose(0).translation().isApprox(before + Vec3(0, 0, 0.2), 1e-12));
}

TEST(Cell, Ur5eArmsWithGrippers) {
  // The DH helper matches the fact sheet: flange at q = 0.
  const auto X0 = testing::Ur5eFrames({0, 0, 0, 0, 0, 0});
  EXPECT_TRUE(X0[6].translation().isApprox(Vec3(-0.8172, -0.2329, 0.0628), 1e-9));

  const std::array<double, 6> home = {0, -kPi / 2, kPi / 2, -kPi / 2, -kPi / 2, 0};
  CellDef def;
  for (int r = 0; r < 2; ++r) {
    CellRobot robot;
    robot.name = "ur" + std::to_string(r);
    robot.chain = testing::Ur5eChain();
    robot.X_WB = Pose({r == 0 ? -0.6 : 0.6, 0, 0.75}, {0, 0, r == 0 ? 0.0 : kPi});
    robot.end_effector = testing::Gripper2f85();
    def.robots.push_back(robot);
  }
  def.objects.push_back(CellObject{"part", BoxMesh({-0.03, -0.03, 0}, {0.03, 0.03, 0.06}),
                                   Translation(0, 0.4, 0.75)});

  // Without a reference configuration the wrist_2 capsule, which reaches 1.1 mm past the flange,
  // touches the gripper body in every configuration.
  auto raw = Cell::Build(def);
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_EQ(raw->world().num_bodies(), 2 * 8 + 1 + 1);
  raw->SetConfiguration(0, home, testing::Ur5eFrames(home, raw->X_WB(0)));
  raw->SetConfiguration(1, home, testing::Ur5eFrames(home, raw->X_WB(1)));
  CollisionResult result;
  ASSERT_TRUE(raw->InCollision(&result));
  EXPECT_EQ(raw->world().shape_name(result.first.body_a, result.first.shape_a), "wrist_2/b");
  EXPECT_EQ(result.first.body_b, raw->end_effector_body(0));

  for (CellRobot& robot : def.robots) {
    robot.reference_link_frames = testing::Ur5eFrames(home, robot.X_WB);
  }
  auto cell = Cell::Build(def);
  ASSERT_TRUE(cell) << cell.error().message;
  EXPECT_TRUE(cell->world().IsAllowed(cell->link_body(0, 5), cell->end_effector_body(0)));
  EXPECT_FALSE(cell->world().IsAllowed(cell->link_body(0, 4), cell->end_effector_body(0)));

  // Typical poses are free of self-collision with the default filters.
  const std::vector<std::array<double, 6>> poses = {
      home, {0.5, -1.2, 1.4, -1.8, -kPi / 2, 0.3}, {-0.4, -2.0, 1.0, -0.6, 1.2, 0}};
  for (const auto& q : poses) {
    for (int r = 0; r < 2; ++r) {
      cell->SetConfiguration(r, q, testing::Ur5eFrames(q, cell->X_WB(r)));
    }
    EXPECT_FALSE(cell->InCollision(&result)) << cell->Describe(result.first);
    EXPECT_GT(cell->MinRobotClearance().distance, 0.1);
  }
  // A real self-collision: the elbow folded so that the wrist meets the upper arm.
  const std::array<double, 6> folded = {0, -kPi / 2, 3.1, -1.7, -0.6, 0};
  cell->SetConfiguration(0, folded, testing::Ur5eFrames(folded, cell->X_WB(0)));
  ASSERT_TRUE(cell->InCollision(&result));
  EXPECT_EQ(result.first.body_a, cell->link_body(0, 2));
  EXPECT_EQ(result.first.body_b, cell->link_body(0, 5));

  // Both arms reaching to the middle at the same height: they meet.
  const std::array<double, 6> reach = {kPi, -0.3, 0.6, -0.3, -kPi / 2, 0};
  for (int r = 0; r < 2; ++r) {
    cell->SetConfiguration(r, reach, testing::Ur5eFrames(reach, cell->X_WB(r)));
  }
  ASSERT_TRUE(cell->InCollision(&result));
  EXPECT_NE(cell->robot_of(result.first.body_a), cell->robot_of(result.first.body_b));
  EXPECT_EQ(cell->MinRobotClearance().distance, 0.0);
}

// The broadphase (sweep and prune) and the distance pruning (box bounds, inner balls) change
// nothing: random UR5e configurations against brute force over every pair of bodies.
TEST(Cell, QueriesAgreeWithBruteForce) {
  const std::array<double, 6> home = {0, -kPi / 2, kPi / 2, -kPi / 2, -kPi / 2, 0};
  CellDef def;
  const Vec3 bases[3] = {{0.5, 0.3, 0.75}, {-0.5, 0.3, 0.75}, {0, -0.5, 0.75}};
  for (int r = 0; r < 3; ++r) {
    CellRobot robot;
    robot.name = "ur" + std::to_string(r);
    robot.chain = testing::Ur5eChain();
    robot.X_WB = Pose(bases[r], {0, 0, std::atan2(bases[r].y(), bases[r].x())});
    robot.end_effector = testing::Gripper2f85();
    robot.reference_link_frames = testing::Ur5eFrames(home, robot.X_WB);
    def.robots.push_back(robot);
  }
  for (int k = 0; k < 4; ++k) {
    def.objects.push_back(CellObject{"p" + std::to_string(k),
                                     BoxMesh({-0.03, -0.03, 0}, {0.03, 0.03, 0.08}),
                                     Translation(0.2 * k - 0.3, 0.0, 0.75)});
  }
  auto cell = Cell::Build(def);
  ASSERT_TRUE(cell) << cell.error().message;
  CollisionWorld& w = cell->world();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> any(-kPi, kPi), up(-kPi, 0.0);
  int free = 0;
  for (int trial = 0; trial < 300; ++trial) {
    for (int r = 0; r < 3; ++r) {
      const std::array<double, 6> q = {any(rng), up(rng), any(rng), any(rng), any(rng), any(rng)};
      cell->SetConfiguration(r, q, testing::Ur5eFrames(q, cell->X_WB(r)));
    }
    bool brute_hit = false;
    double brute_clearance = std::numeric_limits<double>::infinity();
    for (int a = 0; a < w.num_bodies(); ++a) {
      for (int b = a + 1; b < w.num_bodies(); ++b) {
        const BodyId ia{a}, ib{b};
        if (!w.IsAllowed(ia, ib) && w.Collide(ia, ib)) brute_hit = true;
        const int ra = cell->robot_of(ia), rb = cell->robot_of(ib);
        if (ra >= 0 && rb >= 0 && ra != rb) {
          brute_clearance = std::min(brute_clearance, w.Distance(ia, ib).distance);
        }
      }
    }
    ASSERT_EQ(cell->InCollision(), brute_hit) << trial;
    ASSERT_NEAR(cell->MinRobotClearance().distance, brute_clearance, 1e-9) << trial;
    free += brute_hit ? 0 : 1;
  }
  EXPECT_GT(free, 10);
}

TEST(Cell, BuildErrorsNameTheEntity) {
  CellDef def = TwoBoomArms();
  def.robots[1].name = "a";
  auto r = Cell::Build(def);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(r.error().message.find("'a' used twice"), std::string::npos);

  def = TwoBoomArms();
  def.robots[0].chain.joints.pop_back();
  r = Cell::Build(def);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("expected joints + 1"), std::string::npos);

  def = TwoBoomArms();
  def.robots[0].chain.links[1].collision[0].radius = 0.0;
  r = Cell::Build(def);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("'a/column'"), std::string::npos) << r.error().message;

  def = TwoBoomArms();
  def.objects.push_back(CellObject{"empty", {}, Iso3::Identity()});
  r = Cell::Build(def);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("'empty'"), std::string::npos);

  def = TwoBoomArms();
  def.robots[0].reference_link_frames = {Iso3::Identity()};
  r = Cell::Build(def);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("reference link frames"), std::string::npos);

  def = TwoBoomArms();
  def.table.present = true;
  def.table.size = Vec3(1, 0, 1);
  r = Cell::Build(def);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("table"), std::string::npos);
}

}  // namespace
}  // namespace wrap
