// Forward kinematics and Jacobians: known poses from the fact sheet, an independent DH product,
// finite differences.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "robot/catalog.h"
#include "robot/kinematics.h"
#include "test_util.h"

namespace wrap {
namespace {

using testing::LoadOrDie;
using testing::MakePose;
using testing::PositionError;
using testing::RotationError;

constexpr double kPi = std::numbers::pi;

TEST(Kinematics, UrFlangeAtZeroMatchesTheFactSheet) {
  const Chain ur5e = LoadOrDie("ur5e");
  const Iso3 X_BF5 = FlangePose(ur5e, Iso3::Identity(), ZeroConfiguration(ur5e));
  EXPECT_LT((X_BF5.translation() - Vec3(-0.8172, -0.2329, 0.0628)).norm(), 1e-12);
  const Chain ur10e = LoadOrDie("ur10e");
  const Iso3 X_BF10 = FlangePose(ur10e, Iso3::Identity(), ZeroConfiguration(ur10e));
  EXPECT_LT((X_BF10.translation() - Vec3(-1.18425, -0.2907, 0.06085)).norm(), 1e-12);
  // At q = 0 the flange z axis points along -y of the base (wrist 2 turned by alpha5 = -pi/2).
  EXPECT_TRUE(X_BF5.linear().col(2).isApprox(Vec3(0.0, -1.0, 0.0), 1e-12));
}

// The chain built from DH rows equals the textbook product T_1 ... T_6.
TEST(Kinematics, UrMatchesAnIndependentDhProduct) {
  const Chain ur5e = LoadOrDie("ur5e");
  const double d[6] = {0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996};
  const double a[6] = {0.0, -0.425, -0.3922, 0.0, 0.0, 0.0};
  const double alpha[6] = {kPi / 2, 0.0, 0.0, kPi / 2, -kPi / 2, 0.0};
  std::mt19937_64 rng(7);
  std::vector<Iso3> X_BL(7);
  for (int trial = 0; trial < 100; ++trial) {
    const JointVector q = RandomConfiguration(ur5e, rng);
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    ForwardKinematics(ur5e, Iso3::Identity(), q, X_BL);
    for (int i = 0; i < 6; ++i) {
      const double ct = std::cos(q[i]), st = std::sin(q[i]);
      const double ca = std::cos(alpha[i]), sa = std::sin(alpha[i]);
      Eigen::Matrix4d Ti;
      Ti << ct, -st * ca, st * sa, a[i] * ct,  //
          st, ct * ca, -ct * sa, a[i] * st,    //
          0, sa, ca, d[i],                     //
          0, 0, 0, 1;
      T = T * Ti;
    }
    const Iso3 X_BF = FlangePose(ur5e, Iso3::Identity(), q);
    EXPECT_LT((X_BF.matrix() - T).cwiseAbs().maxCoeff(), 1e-12);
    // The last link's frame times X_LF is the flange.
    EXPECT_LT(((X_BL[6] * ur5e.X_LF).matrix() - T).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(Kinematics, OpenArmZeroPoseMatchesTheFactSheet) {
  const Chain arm = LoadOrDie("openarm");
  std::vector<Iso3> X_BL(8);
  ForwardKinematics(arm, Iso3::Identity(), ZeroConfiguration(arm), X_BL);
  const Vec3 expected[8] = {{0, 0, 0},           {0, 0, 0.0625},      {-0.0301, 0, 0.1225},
                            {0, 0, 0.18875},     {0, 0.0315, 0.3425}, {0, 0, 0.438},
                            {0.0375, 0, 0.5585}, {0, 0, 0.5585}};
  for (int i = 0; i < 8; ++i) {
    EXPECT_LT((X_BL[i].translation() - expected[i]).norm(), 1e-12) << "link" << i;
    EXPECT_TRUE(X_BL[i].linear().isIdentity(1e-12));
  }
  const EndEffector hand = *LoadEndEffector("openarm_hand");
  const Iso3 X_BT = TcpPose(arm, Iso3::Identity(), ZeroConfiguration(arm), hand.X_FT);
  EXPECT_LT((X_BT.translation() - Vec3(0.0, -0.0045, 0.7386)).norm(), 1e-5);
}

TEST(Kinematics, BasePoseAndTcpCompose) {
  const Chain arm = LoadOrDie("openarm");
  std::mt19937_64 rng(3);
  const Iso3 X_WB = MakePose(Vec3(0.3, -0.2, 0.75), Vec3(0.1, -0.4, 2.0));
  const Iso3 X_FT = MakePose(Vec3(0.01, -0.02, 0.15), Vec3(0.3, 0.0, -0.2));
  for (int trial = 0; trial < 20; ++trial) {
    const JointVector q = RandomConfiguration(arm, rng);
    const Iso3 expected = X_WB * FlangePose(arm, Iso3::Identity(), q) * X_FT;
    const Iso3 X_WT = TcpPose(arm, X_WB, q, X_FT);
    EXPECT_LT((X_WT.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-12);
    Iso3 X_WT_jac;
    TcpJacobian(arm, X_WB, q, X_FT, &X_WT_jac, nullptr);
    EXPECT_LT((X_WT_jac.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

// Central differences of the TCP pose: linear rows from positions, angular rows from the
// rotation vector of R(q + h) R(q - h)^T.
void CheckJacobian(const Chain& chain, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Iso3 X_WB = MakePose(Vec3(0.5, 0.1, 0.7), Vec3(0.2, 0.3, -1.0));
  const Iso3 X_FT = MakePose(Vec3(0.0, 0.02, 0.15), Vec3(0.0, 0.0, 0.5));
  const double h = 1e-6;
  for (int trial = 0; trial < 50; ++trial) {
    const JointVector q = RandomConfiguration(chain, rng);
    Jacobian J;
    TcpJacobian(chain, X_WB, q, X_FT, nullptr, &J);
    ASSERT_EQ(J.cols(), chain.dof());
    for (int i = 0; i < chain.dof(); ++i) {
      JointVector plus = q, minus = q;
      plus[i] += h;
      minus[i] -= h;
      const Iso3 Xp = TcpPose(chain, X_WB, plus, X_FT);
      const Iso3 Xm = TcpPose(chain, X_WB, minus, X_FT);
      const Vec3 v = (Xp.translation() - Xm.translation()) / (2 * h);
      const Eigen::AngleAxisd dR(Xp.linear() * Xm.linear().transpose());
      const Vec3 w = dR.angle() * dR.axis() / (2 * h);
      EXPECT_LT((J.col(i).head<3>() - v).norm(), 1e-7) << chain.name << " joint " << i;
      EXPECT_LT((J.col(i).tail<3>() - w).norm(), 1e-7) << chain.name << " joint " << i;
    }
  }
}

TEST(Kinematics, JacobianMatchesFiniteDifferences) {
  CheckJacobian(LoadOrDie("ur5e"), 11);
  CheckJacobian(LoadOrDie("ur10e"), 12);
  CheckJacobian(LoadOrDie("openarm"), 13);
  // A prismatic joint and a skewed axis.
  Chain chain;
  chain.name = "rp";
  chain.links.resize(3);
  Joint slide;
  slide.type = Joint::Type::kPrismatic;
  slide.axis = Vec3(1.0, 1.0, 0.0).normalized();
  slide.lower = -0.5;
  slide.upper = 0.5;
  Joint turn;
  turn.X_PJ = MakePose(Vec3(0.1, 0.0, 0.3), Vec3(0.4, 0.0, 0.0));
  turn.axis = Vec3(0.0, 1.0, 1.0).normalized();
  chain.joints = {slide, turn};
  chain.X_LF = MakePose(Vec3(0.0, 0.0, 0.2), Vec3::Zero());
  CheckJacobian(chain, 14);
}

TEST(Kinematics, LimitsRandomAndEquivalents) {
  const Chain ur5e = LoadOrDie("ur5e");
  std::mt19937_64 a(42), b(42);
  for (int i = 0; i < 100; ++i) {
    const JointVector qa = RandomConfiguration(ur5e, a);
    const JointVector qb = RandomConfiguration(ur5e, b);
    EXPECT_EQ(qa, qb);
    EXPECT_TRUE(WithinLimits(ur5e, qa));
  }
  JointVector q = ZeroConfiguration(ur5e);
  q[2] = 4.0;
  EXPECT_FALSE(WithinLimits(ur5e, q));
  EXPECT_DOUBLE_EQ(ClampToLimits(ur5e, q)[2], 3.141593);

  // 2 pi equivalents toward a reference, inside the limits.
  JointVector reference = ZeroConfiguration(ur5e);
  reference[0] = 6.0;
  q = ZeroConfiguration(ur5e);
  q[0] = -0.1;
  q[2] = 3.0;
  reference[2] = -3.0;
  const JointVector near = NearestEquivalent(ur5e, q, reference);
  EXPECT_NEAR(near[0], 2 * kPi - 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(near[2], 3.0);  // 3 - 2 pi is outside the elbow's +-pi.
  EXPECT_NEAR(JointDistanceMax(ur5e, near, q, true), 0.0, 1e-12);
  EXPECT_NEAR(WrapToPi(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(WrapToPi(-kPi), kPi, 1e-12);
  EXPECT_NEAR(WrapToPi(-0.5), -0.5, 1e-15);
}

}  // namespace
}  // namespace wrap
