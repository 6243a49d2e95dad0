// Full-cell collision and clearance timings: 4 UR5e-like arms with 2F-85-like grippers, 8 parts
// (two of them held) and the table. Link frames come from a small local DH FK computed before
// timing, so the figures are the collision world's cost: setting 4 configurations and one query.
//
//   BM_CellCollision        collision-free configurations: every candidate pair is examined
//                           (the worst case of a "no collision" answer; target < 50 us)
//   BM_CellCollisionRandom  uniform random configurations, mostly colliding (early exit)
//   BM_MinRobotClearance    minimum distance between the robots, collision-free configurations
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "robot/cell.h"

namespace wrap {
namespace {

constexpr double kPi = std::numbers::pi;
using Q = std::array<double, 6>;

Iso3 At(const Vec3& xyz, double yaw = 0.0) {
  Iso3 X = Iso3::Identity();
  X.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  X.translation() = xyz;
  return X;
}

Shape Capsule(const Vec3& p0, const Vec3& p1, double r, const char* name,
              Shape::Type type = Shape::Type::kCapsule) {
  Shape s;
  s.type = type;
  s.p0 = p0;
  s.p1 = p1;
  s.radius = r;
  s.name = name;
  return s;
}

Shape Box(const Vec3& c, const Vec3& h, const char* name) {
  Shape s;
  s.type = Shape::Type::kBox;
  s.X_LS.translation() = c;
  s.half_extents = h;
  s.name = name;
  return s;
}

// UR5e standard DH (ROBOTS.md 1.1): world frames of DH frames 0..6 for a base at X_WB.
void Ur5eFrames(const Q& q, const Iso3& X_WB, std::vector<Iso3>* X) {
  constexpr double d[6] = {0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996};
  constexpr double a[6] = {0.0, -0.425, -0.3922, 0.0, 0.0, 0.0};
  constexpr double alpha[6] = {kPi / 2, 0.0, 0.0, kPi / 2, -kPi / 2, 0.0};
  X->assign(7, X_WB);
  for (int i = 0; i < 6; ++i) {
    Iso3 T = Iso3::Identity();
    T.rotate(Eigen::AngleAxisd(q[i], Vec3::UnitZ()));
    T.translate(Vec3(a[i], 0.0, d[i]));
    T.rotate(Eigen::AngleAxisd(alpha[i], Vec3::UnitX()));
    (*X)[i + 1] = (*X)[i] * T;
  }
}

// UR5e links in DH frames with the capsules of ROBOTS.md 1.4.
Chain Ur5eChain() {
  Chain c;
  c.name = "ur5e";
  for (const char* n :
       {"base", "shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3"}) {
    c.links.push_back(Link{n, {}, {}});
  }
  c.links[0].collision = {
      Capsule({0, 0, 0}, {0, 0, 0.099}, 0.0755, "base", Shape::Type::kCylinder)};
  c.links[1].collision = {Capsule({0, -0.0995, 0}, {0, 0.0205, 0}, 0.060, "shoulder")};
  c.links[2].collision = {Capsule({0.425, 0, 0.158}, {0.425, 0, 0.038}, 0.060, "ua/housing"),
                          Capsule({0.425, 0, 0.138}, {0.025, 0, 0.138}, 0.050, "ua/tube")};
  c.links[3].collision = {Capsule({0.3922, 0, 0.147}, {0.3922, 0, 0.027}, 0.055, "fa/housing"),
                          Capsule({0.3822, 0, 0.007}, {0.0022, 0, 0.007}, 0.038, "fa/tube")};
  c.links[4].collision = {Capsule({0, -0.0063, 0}, {0, -0.1463, 0}, 0.040, "wrist_1")};
  c.links[5].collision = {Capsule({0, 0.1202, 0}, {0, 0, 0}, 0.040, "wrist_2/a"),
                          Capsule({0, 0, 0.0607}, {0, 0, -0.0193}, 0.040, "wrist_2/b")};
  c.links[6].collision = {
      Capsule({0, 0, 0.001}, {0, 0, -0.039}, 0.040, "wrist_3", Shape::Type::kCylinder)};
  for (int i = 0; i < 6; ++i) c.joints.push_back(Joint{});
  return c;
}

// A closed prism over an n-gon (radius r, height h, base on z = 0): a part-like mesh.
TriangleMesh Prism(double r, double h, int n) {
  TriangleMesh m;
  m.vertices.emplace_back(0, 0, 0);
  m.vertices.emplace_back(0, 0, h);
  for (int i = 0; i < n; ++i) {
    const double t = 2 * kPi * i / n;
    m.vertices.emplace_back(r * std::cos(t), r * std::sin(t), 0);
    m.vertices.emplace_back(r * std::cos(t), r * std::sin(t), h);
  }
  for (int i = 0; i < n; ++i) {
    const int b0 = 2 + 2 * i, t0 = b0 + 1, b1 = 2 + 2 * ((i + 1) % n), t1 = b1 + 1;
    m.triangles.emplace_back(0, b1, b0);
    m.triangles.emplace_back(1, t0, t1);
    m.triangles.emplace_back(b0, b1, t1);
    m.triangles.emplace_back(b0, t1, t0);
  }
  return m;
}

struct Scene {
  Cell cell;
  std::vector<std::array<std::vector<Iso3>, 4>> free;  // collision-free cell configurations
  std::vector<std::array<std::vector<Iso3>, 4>> random;
};

Scene* BuildScene() {
  CellDef def;
  def.table.size = Vec3(1.6, 1.2, 0.05);
  def.table.top_center = Vec3(0, 0, 0.75);
  const Q home = {0, -kPi / 2, kPi / 2, -kPi / 2, -kPi / 2, 0};
  const Vec3 bases[4] = {
      {0.6, 0.45, 0.75}, {-0.6, 0.45, 0.75}, {-0.6, -0.45, 0.75}, {0.6, -0.45, 0.75}};
  for (int r = 0; r < 4; ++r) {
    CellRobot robot;
    robot.name = "ur" + std::to_string(r);
    robot.chain = Ur5eChain();
    // The arm reaches along its base's -x at q1 = 0: face the table's centre.
    robot.X_WB = At(bases[r], std::atan2(bases[r].y(), bases[r].x()));
    robot.end_effector.name = "2f85";
    robot.end_effector.collision = {Box({0, 0, 0.045}, {0.045, 0.035, 0.045}, "body"),
                                    Box({0.0585, 0, 0.108}, {0.0158, 0.0135, 0.053}, "finger_r"),
                                    Box({-0.0585, 0, 0.108}, {0.0158, 0.0135, 0.053}, "finger_l")};
    robot.end_effector.X_FT = At(Vec3(0, 0, 0.1493));
    Ur5eFrames(home, robot.X_WB, &robot.reference_link_frames);
    def.robots.push_back(robot);
  }
  for (int k = 0; k < 8; ++k) {
    const double t = 2 * kPi * k / 8;
    const TriangleMesh mesh = k % 2 ? Prism(0.035, 0.08, 24) : Prism(0.05, 0.04, 6);
    def.objects.push_back(CellObject{"part" + std::to_string(k), mesh,
                                     At(Vec3(0.3 * std::cos(t), 0.3 * std::sin(t), 0.75))});
  }
  auto cell = Cell::Build(def);
  if (!cell) {
    std::fprintf(stderr, "cell: %s\n", cell.error().message.c_str());
    std::abort();
  }
  auto* scene = new Scene{std::move(*cell), {}, {}};
  // Robots 0 and 1 hold a part each, 2 cm into the fingers.
  for (int r = 0; r < 2; ++r) scene->cell.Attach(r, r, At(Vec3(0, 0, -0.02)));

  std::mt19937 rng(42);
  std::uniform_real_distribution<double> any(-kPi, kPi), up(-kPi, 0.0);
  std::array<std::vector<Iso3>, 4> frames;
  for (int trial = 0; trial < 200000 && scene->free.size() < 256; ++trial) {
    for (int r = 0; r < 4; ++r) {
      const Q q = {any(rng), up(rng), any(rng), any(rng), any(rng), any(rng)};
      Ur5eFrames(q, scene->cell.X_WB(r), &frames[r]);
      scene->cell.SetConfiguration(r, q, frames[r]);
    }
    if (scene->random.size() < 256) scene->random.push_back(frames);
    if (!scene->cell.InCollision()) scene->free.push_back(frames);
  }
  return scene;
}

Scene& GetScene() {
  static Scene* scene = BuildScene();
  return *scene;
}

void SetAll(Cell& cell, const std::array<std::vector<Iso3>, 4>& frames) {
  for (int r = 0; r < 4; ++r) cell.SetConfiguration(r, {}, frames[r]);
}

void BM_CellCollision(benchmark::State& state) {
  Scene& s = GetScene();
  CollisionResult result;
  std::size_t k = 0;
  long hits = 0, tests = 0;
  for (auto _ : state) {
    SetAll(s.cell, s.free[k]);
    hits += s.cell.InCollision(&result);
    tests += result.narrowphase_tests;
    k = (k + 1) % s.free.size();
  }
  state.counters["configs"] = static_cast<double>(s.free.size());
  state.counters["collide_frac"] = static_cast<double>(hits) / state.iterations();
  state.counters["narrowphase"] = static_cast<double>(tests) / state.iterations();
}
BENCHMARK(BM_CellCollision)->Unit(benchmark::kMicrosecond);

void BM_CellCollisionRandom(benchmark::State& state) {
  Scene& s = GetScene();
  CollisionResult result;
  std::size_t k = 0;
  long hits = 0;
  for (auto _ : state) {
    SetAll(s.cell, s.random[k]);
    hits += s.cell.InCollision(&result);
    k = (k + 1) % s.random.size();
  }
  state.counters["collide_frac"] = static_cast<double>(hits) / state.iterations();
}
BENCHMARK(BM_CellCollisionRandom)->Unit(benchmark::kMicrosecond);

void BM_MinRobotClearance(benchmark::State& state) {
  Scene& s = GetScene();
  std::size_t k = 0;
  double sum = 0.0;
  long tests = 0;
  for (auto _ : state) {
    SetAll(s.cell, s.free[k]);
    const DistanceResult d = s.cell.MinRobotClearance();
    sum += d.distance;
    tests += d.narrowphase_tests;
    k = (k + 1) % s.free.size();
  }
  state.counters["mean_clearance_m"] = sum / state.iterations();
  state.counters["narrowphase"] = static_cast<double>(tests) / state.iterations();
}
BENCHMARK(BM_MinRobotClearance)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace wrap
