#include <cstdio>
#include <numbers>
#include <ostream>
#include <string>

#include "cli.h"
#include "load.h"
#include "model/catalog.h"

namespace wrap::cli {

namespace {

std::string Pad(std::string s, size_t width) {
  if (s.size() < width) s.append(width - s.size(), ' ');
  return s;
}

std::string BoxText(const WrenchBox& b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "F <= (%.4g, %.4g, %.4g) N, M <= (%.4g, %.4g, %.4g) N m",
                b.force_N.x(), b.force_N.y(), b.force_N.z(), b.torque_Nm.x(), b.torque_Nm.y(),
                b.torque_Nm.z());
  return buf;
}

std::string AxisText(const Vec3& a) {
  const Vec3 u = a.normalized();
  static const char* kNames[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    if (std::abs(std::abs(u[i]) - 1.0) < 1e-9) return std::string(u[i] > 0 ? "+" : "-") + kNames[i];
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.3f, %.3f, %.3f)", u.x(), u.y(), u.z());
  return buf;
}

// Prints the DAG from `id` down: a step shows its mating, its inputs follow indented.
void PrintNode(const Project& p, const AssemblyTree& tree, int id, const std::string& prefix,
               const std::string& role, std::ostream& out) {
  const AssemblyNode& n = tree.nodes[id];
  out << prefix << n.name;
  if (!role.empty()) out << "  (" << role << ")";
  if (n.step >= 0) {
    const Mating& m = p.steps[n.step].mating;
    out << "  [" << m.moved << " onto " << m.base << " along " << AxisText(m.axis) << ", "
        << Fmt("%.4g", m.force_N) << " N";
    if (m.torque_Nm != 0.0) out << ", " << Fmt("%.4g", m.torque_Nm) << " N m";
    out << ", " << n.parts.size() << " parts]";
  }
  out << "\n";
  if (n.step < 0) return;
  const Mating& m = p.steps[n.step].mating;
  for (int in : n.inputs) {
    const AssemblyNode& child = tree.nodes[in];
    std::string r = child.name == m.moved ? "moved" : child.name == m.base ? "base" : "";
    PrintNode(p, tree, in, prefix + "    ", r, out);
  }
}


// "+z" for an axis direction, else "(0.707, 0, -0.707)".
std::string NormalText(const Vec3& n) { return AxisText(n); }

void PrintContacts(const Project& p, const GeometryReport& g, std::ostream& out) {
  out << "\nContacts (parts whose surfaces come within " << FormatMm(g.contacts.tolerance_m)
      << ", assembled; " << g.contacts.contacts.size() << " pairs):\n";
  for (const Contact& c : g.contacts.contacts) {
    const Vec3 lo = c.extent_A.min * 1000.0, hi = c.extent_A.max * 1000.0;
    const Vec3 at = c.centroid_A * 1000.0;
    char where[160];
    std::snprintf(where, sizeof where,
                  "area %.1f mm2 around (%.1f, %.1f, %.1f) mm, extent %.1f x %.1f x %.1f mm",
                  c.area_m2 * 1e6, at.x(), at.y(), at.z(), hi.x() - lo.x(), hi.y() - lo.y(),
                  hi.z() - lo.z());
    out << "  " << Pad(p.parts[c.a].name + " - " + p.parts[c.b].name, 26) << where;
    if (c.distance_m > 0.0) out << ", gap " << FormatMm(c.distance_m);
    out << "\n    normals (out of " << p.parts[c.b].name << "):";
    double total = 0.0;
    for (const ContactNormal& n : c.normals) total += n.area_m2;
    for (const ContactNormal& n : c.normals) {
      out << " " << NormalText(n.n_A) << " " << Fmt("%.0f", 100.0 * n.area_m2 / total) << "%";
    }
    out << "\n";
  }
  if (g.steps.empty()) return;
  out << "\nInsertion paths (the moved input swept along its axis against the base):\n";
  for (const StepGeometry& sg : g.steps) {
    const Step& step = p.steps[sg.step];
    out << "  " << Pad(step.name, 22);
    if (!sg.touch) {
      out << "inputs do not touch (closest " << FormatMm(sg.inputs.distance_m) << ")";
    } else if (sg.blocked()) {
      out << "blocked (see the errors)";
    } else {
      out << "free over " << FormatMm(step.mating.approach_m) << " along "
          << AxisText(step.mating.axis);
    }
    out << Fmt(", %.1f ms", sg.sweep_ms) << "\n";
  }
}

}  // namespace

