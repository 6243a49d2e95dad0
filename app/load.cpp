#include "load.h"

#include <cstdio>
#include <ostream>

#include "robot/robot_check.h"

namespace wrap::cli {

LoadedProject LoadChecked(const std::string& project, GeometryReport* geometry) {
  LoadedProject loaded = LoadProject(project);
  if (!loaded.project) return loaded;
  loaded.check.diagnostics.Append(CheckRobots(*loaded.project, project));
  if (geometry) {
    *geometry = CheckAssemblyGeometry(*loaded.project, loaded.check, project);
    loaded.check.diagnostics.Append(geometry->diagnostics);
  }
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

std::string Fmt(const char* format, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

}  // namespace wrap::cli
