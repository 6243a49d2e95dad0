// The best split of a held object's load among its supports (verify/detail/best_split.h), on
// hand-computed cases: a 0.1 m block with its centre O as the reference point, the table under
// its bottom face (support points at the corners, z = -0.05 m), the project's default limits.
#include <gtest/gtest.h>

#include <memory>

#include "verify/detail/best_split.h"

namespace wrap::detail {
namespace {

// A gripper at `p` (relative to O) with grasp axes `R` (columns: G's axes in the world).
SplitHolder Holder(const Vec3& p, const Mat3& R, bool vacuum) {
  SplitHolder h;
  h.A = GraspWrenchToWorld(R, p);
  h.vacuum = vacuum;
  return h;
}

std::vector<Vec3> BottomCorners() {
  return {Vec3(-0.05, -0.05, -0.05), Vec3(0.05, -0.05, -0.05), Vec3(0.05, 0.05, -0.05),
          Vec3(-0.05, 0.05, -0.05)};
}

Vec6 Wrench(double fx, double fy, double fz) {
  Vec6 w;
  w << fx, fy, fz, 0.0, 0.0, 0.0;
  return w;
}

class BestSplitTest : public ::testing::Test {
 protected:
  std::optional<std::vector<double>> Split(const SplitQuery& q) {
    return BestSplit(q, *backend_, problem_, solution_);
  }
  std::unique_ptr<LpBackend> backend_ = MakeDenseSimplexBackend();
  LpProblem problem_;
  LpSolution solution_;
};

// One gripper and nothing else: its wrench is determined (the weld's measurement is the answer).
TEST_F(BestSplitTest, SingleSupportHasNoSplit) {
  SplitQuery q;
  q.holders.push_back(Holder(Vec3(0, 0, 0.05), Mat3::Identity(), false));
  q.whole = Wrench(0, 0, 10);
  EXPECT_FALSE(Split(q).has_value());
  q.holders.clear();
  q.support_points = BottomCorners();
  EXPECT_FALSE(Split(q).has_value()) << "no gripper: nothing to judge";
}

// A block held at its top while it rests on the table: the table can carry its weight alone.
TEST_F(BestSplitTest, TheTableCarriesTheWeightOfAHeldBlock) {
  SplitQuery q;
  q.holders.push_back(Holder(Vec3(0, 0, 0.05), Mat3::Identity(), false));
  q.support_points = BottomCorners();
  q.whole = Wrench(0, 0, 10);
  auto u = Split(q);
  ASSERT_TRUE(u.has_value());
  EXPECT_LT((*u)[0], 0.002);
}

// The same block pushed along -x by 6 N at O: friction gives 0.4 (10 N + what the gripper
// presses down, d) and the gripper pushes along +x by g. The least max(g, d) / 50 N (the
// two-finger box along x and z) has g = d = t with t + 0.4 (10 + t) = 6: t = 2 / 1.4 N,
// u = t / 50 = 0.028571.
TEST_F(BestSplitTest, AGripperPressingOnTheTableNeedsLessThanPushingAlone) {
  SplitQuery q;
  q.holders.push_back(Holder(Vec3(0, 0, 0.05), Mat3::Identity(), false));
  q.support_points = BottomCorners();
  q.friction = 0.4;
  q.whole = Wrench(6, 0, 10);
  auto u = Split(q);
  ASSERT_TRUE(u.has_value());
  const double expected = (2.0 / 1.4) / 50.0;
  EXPECT_GE((*u)[0], expected - 1e-6);
  EXPECT_LE((*u)[0], expected + 1.1e-3);  // bisection to 0.1% absolute
}

// Two two-finger grippers at x = -+0.1 m carry 60 N between them, no table: the best split is
// 30 N each (anything else loads one more; no torque needed), 30 / 50 = 60% of their z bound.
TEST_F(BestSplitTest, TwoGrippersShareAHeavyLoadEvenly) {
  SplitQuery q;
  q.holders.push_back(Holder(Vec3(-0.1, 0, 0), Mat3::Identity(), false));
  q.holders.push_back(Holder(Vec3(0.1, 0, 0), Mat3::Identity(), false));
  q.whole = Wrench(0, 0, 60);
  auto u = Split(q);
  ASSERT_TRUE(u.has_value());
  ASSERT_EQ(u->size(), 2u);
  EXPECT_NEAR((*u)[0], 0.6, 0.004);
  EXPECT_NEAR((*u)[1], 0.6, 0.004);
  // 120 N is beyond the two: each at 120%.
  q.whole = Wrench(0, 0, 120);
  u = Split(q);
  ASSERT_TRUE(u.has_value());
  EXPECT_NEAR((*u)[0], 1.2, 0.008);
  EXPECT_NEAR((*u)[1], 1.2, 0.008);
}

// A suction cup on the block's -y face (its axis along +y) while an insertion pushes the block
// along -x with 10 N (its weight 2.8 N): while mating, the cup takes no lateral force, but held
// as before the insertion it may press the block onto the table within its transport box, and
// friction then takes the mating force. Without friction nothing can: only the cup's floor of
// 1 N lateral, so lambda = 10.
TEST_F(BestSplitTest, ACupSlidingABlockAlongTheTableHoldsByPressingItDown) {
  Mat3 R;  // G's x along world x, y along -z, z along +y (into the block)
  R << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  SplitQuery q;
  q.holders.push_back(Holder(Vec3(0, -0.05, 0), R, true));
  q.support_points = BottomCorners();
  q.friction = 0.4;
  q.whole = Wrench(10, 0, 2.8);
  q.mating = Wrench(10, 0, 0);
  auto u = Split(q);
  ASSERT_TRUE(u.has_value());
  EXPECT_LT((*u)[0], 0.5);
  EXPECT_GT((*u)[0], 0.05) << "it must press: the weight alone gives 1.1 N of friction";
  q.friction = 0.0;
  u = Split(q);
  ASSERT_TRUE(u.has_value());
  EXPECT_NEAR((*u)[0], 10.0, 0.06);
}

}  // namespace
}  // namespace wrap::detail
