// Geometry-check timings on the example projects' real meshes (Fabrica ones when ../shared is
// beside the repository):
//
//   BM_InsertionSweep/P/S  one step's insertion path swept into its mating pose (the exact sweep of
//                          a translation on the inset meshes), the sweep trees already built: what
//                          validation and the planner pay per step (target < 50 ms)
//   BM_ContactGraph/P      the whole contact graph of a project (distance and surface samples)
//   BM_InsetTrees/P        building the inset meshes' FCL trees of every part (once per run, for
//                          the checks that replay a plan: OverlapBeyond)
//   BM_SweepTrees/P        building the inset meshes and their sweep trees of every part, one
//                          depth (once per run and depth, for the insertion sweeps)
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "mating/check.h"
#include "model/project_io.h"
#include "model/validate.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kProjects = {
    "stool", "chair", "cube_2x2x3", "fabrica_beam", "fabrica_plumbers_block", "fabrica_car"};

struct Loaded {
  LoadedProject project;
  bool ok = false;
};

const Loaded& Load(const std::string& name) {
  static std::map<std::string, Loaded> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  Loaded l;
  const fs::path file = fs::path(WRAP_SOURCE_DIR) / "projects" / (name + ".json");
  l.project = LoadProject(file);
  l.ok = l.project.ok();
  return cache.emplace(name, std::move(l)).first->second;
}

void BM_InsertionSweep(benchmark::State& state) {
  const Loaded& l = Load(kProjects[state.range(0)]);
  const int s = static_cast<int>(state.range(1));
  if (!l.ok || s >= static_cast<int>(l.project.project->steps.size())) {
    state.SkipWithError("project or step not available");
    return;
  }
  const Project& p = *l.project.project;
  AssemblyGeometry g = AssemblyGeometry::FromProject(p, l.project.check);
  const InsertionPath path = StepInsertionPath(p, *l.project.check.tree, s, -1);
  SweepStats stats;
  (void)SweepInsertion(g, path, &stats);  // builds the inset trees
  for (auto _ : state) benchmark::DoNotOptimize(SweepInsertion(g, path));
  state.SetLabel(p.name + " " + p.steps[s].name + " (" + std::to_string(stats.triangle_tests) +
                 " triangle pairs, " + std::to_string(stats.box_tests) + " box pairs)");
}

void BM_ContactGraph(benchmark::State& state) {
  const Loaded& l = Load(kProjects[state.range(0)]);
  if (!l.ok) {
    state.SkipWithError("project not available");
    return;
  }
  AssemblyGeometry g = AssemblyGeometry::FromProject(*l.project.project, l.project.check);
  (void)ComputeContactGraph(g);  // trees, queries and samples built once
  for (auto _ : state) benchmark::DoNotOptimize(ComputeContactGraph(g));
  state.SetLabel(l.project.project->name);
}

void BM_InsetTrees(benchmark::State& state) {
  const Loaded& l = Load(kProjects[state.range(0)]);
  if (!l.ok) {
    state.SkipWithError("project not available");
    return;
  }
  for (auto _ : state) {
    AssemblyGeometry g = AssemblyGeometry::FromProject(*l.project.project, l.project.check);
    // A fresh inset depth per iteration, so that no tree comes from the process-wide cache.
    static int round = 0;
    benchmark::DoNotOptimize(&g.world(1e-4 + 1e-9 * ++round));
  }
  state.SetLabel(l.project.project->name);
}

void BM_SweepTrees(benchmark::State& state) {
  const Loaded& l = Load(kProjects[state.range(0)]);
  if (!l.ok) {
    state.SkipWithError("project not available");
    return;
  }
  const Project& p = *l.project.project;
  for (auto _ : state) {
    AssemblyGeometry g = AssemblyGeometry::FromProject(p, l.project.check);
    for (int part = 0; part < g.num_parts(); ++part) {
      benchmark::DoNotOptimize(&g.sweep_mesh(part, 0.5 * p.geometry.touch_depth_m));
    }
  }
  state.SetLabel(p.name);
}

// One benchmark per step of each project (the project files parsed without their meshes).
void StepArgs(benchmark::internal::Benchmark* b) {
  for (int p = 0; p < static_cast<int>(kProjects.size()); ++p) {
    const fs::path file = fs::path(WRAP_SOURCE_DIR) / "projects" / (kProjects[p] + ".json");
    const ProjectParse parse = ReadProjectFile(file);
    const int steps = parse.project ? static_cast<int>(parse.project->steps.size()) : 0;
    for (int s = 0; s < steps; ++s) b->Args({p, s});
  }
}
void ProjectArgs(benchmark::internal::Benchmark* b) {
  for (int p = 0; p < static_cast<int>(kProjects.size()); ++p) b->Arg(p);
}

BENCHMARK(BM_InsertionSweep)->Apply(StepArgs)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ContactGraph)->Apply(ProjectArgs)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_InsetTrees)->Apply(ProjectArgs)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SweepTrees)->Apply(ProjectArgs)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace wrap
