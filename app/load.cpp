#include "load.h"

#include <cstdio>
#include <ostream>

#include "robot/robot_check.h"

namespace wrap::cli {

LoadedProject LoadChecked(const std::string& project) {
  LoadedProject loaded = LoadProject(project);
  if (loaded.project) loaded.check.diagnostics.Append(CheckRobots(*loaded.project, project));
  return loaded;
}

bool ReportLoad(const LoadedProject& loaded, const std::string& project, std::ostream& err,
                bool warnings) {
  const Diagnostics& diags = loaded.check.diagnostics;
  if (warnings || !loaded.ok()) {
    for (const Diagnostic& d : diags.items) err << Format(d) << "\n";
  }
  if (!loaded.ok()) {
    err << project << ": invalid: " << diags.error_count() << " error(s); run 'wrap validate'\n";
  }
  return loaded.ok();
}

std::string Fmt(const char* format, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

}  // namespace wrap::cli
