// The team's own benchmark parts (WRAP paper, "Experiments": Stool, Chair, Cross, Cube): their
// meshes, and the designed peg-in-pocket joints that tests check the meshes against.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/result.h"
#include "geometry/mesh.h"

namespace wrap::partgen {

/// File format of a generated mesh.
enum class MeshFormat {
  kStl,  ///< Binary STL.
  kObj,  ///< Wavefront OBJ.
};

/// Generated meshes are built in metres and written in millimetres (projects use scale 0.001).
inline constexpr double kFileUnitsPerMetre = 1000.0;

/// One generated part mesh.
struct GeneratedPart {
  std::string assembly;                  ///< Folder under the output directory, e.g. "stool".
  std::string name;                      ///< File stem, e.g. "seat".
  MeshFormat format = MeshFormat::kObj;  ///< File format.
  TriangleMesh mesh;                     ///< Closed, outward-oriented, part frame [m].

  /// "<assembly>/<name>.<stl|obj>".
  std::filesystem::path RelativePath() const;
  /// "<assembly>/<name>", the key used by Joint.
  std::string Key() const { return assembly + "/" + name; }
};

/// Every part mesh of every built-in assembly, in a fixed order. Deterministic: the same meshes,
/// hence the same file bytes, on every run. kInternal if a design produces a broken mesh.
Result<std::vector<GeneratedPart>> GenerateParts();

/// Writes `part` to `out_dir / part.RelativePath()` in millimetres, creating the folder. kIo on
/// failure.
Result<void> WritePart(const std::filesystem::path& out_dir, const GeneratedPart& part);

/// A designed joint: where the moved part sits in the base part when assembled, and the pockets
/// its pegs go into. Design data (independent of the meshes) for tests and project authors.
struct Joint {
  std::string base;              ///< Key of the part with the pockets, e.g. "stool/seat".
  std::string moved;             ///< Key of the part with the pegs, e.g. "stool/leg".
  Iso3 X_BM = Iso3::Identity();  ///< Moved part frame in the base part frame, assembled [m].
  Vec3 axis_B = Vec3::UnitZ();   ///< Direction the moved part travels while inserting, base frame.
  std::vector<Aabb> pockets_B;   ///< Pocket cavities (mouth to floor) in the base frame [m].
  double lateral_clearance_m = 0.0;  ///< Least gap between the pegs and the pocket mouths [m].
  double floor_clearance_m = 0.0;    ///< Gap between a peg tip and its pocket floor [m].
};

/// The joints of all built-in assemblies (one per distinct base/moved/pose combination).
std::vector<Joint> DesignedJoints();

}  // namespace wrap::partgen
