#include "authoring/new_project.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "authoring/layout.h"
#include "authoring/sequence.h"
#include "grasp/grasp_probe.h"
#include "mating/check.h"
#include "model/catalog.h"
#include "model/entity_path.h"

namespace wrap {

namespace fs = std::filesystem;

namespace {

// Distinct colours (a qualitative palette), cycled.
const Rgba kPalette[] = {{0.306, 0.475, 0.655, 1}, {0.949, 0.557, 0.169, 1},
                         {0.882, 0.341, 0.349, 1}, {0.463, 0.718, 0.698, 1},
                         {0.349, 0.631, 0.310, 1}, {0.929, 0.788, 0.282, 1},
                         {0.690, 0.478, 0.631, 1}, {1.000, 0.616, 0.655, 1},
                         {0.612, 0.459, 0.373, 1}, {0.729, 0.690, 0.675, 1}};

std::string Names(const std::vector<std::string>& names, const std::vector<int>& parts) {
  std::string out;
  for (int p : parts) out += (out.empty() ? "'" : ", '") + names[p] + "'";
  return out;
}

// The groups of parts that touch each other (connected components of the contact graph).
std::vector<std::vector<int>> Groups(const ContactGraph& graph, int n) {
  std::vector<int> group(n, -1);
  std::vector<std::vector<int>> out;
  for (int s = 0; s < n; ++s) {
    if (group[s] >= 0) continue;
    out.emplace_back();
    std::vector<int> stack = {s};
    group[s] = static_cast<int>(out.size()) - 1;
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      out.back().push_back(p);
      for (int q : graph.Neighbours(p)) {
        if (group[q] < 0) {
          group[q] = group[s];
          stack.push_back(q);
        }
      }
    }
    std::sort(out.back().begin(), out.back().end());
  }
  return out;
}

// The project's parts, meshes relative to the output's folder.
void AddParts(const MeshIntake& in, const fs::path& output, Project& p) {
  const fs::path dir = fs::absolute(output).parent_path();
  for (size_t i = 0; i < in.names.size(); ++i) {
    Part part;
    part.name = in.names[i];
    part.mesh = fs::absolute(in.files[i]).lexically_relative(dir).generic_string();
    if (part.mesh.empty()) part.mesh = fs::absolute(in.files[i]).generic_string();
    part.scale = in.scale;
    part.solid = in.solids[i];
    part.assembled_pose = FromIsometry(in.X_AP[i]);
    part.color = kPalette[i % std::size(kPalette)];
    if (in.colors[i]) part.color = *in.colors[i];
    p.parts.push_back(std::move(part));
  }
}

// The DAG: one step per proposed step, its inputs the nodes holding exactly its part sets.
Result<void> AddSteps(const ProposedSequence& seq, const NewProjectOptions& options, Project& p) {
  const EndEffectorInfo* ee = FindEndEffector(options.end_effector);
  const bool options_vacuum = ee != nullptr && ee->kind == EndEffectorKind::kVacuum;
  std::map<std::vector<int>, std::string> node;  // part set -> node name
  for (size_t i = 0; i < p.parts.size(); ++i) node[{static_cast<int>(i)}] = p.parts[i].name;
  for (size_t k = 0; k < seq.steps.size(); ++k) {
    const ProposedStep& s = seq.steps[k];
    std::vector<int> moved = s.moved, base = s.base;
    std::sort(moved.begin(), moved.end());
    std::sort(base.begin(), base.end());
    if (!node.contains(moved) || !node.contains(base)) {
      return Fail(ErrorCode::kInternal, "wrap new: step " + std::to_string(k + 1) +
                                            " joins inputs no earlier step built");
    }
    Step step;
    step.name = "s" + std::to_string(k + 1) + "_" + node[moved];
    step.inputs = {node[base], node[moved]};
    step.mating.moved = node[moved];
    step.mating.base = node[base];
    step.mating.axis = s.axis_A;
    step.mating.force_N = options.force_N;
    // The robust check's noise (paper §IV-A): 10% transverse force and 5 mm of offset for a
    // two-finger grip; none for suction, which transmits only its axial force while mating
    // (the paper's vacuum experiments carry no noise either).
    if (options_vacuum) {
      step.mating.transverse_fraction = 0.0;
      step.mating.offset_m = 0.0;
    } else {
      step.mating.transverse_fraction = 0.1;
      step.mating.offset_m = 0.005;
    }
    std::vector<int> joined = moved;
    joined.insert(joined.end(), base.begin(), base.end());
    std::sort(joined.begin(), joined.end());
    node[joined] = step.name;
    p.steps.push_back(std::move(step));
  }
  return {};
}

}  // namespace

