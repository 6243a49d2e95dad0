// Loading a project for a subcommand: parse, validate, and check robots against the catalog.
#pragma once

#include <iosfwd>

#include <string>

#include "model/validate.h"

namespace wrap::cli {

/// Parses the file, then CheckProject (the model's validation and the robot stage's checks).
LoadedProject LoadChecked(const std::string& project);

/// Prints the load's diagnostics to `err` (all of them, or with `warnings` false only when the
/// project is invalid) and, when it is invalid, a line saying so. Returns loaded.ok(): false
/// means the subcommand exits 2.
bool ReportLoad(const LoadedProject& loaded, const std::string& project, std::ostream& err,
                bool warnings = true);

/// printf-style formatting of one number, e.g. Fmt("%.2f", 1.5).
std::string Fmt(const char* format, double value);

}  // namespace wrap::cli
