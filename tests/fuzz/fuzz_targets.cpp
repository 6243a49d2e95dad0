#include "fuzz_targets.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string_view>

#include "geometry/mesh.h"
#include "geometry/mesh_import.h"
#include "geometry/step_import.h"
#include "model/project_io.h"
#include "model/validate.h"
#include "robot/urdf_import.h"

namespace wrap::fuzz {

namespace fs = std::filesystem;

namespace {

/// A folder of this process for the files the loaders read, removed at exit.
class ScratchDir {
 public:
  ScratchDir() : dir_(fs::temp_directory_path() / ("wrap_fuzz_" + std::to_string(::getpid()))) {
    fs::create_directories(dir_);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  const fs::path& path() const { return dir_; }

 private:
  fs::path dir_;
};

const fs::path& Scratch() {
  static const ScratchDir dir;
  return dir.path();
}

fs::path WriteScratch(const std::string& name, const uint8_t* data, size_t size) {
  const fs::path file = Scratch() / name;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write scratch file %s\n", file.c_str());
    std::abort();
  }
  return file;
}

[[noreturn]] void Broken(const char* target, const std::string& what) {
  std::fprintf(stderr, "fuzz %s: broken promise: %s\n", target, what.c_str());
  std::abort();
}

}  // namespace

int FuzzProjectJson(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::string label = (Scratch() / "fuzz.json").string();
  try {
    const ProjectParse parsed = ParseProject(text, label);
    if (!parsed.project) return 0;
    ValidationOptions options;
    options.load_meshes = false;  // Mesh paths in fuzzed JSON point anywhere; FuzzMesh covers them.
    ProjectCheck check = ValidateProject(*parsed.project, label, options);
    if (parsed.diagnostics.has_errors() || check.diagnostics.has_errors()) return 0;
    const std::string again = SerializeProject(*parsed.project);
    const ProjectParse reparsed = ParseProject(again, label);
    if (!reparsed.project || reparsed.diagnostics.has_errors()) {
      Broken("project", "a valid project does not parse back after SerializeProject:\n" + again);
    }
  } catch (const std::exception& e) {
    Broken("project", std::string("exception escaped: ") + e.what());
  }
  return 0;
}

int FuzzMesh(const uint8_t* data, size_t size, const std::string& extension) {
  const fs::path file = WriteScratch("mesh" + extension, data, size);
  try {
    auto mesh = ImportMesh(file);
    if (!mesh) {
      if (mesh.error().message.empty()) Broken("mesh", "failure without a message");
      return 0;
    }
    const int n = static_cast<int>(mesh->vertices.size());
    if (mesh->triangles.empty()) Broken("mesh", "accepted a mesh without triangles");
    for (const auto& t : mesh->triangles) {
      for (int k = 0; k < 3; ++k) {
        if (t[k] < 0 || t[k] >= n) Broken("mesh", "triangle index out of range");
      }
    }
    // What validation computes from every part's mesh.
    (void)ComputeAabb(*mesh);
    (void)SurfaceArea(*mesh);
    (void)AnalyzeTopology(*mesh);
    (void)ComputeMassProperties(*mesh);
  } catch (const std::exception& e) {
    Broken("mesh", std::string("exception escaped: ") + e.what());
  }
  return 0;
}

int FuzzStep(const uint8_t* data, size_t size, StepProcess process) {
  const fs::path file = WriteScratch("model.step", data, size);
  try {
    const StepTessellation coarse{.linear_deflection_m = 1e-3, .angular_deflection_rad = 0.5};
    auto assembly = process == StepProcess::kChild ? ImportStep(file, coarse)
                                                   : ImportStepInProcess(file, coarse);
    if (!assembly) {
      if (assembly.error().message.empty()) Broken("step", "failure without a message");
      return 0;
    }
    if (!StepImportAvailable()) Broken("step", "accepted a file without OpenCASCADE");
    if (assembly->instances.empty()) Broken("step", "accepted a file without instances");
    for (const StepInstance& inst : assembly->instances) {
      if (inst.solid < 0 || inst.solid >= static_cast<int>(assembly->solids.size())) {
        Broken("step", "instance '" + inst.name + "' names no solid");
      }
      if (!inst.X_AS.matrix().allFinite()) Broken("step", "non-finite placement");
    }
    for (const StepSolid& solid : assembly->solids) {
      const int n = static_cast<int>(solid.mesh.vertices.size());
      for (const auto& t : solid.mesh.triangles) {
        if (t.minCoeff() < 0 || t.maxCoeff() >= n) Broken("step", "triangle index out of range");
      }
      if (!AnalyzeTopology(solid.mesh).closed()) Broken("step", "open solid '" + solid.name + "'");
      if (!(ComputeMassProperties(solid.mesh).volume_m3 > 0.0)) {
        Broken("step", "solid '" + solid.name + "' is not outward");
      }
      auto picked = FindStepSolid(*assembly, solid.name, file.string());
      if (!picked) Broken("step", "solid '" + solid.name + "' cannot be picked by its name");
    }
    (void)ComputeMassProperties(MergedInstances(*assembly));
  } catch (const std::exception& e) {
    Broken("step", std::string("exception escaped: ") + e.what());
  }
  return 0;
}

int FuzzUrdf(const uint8_t* data, size_t size) {
  const fs::path file = WriteScratch("robot.urdf", data, size);
  try {
    auto chain = ImportUrdf(file);
    if (!chain) {
      if (chain.error().message.empty()) Broken("urdf", "failure without a message");
      return 0;
    }
    if (chain->links.size() != chain->joints.size() + 1) {
      Broken("urdf", "links and joints do not alternate");
    }
    for (const Joint& j : chain->joints) {
      if (!(j.lower <= j.upper)) Broken("urdf", "joint '" + j.name + "' limits out of order");
    }
  } catch (const std::exception& e) {
    Broken("urdf", std::string("exception escaped: ") + e.what());
  }
  return 0;
}

}  // namespace wrap::fuzz