Result<NewProjectResult> NewProject(const std::vector<fs::path>& meshes, const fs::path& output,
                                    const NewProjectOptions& options) {
  NewProjectResult out;
  auto& log = out.decisions;
  if (!FindRobotModel(options.robot_model)) {
    return Fail(ErrorCode::kInvalidInput, "--robot-model: unknown robot model '" +
                                              options.robot_model +
                                              "' (known: " + RobotModelNames() + ")");
  }
  if (!FindEndEffector(options.end_effector)) {
    return Fail(ErrorCode::kInvalidInput, "--end-effector: unknown end effector '" +
                                              options.end_effector +
                                              "' (known: " + EndEffectorNames() + ")");
  }
  if (options.robots < 1 || options.robots > 12) {
    return Fail(ErrorCode::kInvalidInput, "--robots: between 1 and 12");
  }
  if (!(options.force_N >= 0.0) || !std::isfinite(options.force_N)) {
    return Fail(ErrorCode::kInvalidInput, "--force: a finite number of newtons >= 0");
  }
  auto tell = [&](const char* stage, double fraction) {
    if (options.progress) options.progress(stage, fraction);
  };
  tell("reading the meshes", 0.0);
  auto intake = ReadAssemblyMeshes(meshes, options.unit);
  if (!intake) return std::unexpected(intake.error());
  log.push_back("unit: " + std::string(ToString(intake->unit)) + " (" + intake->unit_reason + ")");
  const int n = static_cast<int>(intake->names.size());
  AssemblyGeometry g(intake->names, intake->meshes, std::vector<Iso3>(n, Iso3::Identity()));

  // The meshes as assembled: no overlaps, one connected whole.
  const GeometryTolerances tol;
  const auto overlaps = StartOverlaps(g, std::vector<Iso3>(n, Iso3::Identity()), tol.touch_depth_m);
  if (!overlaps.empty()) {
    const StartOverlap& o = overlaps.front();
    return Fail(ErrorCode::kInvalidInput,
                "the meshes overlap where they are assembled: '" + g.name(o.b) + "' (" +
                    intake->files[o.b].string() + ") is " + FormatMm(o.depth_m) + " inside '" +
                    g.name(o.a) + "' (" + intake->files[o.a].string() +
                    "); export the parts in their assembled positions, apart or touching");
  }
  tell("finding the contacts", 0.1);
  ContactOptions contact_options;
  contact_options.tolerance_m = tol.contact_m;
  const ContactGraph contacts = ComputeContactGraph(g, contact_options);
  log.push_back("contacts: " + std::to_string(contacts.contacts.size()) + " touching pairs");
  const auto groups = Groups(contacts, n);
  if (groups.size() > 1) {
    std::string list;
    for (const auto& grp : groups) list += (list.empty() ? "" : " | ") + Names(intake->names, grp);
    return Fail(ErrorCode::kInvalidInput,
                "the parts form " + std::to_string(groups.size()) +
                    " groups that do not touch each other (surfaces within " +
                    FormatMm(tol.contact_m) + "): " + list +
                    "; an assembly is one connected whole (check the unit and the positions)");
  }

  // The sequence, with the grasps of the chosen end effector.
  std::vector<const TriangleMesh*> mesh_ptrs;
  for (const TriangleMesh& m : intake->meshes) mesh_ptrs.push_back(&m);
  const std::vector<Iso3> X_AP(n, Iso3::Identity());
  const std::string ees[1] = {options.end_effector};
  tell("sampling grasps", 0.2);
  RunContext ctx(0);
  auto probe = GraspProbe::Build(mesh_ptrs, X_AP, ees, GraspProbeOptions{}, ctx);
  if (!probe) return std::unexpected(probe.error());
  SequenceOptions seq_options;
  seq_options.touch_depth_m = tol.touch_depth_m;
  tell("finding an assembly sequence", 0.35);
  const ProposedSequence seq = ProposeSequence(g, contacts, &*probe, seq_options);
  if (!seq.ok()) {
    return Fail(ErrorCode::kInfeasible,
                "no assembly sequence: the parts " + Names(intake->names, seq.interlocked) +
                    " are interlocked (none of them, nor a touching pair, can leave the others "
                    "along the axes, the contact normals or 32 directions over the sphere)");
  }
  for (size_t k = 0; k < seq.steps.size(); ++k) {
    log.push_back("step " + std::to_string(k + 1) + ": " + seq.steps[k].why);
  }

  Project& p = out.project;
  p.name = options.name.empty() ? output.stem().string() : options.name;
  const bool step = !intake->solids.front().empty();
  p.description =
      "Made by wrap new from " +
      (step ? std::to_string(n) + " parts of " + intake->files.front().filename().string()
            : std::to_string(n) + " meshes (" + ToString(intake->unit) + ")") +
      ": the DAG by assembly-by-disassembly, initial poses from stable placements a "
      "robot can pick.";
  p.table = TableFor(options.robot_model);
  p.planner.grasps = options.grasps;
  AddParts(*intake, output, p);
  if (auto ok = AddSteps(seq, options, p); !ok) return std::unexpected(ok.error());
  p.robots = RobotsAroundTable(p.table, options.robots, options.robot_model, options.end_effector);
  log.push_back("robots: " + std::to_string(options.robots) + " " + options.robot_model + " with " +
                options.end_effector + " around the table, facing its centre");
  for (Part& part : p.parts) part.initial_pose.xyz = Vec3(0, 0, p.table.height);

  // The layout needs the project's own view of the meshes (as validation reads them).
  ProjectCheck check = ValidateProject(p, output);
  for (const Diagnostic& d : check.diagnostics.items) {
    if (d.severity == Severity::kError) {
      return Fail(ErrorCode::kInternal,
                  "wrap new: the project does not validate: " + FormatNamed(d, p));
    }
  }
  tell("laying out the parts on the table", 0.6);
  auto layout = LayOutParts(p, check, output);
  if (!layout) return std::unexpected(layout.error());
  log.insert(log.end(), layout->decisions.begin(), layout->decisions.end());
  for (int part : layout->overhanging) {
    log.push_back("'" + p.parts[part].name +
                  "' rests over the table's edge: no placement on the table lets a robot pick it");
  }
  if (!layout->unpickable.empty()) {
    return Fail(ErrorCode::kInfeasible,
                "no robot can pick " + Names(intake->names, layout->unpickable) +
                    " in any stable placement on the table (" + options.end_effector + ")");
  }
  return out;
}

}  // namespace wrap
