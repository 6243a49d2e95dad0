// Inverse kinematics: UR closed-form round trips on thousands of random configurations and at the
// singularities; numeric IK convergence on the OpenArm, agreement with the closed form on the UR,
// clean failures, joint limits and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>

#include "robot/catalog.h"
#include "robot/ik.h"
#include "robot/kinematics.h"
#include "test_util.h"

namespace wrap {
namespace {

using testing::LoadOrDie;
using testing::MakePose;
using testing::PositionError;
using testing::RotationError;

constexpr double kPi = std::numbers::pi;

UrAnalyticIk UrIkOrDie(const Chain& chain) {
  Result<UrAnalyticIk> ik = UrAnalyticIk::FromChain(chain);
  EXPECT_TRUE(ik.has_value()) << (ik ? "" : ik.error().message);
  return *ik;
}

// The smallest modulo-2pi distance from `q` to any solution.
double DistanceToSolutions(const Chain& chain, const UrIkSolutions& sols, const JointVector& q) {
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < sols.count; ++k) {
    best = std::min(best, JointDistanceMax(chain, sols.q[k], q, true));
  }
  return best;
}

void CheckSolutionsReproduce(const Chain& chain, const UrIkSolutions& sols, const Iso3& X_BF) {
  for (int k = 0; k < sols.count; ++k) {
    const Iso3 X = FlangePose(chain, Iso3::Identity(), sols.q[k]);
    EXPECT_LT(PositionError(X, X_BF), 1e-9) << "solution " << k;
    EXPECT_LT(RotationError(X, X_BF), 1e-9) << "solution " << k;
    EXPECT_TRUE(WithinLimits(chain, sols.q[k]));
    for (int j = 0; j < 6; ++j) {
      EXPECT_GT(sols.q[k][j], -kPi);  // Canonical angles in (-pi, pi].
      EXPECT_LE(sols.q[k][j], kPi);
    }
  }
}

void RoundTrip(const std::string& model, std::uint64_t seed) {
  const Chain chain = LoadOrDie(model);
  const UrAnalyticIk ik = UrIkOrDie(chain);
  std::mt19937_64 rng(seed);
  int total = 0;
  int eight = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    const JointVector q = RandomConfiguration(chain, rng);
    const Iso3 X_BF = FlangePose(chain, Iso3::Identity(), q);
    const UrIkSolutions sols = ik.Solve(X_BF);
    ASSERT_GE(sols.count, 1) << model << " trial " << trial;
    CheckSolutionsReproduce(chain, sols, X_BF);
    EXPECT_LT(DistanceToSolutions(chain, sols, q), 1e-7) << model << " trial " << trial;
    std::set<int> branches(sols.branch.begin(), sols.branch.begin() + sols.count);
    EXPECT_EQ(static_cast<int>(branches.size()), sols.count);
    total += sols.count;
    eight += sols.count == 8 ? 1 : 0;
  }
  // With the other shoulder branch the wrist is often out of the elbow's reach: about three in
  // four random poses have all eight solutions, the rest fewer (never zero: checked above).
  EXPECT_GT(eight, 2500) << model << ": " << total << " solutions in all";
}

TEST(UrAnalyticIk, RoundTripOnRandomConfigurationsUr5e) { RoundTrip("ur5e", 1); }
TEST(UrAnalyticIk, RoundTripOnRandomConfigurationsUr10e) { RoundTrip("ur10e", 2); }

