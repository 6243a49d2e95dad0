// Tests of the grasp types (grasp.h GraspType): the torque model of reduced grasps, a short
// collar on a plate that only reduced grasps hold at the mating pose, the order of a set (full-pad
// grasps first, unchanged by the reduced ones), determinism, and an LP question that a full-pad
// grasp passes and a fingertip grasp at the same pose fails.
#include <gtest/gtest.h>

#include <cmath>

#include "../geometry/test_meshes.h"
#include "grasp/grasp.h"
#include "grasp/preprocess.h"
#include "scenes.h"
#include "wrench/wrench.h"

namespace wrap {
namespace {

using test_meshes::MakeBox;
using test_meshes::MakeCylinder;
using test_scenes::AddPart;
using test_scenes::AddRobots;
using test_scenes::AddStep;
using test_scenes::Finish;
using test_scenes::Scene;

constexpr double kFullArea = 1e-4;  // TwoFingerGraspOptions::min_pad_contact_m2's default

TEST(GraspTorqueScale, FollowsThePatchAxisByAxis) {
  // Robotiq axes in G: closing x, approach z, so the pad's width runs along y.
  const Vec3 closing = Vec3::UnitX(), approach = Vec3::UnitZ();
  // A 5 x 4 mm patch (width x length), 0.2 cm^2: radius sqrt(0.2), length 4/10, width 5/10 of
  // the reference 10 x 10 mm square.
  const PadPatch patch{2e-5, 5e-3, 4e-3};
  const Vec3 s = GraspTorqueScale(patch, kFullArea, closing, approach);
  EXPECT_NEAR(s.x(), std::sqrt(0.2), 1e-12) << "about the closing axis: the patch's radius";
  EXPECT_NEAR(s.y(), 0.4, 1e-12) << "about the pad's width axis: its length";
  EXPECT_NEAR(s.z(), 0.5, 1e-12) << "about the approach axis: its width";
  // A long strip: capped at the adopted box.
  const Vec3 strip = GraspTorqueScale({9e-5, 3e-3, 30e-3}, kFullArea, closing, approach);
  EXPECT_NEAR(strip.x(), std::sqrt(0.9), 1e-12);
  EXPECT_EQ(strip.y(), 1.0);
  EXPECT_NEAR(strip.z(), 0.3, 1e-12);
  // The OpenArm hand closes along y: the same patch lands on other components.
  const Vec3 y_closing = GraspTorqueScale(patch, kFullArea, Vec3::UnitY(), approach);
  EXPECT_NEAR(y_closing.y(), std::sqrt(0.2), 1e-12);
  EXPECT_NEAR(y_closing.x(), 0.4, 1e-12);
  EXPECT_NEAR(y_closing.z(), 0.5, 1e-12);
}

TEST(GraspLimits, ReducedBoxKeepsForcesAndScalesTorques) {
  const WrenchLimits adopted;
  Grasp g;
  EXPECT_EQ(GraspLimits(adopted, g).two_finger, adopted.two_finger) << "full-pad: the adopted box";
  g.type = GraspType::kFingertip;
  g.torque_scale = Vec3(0.5, 0.25, 1.0);
  const WrenchLimits reduced = GraspLimits(adopted, g);
  EXPECT_EQ(reduced.two_finger.force_N, adopted.two_finger.force_N);
  EXPECT_EQ(reduced.two_finger.torque_Nm,
            Vec3(0.5 * adopted.two_finger.torque_Nm.x(), 0.25 * adopted.two_finger.torque_Nm.y(),
                 adopted.two_finger.torque_Nm.z()));
  EXPECT_EQ(reduced.vacuum_assembly, adopted.vacuum_assembly);
  EXPECT_EQ(reduced.vacuum_transport, adopted.vacuum_transport);
}

// A 60 x 60 x 4 mm plate with a collar (radius 10 mm, 8 mm tall, a 32-gon) standing on it.
// Across its 20 mm diameter the pads touch a strip of at most 8 x ~9 mm (< 1 cm^2); across its
// flat ends one pad would sit inside the plate.
Scene CollarOnPlate() {
  Scene s;
  AddPart(s, "plate", MakeBox(Vec3(-0.03, -0.03, -0.004), Vec3(0.03, 0.03, 0.0)));
  Pose collar_pose;
  collar_pose.xyz = Vec3(0.0, 0.0, 0.004);
  AddPart(s, "collar", MakeCylinder(0.010, 0.008, 32), collar_pose);
  AddStep(s, "plate+collar", "collar", "plate");
  s.project.steps[0].mating.axis = Vec3(0.0, 0.0, -1.0);
  AddRobots(s, "robotiq_2f85");
  EXPECT_TRUE(Finish(s));
  return s;
}

PreprocessOptions Quick(int grasps = 16) {
  PreprocessOptions o;
  o.grasps = grasps;
  o.compute_table_slots = false;
  return o;
}

const GraspSet& SetOf(const Preprocessed& pre, const std::string& name) {
  const Subassembly* sub = pre.Find(name);
  EXPECT_NE(sub, nullptr) << name;
  return sub->grasp_sets.at(0);
}

TEST(GraspTypes, OnlyReducedGraspsHoldAShortCollarOnItsPlate) {
  const Scene s = CollarOnPlate();
  RunContext ctx(5);
  auto pre = Preprocess(s.project, s.check, Quick(), ctx);
  ASSERT_TRUE(pre) << pre.error().message;
  // Alone, the collar has full-pad grasps (across its flat ends).
  int alone_full = 0;
  for (const Grasp& g : SetOf(*pre, "collar").grasps) alone_full += g.type == GraspType::kFullPad;
  EXPECT_GT(alone_full, 0);
  // On the plate, every grasp of the collar is a reduced one, and fingertip grasps are among
  // them; each has a box smaller than the adopted one about some axis.
  int on_plate = 0, fingertip = 0;
  const WrenchLimits adopted;
  for (const Grasp& g : SetOf(*pre, "plate+collar").grasps) {
    if (g.part != 1) continue;
    ++on_plate;
    EXPECT_NE(g.type, GraspType::kFullPad);
    fingertip += g.type == GraspType::kFingertip;
    EXPECT_LT(g.contact_area_m2, kFullArea);
    EXPECT_GE(g.contact_area_m2, TwoFingerGraspOptions{}.min_reduced_contact_m2);
    const WrenchBox box = GraspLimits(adopted, g).two_finger;
    EXPECT_EQ(box.force_N, adopted.two_finger.force_N);
    EXPECT_TRUE((box.torque_Nm.array() <= adopted.two_finger.torque_Nm.array()).all());
    EXPECT_LT((box.torque_Nm.array() / adopted.two_finger.torque_Nm.array()).minCoeff(), 1.0);
  }
  EXPECT_GT(on_plate, 0) << "no grasp holds the collar on its plate";
  EXPECT_GT(fingertip, 0);

  // Without reduced grasps, nothing holds the collar on its plate.
  PreprocessOptions full_only = Quick();
  full_only.two_finger.reduced = false;
  RunContext ctx2(5);
  auto pre2 = Preprocess(s.project, s.check, full_only, ctx2);
  ASSERT_TRUE(pre2) << pre2.error().message;
  for (const Grasp& g : SetOf(*pre2, "plate+collar").grasps) EXPECT_NE(g.part, 1);
}

// The reduced pass runs only for parts with too few full-pad grasps clear of their partner
// (ReducedGraspThreshold): the collar, not the plate, whose edges the fingers
// clear around the collar.
TEST(GraspTypes, OnlyPartsThatNeedThemGetReducedGrasps) {
  const Scene s = CollarOnPlate();
  const auto reduced_count = [](const GraspSet& set) {
    return set.candidates_by_type[static_cast<int>(GraspType::kPartialPad)] +
           set.candidates_by_type[static_cast<int>(GraspType::kFingertip)];
  };
  RunContext ctx(5);
  auto pre = Preprocess(s.project, s.check, Quick(), ctx);
  ASSERT_TRUE(pre) << pre.error().message;
  const int threshold = ReducedGraspThreshold(TwoFingerGraspOptions{}, pre->grasps_per_set);
  EXPECT_GT(threshold, 0);
  EXPECT_GE(SetOf(*pre, "plate").assembly_candidates_by_type[0], threshold);
  EXPECT_EQ(reduced_count(SetOf(*pre, "plate")), 0);
  EXPECT_LT(SetOf(*pre, "collar").assembly_candidates_by_type[0], threshold);
  EXPECT_GT(reduced_count(SetOf(*pre, "collar")), 0);

  // reduced_below_share = 0: no part needs them.
  PreprocessOptions never = Quick();
  never.two_finger.reduced_below_share = 0.0;
  RunContext ctx2(5);
  auto none = Preprocess(s.project, s.check, never, ctx2);
  ASSERT_TRUE(none) << none.error().message;
  for (const std::string name : {"plate", "collar", "plate+collar"}) {
    EXPECT_EQ(reduced_count(SetOf(*none, name)), 0) << name;
  }
}

TEST(GraspTypes, FullPadGraspsComeFirstAndStayAsTheyWere) {
  const Scene s = CollarOnPlate();
  RunContext a_ctx(9), b_ctx(9);
  auto with = Preprocess(s.project, s.check, Quick(), a_ctx);
  PreprocessOptions off = Quick();
  off.two_finger.reduced = false;
  auto without = Preprocess(s.project, s.check, off, b_ctx);
  ASSERT_TRUE(with && without);
  for (const std::string name : {"plate", "collar", "plate+collar"}) {
    const GraspSet& a = SetOf(*with, name);
    const GraspSet& b = SetOf(*without, name);
    ASSERT_LE(b.grasps.size(), a.grasps.size()) << name;
    for (size_t i = 0; i < a.grasps.size(); ++i) {
      if (i < b.grasps.size()) {
        EXPECT_TRUE(a.grasps[i].X_PG.matrix() == b.grasps[i].X_PG.matrix()) << name << " " << i;
        EXPECT_EQ(a.grasps[i].type, GraspType::kFullPad) << name << " " << i;
      } else {
        EXPECT_NE(a.grasps[i].type, GraspType::kFullPad) << name << " " << i;
      }
    }
  }
}

TEST(GraspTypes, SameSeedSameReducedGrasps) {
  const Scene s = CollarOnPlate();
  auto run = [&](bool parallel) {
    RunContext ctx(21);
    PreprocessOptions o = Quick();
    o.parallel = parallel;
    auto r = Preprocess(s.project, s.check, o, ctx);
    EXPECT_TRUE(r);
    return SetOf(*r, "plate+collar").grasps;
  };
  const auto a = run(true), b = run(true), c = run(false);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].X_PG.matrix() == b[i].X_PG.matrix()) << i;
    EXPECT_TRUE(a[i].X_PG.matrix() == c[i].X_PG.matrix()) << i << " (serial)";
    EXPECT_EQ(a[i].type, c[i].type);
    EXPECT_EQ(a[i].torque_scale, c[i].torque_scale);
  }
}

