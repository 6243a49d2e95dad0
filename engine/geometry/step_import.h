// STEP (ISO 10303-21: AP203, AP214, AP242) import through OpenCASCADE: an assembly file's product
// structure (parts, names, colours, placements) and its solids tessellated into triangle meshes.
// step_import.cpp is the one file that includes OpenCASCADE; a build without it
// (-DWRAP_WITH_OCCT=OFF) compiles step_import_unavailable.cpp instead, whose functions fail with
// a message saying so.
#pragma once

#include <array>
#include <filesystem>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "geometry/mesh.h"

namespace wrap {

/// How finely solids are tessellated (OpenCASCADE's BRepMesh deflections).
struct StepTessellation {
  /// Largest distance between a triangle and the surface it approximates [m]. The default keeps a
  /// 5 cm part within 0.1 mm of its surface (half that, for margin) and under 20k triangles.
  double linear_deflection_m = 5e-5;
  /// Largest angle between the normals of neighbouring facets of a curved face [rad] (20 deg).
  double angular_deflection_rad = 20.0 * std::numbers::pi / 180.0;
  bool operator==(const StepTessellation&) const = default;
};

/// A tessellated solid of a STEP file: the geometry of one product (or one solid of a product
/// with several), shared by every instance of it.
struct StepSolid {
  std::string name;     ///< Unique among the file's solids: the product's name; "NAME.k" for the
                        ///< k-th solid of a product with several (its own name if it has one);
                        ///< "NAME_2", ... where names repeat.
  std::string product;  ///< The product's name as written in the file.
  std::string entity;   ///< The STEP entity of the solid, e.g. "#123 MANIFOLD_SOLID_BREP".
  TriangleMesh mesh;    ///< Closed and outward, in the product's own frame [m].
};

/// One leaf instance of the product structure: a part of the assembly.
struct StepInstance {
  std::string name;              ///< Unique among the instances: the instance's name where the
                                 ///< file gives one, else the solid's name; "_2", ... on repeats.
  int solid = -1;                ///< Index into StepAssembly::solids.
  Iso3 X_AS = Iso3::Identity();  ///< The solid's frame in the assembly (root) frame [m].
  std::optional<std::array<double, 4>> color;  ///< RGBA in [0, 1] where the file gives one
                                               ///< (instance, solid, product or face colour).
};

/// What ImportStep read: everything the file holds, in metres.
struct StepAssembly {
  std::string unit;                     ///< The file's length unit as written, e.g. "millimetre".
  double metres_per_unit = 1.0;         ///< That unit in metres.
  std::vector<StepSolid> solids;        ///< Distinct geometry, in file order.
  std::vector<StepInstance> instances;  ///< Every leaf instance (part), in file order.
  std::vector<std::string> warnings;    ///< What was skipped (e.g. a product without a solid).
  int triangles() const;                ///< Triangles of all solids (each counted once).
};

/// False in a build without OpenCASCADE (-DWRAP_WITH_OCCT=OFF).
bool StepImportAvailable();

/// True for a file named .step, .stp or .p21 (any case), or one that starts with ISO 10303-21's
/// "ISO-10303-21;" (a STEP file under another name).
bool LooksLikeStep(const std::filesystem::path& path);

/// Reads a STEP file: the product structure (one StepInstance per leaf instance, repeated
/// products sharing one StepSolid), names, colours and placements, every solid tessellated with
/// `tessellation` and converted from the file's length unit to metres. Fails with kIo (missing,
/// unreadable) or kInvalidInput naming the file and, where there is one, the entity: not a STEP
/// file, truncated, syntax errors, no length unit, no solid, a solid that does not mesh closed,
/// deflections out of range; a build without OpenCASCADE fails with kInvalidInput saying that
/// STEP is unavailable. OpenCASCADE runs in a child process: where it crashes on a damaged file,
/// this fails with kInvalidInput ("OpenCASCADE crashed on it") and the caller lives on.
/// Thread-safe. Does not throw.
[[nodiscard]] Result<StepAssembly> ImportStep(const std::filesystem::path& path,
                                              const StepTessellation& tessellation = {});

/// ImportStep in this process, one thread at a time: the same answers, without the cost of a
/// child process (a few milliseconds), and a damaged file that crashes OpenCASCADE crashes the
/// caller. For the fuzzer, which must see OpenCASCADE's crashes and its code coverage.
[[nodiscard]] Result<StepAssembly> ImportStepInProcess(const std::filesystem::path& path,
                                                       const StepTessellation& tessellation = {});

/// Every instance's mesh placed in the assembly frame, in one mesh [m] (what a part whose mesh is
/// the whole file gets).
TriangleMesh MergedInstances(const StepAssembly& assembly);

/// The solid named `name` (a StepSolid name, else an instance's name, whose solid it is), in its
/// own frame. Fails with kInvalidInput naming `file` and listing the names there are.
Result<TriangleMesh> FindStepSolid(const StepAssembly& assembly, const std::string& name,
                                   const std::string& file);

// ---- Writing (tests, generated example assemblies) ---------------------------------------------

/// A primitive of a constructive solid, in the product frame [m].
struct StepPrimitive {
  enum class Kind { kBox, kCylinder, kSphere };
  Kind kind = Kind::kBox;
  bool subtract = false;       ///< Cut from the solid so far (else fused with it).
  Vec3 origin = Vec3::Zero();  ///< Box: lower corner. Cylinder: centre of its base. Sphere:
                               ///< centre.
  Vec3 size = Vec3::Zero();    ///< Box: side lengths along x, y, z.
  Vec3 axis = Vec3::UnitZ();   ///< Cylinder: direction from base to top.
  double radius = 0.0;         ///< Cylinder or sphere radius.
  double height = 0.0;         ///< Cylinder height.
};

/// A product to write: one or more solids, each a sequence of primitives fused or cut in order.
struct StepProductSpec {
  std::string name;
  std::vector<std::vector<StepPrimitive>> solids;
  std::optional<std::array<double, 4>> color;  ///< Written on the product's solids.
};

/// One placed instance of a product.
struct StepInstanceSpec {
  std::string name;              ///< Written as the instance's name (may be empty).
  int product = 0;               ///< Index into StepDocumentSpec::products.
  Iso3 X_AP = Iso3::Identity();  ///< Placement in the assembly [m].
};

/// A whole file: an assembly `name` of `instances`, or, with no instances, the products as
/// top-level shapes. `unit` is the length unit written: "MM", "M", "CM" or "INCH".
struct StepDocumentSpec {
  std::string name = "assembly";
  std::string unit = "MM";
  std::vector<StepProductSpec> products;
  std::vector<StepInstanceSpec> instances;
};

/// Builds the solids with OpenCASCADE and writes them as an AP214 file (atomically). Fails with
/// kInvalidInput for a spec OpenCASCADE cannot build, kIo when the file cannot be written.
Result<void> WriteStep(const StepDocumentSpec& spec, const std::filesystem::path& path);

}  // namespace wrap
