// Steady-state queries allocate nothing: this binary counts every operator new, and a cell of
// capsules, cylinders, boxes and meshes is queried while moving after one warm-up round.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "robot/cell.h"
#include "scenes.h"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

#if defined(__SANITIZE_ADDRESS__)
// Under AddressSanitizer the allocation functions are its own: FCL's library allocates with
// them and FCL's inline destructors, compiled here, would free with ours (an
// alloc-dealloc-mismatch). Its allocator's hooks count every allocation instead.
// (The sanitizer runtime's interface; GCC ships no header declaring it.)
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*,
                                                                             std::size_t),
                                                         void (*free_hook)(const volatile void*));
namespace {
void CountAllocation(const volatile void*, std::size_t) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
}
void IgnoreFree(const volatile void*) {}
const int g_hooks = __sanitizer_install_malloc_and_free_hooks(CountAllocation, IgnoreFree);
}  // namespace
#else
// g++ 12 sees the malloc behind these replacements and warns that free() meets operator new.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

// Replacements of the global allocation functions for this test binary (counting only).
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#endif

namespace wrap {
namespace {

using testing::Pose;

TEST(NoAllocation, CellQueriesInSteadyState) {
  constexpr double kPi = std::numbers::pi;
  CellDef def;
  for (int r = 0; r < 2; ++r) {
    CellRobot robot;
    robot.name = "ur" + std::to_string(r);
    robot.chain = testing::Ur5eChain();  // capsules and cylinders
    robot.X_WB = Pose({r == 0 ? -0.6 : 0.6, 0, 0.75}, {0, 0, r == 0 ? 0.0 : kPi});
    robot.end_effector = testing::Gripper2f85();  // boxes
    robot.reference_link_frames =
        testing::Ur5eFrames({0, -kPi / 2, kPi / 2, -kPi / 2, -kPi / 2, 0}, robot.X_WB);
    def.robots.push_back(robot);
  }
  // Two meshes that touch each other (mesh-mesh narrowphase), resting on the table.
  for (int k = 0; k < 2; ++k) {
    def.objects.push_back(CellObject{"part" + std::to_string(k),
                                     testing::BoxMesh({-0.03, -0.03, 0}, {0.03, 0.03, 0.06}),
                                     testing::Translation(0.05 * k, 0.45, 0.75)});
  }
  auto cell = Cell::Build(def);
  ASSERT_TRUE(cell) << cell.error().message;

  // Configurations from apart to interlocked: every narrowphase path between arms.
  std::vector<std::array<double, 6>> qs;
  for (int k = 0; k < 16; ++k) {
    const double s = k / 15.0;
    qs.push_back(
        {kPi * s, -kPi / 2 + 1.2 * s, kPi / 2 - 0.9 * s, -kPi / 2 + 0.3 * s, -kPi / 2, 0.5 * s});
  }
  std::vector<std::vector<Iso3>> frames[2];
  for (int r = 0; r < 2; ++r) {
    for (const auto& q : qs) frames[r].push_back(testing::Ur5eFrames(q, cell->X_WB(r)));
  }
  CollisionResult result;
  result.pairs.reserve(64);
  CollisionRequest all;
  all.all_pairs = true;

  int collisions = 0;
  double clearance_sum = 0.0;
  auto round = [&] {
    for (std::size_t k = 0; k < qs.size(); ++k) {
      cell->SetConfiguration(0, qs[k], frames[0][k]);
      cell->SetConfiguration(1, qs[qs.size() - 1 - k], frames[1][qs.size() - 1 - k]);
      collisions += cell->InCollision(&result) ? 1 : 0;
      cell->InCollision(&result, all);
      clearance_sum += cell->MinRobotClearance().distance;
    }
  };
  round();  // warm-up: scratch buffers reach their size
  const long before = g_allocations.load();
  round();
  round();
  const long after = g_allocations.load();
  EXPECT_EQ(after - before, 0) << "allocations in steady-state queries";
  EXPECT_GT(collisions, 0);  // some configurations did collide (the hit paths ran)
  EXPECT_GT(clearance_sum, 0.0);
}

}  // namespace
}  // namespace wrap
