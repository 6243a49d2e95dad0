// The kinematics hot path allocates nothing: FK, Jacobian and the UR closed form run with the
// global operator new counting (its own binary, since it replaces operator new).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include "robot/catalog.h"
#include "robot/ik.h"
#include "robot/kinematics.h"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace wrap {
namespace {

TEST(KinematicsNoAlloc, FkJacobianAndUrIkAllocateNothing) {
  for (const char* model : {"ur5e", "openarm"}) {
    const Chain chain = *LoadRobotModel(model);
    std::mt19937_64 rng(1);
    std::vector<JointVector> qs;
    for (int i = 0; i < 64; ++i) qs.push_back(RandomConfiguration(chain, rng));
    std::vector<Iso3> X_WL(chain.dof() + 1);
    const Iso3 X_FT = Iso3(Eigen::Translation3d(0.0, 0.0, 0.15));
    Jacobian J;
    Iso3 X_WT;
    double sink = 0.0;
    const long before = g_allocations.load();
    for (const JointVector& q : qs) {
      ForwardKinematics(chain, Iso3::Identity(), q, X_WL);
      X_WT = TcpPose(chain, Iso3::Identity(), q, X_FT);
      TcpJacobian(chain, Iso3::Identity(), q, X_FT, &X_WT, &J);
      const JointVector near = NearestEquivalent(chain, ClampToLimits(chain, q), qs[0]);
      sink += X_WL.back().translation().x() + J(0, 0) + near[0] +
              JointDistanceMax(chain, q, near, true);
    }
    EXPECT_EQ(g_allocations.load() - before, 0) << model;
    EXPECT_TRUE(std::isfinite(sink));
  }
  const Chain ur5e = *LoadRobotModel("ur5e");
  const UrAnalyticIk ik = *UrAnalyticIk::FromChain(ur5e);
  std::mt19937_64 rng(2);
  std::vector<Iso3> targets;
  for (int i = 0; i < 64; ++i) {
    targets.push_back(FlangePose(ur5e, Iso3::Identity(), RandomConfiguration(ur5e, rng)));
  }
  int count = 0;
  const long before = g_allocations.load();
  for (const Iso3& X_BF : targets) count += ik.Solve(X_BF).count;
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(count, 64);
}

}  // namespace
}  // namespace wrap
