// The kinematic chain of a project's robot, from the catalog or from its URDF: the one place
// every stage (preprocessing, the planner, the validator, the scene) loads robots through.
#pragma once

#include <filesystem>

#include "core/result.h"
#include "model/project.h"
#include "robot/chain.h"

namespace wrap {

/// The chain of `robot`: its catalog model, or its URDF resolved against `project_file` (path
/// variables expanded) between the robot's root and tip links. `import_visual` false skips the
/// URDF's visual meshes (planning needs only collision shapes). Fails with kInvalidInput naming
/// the model or file.
Result<Chain> LoadProjectChain(const Project& project, const Robot& robot,
                               const std::filesystem::path& project_file,
                               bool import_visual = true);

}  // namespace wrap
