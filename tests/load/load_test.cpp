// Load behaviour of the planner in one long-lived process, as the GUI and `wrap bench` use it:
// - runs cancelled at random moments (preprocessing, task planning, keyframes, motion) end
//   cancelled or with a complete plan, never hang, and leave the heap where it was;
// - every example project planned again and again keeps the heap flat and gives the same plan
//   for the same seed.
// Heap in use is glibc's mallinfo2 (under AddressSanitizer, which replaces malloc, it reads 0 and
// LeakSanitizer does the leak check instead).
#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <cstdlib>
#include <chrono>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "../task/planning_fixture.h"
#include "pipeline/pipeline.h"
#include "task/plan_json.h"

namespace wrap {
namespace {

using Clock = std::chrono::steady_clock;

double HeapInUseMiB() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks) / (1024.0 * 1024.0);
}

// Planning preprocesses and plans `lp` (motion unless task_only) under ctx.
Result<Plan> PlanOnce(const LoadedProject& lp, const fs::path& file, bool task_only,
                      RunContext& ctx) {
  PreprocessOptions pre_options;
  pre_options.project_file = file;
  auto pre = Preprocess(*lp.project, lp.check, pre_options, ctx);
  if (!pre) return std::unexpected(pre.error());
  PipelineOptions options;
  options.task.project_file = file;
  options.task_only = task_only;
  options.seed = 0;
  return PlanAssembly(*lp.project, lp.check, *pre, options, ctx);
}

// The plan without its timings (which differ from run to run).
std::string Timeless(Plan plan) {
  PlanStats& s = plan.stats;
  s.t_init_s = s.t_grasp_s = s.t_bwd_s = s.t_lp_s = s.t_fwd_s = s.t_ik_s = s.t_opt_s = 0.0;
  s.t_kf_s = s.t_mp_s = s.t_retime_s = 0.0;
  for (auto& [t, cost] : s.cost_history) t = 0.0;
  return SerializePlan(plan);
}

// 100 runs of the whole pipeline, each stopped after a random delay (0 to 0.6 s: through
// preprocessing, the task search, keyframe optimisation and motion). Each ends kCancelled or with
// a solved plan; the stop is answered (the latency is a measurement, printed here and
// benchmarked, not asserted; a hang would meet ctest's timeout); the heap comes back.
TEST(Load, CancelledAtRandomMomentsAlwaysStops) {
  const std::vector<std::string> names = {"half_stool", "cross", "stool"};
  std::vector<LoadedProject> projects;
  for (const std::string& n : names) {
    projects.push_back(LoadProject(ProjectFile(n)));
    ASSERT_TRUE(projects.back().ok()) << n;
  }
  std::mt19937_64 rng(20261123);
  std::uniform_real_distribution<double> delay_s(0.0, 0.6);
  std::vector<double> latency_ms;
  int cancelled = 0, finished = 0;
  double heap_after_warmup = 0.0;
  constexpr int kRuns = 100;
  constexpr int kWarmup = 10;
  for (int run = 0; run < kRuns; ++run) {
    const size_t k = static_cast<size_t>(run) % names.size();
    const double delay = delay_s(rng);
    RunContext ctx(static_cast<std::uint64_t>(run));
    ctx.set_time_limit_s(120.0);
    std::stop_source stop;
    ctx.set_stop_token(stop.get_token());
    Clock::time_point stopped_at{};
    Clock::time_point returned_at{};
    Result<Plan> plan = Fail(ErrorCode::kInternal, "not run");
    {
      std::jthread worker([&] {
        plan = PlanOnce(projects[k], ProjectFile(names[k]), false, ctx);
        returned_at = Clock::now();
      });
      std::this_thread::sleep_for(std::chrono::duration<double>(delay));
      stopped_at = Clock::now();
      stop.request_stop();
    }  // joins the worker
    if (plan) {
      // It finished before the stop (or at it, with its plan complete).
      EXPECT_TRUE(plan->stats.solved) << names[k] << " run " << run << ": " << plan->stats.failure;
      ++finished;
    } else {
      EXPECT_EQ(plan.error().code, ErrorCode::kCancelled)
          << names[k] << " run " << run << ": " << plan.error().message;
      ++cancelled;
      const double ms = std::chrono::duration<double, std::milli>(returned_at - stopped_at).count();
      latency_ms.push_back(ms);
    }
    if (run + 1 == kWarmup) heap_after_warmup = HeapInUseMiB();
  }
  const double heap_end = HeapInUseMiB();
  EXPECT_GT(cancelled, kRuns / 2) << "the delays should stop most runs midway";
  std::sort(latency_ms.begin(), latency_ms.end());
  if (!latency_ms.empty()) {
    std::printf("stop latency over %zu cancelled runs: median %.1f ms, max %.1f ms\n",
                latency_ms.size(), latency_ms[latency_ms.size() / 2], latency_ms.back());
  }
  std::printf("%d cancelled, %d finished first; heap in use %.2f MiB after %d runs, %.2f MiB "
              "after %d\n",
              cancelled, finished, heap_after_warmup, kWarmup, heap_end, kRuns);
  // Nothing a cancelled run allocated stays behind (beyond allocator noise).
  EXPECT_LT(heap_end - heap_after_warmup, 2.0);
}

