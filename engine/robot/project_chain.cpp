#include "robot/project_chain.h"

#include "model/paths.h"
#include "robot/catalog.h"
#include "robot/urdf_import.h"

namespace wrap {

Result<Chain> LoadProjectChain(const Project& project, const Robot& robot,
                               const std::filesystem::path& project_file, bool import_visual) {
  if (!robot.model.empty()) return LoadRobotModel(robot.model);
  auto resolved = ResolveProjectPath(project, project_file, robot.urdf);
  if (!resolved) return std::unexpected(resolved.error());
  UrdfImportOptions options;
  options.root = robot.urdf_root;
  options.tip = robot.urdf_tip;
  options.import_visual = import_visual;
  return ImportUrdf(resolved->path, options);
}

}  // namespace wrap