TEST(UrAnalyticIk, ReadsTheDhLengthsAndRejectsOtherChains) {
  const UrAnalyticIk ik = UrIkOrDie(LoadOrDie("ur10e"));
  EXPECT_DOUBLE_EQ(ik.parameters().d1, 0.1807);
  EXPECT_DOUBLE_EQ(ik.parameters().a2, -0.6127);
  EXPECT_DOUBLE_EQ(ik.parameters().a3, -0.57155);
  EXPECT_DOUBLE_EQ(ik.parameters().d4, 0.17415);
  EXPECT_DOUBLE_EQ(ik.parameters().d5, 0.11985);
  EXPECT_DOUBLE_EQ(ik.parameters().d6, 0.11655);
  Result<UrAnalyticIk> openarm = UrAnalyticIk::FromChain(LoadOrDie("openarm"));
  ASSERT_FALSE(openarm.has_value());
  EXPECT_EQ(openarm.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(openarm.error().message.find("not a UR-class"), std::string::npos);
  Chain bent = LoadOrDie("ur5e");
  bent.joints[3].X_PJ.translation().z() = 0.01;
  Result<UrAnalyticIk> bad = UrAnalyticIk::FromChain(bent);
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("joint 4"), std::string::npos);
}

TEST(UrAnalyticIk, WristSingularityUsesTheGivenQ6) {
  const Chain chain = LoadOrDie("ur5e");
  const UrAnalyticIk ik = UrIkOrDie(chain);
  for (const double q5 : {0.0, kPi}) {
    JointVector q(6);
    q << 0.3, -1.2, 1.4, -0.7, q5, 0.9;
    const Iso3 X_BF = FlangePose(chain, Iso3::Identity(), q);
    UrIkOptions options;
    options.q6_if_singular = 0.9;
    const UrIkSolutions sols = ik.Solve(X_BF, options);
    ASSERT_GE(sols.count, 1);
    EXPECT_TRUE(sols.singular_wrist);
    CheckSolutionsReproduce(chain, sols, X_BF);
    EXPECT_LT(DistanceToSolutions(chain, sols, q), 1e-9);
    // Another q6 still reaches the pose (q4 absorbs the difference).
    options.q6_if_singular = -2.0;
    const UrIkSolutions other = ik.Solve(X_BF, options);
    ASSERT_GE(other.count, 1);
    CheckSolutionsReproduce(chain, other, X_BF);
  }
}

TEST(UrAnalyticIk, ElbowStretchedAndUnreachable) {
  const Chain chain = LoadOrDie("ur5e");
  const UrAnalyticIk ik = UrIkOrDie(chain);
  JointVector q(6);
  q << -0.4, -1.0, 0.0, 0.5, 1.1, -0.3;  // Elbow straight: the two elbow branches coincide.
  const Iso3 X_BF = FlangePose(chain, Iso3::Identity(), q);
  const UrIkSolutions sols = ik.Solve(X_BF);
  ASSERT_GE(sols.count, 1);
  CheckSolutionsReproduce(chain, sols, X_BF);
  EXPECT_LT(DistanceToSolutions(chain, sols, q), 1e-6);

  EXPECT_EQ(ik.Solve(MakePose(Vec3(2.0, 0.0, 0.5), Vec3::Zero())).count, 0);
  // Inside the cylinder of radius d4 around the base axis, with the tool pointing down.
  EXPECT_EQ(ik.Solve(MakePose(Vec3(0.0, 0.0, 0.4), Vec3(kPi, 0.0, 0.0))).count, 0);
}

TEST(UrAnalyticIk, TcpTargetsSubtractTheTool) {
  const Chain chain = LoadOrDie("ur5e");
  const UrAnalyticIk ik = UrIkOrDie(chain);
  const EndEffector gripper = *LoadEndEffector("robotiq_2f85");
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    const JointVector q = RandomConfiguration(chain, rng);
    const Iso3 X_BT = TcpPose(chain, Iso3::Identity(), q, gripper.X_FT);
    const UrIkSolutions sols = ik.SolveTcp(X_BT, gripper.X_FT);
    ASSERT_GE(sols.count, 1);
    for (int k = 0; k < sols.count; ++k) {
      const Iso3 X = TcpPose(chain, Iso3::Identity(), sols.q[k], gripper.X_FT);
      EXPECT_LT(PositionError(X, X_BT), 1e-9);
      EXPECT_LT(RotationError(X, X_BT), 1e-9);
    }
  }
}

