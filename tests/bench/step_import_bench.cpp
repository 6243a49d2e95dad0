// STEP import speed (engine/geometry/step_import.cpp): reading, tessellating and converting
// OpenCASCADE-written assemblies of growing size, and reopening one from the tessellation cache.
// Counters: parts (instances), solids (distinct products), triangles, and seconds per part.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>

#include "generator/step_designs.h"
#include "geometry/detail/step_isolation.h"
#include "geometry/step_cache.h"
#include "geometry/step_import.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

/// A folder of this process for the benchmark's STEP files and cache, removed at exit.
fs::path BenchDir() {
  struct Dir {
    fs::path path = fs::temp_directory_path() / ("wrap_step_bench_" + std::to_string(::getpid()));
    Dir() { fs::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

/// `products` distinct products (a plate with a row of holes and a pin, each a little different),
/// each instanced `copies` times side by side: a parts-bin assembly.
StepDocumentSpec Bin(int products, int copies) {
  using Kind = StepPrimitive::Kind;
  StepDocumentSpec spec;
  spec.name = "bin";
  for (int p = 0; p < products; ++p) {
    const double w = 0.04 + 0.002 * p;
    std::vector<StepPrimitive> plate = {
        {.kind = Kind::kBox, .origin = Vec3::Zero(), .size = Vec3(w, 0.03, 0.01)}};
    for (int h = 0; h < 3; ++h) {
      plate.push_back({.kind = Kind::kCylinder,
                       .subtract = true,
                       .origin = Vec3(0.01 + 0.01 * h, 0.015, -0.001),
                       .radius = 0.003,
                       .height = 0.012});
    }
    plate.push_back({.kind = Kind::kCylinder,
                     .origin = Vec3(w - 0.006, 0.015, 0.009),
                     .radius = 0.004,
                     .height = 0.02});
    spec.products.push_back({"plate_" + std::to_string(p), {plate}, std::nullopt});
    for (int c = 0; c < copies; ++c) {
      Iso3 X = Iso3::Identity();
      X.translation() = Vec3(0.1 * c, 0.06 * p, 0.0);
      spec.instances.push_back({"plate_" + std::to_string(p) + "_" + std::to_string(c + 1), p, X});
    }
  }
  return spec;
}

fs::path Written(const StepDocumentSpec& spec, const std::string& name) {
  const fs::path file = BenchDir() / name;
  if (!fs::exists(file)) {
    if (auto ok = WriteStep(spec, file); !ok) {
      std::fprintf(stderr, "step bench: %s\n", ok.error().message.c_str());
      std::abort();
    }
  }
  return file;
}

void Report(benchmark::State& state, const StepAssembly& a) {
  const double parts = static_cast<double>(a.instances.size());
  state.counters["parts"] = parts;
  state.counters["solids"] = static_cast<double>(a.solids.size());
  state.counters["triangles"] = a.triangles();
  state.counters["s_per_part"] = benchmark::Counter(
      parts, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

/// ImportStep (OpenCASCADE in a child process, as `wrap` reads STEP) or ImportStepInProcess.
enum class Where { kChild, kThisProcess };

void Import(benchmark::State& state, const fs::path& file, const StepTessellation& t = {},
            Where where = Where::kChild) {
  StepAssembly last;
  for (auto _ : state) {
    auto a = where == Where::kChild ? ImportStep(file, t) : ImportStepInProcess(file, t);
    if (!a) {
      state.SkipWithError(a.error().message.c_str());
      return;
    }
    last = std::move(*a);
  }
  Report(state, last);
}

// The example project's stool: 2 products, 5 parts.
void BM_StepImportStool(benchmark::State& state) {
  Import(state, Written(partgen::StepStoolSpec(), "stool.step"));
}
BENCHMARK(BM_StepImportStool)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same in this process: the difference is the child process's cost.
void BM_StepImportStoolInProcess(benchmark::State& state) {
  Import(state, Written(partgen::StepStoolSpec(), "stool.step"), {}, Where::kThisProcess);
}
BENCHMARK(BM_StepImportStoolInProcess)->Unit(benchmark::kMillisecond)->UseRealTime();

// The child process alone: fork, a one-solid answer through the pipe, wait.
void BM_StepChildProcessOverhead(benchmark::State& state) {
  std::mutex held;
  StepAssembly tiny;
  tiny.solids.push_back({.name = "s", .product = "s", .entity = "#1", .mesh = {}});
  tiny.solids[0].mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  tiny.solids[0].mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  tiny.instances.push_back({.name = "s", .solid = 0});
  for (auto _ : state) {
    auto a = detail::ImportInChild(
        "tiny.step", [&] { return Result<StepAssembly>(tiny); }, held);
    if (!a) {
      state.SkipWithError(a.error().message.c_str());
      return;
    }
    benchmark::DoNotOptimize(a);
  }
}
BENCHMARK(BM_StepChildProcessOverhead)->Unit(benchmark::kMillisecond)->UseRealTime();

// The stool with a finer tessellation (0.01 mm, 10 degrees).
void BM_StepImportStoolFine(benchmark::State& state) {
  Import(state, Written(partgen::StepStoolSpec(), "stool.step"),
         {.linear_deflection_m = 1e-5, .angular_deflection_rad = 0.1745});
}
BENCHMARK(BM_StepImportStoolFine)->Unit(benchmark::kMillisecond)->UseRealTime();

// Parts bins: products x copies.
void BM_StepImportBin(benchmark::State& state) {
  const int products = static_cast<int>(state.range(0));
  const int copies = static_cast<int>(state.range(1));
  Import(state, Written(Bin(products, copies), "bin_" + std::to_string(products) + "x" +
                                                   std::to_string(copies) + ".step"));
}
BENCHMARK(BM_StepImportBin)
    ->Args({10, 1})
    ->Args({10, 5})
    ->Args({40, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A reopen: the 40-product bin read back from the disk cache (no OpenCASCADE at all).
void BM_StepReopenFromCache(benchmark::State& state) {
  const fs::path file = Written(Bin(40, 1), "bin_40x1.step");
  const StepLoadOptions options{.cache_dir = BenchDir() / "cache"};
  if (!LoadStep(file, options)) state.SkipWithError("first load failed");
  StepAssembly copy;
  for (auto _ : state) {
    ClearStepMemoryCache();
    auto load = LoadStep(file, options);
    if (!load || load->source != StepSource::kDiskCache) {
      state.SkipWithError("not served from the disk cache");
      return;
    }
    copy = *load->assembly;
  }
  Report(state, copy);
}
BENCHMARK(BM_StepReopenFromCache)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace wrap
