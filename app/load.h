// Loading a project for a subcommand: parse, validate, and check robots against the catalog.
#pragma once

#include <iosfwd>

#include <string>

#include "core/run_context.h"
#include "mating/check.h"
#include "model/validate.h"
#include "task/plan.h"

namespace wrap::cli {

/// Parses the file, then CheckProject: the model's validation, the robot stage's checks and,
/// when `geometry` is given, the geometry's (contacts, insertion paths, overlaps at the
/// start), whose diagnostics join the load's and whose report lands in `*geometry`.
LoadedProject LoadChecked(const std::string& project, GeometryReport* geometry = nullptr);

/// Prints the load's diagnostics to `err` (all of them, or with `warnings` false only when the
/// project is invalid) and, when it is invalid, a line saying so. Returns loaded.ok(): false
/// means the subcommand exits 2.
bool ReportLoad(const LoadedProject& loaded, const std::string& project, std::ostream& err,
                bool warnings = true);

/// The contact graph as the plan records it.
std::vector<PlanContact> ToPlanContacts(const ContactGraph& graph);

/// The log topics of this process (`--log` or WRAP_LOG), set once after the arguments are
/// parsed; false (and a message in `err`) when `spec` names an unknown topic or level.
bool SetLogTopics(const std::string& spec, std::ostream& err);

/// Sends `ctx`'s log to `err`, for the topics set by SetLogTopics (none: nothing logged).
void UseLog(RunContext& ctx, std::ostream& err);

/// printf-style formatting of one number, e.g. Fmt("%.2f", 1.5).
std::string Fmt(const char* format, double value);

}  // namespace wrap::cli
