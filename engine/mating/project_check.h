// Every check `wrap validate` makes of a parsed project, in one function, so that the CLI's
// loader, the GUI's live validation and the GUI's planner runs judge a project alike.
#pragma once

#include <filesystem>

#include "mating/check.h"
#include "model/project.h"
#include "model/validate.h"

namespace wrap {

/// Which of CheckProject's checks run.
struct ProjectCheckOptions {
  bool geometry = true;  ///< The geometry's checks (a renderer or a grasp table can do without).
};

/// The model's ValidateProject, the robot stage's CheckRobots (URDFs import, catalog loads),
/// then the geometry's CheckAssemblyGeometry (contacts, insertion paths, overlaps at the start),
/// whose diagnostics join the others (unless options.geometry is false). The geometry's report
/// lands in `*geometry` when given.
[[nodiscard]] ProjectCheck CheckProject(const Project& project,
                                        const std::filesystem::path& project_file,
                                        GeometryReport* geometry = nullptr,
                                        const ProjectCheckOptions& options = {});

}  // namespace wrap