TEST(NumericIk, OpenArmConvergesOnReachablePoses) {
  const Chain arm = LoadOrDie("openarm");
  const EndEffector hand = *LoadEndEffector("openarm_hand");
  std::mt19937_64 targets(21);
  std::mt19937_64 rng(22);
  NumericIkOptions options;
  options.restarts = 20;
  const int trials = 500;
  int solved = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const JointVector q = RandomConfiguration(arm, targets);
    NumericIkRequest request;
    request.X_BT = TcpPose(arm, Iso3::Identity(), q, hand.X_FT);
    request.X_FT = hand.X_FT;
    Result<NumericIkResult> result = SolveNumericIk(arm, request, rng, options);
    if (!result) continue;
    ++solved;
    EXPECT_TRUE(WithinLimits(arm, result->q));
    const Iso3 X = TcpPose(arm, Iso3::Identity(), result->q, hand.X_FT);
    EXPECT_LE(PositionError(X, request.X_BT), options.position_tolerance_m);
    EXPECT_LE(RotationError(X, request.X_BT), options.rotation_tolerance_rad);
    EXPECT_NEAR(result->position_error_m, PositionError(X, request.X_BT), 1e-12);
  }
  EXPECT_GE(solved, trials * 99 / 100) << solved << " of " << trials;
}

TEST(NumericIk, UrAgreesWithTheClosedForm) {
  const Chain chain = LoadOrDie("ur5e");
  const UrAnalyticIk ik = UrIkOrDie(chain);
  std::mt19937_64 targets(31);
  std::mt19937_64 rng(32);
  NumericIkOptions options;
  options.position_tolerance_m = 1e-10;
  options.rotation_tolerance_rad = 1e-10;
  options.restarts = 40;
  options.all_branches = true;
  for (int trial = 0; trial < 30; ++trial) {
    const JointVector q = RandomConfiguration(chain, targets);
    NumericIkRequest request;
    request.X_BT = FlangePose(chain, Iso3::Identity(), q);
    const UrIkSolutions analytic = ik.Solve(request.X_BT);
    Result<NumericIkResult> result = SolveNumericIk(chain, request, rng, options);
    ASSERT_TRUE(result.has_value()) << result.error().message;
    EXPECT_GE(result->branches.size(), 2u);
    for (const JointVector& branch : result->branches) {
      EXPECT_LT(DistanceToSolutions(chain, analytic, branch), 1e-6) << "trial " << trial;
    }
    // Seeded near the generating configuration, it returns that branch.
    JointVector seed = q;
    seed.array() += 0.05;
    request.seeds = {seed};
    NumericIkOptions one = options;
    one.all_branches = false;
    one.restarts = 0;
    result = SolveNumericIk(chain, request, rng, one);
    ASSERT_TRUE(result.has_value()) << result.error().message;
    EXPECT_LT((result->q - q).cwiseAbs().maxCoeff(), 1e-6);
  }
}

TEST(NumericIk, ReferencePicksTheNearestBranch) {
  const Chain chain = LoadOrDie("ur5e");
  std::mt19937_64 rng(41);
  JointVector q(6);
  q << -0.5, -1.3, 1.6, -1.9, -1.5, 0.4;
  NumericIkRequest request;
  request.X_BT = FlangePose(chain, Iso3::Identity(), q);
  // Same pose, another winding of joints 1 and 5 (both have +-2 pi).
  JointVector reference = q;
  reference[0] += 2 * kPi;
  reference[4] += 2 * kPi;
  request.reference = reference;
  NumericIkOptions options;
  options.all_branches = true;
  options.restarts = 30;
  Result<NumericIkResult> result = SolveNumericIk(chain, request, rng, options);
  ASSERT_TRUE(result.has_value()) << result.error().message;
  // The reference was the first start: its branch is found and, moved by 2 pi, comes first.
  EXPECT_LT((result->q - reference).cwiseAbs().maxCoeff(), 1e-3);
  for (std::size_t k = 1; k < result->branches.size(); ++k) {
    EXPECT_LE((result->branches[0] - reference).norm(), (result->branches[k] - reference).norm());
    EXPECT_TRUE(WithinLimits(chain, result->branches[k]));
  }
}

