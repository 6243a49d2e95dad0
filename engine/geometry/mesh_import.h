// Mesh import: the one assimp adapter.
#pragma once

#include <filesystem>

#include "core/result.h"
#include "geometry/mesh.h"

namespace wrap {

/// Options of ImportMesh.
struct MeshImportOptions {
  double scale = 1.0;           ///< Multiplies every coordinate (0.01 for cm, 0.001 for mm).
  double weld_tolerance = 0.0;  ///< Vertices closer than this [m, after scaling] are welded; 0
                                ///< welds exact duplicates only.
};

/// Reads any format assimp 5.2 reads (STL, OBJ, PLY, glTF/GLB, OFF, 3MF, DAE, ...), triangulates,
/// welds identical vertices, flattens the node hierarchy into one mesh and applies the scale.
/// Fails with kIo (missing, unreadable) or kInvalidInput (not a mesh, no triangles), naming the
/// file.
///
/// Coordinates are taken as written, times `scale`: node transforms (glTF, DAE, 3MF build items)
/// are applied, a COLLADA up axis is ignored (a Z-up file stays Z-up), but a COLLADA `<unit>` is
/// applied by assimp (such files come in metres). Points and lines are dropped, and so are
/// triangles whose corners weld together. Does not throw; damaged files on which assimp 5.2 is
/// known to hang or abort are rejected before it reads them, but assimp is not proof against
/// every hostile file (mesh_import.cpp lists what fuzzing found).
[[nodiscard]] Result<TriangleMesh> ImportMesh(const std::filesystem::path& path,
                                              const MeshImportOptions& options = {});

}  // namespace wrap
