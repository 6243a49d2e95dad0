// Mesh writers for the team's part generator and for tests (plain formats written by us).
#pragma once

#include <filesystem>
#include <string>

#include "core/result.h"
#include "geometry/mesh.h"

namespace wrap {

/// Binary STL, coordinates multiplied by `scale` (e.g. 1000 to write millimetres). Deterministic
/// bytes for the same mesh. Written atomically.
Result<void> WriteStl(const std::filesystem::path& path, const TriangleMesh& mesh,
                      double scale = 1.0);

/// Wavefront OBJ (v and f lines only, fixed 6-digit precision), coordinates times `scale`.
/// Written atomically.
Result<void> WriteObj(const std::filesystem::path& path, const TriangleMesh& mesh,
                      double scale = 1.0);

/// ASCII PLY, coordinates times `scale`. Written atomically.
Result<void> WritePly(const std::filesystem::path& path, const TriangleMesh& mesh,
                      double scale = 1.0);

/// ASCII OFF, coordinates times `scale`. Written atomically.
Result<void> WriteOff(const std::filesystem::path& path, const TriangleMesh& mesh,
                      double scale = 1.0);

}  // namespace wrap