int Info(const std::string& project, std::ostream& out, std::ostream& err) {
  GeometryReport geometry;
  const LoadedProject loaded = LoadChecked(project, &geometry);
  // A project whose only errors are the geometry's is still described (the contacts and paths
  // say how to fix it); the exit code says it is invalid.
  const bool valid = ReportLoad(loaded, project, err);
  const bool describable = loaded.project.has_value() &&
                           geometry.diagnostics.error_count() ==
                               loaded.check.diagnostics.error_count();
  if (!valid && !describable) return 2;
  const Project& p = *loaded.project;
  const ProjectCheck& check = loaded.check;

  out << "Project '" << p.name << "' (" << project << ")\n";
  if (!p.description.empty()) out << "  " << p.description << "\n";
  out << "\nTable: " << Fmt("%.2f", p.table.size.x()) << " x " << Fmt("%.2f", p.table.size.y())
      << " m, top at z = " << Fmt("%.3f", p.table.height) << " m, friction "
      << Fmt("%.2f", p.table.friction) << "\n";

  out << "\nParts (" << p.parts.size() << "):\n";
  out << "  " << Pad("name", 18) << Pad("mass [kg]", 11) << Pad("size [mm]", 26)
      << Pad("triangles", 11) << "mesh\n";
  double total = 0.0;
  for (size_t i = 0; i < p.parts.size(); ++i) {
    const PartGeometry& g = check.parts[i];
    const Vec3 s = g.aabb.size() * 1000.0;
    char size[64];
    std::snprintf(size, sizeof size, "%.1f x %.1f x %.1f", s.x(), s.y(), s.z());
    out << "  " << Pad(p.parts[i].name, 18) << Pad(Fmt("%.4f", g.mass_kg), 11) << Pad(size, 26)
        << Pad(std::to_string(g.mesh.triangles.size()), 11) << p.parts[i].mesh
        << (p.parts[i].solid.empty() ? "" : " [" + p.parts[i].solid + "]") << "\n";
    total += g.mass_kg;
  }
  out << "  total mass " << Fmt("%.4f", total) << " kg\n";

  out << "\nAssembly (" << p.steps.size() << " steps, root first; each step: moved onto base):\n";
  if (check.tree) PrintNode(p, *check.tree, check.tree->root, "  ", "", out);
  PrintContacts(p, geometry, out);

  out << "\nRobots (" << p.robots.size() << "):\n";
  for (const Robot& r : p.robots) {
    const Iso3 X_WR = RobotBaseInWorld(p, r);
    const Vec3 t = X_WR.translation();
    std::string model = r.model.empty() ? "URDF " + r.urdf : r.model;
    if (const RobotModelInfo* info = FindRobotModel(r.model)) {
      model = info->title + " (" + std::to_string(info->dof) + " DoF, reach " +
              Fmt("%.2f", info->reach_m) + " m)";
    }
    const EndEffectorInfo* ee = FindEndEffector(r.end_effector);
    char base[96];
    std::snprintf(base, sizeof base, "base (%.3f, %.3f, %.3f) m", t.x(), t.y(), t.z());
    out << "  " << Pad(r.name, 12) << Pad(model, 46)
        << Pad(r.end_effector + " (" + std::string(ToString(ee->kind)) + ")", 30) << base;
    if (!r.mounted_on.empty()) out << " on " << r.mounted_on << "/" << r.mount;
    out << "\n";
  }

  out << "\nEnd-effector wrench limits (grasp frame):\n";
  out << "  two-finger          " << BoxText(p.wrench_limits.two_finger) << "\n";
  out << "  vacuum, assembly    " << BoxText(p.wrench_limits.vacuum_assembly) << "\n";
  out << "  vacuum, transport   " << BoxText(p.wrench_limits.vacuum_transport) << "\n";
  for (const Robot& r : p.robots) {
    if (r.wrench_limits) out << "  (robot " << r.name << " overrides these)\n";
  }
  out << "Connection limits (default T_pq): " << BoxText(p.connection_limits) << "\n";
  out << "\nPlanner defaults: " << p.planner.grasps << " grasps"
      << (p.planner.widen_grasps ? " (widened on failure)" : " (fixed)") << ", time limit "
      << Fmt("%.4g", p.planner.time_limit_s) << " s, seed " << p.planner.seed << "\n";
  return valid ? 0 : 2;
}

}  // namespace wrap::cli
