// `wrap new`: a plannable project from the meshes of an assembly, with no numbers typed.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "authoring/mesh_intake.h"
#include "core/result.h"
#include "core/run_context.h"
#include "model/project.h"

namespace wrap {

/// Options of NewProject (the CLI's flags).
struct NewProjectOptions {
  LengthUnit unit = LengthUnit::kAuto;        ///< The mesh files' unit.
  int robots = 4;                             ///< Robots around the table.
  std::string robot_model = "ur5e";           ///< Their catalog model.
  std::string end_effector = "robotiq_2f85";  ///< Their end effector.
  double force_N = 10.0;                      ///< Mating force of every step [N].
  std::string name;                           ///< Project name (default: the output's stem).
  int grasps = 64;                            ///< The project's grasp-set size (the paper's).
  /// Told each stage as it starts (e.g. "reading the meshes"), with the fraction of the work
  /// done before it; empty: nothing told. Called on the caller's thread.
  std::function<void(const std::string& stage, double fraction)> progress;
};

/// A project made from meshes, and what was decided on the way.
struct NewProjectResult {
  Project project;                     ///< Ready to save beside `output`.
  std::vector<std::string> decisions;  ///< One line per decision, with its reason.
};

/// Reads the meshes (assembled positions), finds the contact graph, an assembly sequence by
/// disassembly (the DAG, each step's axis and roles), robots around the table and an initial
/// layout of stable, pickable placements; the project validates with no error and mesh paths
/// relative to `output`. Fails with kInvalidInput for bad meshes (none, one, unreadable, not
/// closed, overlapping where assembled, not all connected), kInfeasible when the parts are
/// interlocked (naming them) or cannot be laid out. Deterministic.
[[nodiscard]] Result<NewProjectResult> NewProject(const std::vector<std::filesystem::path>& meshes,
                                                  const std::filesystem::path& output,
                                                  const NewProjectOptions& options);

}  // namespace wrap
