#include "mating/project_check.h"

#include "robot/robot_check.h"

namespace wrap {

ProjectCheck CheckProject(const Project& project, const std::filesystem::path& project_file,
                          GeometryReport* geometry, const ProjectCheckOptions& options) {
  ProjectCheck check = ValidateProject(project, project_file);
  check.diagnostics.Append(CheckRobots(project, project_file));
  if (!options.geometry) return check;
  GeometryReport report = CheckAssemblyGeometry(project, check, project_file.string());
  check.diagnostics.Append(report.diagnostics);
  if (geometry) *geometry = std::move(report);
  return check;
}

}  // namespace wrap
