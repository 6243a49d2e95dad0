#include "load.h"

#include <cstdio>
#include <ostream>

#include "mating/project_check.h"
#include "model/entity_path.h"
#include "model/project_io.h"

namespace wrap::cli {

LoadedProject LoadChecked(const std::string& project, GeometryReport* geometry) {
  // Parse, then every check the GUI's live validation makes too (CheckProject); the geometry's
  // only when its report is wanted.
  LoadedProject loaded;
  ProjectParse parse = ReadProjectFile(project);
  loaded.check.diagnostics = std::move(parse.diagnostics);
  if (!parse.project) return loaded;
  ProjectCheck check =
      CheckProject(*parse.project, project, geometry, {.geometry = geometry != nullptr});
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
    const Project* named = loaded.project ? &*loaded.project : nullptr;
    for (const Diagnostic& d : diags.items) err << FormatNamed(d, named) << "\n";
  }
  if (!loaded.ok()) {
    err << project << ": invalid: " << diags.error_count() << " error(s); run 'wrap validate'\n";
  }
  return loaded.ok();
}

std::vector<PlanContact> ToPlanContacts(const ContactGraph& graph) {
  std::vector<PlanContact> out;
  for (const Contact& c : graph.contacts) {
    PlanContact pc;
    pc.part_a = c.a;
    pc.part_b = c.b;
    pc.distance_m = c.distance_m;
    pc.area_m2 = c.area_m2;
    pc.centroid_A = c.centroid_A;
    pc.extent_min_A = c.extent_A.min;
    pc.extent_max_A = c.extent_A.max;
    for (const ContactNormal& n : c.normals) pc.normals.emplace_back(n.n_A, n.area_m2);
    out.push_back(std::move(pc));
  }
  return out;
}

namespace {
LogTopics& ProcessLogTopics() {
  static LogTopics topics;
  return topics;
}
}  // namespace

bool SetLogTopics(const std::string& spec, std::ostream& err) {
  auto topics = LogTopics::Parse(spec);
  if (!topics) {
    err << "--log (or WRAP_LOG): " << topics.error().message << "\n";
    return false;
  }
  ProcessLogTopics() = std::move(*topics);
  return true;
}

void UseLog(RunContext& ctx, std::ostream& err) {
  if (!ProcessLogTopics().empty()) ctx.set_log(StreamLogSink(err), ProcessLogTopics());
}

std::string Fmt(const char* format, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

}  // namespace wrap::cli
