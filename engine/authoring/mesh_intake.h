// The meshes of an assembly as CAD exports them (one file per part, every part in its assembled
// position): files and folders read, names from the file names, the unit inferred or given.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "geometry/mesh.h"

namespace wrap {

/// The length unit of mesh files.
enum class LengthUnit { kAuto, kMillimetre, kCentimetre, kMetre };

/// "mm", "cm", "m" or "auto".
const char* ToString(LengthUnit unit);
/// Parses "auto", "mm", "cm" or "m".
Result<LengthUnit> ParseLengthUnit(const std::string& text);

/// The parts read.
struct MeshIntake {
  std::vector<std::string> names;                ///< Part names (file stems, made unique; a
                                                 ///< STEP assembly's instance names).
  std::vector<std::filesystem::path> files;      ///< The files, as found.
  std::vector<TriangleMesh> meshes;              ///< In metres, in the assembly frame.
  /// Per part, a STEP assembly's solid (Part::solid); empty for mesh files.
  std::vector<std::string> solids;
  /// Per part, its frame in the assembly (Part::assembled_pose): a STEP instance's placement;
  /// identity for mesh files, which are modelled in place.
  std::vector<Iso3> X_AP;
  /// Per part, the file's colour where a STEP file gives one.
  std::vector<std::optional<std::array<double, 4>>> colors;
  double scale = 1.0;                            ///< Metres per file unit.
  LengthUnit unit = LengthUnit::kMetre;          ///< The unit used.
  std::string unit_reason;                       ///< Why (for `auto`: the sizes it compared).
};

/// Reads the mesh files given (folders: their mesh files, not recursing, in name order), or one
/// STEP assembly file (one part per leaf instance: its name, solid, placement and colour; in
/// metres from the file's own unit, so `unit` does not apply). Fails
/// with kInvalidInput naming the file for: no mesh found, a single part, a file that does not
/// read, a mesh that is not closed (contacts, mass and overlaps need solids). `auto` picks the
/// unit that makes the assembly's largest extent closest to 20 cm (CAD exports of table-top
/// assemblies: 2 cm to 1.5 m) and says so.
Result<MeshIntake> ReadAssemblyMeshes(const std::vector<std::filesystem::path>& inputs,
                                      LengthUnit unit);

}  // namespace wrap
