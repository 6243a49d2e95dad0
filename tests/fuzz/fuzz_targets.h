// The fuzz targets' bodies: one function per loader, shared by the libFuzzer executables
// (fuzz_*.cpp, clang build: scripts/fuzz.sh) and by the regression replay test (fuzz_replay_test,
// normal build), which feeds them every file of tests/fuzz/regressions and tests/fuzz/seeds.
//
// Each function takes untrusted bytes, runs one loader on them the way `wrap` does, and checks what
// the loader promises: it never throws, never crashes, and what it accepts is consistent. A broken
// promise aborts (a crash for libFuzzer, a failed test for the replay).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace wrap::fuzz {

/// Project JSON: ParseProject, then ValidateProject without meshes; a project that parses and
/// validates without errors must serialise and parse back without errors.
int FuzzProjectJson(const uint8_t* data, size_t size);

/// Mesh bytes written to a file with `extension` (".stl", ".obj", ".ply") and read by ImportMesh;
/// an accepted mesh has triangles with indices in range and goes through topology and mass
/// properties as validation does.
int FuzzMesh(const uint8_t* data, size_t size, const std::string& extension);

/// Where FuzzStep runs OpenCASCADE.
enum class StepProcess {
  kThisProcess,  ///< ImportStepInProcess: libFuzzer sees OpenCASCADE's crashes and coverage.
  kChild,        ///< ImportStep, as `wrap` does: a crash in OpenCASCADE must become an error.
};

/// STEP bytes written to a .step file and imported (coarse tessellation, so that huge
/// coordinates cannot ask for billions of triangles); an accepted file has instances whose
/// solids exist, closed outward solids with indices in range and finite placements, and every
/// solid can be picked by name. Without OpenCASCADE the import must fail with a message.
int FuzzStep(const uint8_t* data, size_t size, StepProcess process);

/// URDF bytes written to a file and read by ImportUrdf; an accepted chain has one more link than
/// joints and ordered joint limits.
int FuzzUrdf(const uint8_t* data, size_t size);

}  // namespace wrap::fuzz
