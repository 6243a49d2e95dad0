// A part's mesh file, whatever its format: STEP through the OpenCASCADE adapter (with its
// tessellation cache), every other format through assimp. What validation, and so every stage
// after it, and the GUI's import read part meshes with.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/result.h"
#include "geometry/mesh.h"
#include "geometry/step_import.h"

namespace wrap {

/// Options of LoadMeshFile.
struct MeshFileOptions {
  /// Multiplies every coordinate: mesh units to metres for mesh formats (0.001 for mm); STEP
  /// files come in metres from their own unit, so 1 unless the part is meant to be resized.
  double scale = 1.0;
  /// STEP only: the solid (or part) of the file to take, in its own frame; empty: every part of
  /// the file, placed as in the assembly.
  std::string solid;
  StepTessellation tessellation;    ///< STEP only: how finely to tessellate.
  std::filesystem::path cache_dir;  ///< STEP only: folder of cached tessellations (may be empty).
};

/// What LoadMeshFile read.
struct MeshFile {
  TriangleMesh mesh;                  ///< [m], in the part frame.
  std::vector<std::string> warnings;  ///< STEP: what the file held that was skipped (a product
                                      ///< without a solid, an open surface).
};

/// Reads a part mesh [m]. STEP files (LooksLikeStep) go through LoadStep, the rest through
/// ImportMesh. Fails with kIo or kInvalidInput naming the file; `solid` on a file that is not
/// STEP is refused.
Result<MeshFile> LoadMeshFile(const std::filesystem::path& path,
                              const MeshFileOptions& options = {});

}  // namespace wrap
