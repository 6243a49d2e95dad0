// Loading a project for a subcommand: parse, validate, and check robots against the catalog.
#pragma once

#include <string>

#include "model/validate.h"

namespace wrap::cli {

/// The model's LoadProject plus the robot stage's CheckRobots (URDFs import, catalog loads).
LoadedProject LoadChecked(const std::string& project);

}  // namespace wrap::cli
