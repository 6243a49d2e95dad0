// Forward kinematics, Jacobian, UR closed-form IK and numeric IK on the catalog arms.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "robot/catalog.h"
#include "robot/ik.h"
#include "robot/kinematics.h"

namespace wrap {
namespace {

constexpr int kSamples = 1024;  // Inputs cycled through, so branch predictors see variety.

Chain Model(const char* name) {
  Result<Chain> chain = LoadRobotModel(name);
  if (!chain) {
    std::fprintf(stderr, "%s\n", chain.error().message.c_str());
    std::abort();
  }
  return *chain;
}

std::vector<JointVector> RandomConfigurations(const Chain& chain, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<JointVector> out;
  for (int i = 0; i < kSamples; ++i) out.push_back(RandomConfiguration(chain, rng));
  return out;
}

// TCP pose only (what IK and the planner's reachability checks use).
void ForwardKinematicsTcp(benchmark::State& state, const char* model) {
  const Chain chain = Model(model);
  const std::vector<JointVector> qs = RandomConfigurations(chain, 1);
  const Iso3 X_WB = Iso3::Identity();
  const Iso3 X_FT = Iso3(Eigen::Translation3d(0.0, 0.0, 0.15));
  int i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(TcpPose(chain, X_WB, qs[i], X_FT));
    i = (i + 1) % kSamples;
  }
}

// Every link frame (what the collision world needs).
void ForwardKinematicsLinks(benchmark::State& state, const char* model) {
  const Chain chain = Model(model);
  const std::vector<JointVector> qs = RandomConfigurations(chain, 2);
  std::vector<Iso3> X_WL(chain.dof() + 1);
  int i = 0;
  for (auto _ : state) {
    ForwardKinematics(chain, Iso3::Identity(), qs[i], X_WL);
    benchmark::DoNotOptimize(X_WL.data());
    benchmark::ClobberMemory();
    i = (i + 1) % kSamples;
  }
}

void ForwardKinematicsJacobian(benchmark::State& state, const char* model) {
  const Chain chain = Model(model);
  const std::vector<JointVector> qs = RandomConfigurations(chain, 3);
  Iso3 X_WT;
  Jacobian J;
  int i = 0;
  for (auto _ : state) {
    TcpJacobian(chain, Iso3::Identity(), qs[i], Iso3::Identity(), &X_WT, &J);
    benchmark::DoNotOptimize(J.data());
    benchmark::ClobberMemory();
    i = (i + 1) % kSamples;
  }
}

// All eight branches of a reachable flange pose.
void AnalyticIK(benchmark::State& state, const char* model) {
  const Chain chain = Model(model);
  const UrAnalyticIk ik = *UrAnalyticIk::FromChain(chain);
  std::vector<Iso3> targets;
  for (const JointVector& q : RandomConfigurations(chain, 4)) {
    targets.push_back(FlangePose(chain, Iso3::Identity(), q));
  }
  int i = 0;
  std::int64_t solutions = 0;
  for (auto _ : state) {
    const UrIkSolutions sols = ik.Solve(targets[i]);
    solutions += sols.count;
    benchmark::DoNotOptimize(sols.q[0].data());
    i = (i + 1) % kSamples;
  }
  state.counters["solutions"] =
      benchmark::Counter(static_cast<double>(solutions), benchmark::Counter::kAvgIterations);
}

// Numeric IK of a reachable TCP pose. `seeded`: started from a configuration 0.2 rad away from a
// solution (a planner's warm start); otherwise random restarts only (effort 10).
void NumericIK(benchmark::State& state, const char* model, bool seeded) {
  const Chain chain = Model(model);
  const std::vector<JointVector> qs = RandomConfigurations(chain, 5);
  const Iso3 X_FT = Iso3(Eigen::Translation3d(0.0, 0.0, 0.15));
  std::vector<NumericIkRequest> requests;
  std::mt19937_64 noise(6);
  std::uniform_real_distribution<double> offset(-0.2, 0.2);
  for (const JointVector& q : qs) {
    NumericIkRequest request;
    request.X_BT = TcpPose(chain, Iso3::Identity(), q, X_FT);
    request.X_FT = X_FT;
    if (seeded) {
      JointVector seed = q;
      for (int j = 0; j < seed.size(); ++j) seed[j] += offset(noise);
      request.seeds = {seed};
    }
    requests.push_back(std::move(request));
  }
  NumericIkOptions options;
  options.restarts = 10;
  std::mt19937_64 rng(7);
  int i = 0;
  std::int64_t failures = 0;
  std::int64_t iterations = 0;
  for (auto _ : state) {
    Result<NumericIkResult> result = SolveNumericIk(chain, requests[i], rng, options);
    if (result) {
      iterations += result->iterations;
    } else {
      ++failures;
    }
    i = (i + 1) % kSamples;
  }
  state.counters["failures"] =
      benchmark::Counter(static_cast<double>(failures), benchmark::Counter::kAvgIterations);
  state.counters["iterations"] =
      benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
}

BENCHMARK_CAPTURE(ForwardKinematicsTcp, UR5e, "ur5e");
BENCHMARK_CAPTURE(ForwardKinematicsTcp, OpenArm, "openarm");
BENCHMARK_CAPTURE(ForwardKinematicsLinks, UR5e, "ur5e");
BENCHMARK_CAPTURE(ForwardKinematicsLinks, OpenArm, "openarm");
BENCHMARK_CAPTURE(ForwardKinematicsJacobian, UR5e, "ur5e");
BENCHMARK_CAPTURE(ForwardKinematicsJacobian, OpenArm, "openarm");
BENCHMARK_CAPTURE(AnalyticIK, UR5e, "ur5e");
BENCHMARK_CAPTURE(AnalyticIK, UR10e, "ur10e");
BENCHMARK_CAPTURE(NumericIK, UR5e_Random, "ur5e", false);
BENCHMARK_CAPTURE(NumericIK, UR5e_Seeded, "ur5e", true);
BENCHMARK_CAPTURE(NumericIK, OpenArm_Random, "openarm", false);
BENCHMARK_CAPTURE(NumericIK, OpenArm_Seeded, "openarm", true);

}  // namespace
}  // namespace wrap
