#include "load.h"

#include "robot/robot_check.h"

namespace wrap::cli {

LoadedProject LoadChecked(const std::string& project) {
  LoadedProject loaded = LoadProject(project);
  if (loaded.project) loaded.check.diagnostics.Append(CheckRobots(*loaded.project, project));
  return loaded;
}

}  // namespace wrap::cli
