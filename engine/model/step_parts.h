// A project's parts from a STEP assembly: what the GUI's Import of an assembly (and `wrap new
// model.step`, issue 29) builds the parts of a project from, in one edit.
#pragma once

#include <string>
#include <vector>

#include "geometry/step_import.h"
#include "model/project.h"

namespace wrap {

/// The colour a new part without one of its own gets: the `index`-th of a palette of six.
Rgba NewPartColor(size_t index);

/// Options of PartsFromStep.
struct StepPartsOptions {
  std::string mesh;               ///< The STEP file's path as the project writes it (relative to
                                  ///< the project file).
  double density_kg_m3 = 1240.0;  ///< Density of every part (PLA).
};

/// One Part per instance of `assembly`, in file order: named after the instance (made unique
/// among `project`'s parts and steps and each other with "_2", ...), `mesh` = options.mesh and
/// `solid` = the instance's solid (so instances of one product share one mesh), assembled pose =
/// the instance's placement in the file, colour = the file's (else one from a palette), initial
/// pose = resting on `project`'s table in the part's most stable placement, side by side in rows
/// from the table's -x/-y corner, clear of the parts already there and of the robots' bases.
std::vector<Part> PartsFromStep(const StepAssembly& assembly, const Project& project,
                                const StepPartsOptions& options);

}  // namespace wrap
