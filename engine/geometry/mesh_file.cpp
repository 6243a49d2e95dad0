#include "geometry/mesh_file.h"

#include <cmath>

#include "geometry/mesh_import.h"
#include "geometry/step_cache.h"

namespace wrap {

Result<MeshFile> LoadMeshFile(const std::filesystem::path& path, const MeshFileOptions& options) {
  if (!LooksLikeStep(path)) {
    if (!options.solid.empty()) {
      return Fail(ErrorCode::kInvalidInput,
                  "mesh file '" + path.string() + "' is not a STEP file, so it has no solid '" +
                      options.solid + "' to pick; 'solid' applies to .step/.stp files only");
    }
    auto mesh = ImportMesh(path, {.scale = options.scale});
    if (!mesh) return std::unexpected(mesh.error());
    return MeshFile{std::move(*mesh), {}};
  }
  if (!std::isfinite(options.scale) || options.scale <= 0.0) {
    return Fail(ErrorCode::kInvalidInput, "STEP import of '" + path.string() + "': scale " +
                                              std::to_string(options.scale) +
                                              " is not a positive finite number");
  }
  auto load =
      LoadStep(path, {.tessellation = options.tessellation, .cache_dir = options.cache_dir});
  if (!load) return std::unexpected(load.error());
  MeshFile out;
  if (options.solid.empty()) {
    out.mesh = MergedInstances(*load->assembly);
    out.warnings = load->assembly->warnings;
  } else {
    auto mesh = FindStepSolid(*load->assembly, options.solid, path.string());
    if (!mesh) return std::unexpected(mesh.error());
    out.mesh = std::move(*mesh);
  }
  if (options.scale != 1.0) {
    for (Vec3& v : out.mesh.vertices) v *= options.scale;
  }
  return out;
}

}  // namespace wrap
