#include "mating/check.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace wrap {

namespace {

std::string Quote(const std::string& s) { return "'" + s + "'"; }

std::string StepPath(int s) { return "steps[" + std::to_string(s) + "]"; }

// The parts outside `inside` that the parts of `inside` touch, by name.
std::string TouchedNames(const AssemblyGeometry& g, const ContactGraph& graph,
                         const std::vector<int>& inside) {
  std::vector<int> touched;
  for (int p : inside) {
    for (int q : graph.Neighbours(p)) {
      if (std::find(inside.begin(), inside.end(), q) == inside.end() &&
          std::find(touched.begin(), touched.end(), q) == touched.end()) {
        touched.push_back(q);
      }
    }
  }
  std::sort(touched.begin(), touched.end());
  std::string out;
  for (int q : touched) out += (out.empty() ? "" : ", ") + Quote(g.name(q));
  return out;
}

// "'leg1'" for a one-part input; "'top' (its part 'leg1')" otherwise.
std::string InputPart(const AssemblyGeometry& g, const AssemblyNode& node, int part) {
  if (node.parts.size() == 1) return Quote(node.name);
  return Quote(node.name) + " (its part " + Quote(g.name(part)) + ")";
}

void ReportTouch(const Project& project, const AssemblyTree& tree, const AssemblyGeometry& g,
                 const ContactGraph& graph, const std::string& file, const StepGeometry& sg,
                 Diagnostics& diags) {
  if (sg.touch) return;
  const Step& step = project.steps[sg.step];
  const AssemblyNode& moved = tree.nodes[sg.moved];
  const AssemblyNode& base = tree.nodes[sg.base];
  std::string msg = "step " + Quote(step.name) + ": its inputs " + Quote(moved.name) + " and " +
                    Quote(base.name) + " do not touch at the mating pose (closest " +
                    FormatMm(sg.inputs.distance_m);
  if (sg.inputs.part_a >= 0 && (moved.parts.size() > 1 || base.parts.size() > 1)) {
    msg +=
        ", between " + Quote(g.name(sg.inputs.part_a)) + " and " + Quote(g.name(sg.inputs.part_b));
  }
  msg += "; surfaces within " + FormatMm(graph.tolerance_m) + " touch); " + Quote(moved.name);
  const std::string touched = TouchedNames(g, graph, moved.parts);
  msg += touched.empty() ? " touches no other part" : " touches " + touched;
  diags.Error(file, StepPath(sg.step) + ".mating.base", msg);
}

void ReportPaths(const Project& project, const AssemblyTree& tree, const AssemblyGeometry& g,
                 const std::string& file, const StepGeometry& sg, int sphere, Diagnostics& diags) {
  const Step& step = project.steps[sg.step];
  const Mating& m = step.mating;
  const AssemblyNode& moved = tree.nodes[sg.moved];
  const AssemblyNode& base = tree.nodes[sg.base];
  for (size_t k = 0; k < sg.paths.size(); ++k) {
    const PathHit& hit = sg.paths[k];
    if (!hit.blocked) continue;
    std::string msg = "step " + Quote(step.name) + ": " + InputPart(g, moved, hit.moved_part) +
                      " moving along " + FormatDirection(m.axis.normalized());
    if (!m.final_poses.empty()) msg += " into final pose " + std::to_string(k);
    if (hit.at_m <= m.interference_travel_m + 1e-9) {
      msg += " overlaps " + InputPart(g, base, hit.base_part) + " by more than the " +
             FormatMm(AllowedOverlap(m.interference_travel_m, m.interference_depth_m,
                                     project.geometry.touch_depth_m, hit.at_m)) +
             " allowed in its last " + FormatMm(m.interference_travel_m) +
             " (interference_depth_m, interference_travel_m)";
    } else {
      msg += " hits " + InputPart(g, base, hit.base_part) + " " + FormatMm(hit.at_m) +
             " before its mating pose";
    }
    if (sg.free_axes.empty()) {
      msg += "; no free direction among the axes, the contact normals and " +
             std::to_string(sphere) +
             " sampled directions (interlocked, or overlapping where "
             "they are mated)";
    } else {
      msg += "; free directions: ";
      std::vector<Vec3> free = sg.free_axes;
      std::stable_sort(free.begin(), free.end(), [](const Vec3& a, const Vec3& b) {
        return AxisPreference(a) > AxisPreference(b);
      });
      const size_t shown = std::min<size_t>(free.size(), 4);
      for (size_t i = 0; i < shown; ++i) msg += (i ? ", " : "") + FormatDirection(free[i]);
      if (sg.free_axes.size() > shown) {
        msg += " (and " + std::to_string(sg.free_axes.size() - shown) + " more)";
      }
    }
    diags.Error(file, StepPath(sg.step) + ".mating.axis", msg);
  }
}

StepGeometry CheckStep(const Project& project, const AssemblyTree& tree, AssemblyGeometry& g,
                       const ContactGraph& graph, int s, const GeometryCheckOptions& options) {
  StepGeometry sg;
  sg.step = s;
  const Mating& m = project.steps[s].mating;
  sg.moved = tree.Find(m.moved);
  sg.base = tree.Find(m.base);
  const std::vector<int>& moved = tree.nodes[sg.moved].parts;
  const std::vector<int>& base = tree.nodes[sg.base].parts;
  sg.inputs = DistanceBetween(g, moved, base);
  sg.touch = sg.inputs.distance_m <= graph.tolerance_m;
  if (!options.insertions) return sg;
  const auto t0 = std::chrono::steady_clock::now();
  const int poses = std::max<int>(1, static_cast<int>(m.final_poses.size()));
  for (int k = 0; k < poses; ++k) {
    const InsertionPath path = StepInsertionPath(project, tree, s, m.final_poses.empty() ? -1 : k);
    sg.paths.push_back(SweepInsertion(g, path, &sg.stats));
  }
  sg.sweep_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (sg.blocked()) {
    const InsertionPath path = StepInsertionPath(project, tree, s, -1);
    sg.free_axes = FreeAxes(g, path, CandidateAxes(graph, moved, base, options.sphere_axes));
  }
  return sg;
}

// The steps can be judged: the DAG is sound and every part's mesh was read (a missing mesh is
// already an error; without it every step holding the part would also "not touch").
bool StepsUsable(const Project& project, const ProjectCheck& check) {
  if (!check.tree) return false;
  if (check.parts.size() != project.parts.size()) return false;
  for (const PartGeometry& part : check.parts) {
    if (!part.loaded) return false;
  }
  for (const Step& step : project.steps) {
    if (check.tree->Find(step.mating.moved) < 0 || check.tree->Find(step.mating.base) < 0) {
      return false;
    }
    if (!(step.mating.axis.allFinite() && step.mating.axis.norm() > 1e-9)) return false;
  }
  return true;
}

}  // namespace

