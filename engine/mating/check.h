// The geometry's verdicts on a project: the contact graph, whether each step's inputs touch and
// its insertion path is free, and whether the parts overlap where they start. Validation (wrap
// validate, the GUI), the planner and authoring all ask this.
#pragma once

#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "mating/assembly_geometry.h"
#include "mating/contact_graph.h"
#include "mating/insertion.h"
#include "mating/start_layout.h"
#include "model/project.h"
#include "model/validate.h"

namespace wrap {

/// Options of CheckAssemblyGeometry.
struct GeometryCheckOptions {
  bool insertions = true;  ///< Sweep every step's insertion path.
  bool start = true;       ///< Look for parts that overlap in their initial poses.
  int sphere_axes = 64;    ///< Directions sampled over the sphere when looking for free axes.
};

/// What the geometry says of one step.
struct StepGeometry {
  int step = -1;                ///< Index into Project::steps.
  int moved = -1;               ///< Node id of the moved input.
  int base = -1;                ///< Node id of the base input.
  SetDistance inputs;           ///< Closest approach of the inputs at the mating pose.
  bool touch = false;           ///< The inputs touch (within the contact tolerance).
  std::vector<PathHit> paths;   ///< One per final pose (the assembled pose when none given).
  std::vector<Vec3> free_axes;  ///< Free insertion axes, searched when a path is blocked.
  double sweep_ms = 0.0;        ///< Time the declared paths' sweeps took [ms].
  SweepStats stats;             ///< Their part pairs, box and triangle tests.
  bool blocked() const;         ///< Some declared path is blocked.
};

/// Everything CheckAssemblyGeometry found.
struct GeometryReport {
  ContactGraph contacts;                     ///< Which parts touch, assembled.
  std::vector<StepGeometry> steps;           ///< One per step of the project (when the DAG is
                                             ///< well formed and the meshes loaded).
  std::vector<StartOverlap> start_overlaps;  ///< Parts that overlap where they start.
  Diagnostics diagnostics;                   ///< Errors for each problem above, naming the
                                             ///< step or part, the parts and the distances.
};

/// Judges the project's geometry (see GeometryReport). Needs the meshes and the DAG from
/// validation; parts whose mesh did not load and steps of a broken DAG are left out. `file`
/// names the project file in the diagnostics.
GeometryReport CheckAssemblyGeometry(const Project& project, const ProjectCheck& check,
                                     const std::string& file,
                                     const GeometryCheckOptions& options = {});

/// The InsertionPath of step `s` of the project for final pose `k` (-1: the assembled pose).
InsertionPath StepInsertionPath(const Project& project, const AssemblyTree& tree, int s, int k);

/// "12.3 mm" (one decimal; "0 mm" below 0.05 mm).
std::string FormatMm(double metres);

}  // namespace wrap
