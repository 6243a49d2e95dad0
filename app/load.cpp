#include "load.h"

#include <cstdio>
#include <ostream>

#include "model/project_io.h"
#include "robot/robot_check.h"

namespace wrap::cli {

LoadedProject LoadChecked(const std::string& project) {
  // Parse, then the checks the GUI's live validation makes too (CheckProject).
  LoadedProject loaded;
  ProjectParse parse = ReadProjectFile(project);
  loaded.check.diagnostics = std::move(parse.diagnostics);
  if (!parse.project) return loaded;
  ProjectCheck check = CheckProject(*parse.project, project);
  loaded.check.diagnostics.Append(check.diagnostics);
  loaded.check.parts = std::move(check.parts);
  loaded.check.tree = std::move(check.tree);
  loaded.project = std::move(parse.project);
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
