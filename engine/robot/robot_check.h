// Checks of a project's robots that need the robot stage: URDF import, catalog loading.
#pragma once

#include <filesystem>

#include "core/diagnostics.h"
#include "model/project.h"
#include "model/validate.h"

namespace wrap {

/// Loads every robot's kinematic chain (catalog model or URDF through ImportUrdf with the
/// robot's `urdf_root`/`urdf_tip`) and its end effector, reporting each failure at the robot's
/// JSON path (`robots[i].urdf`, ...) with the importer's message. `wrap validate` runs it after
/// the model's validation; robots that validation already rejected are skipped.
Diagnostics CheckRobots(const Project& project, const std::filesystem::path& project_file);

}  // namespace wrap