TEST(NumericIk, UnreachableTargetFailsCleanly) {
  const Chain arm = LoadOrDie("openarm");
  std::mt19937_64 rng(51);
  NumericIkRequest request;
  request.X_BT = MakePose(Vec3(2.0, 0.0, 0.3), Vec3::Zero());
  request.seeds = {ZeroConfiguration(arm)};
  NumericIkOptions options;
  options.restarts = 5;
  Result<NumericIkResult> result = SolveNumericIk(arm, request, rng, options);
  ASSERT_FALSE(result.has_value());
  EXPECT_EQ(result.error().code, ErrorCode::kInfeasible);
  const std::string& message = result.error().message;
  EXPECT_NE(message.find("openarm"), std::string::npos) << message;
  EXPECT_NE(message.find("xyz (2.0000, 0.0000, 0.3000)"), std::string::npos) << message;
  EXPECT_NE(message.find("6 starts"), std::string::npos) << message;
  EXPECT_NE(message.find("best residual"), std::string::npos) << message;
}

TEST(NumericIk, SeedsOutsideTheLimitsAreClampedAndSolutionsStayInside) {
  const Chain arm = LoadOrDie("openarm");
  std::mt19937_64 targets(61);
  std::mt19937_64 rng(62);
  JointVector outside = ZeroConfiguration(arm);
  outside[3] = -1.0;  // joint4 range is [0, 2.44].
  outside[5] = 2.0;   // joint6 range is +-0.785.
  for (int trial = 0; trial < 50; ++trial) {
    const JointVector q = RandomConfiguration(arm, targets);
    NumericIkRequest request;
    request.X_BT = FlangePose(arm, Iso3::Identity(), q);
    request.seeds = {outside};
    NumericIkOptions options;
    options.all_branches = true;
    options.restarts = 5;
    Result<NumericIkResult> result = SolveNumericIk(arm, request, rng, options);
    if (!result) continue;
    for (const JointVector& branch : result->branches) EXPECT_TRUE(WithinLimits(arm, branch));
  }
}

TEST(NumericIk, SameSeedSameAnswer) {
  const Chain arm = LoadOrDie("openarm");
  JointVector q(7);
  q << 0.4, 0.3, -0.2, 1.2, 0.1, 0.3, -0.5;
  NumericIkRequest request;
  request.X_BT = FlangePose(arm, Iso3::Identity(), q);
  NumericIkOptions options;
  options.all_branches = true;
  options.restarts = 8;
  std::mt19937_64 rng_a(99), rng_b(99);
  Result<NumericIkResult> a = SolveNumericIk(arm, request, rng_a, options);
  Result<NumericIkResult> b = SolveNumericIk(arm, request, rng_b, options);
  ASSERT_TRUE(a.has_value() && b.has_value());
  ASSERT_EQ(a->branches.size(), b->branches.size());
  for (std::size_t k = 0; k < a->branches.size(); ++k) EXPECT_EQ(a->branches[k], b->branches[k]);
  EXPECT_EQ(a->iterations, b->iterations);
  EXPECT_EQ(rng_a(), rng_b());
}

TEST(NumericIk, MaxBranchesStopsOnceEnoughAreFound) {
  const Chain arm = LoadOrDie("openarm");
  JointVector q(7);
  q << 0.4, 0.3, -0.2, 1.2, 0.1, 0.3, -0.5;
  NumericIkRequest request;
  request.X_BT = FlangePose(arm, Iso3::Identity(), q);
  NumericIkOptions all;
  all.all_branches = true;
  all.restarts = 20;
  std::mt19937_64 rng_all(7);
  Result<NumericIkResult> every = SolveNumericIk(arm, request, rng_all, all);
  ASSERT_TRUE(every.has_value()) << every.error().message;
  // A 7-DoF arm finds a new branch at almost every start.
  ASSERT_GT(every->branches.size(), 3u);
  NumericIkOptions capped = all;
  capped.max_branches = 3;
  std::mt19937_64 rng_capped(7);
  Result<NumericIkResult> few = SolveNumericIk(arm, request, rng_capped, capped);
  ASSERT_TRUE(few.has_value()) << few.error().message;
  EXPECT_EQ(few->branches.size(), 3u);
  EXPECT_LT(few->starts, every->starts);
  EXPECT_LT(few->iterations, every->iterations);
  for (const JointVector& branch : few->branches) {
    const Iso3 X = FlangePose(arm, Iso3::Identity(), branch);
    EXPECT_LE(PositionError(X, request.X_BT), capped.position_tolerance_m);
    EXPECT_TRUE(WithinLimits(arm, branch));
  }
}

