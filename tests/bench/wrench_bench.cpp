// The wrench LP (paper §IV-A): a robust check of a two-part step held by two grippers with the
// base on the table (16 vertices of U), with our dense simplex and with Clp, and cached answers.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>

#include "wrench/wrench.h"

namespace wrap {
namespace {

Iso3 At(const Vec3& p, const Mat3& R = Mat3::Identity()) {
  Iso3 X = Iso3::Identity();
  X.linear() = R;
  X.translation() = p;
  return X;
}

// A leg (0.3 kg, held by a two-finger gripper) pressed down into a seat (1 kg) that rests on the
// table (4-vertex polygon, pyramids of `pyramid_edges`) and is braced by a second two-finger
// gripper; 10 N along -z with 10% transverse force and a 2 mm offset: 16 vertices, all feasible.
StepConfiguration RobustStep(int pyramid_edges) {
  StepConfiguration c;
  c.bodies.push_back({"seat", 1.0, Vec3(0.4, 0.1, 0.8)});
  c.bodies.push_back({"leg", 0.3, Vec3(0.41, 0.11, 0.95)});
  WrenchTableSupport table;
  table.body = 0;
  table.p_WV = {Vec3(0.5, 0.2, 0.75), Vec3(0.3, 0.2, 0.75), Vec3(0.3, 0.0, 0.75),
                Vec3(0.5, 0.0, 0.75)};
  table.friction = 0.4;
  table.pyramid_edges = pyramid_edges;
  c.tables.push_back(table);
  const WrenchLimits limits;
  c.grippers.push_back(MakeGripper(
      "r1", 1, At(Vec3(0.41, 0.11, 1.0), Eigen::AngleAxisd(3.0, Vec3::UnitX()).toRotationMatrix()),
      EndEffectorKind::kTwoFinger, limits));
  c.grippers.push_back(MakeGripper(
      "r2", 0, At(Vec3(0.5, 0.1, 0.8), Eigen::AngleAxisd(1.5, Vec3::UnitY()).toRotationMatrix()),
      EndEffectorKind::kTwoFinger, limits));
  MatingLoad m;
  m.moved = 1;
  m.base = 0;
  m.axis_W = -Vec3::UnitZ();
  m.p_WContact = Vec3(0.4, 0.1, 0.85);
  m.force_N = 10.0;
  m.transverse_fraction = 0.1;
  m.offset_m = 0.002;
  c.mating = m;
  return c;
}

void Require(const Result<WrenchCheck>& r) {
  if (!r || !r->feasible || r->vertex_count != 16) {
    std::fprintf(stderr, "wrench bench scene is not the intended one: %s\n",
                 r ? r->reason.c_str() : r.error().message.c_str());
    std::abort();
  }
}

// One robust check, solved every time: 16 load-factor LPs of 12 rows. `verdict_only`: the
// planner's fast path (first_failure_suffices: the load factor capped at 1, a vertex's final
// basis tried first for the next).
void BM_WrenchLpRobust(benchmark::State& state, WrenchLpBackend backend, int pyramid_edges,
                       bool verdict_only) {
  const StepConfiguration c = RobustStep(pyramid_edges);
  WrenchOptions options;
  options.backend = backend;
  options.first_failure_suffices = verdict_only;
  WrenchChecker checker(options);
  Require(checker.Check(c));
  for (auto _ : state) {
    Result<WrenchCheck> r = checker.Check(c);
    benchmark::DoNotOptimize(r);
  }
  state.counters["vertices"] = 16;
}
BENCHMARK_CAPTURE(BM_WrenchLpRobust, dense, WrenchLpBackend::kDense, 8, false);  // The default.
BENCHMARK_CAPTURE(BM_WrenchLpRobust, dense_pyramid4, WrenchLpBackend::kDense, 4, false);
BENCHMARK_CAPTURE(BM_WrenchLpRobust, dense_verdict, WrenchLpBackend::kDense, 8, true);
BENCHMARK_CAPTURE(BM_WrenchLpRobust, clp, WrenchLpBackend::kClp, 8, false);

// A cached answer through the canonical key (encode, hash, compare, copy the answer out).
void BM_WrenchLpCached(benchmark::State& state) {
  const StepConfiguration c = RobustStep(8);
  WrenchChecker checker;
  Require(checker.CheckCached(c));
  for (auto _ : state) {
    Result<WrenchCheck> r = checker.CheckCached(c);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_WrenchLpCached);

// A cached answer through a key the caller computed (grasp ids, placement, mating, mode).
void BM_WrenchLpCachedCallerKey(benchmark::State& state) {
  const StepConfiguration c = RobustStep(8);
  WrenchChecker checker;
  Require(checker.CheckCached(0x5eed, c));
  for (auto _ : state) {
    Result<WrenchCheck> r = checker.CheckCached(0x5eed, c);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_WrenchLpCachedCallerKey);

}  // namespace
}  // namespace wrap