bool StepGeometry::blocked() const {
  for (const PathHit& h : paths) {
    if (h.blocked) return true;
  }
  return false;
}

std::string FormatMm(double metres) {
  const double mm = metres * 1000.0;
  if (std::abs(mm) < 0.05) return "0 mm";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.1f mm", mm);
  return buf;
}

InsertionPath StepInsertionPath(const Project& project, const AssemblyTree& tree, int s, int k) {
  const Mating& m = project.steps[s].mating;
  InsertionPath path;
  path.moved = tree.nodes[tree.Find(m.moved)].parts;
  path.base = tree.nodes[tree.Find(m.base)].parts;
  if (k >= 0 && k < static_cast<int>(m.final_poses.size())) {
    path.X_BM = ToIsometry(m.final_poses[k]);
  }
  path.axis_A = m.axis.normalized();
  path.length_m = m.approach_m;
  path.interference_travel_m = m.interference_travel_m;
  path.interference_depth_m = m.interference_depth_m;
  path.touch_depth_m = project.geometry.touch_depth_m;
  return path;
}

GeometryReport CheckAssemblyGeometry(const Project& project, const ProjectCheck& check,
                                     const std::string& file, const GeometryCheckOptions& options) {
  GeometryReport report;
  AssemblyGeometry g = AssemblyGeometry::FromProject(project, check);
  ContactOptions contact_options;
  contact_options.tolerance_m = project.geometry.contact_m;
  report.contacts = ComputeContactGraph(g, contact_options);
  if (StepsUsable(project, check)) {
    const AssemblyTree& tree = *check.tree;
    for (int s = 0; s < static_cast<int>(project.steps.size()); ++s) {
      report.steps.push_back(CheckStep(project, tree, g, report.contacts, s, options));
      const StepGeometry& sg = report.steps.back();
      ReportTouch(project, tree, g, report.contacts, file, sg, report.diagnostics);
      ReportPaths(project, tree, g, file, sg, options.sphere_axes, report.diagnostics);
    }
  }
  if (options.start) {
    std::vector<Iso3> X_WP;
    for (const Part& part : project.parts) X_WP.push_back(ToIsometry(part.initial_pose));
    report.start_overlaps = StartOverlaps(g, X_WP, project.geometry.touch_depth_m);
    for (const StartOverlap& o : report.start_overlaps) {
      report.diagnostics.Error(file, "parts[" + std::to_string(o.b) + "].initial_pose",
                               "part " + Quote(g.name(o.b)) + " overlaps part " +
                                   Quote(g.name(o.a)) + " by " + FormatMm(o.depth_m) +
                                   " where they start on the table");
    }
  }
  return report;
}

}  // namespace wrap
