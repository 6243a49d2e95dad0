// The preprocessing result as JSON (what `wrap preprocess -o FILE.json` writes).
#pragma once

#include <string>

#include "grasp/preprocess.h"
#include "model/project.h"

namespace wrap {

/// The result as a JSON document (format "wrap-preprocess", version 1): the run's seed, set
/// size and friction, "timings_s" (per part of the stage; "total" is t_grasp), "table_slots",
/// and a top-level "subassemblies" array whose items hold "name", "parts" (names), "part_poses"
/// (X_AP), mass, COM, a hull summary, "placements" (X_TA, support polygons in A and T, margin) and
/// "grasps" (each: end effector, kind, part name, X_PG and X_AG, quality, width, contacts), with
/// "grasp_counts" per end effector. Poses are {"xyz": [m], "rpy": [rad]} as in project files.
std::string PreprocessedToJson(const Project& project, const Preprocessed& result);

}  // namespace wrap