// Example projects planned (task plan, seed 0) again and again in this process: the plan is the
// same every time and the heap in use does not grow after the first round. Every example project
// takes part; the quick ones (well under a second each) run 20 rounds, the five that take
// seconds run 2 (50 rounds of all ten take ~25 CPU minutes: WRAP_SOAK_ROUNDS=50 runs every project
// that many times, as `scripts/dev.sh soak` does).
void PlanRepeatedly(const std::vector<std::string>& candidates, int rounds) {
  if (const char* soak = std::getenv("WRAP_SOAK_ROUNDS")) rounds = std::max(1, std::atoi(soak));
  std::vector<std::string> names;
  std::vector<LoadedProject> projects;
  for (const std::string& n : candidates) {
    LoadedProject lp = LoadProject(ProjectFile(n));
    // The Fabrica projects read their meshes from ../shared/fabrica: skipped when it is absent.
    if (!lp.ok() && n.starts_with("fabrica")) continue;
    ASSERT_TRUE(lp.ok()) << n;
    names.push_back(n);
    projects.push_back(std::move(lp));
  }
  std::map<std::string, std::string> first;
  double heap_round1 = 0.0;
  double heap_peak = 0.0;
  for (int round = 0; round < rounds; ++round) {
    for (size_t k = 0; k < names.size(); ++k) {
      RunContext ctx(0);
      ctx.set_time_limit_s(300.0);
      auto plan = PlanOnce(projects[k], ProjectFile(names[k]), true, ctx);
      ASSERT_TRUE(plan.has_value()) << names[k] << ": " << plan.error().message;
      ASSERT_TRUE(plan->stats.solved) << names[k] << ": " << plan->stats.failure;
      const std::string text = Timeless(*plan);
      if (round == 0) {
        first[names[k]] = text;
      } else if (text != first[names[k]]) {
        ADD_FAILURE() << names[k] << ": round " << round << " planned differently from round 0";
      }
    }
    const double heap = HeapInUseMiB();
    if (round == 0) heap_round1 = heap;
    heap_peak = std::max(heap_peak, heap);
  }
  std::printf("%zu projects x %d rounds: heap in use %.2f MiB after round 1, peak %.2f MiB\n",
              names.size(), rounds, heap_round1, heap_peak);
  EXPECT_LT(heap_peak - heap_round1, 4.0);
}

TEST(Load, QuickProjectsPlannedTwentyTimesKeepMemoryFlatAndPlansTheSame) {
  PlanRepeatedly({"half_stool", "cross", "fabrica_beam", "fabrica_plumbers_block"}, 20);
}

// Busy threads, two per core, until destroyed: a machine loaded by other work.
class CpuHog {
 public:
  CpuHog() {
    const unsigned n = 2 * std::max(1u, std::thread::hardware_concurrency());
    for (unsigned i = 0; i < n; ++i) {
      threads_.emplace_back([](std::stop_token stop) {
        volatile double x = 1.0;
        while (!stop.stop_requested()) {
          for (int k = 0; k < 100000; ++k) x = x * 1.0000001 + 1e-9;
        }
      });
    }
  }

 private:
  std::vector<std::jthread> threads_;
};

// The same project, options and seed give the same plan, motion included, on a loaded machine:
// every search's budget is work (collision checks, poses tried, nodes expanded), not time. Each
// project is planned alone, then again with two busy threads per core beside it; no time limit
// (ctest's timeout catches a hang).
TEST(Load, SamePlanUnderACpuHog) {
  for (const std::string name : {"cross", "stool"}) {
    const LoadedProject lp = LoadProject(ProjectFile(name));
    ASSERT_TRUE(lp.ok()) << name;
    RunContext quiet_ctx(0);
    auto quiet = PlanOnce(lp, ProjectFile(name), false, quiet_ctx);
    ASSERT_TRUE(quiet.has_value()) << name << ": " << quiet.error().message;
    ASSERT_TRUE(quiet->stats.solved && quiet->stats.motion) << name << ": " << quiet->stats.failure;
    Result<Plan> loaded = Fail(ErrorCode::kInternal, "not run");
    double t_loaded = 0.0;
    {
      CpuHog hog;
      RunContext ctx(0);
      const auto t0 = Clock::now();
      loaded = PlanOnce(lp, ProjectFile(name), false, ctx);
      t_loaded = std::chrono::duration<double>(Clock::now() - t0).count();
    }
    ASSERT_TRUE(loaded.has_value()) << name << ": " << loaded.error().message;
    std::printf("%s: planned with motion in %.1f s beside the busy threads\n", name.c_str(),
                t_loaded);
    EXPECT_EQ(Timeless(*loaded), Timeless(*quiet))
        << name << ": the loaded machine planned differently";
  }
}

TEST(Load, SlowProjectsPlannedRepeatedlyKeepMemoryFlatAndPlansTheSame) {
#if defined(__SANITIZE_ADDRESS__)
  // Under ASan cross_openarm's task plan alone takes about 370 s on two cores (ExamplePlan plans
  // it in that build); twice more would not fit the test's 1500 s. The normal build plans it.
  PlanRepeatedly({"stool", "chair", "cube", "cube_2x2x3"}, 2);
#else
  PlanRepeatedly({"stool", "chair", "cross_openarm", "cube", "cube_2x2x3"}, 2);
#endif
}

}  // namespace
}  // namespace wrap