// A 0.5 kg bar held at one end from above (approach -z_W, closing x_W), its centre of mass
// 0.6 m along x: gravity's moment about the grasp's width axis (y_G) is 0.5 * 9.81 * 0.6 =
// 2.94 N m, inside the adopted 4.5 N m and outside a fingertip grasp's 0.4 * 4.5 = 1.8 N m.
TEST(GraspTypes, TheLpDecidesWhetherAReducedGraspSuffices) {
  const Iso3 X_WG = [] {
    Iso3 X = Iso3::Identity();
    X.linear() = Eigen::AngleAxisd(std::acos(-1.0), Vec3::UnitX()).toRotationMatrix();
    X.translation() = Vec3(0.0, 0.0, 1.0);
    return X;
  }();
  auto check = [&](const Vec3& torque_scale) {
    StepConfiguration c;
    c.bodies.push_back({"bar", 0.5, Vec3(0.6, 0.0, 1.0)});
    c.grippers.push_back(MakeGripper("r1", 0, X_WG, EndEffectorKind::kTwoFinger,
                                     GraspLimits(WrenchLimits{}, torque_scale)));
    WrenchQuery q;
    q.gate = WrenchGate::kTransport;
    q.accel_margin_mps2 = 0.0;
    auto r = CheckWrench(c, q);
    EXPECT_TRUE(r) << (r ? "" : r.error().message);
    return r ? r->feasible : false;
  };
  EXPECT_TRUE(check(Vec3::Ones())) << "full-pad";
  const Vec3 fingertip =
      GraspTorqueScale({3e-5, 8e-3, 4e-3}, kFullArea, Vec3::UnitX(), Vec3::UnitZ());
  EXPECT_NEAR(fingertip.y(), 0.4, 1e-12);
  EXPECT_FALSE(check(fingertip)) << "fingertip at the same pose";
}

// The threshold is a share of the set, so a larger set asks for more full-pad assembly grasps
// before it goes without reduced ones (the gamepad's slide has 4-10 of 256).
TEST(GraspTypes, ReducedGraspThresholdIsAShareOfTheSet) {
  TwoFingerGraspOptions options;
  EXPECT_EQ(ReducedGraspThreshold(options, 64), 16);
  EXPECT_EQ(ReducedGraspThreshold(options, 5), 2);
  EXPECT_EQ(ReducedGraspThreshold(options, 256), 64);
  options.reduced_below_share = 0.0;
  EXPECT_EQ(ReducedGraspThreshold(options, 64), 0);
  options.reduced_below_share = 1.0;
  EXPECT_EQ(ReducedGraspThreshold(options, 64), 64);
}

}  // namespace
}  // namespace wrap