TEST(NumericIk, GivesUpEarlyOnlyWhenTheFirstStartsEndFarAway) {
  const Chain arm = LoadOrDie("openarm");
  NumericIkOptions options;
  options.restarts = 40;
  options.give_up_after = 5;
  options.give_up_residual_m = 0.02;
  // Out of reach: the first five starts end far away, the other 35 are not run.
  NumericIkRequest far;
  far.X_BT = MakePose(Vec3(2.0, 0.0, 0.3), Vec3::Zero());
  std::mt19937_64 rng(81);
  Result<NumericIkResult> result = SolveNumericIk(arm, far, rng, options);
  ASSERT_FALSE(result.has_value());
  EXPECT_NE(result.error().message.find("5 starts"), std::string::npos) << result.error().message;
  // Without the early exit every start runs.
  NumericIkOptions patient = options;
  patient.give_up_after = 0;
  result = SolveNumericIk(arm, far, rng, patient);
  ASSERT_FALSE(result.has_value());
  EXPECT_NE(result.error().message.find("40 starts"), std::string::npos) << result.error().message;
  // Reachable targets: nearly all are solved as without the early exit (it needs every one of the
  // first five starts to end over 2 cm away; a few targets whose first starts all fall into far
  // local minima are lost, the price of not running 40 starts on every unreachable one).
  std::mt19937_64 targets(82);
  int solved = 0, solved_patient = 0;
  for (int trial = 0; trial < 200; ++trial) {
    NumericIkRequest request;
    request.X_BT = FlangePose(arm, Iso3::Identity(), RandomConfiguration(arm, targets));
    std::mt19937_64 rng_a(1000 + trial), rng_b(1000 + trial);
    solved += SolveNumericIk(arm, request, rng_a, options).has_value();
    solved_patient += SolveNumericIk(arm, request, rng_b, patient).has_value();
  }
  EXPECT_GE(solved_patient, 198);
  EXPECT_GE(solved, solved_patient - 6) << solved << " vs " << solved_patient << " of 200";
}

TEST(NumericIk, JointsHeldAtALimitStillReachTargetsNearTheLimit) {
  // Targets generated with joint 4 at its lower limit (0) and joint 6 at its upper limit: the
  // descent must hold those joints (the active set) and still converge with the rest.
  const Chain arm = LoadOrDie("openarm");
  std::mt19937_64 targets(71);
  std::mt19937_64 rng(72);
  NumericIkOptions options;
  options.restarts = 20;
  int solved = 0;
  const int trials = 100;
  for (int trial = 0; trial < trials; ++trial) {
    JointVector q = RandomConfiguration(arm, targets);
    q[3] = arm.joints[3].lower;
    q[5] = arm.joints[5].upper;
    NumericIkRequest request;
    request.X_BT = FlangePose(arm, Iso3::Identity(), q);
    Result<NumericIkResult> result = SolveNumericIk(arm, request, rng, options);
    if (!result) continue;
    ++solved;
    EXPECT_TRUE(WithinLimits(arm, result->q));
    const Iso3 X = FlangePose(arm, Iso3::Identity(), result->q);
    EXPECT_LE(PositionError(X, request.X_BT), options.position_tolerance_m);
    EXPECT_LE(RotationError(X, request.X_BT), options.rotation_tolerance_rad);
  }
  EXPECT_GE(solved, trials * 95 / 100) << solved << " of " << trials;
}

}  // namespace
}  // namespace wrap
