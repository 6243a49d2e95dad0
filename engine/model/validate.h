// Validation of a project: every problem, each naming the file, the JSON path and what is wrong.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "geometry/mesh.h"
#include "model/assembly.h"
#include "model/project.h"

namespace wrap {

/// A part's mesh as loaded for validation, with the facts `wrap info` shows.
struct PartGeometry {
  bool loaded = false;             ///< The mesh was read and has triangles.
  std::filesystem::path resolved;  ///< The file that was opened.
  TriangleMesh mesh;               ///< In metres, in the part frame.
  MeshTopology topology;           ///< Closedness and degeneracy.
  MassProperties mass_properties;  ///< Per unit density (valid when closed).
  Aabb aabb;                       ///< Bounding box in the part frame [m].
  double mass_kg = 0.0;            ///< Given mass, or density times volume.
};

/// Options of ValidateProject.
struct ValidationOptions {
  bool load_meshes = true;  ///< Read every mesh (needed for the mesh checks and mass).
};

/// What validation found.
struct ProjectCheck {
  Diagnostics diagnostics;           ///< All problems (errors and warnings).
  std::vector<PartGeometry> parts;   ///< One per Project::parts entry.
  std::optional<AssemblyTree> tree;  ///< The DAG, when it is well formed.
};

/// Checks everything a planner run relies on (see README "Validation"): numbers positive and
/// finite, unique names, references, the DAG, matings, robots and end effectors against the
/// catalog, meshes readable, non-degenerate, closed and of plausible size, parts resting on the
/// table within reach of at least two robots. `project_file` resolves relative paths and names
/// the file in messages.
ProjectCheck ValidateProject(const Project& project, const std::filesystem::path& project_file,
                             const ValidationOptions& options = {});

/// A project file read, parsed and validated in one go.
struct LoadedProject {
  std::optional<Project> project;  ///< Absent when the file could not be parsed at all.
  ProjectCheck check;              ///< Parse and validation diagnostics, meshes, DAG.
  bool ok() const { return project.has_value() && !check.diagnostics.has_errors(); }
};

/// Reads, parses and validates a project file. Never throws.
LoadedProject LoadProject(const std::filesystem::path& path, const ValidationOptions& options = {});

/// Robot base frame in the world, composing a mobile base's pose and mount when mounted
/// (identity mount when the base or mount is unknown).
Iso3 RobotBaseInWorld(const Project& project, const Robot& robot);

}  // namespace wrap
