#include <ostream>

#include "cli.h"
#include "load.h"

namespace wrap::cli {

namespace {

void PrintDiagnostics(const Diagnostics& diags, bool errors_only, std::ostream& err) {
  for (const Diagnostic& d : diags.items) {
    if (errors_only && d.severity != Severity::kError) continue;
    err << Format(d) << "\n";
  }
}

}  // namespace

int Validate(const std::string& project, bool quiet, std::ostream& out, std::ostream& err) {
  const LoadedProject loaded = LoadChecked(project);
  const Diagnostics& diags = loaded.check.diagnostics;
  PrintDiagnostics(diags, quiet, err);
  if (!loaded.ok()) {
    if (!quiet) {
      err << project << ": invalid: " << diags.error_count() << " error(s), "
          << diags.warning_count() << " warning(s)\n";
    }
    return 2;
  }
  if (!quiet) {
    const Project& p = *loaded.project;
    out << project << ": valid: " << p.parts.size() << " parts, " << p.steps.size() << " steps, "
        << p.robots.size() << " robots, " << diags.warning_count() << " warning(s)\n";
  }
  return 0;
}

}  // namespace wrap::cli
