#include "robot/robot_check.h"

#include "model/catalog.h"
#include "model/paths.h"
#include "robot/catalog.h"
#include "robot/urdf_import.h"

namespace wrap {

namespace fs = std::filesystem;

Diagnostics CheckRobots(const Project& project, const fs::path& project_file) {
  Diagnostics diags;
  const std::string file = project_file.string();
  for (size_t i = 0; i < project.robots.size(); ++i) {
    const Robot& r = project.robots[i];
    const std::string path = "robots[" + std::to_string(i) + "]";
    if (!r.urdf.empty() && r.model.empty()) {
      auto resolved = ResolveProjectPath(project, project_file, r.urdf);
      std::error_code ec;
      if (!resolved || !fs::is_regular_file(resolved->path, ec)) continue;  // Reported already.
      UrdfImportOptions options;
      options.root = r.urdf_root;
      options.tip = r.urdf_tip;
      if (auto chain = ImportUrdf(resolved->path, options); !chain) {
        diags.Error(file, path + ".urdf",
                    "cannot use URDF '" + r.urdf + "': " + chain.error().message);
      }
    } else if (FindRobotModel(r.model)) {
      if (auto chain = LoadRobotModel(r.model); !chain) {
        diags.Error(file, path + ".model", chain.error().message);
      }
    }
    if (FindEndEffector(r.end_effector)) {
      if (auto ee = LoadEndEffector(r.end_effector); !ee) {
        diags.Error(file, path + ".end_effector", ee.error().message);
      }
    }
  }
  return diags;
}

}  // namespace wrap
