// What the STEP importer does without OpenCASCADE (step_assembly.cpp), shared by the OpenCASCADE
// adapter (step_import.cpp) and the build without it (step_import_unavailable.cpp).
#pragma once

#include <filesystem>
#include <string>

#include "core/result.h"
#include "geometry/mesh.h"

namespace wrap::detail {

/// The checks before a file goes to OpenCASCADE: it exists, is a non-empty regular file, starts
/// with "ISO-10303-21;" (else: not a STEP file, saying what it looks like) and ends with
/// "END-ISO-10303-21;" (else: truncated). Errors name the file.
Result<void> CheckStepFile(const std::filesystem::path& path);

/// What is wrong with the entity references of a STEP file's DATA section, or empty: a reference
/// to an entity the file does not define ("entity #5 refers to #9, which the file does not
/// define"), or the first cycle ("its entities refer to each other in a cycle (#4 -> #5 -> #4)");
/// a well-formed file has neither.
std::string FindBrokenReference(const std::filesystem::path& path);

/// A tessellated solid must be closed and enclose a volume: fails naming `what` otherwise.
/// Inward-facing triangles (negative volume) are turned outward.
Result<TriangleMesh> CheckClosedSolid(TriangleMesh mesh, const std::string& what);

/// The entity a line of a STEP file belongs to ("#40"): the nearest line at or before `line`
/// (1-based) that starts with an entity name; empty when there is none.
std::string EntityAtLine(const std::filesystem::path& path, long line);

/// `message` with " (near entity #N)" added after its first "Line N" (OpenCASCADE's syntax errors
/// name only the line).
std::string WithEntityOfLine(const std::filesystem::path& path, const std::string& message);

/// STEP's name of an entity type from OpenCASCADE's class or type name:
/// "StepShape_ManifoldSolidBrep"
/// -> "MANIFOLD_SOLID_BREP" (names already in upper case are kept).
std::string StepTypeName(const std::string& occt_name);

}  // namespace wrap::detail
