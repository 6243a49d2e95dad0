#include "authoring/suggest.h"

#include <algorithm>
#include <map>
#include <set>

#include "authoring/layout.h"
#include "authoring/sequence.h"
#include "grasp/grasp_probe.h"
#include "mating/check.h"
#include "task/planner.h"

namespace wrap {

namespace fs = std::filesystem;

namespace {

std::string StepPath(int s) { return "steps[" + std::to_string(s) + "]"; }

// The steps of a proposed sequence, named after the parts of `project`.
OrderSuggestion StepsOf(const Project& project, const ProposedSequence& seq) {
  OrderSuggestion out;
  std::map<std::vector<int>, std::string> node;
  for (size_t i = 0; i < project.parts.size(); ++i) {
    node[{static_cast<int>(i)}] = project.parts[i].name;
  }
  const Mating defaults = project.steps.empty() ? Mating{} : project.steps.front().mating;
  for (size_t k = 0; k < seq.steps.size(); ++k) {
    std::vector<int> moved = seq.steps[k].moved, base = seq.steps[k].base;
    std::sort(moved.begin(), moved.end());
    std::sort(base.begin(), base.end());
    Step step;
    step.name = "s" + std::to_string(k + 1) + "_" + node[moved];
    step.inputs = {node[base], node[moved]};
    step.mating = defaults;
    step.mating.final_poses.clear();
    step.mating.moved = node[moved];
    step.mating.base = node[base];
    step.mating.axis = seq.steps[k].axis_A;
    std::vector<int> joined = moved;
    joined.insert(joined.end(), base.begin(), base.end());
    std::sort(joined.begin(), joined.end());
    node[joined] = step.name;
    out.why.push_back(seq.steps[k].why);
    out.steps.push_back(std::move(step));
  }
  return out;
}

// The grasp probe of the project's end effectors on its parts as assembled.
Result<GraspProbe> ProbeOf(const Project& project, const AssemblyGeometry& g) {
  std::vector<const TriangleMesh*> meshes;
  std::vector<Iso3> X_AP;
  for (int p = 0; p < g.num_parts(); ++p) {
    meshes.push_back(&g.mesh(p));
    X_AP.push_back(g.X_AP(p));
  }
  std::vector<std::string> ees;
  for (const Robot& r : project.robots) {
    if (std::find(ees.begin(), ees.end(), r.end_effector) == ees.end()) ees.push_back(r.end_effector);
  }
  RunContext ctx(0);
  return GraspProbe::Build(meshes, X_AP, ees, GraspProbeOptions{}, ctx);
}

// A new DAG for the whole project from the geometry; false when the parts are interlocked.
bool Reorder(const Project& project, AssemblyGeometry& g, const ContactGraph& contacts,
             GraspProbe* probe, Project& edited, std::vector<Suggestion>& out) {
  SequenceOptions options;
  options.touch_depth_m = project.geometry.touch_depth_m;
  const ProposedSequence seq = ProposeSequence(g, contacts, probe, options);
  if (!seq.ok()) return false;
  OrderSuggestion order = StepsOf(project, seq);
  edited.steps = std::move(order.steps);
  std::string text;
  for (const std::string& why : order.why) text += (text.empty() ? "" : "; ") + why;
  out.push_back({"steps", "a new order from the geometry (assembly by disassembly): " + text});
  return true;
}

}  // namespace

Result<OrderSuggestion> SuggestOrder(const Project& project, const ProjectCheck& check) {
  for (size_t p = 0; p < project.parts.size(); ++p) {
    if (p >= check.parts.size() || !check.parts[p].loaded) {
      return Fail(ErrorCode::kInvalidInput,
                  "the mesh of part '" + project.parts[p].name + "' did not load");
    }
  }
  if (project.parts.size() < 2) {
    return Fail(ErrorCode::kInvalidInput, "an assembly order needs at least two parts");
  }
  AssemblyGeometry g = AssemblyGeometry::FromProject(project, check);
  ContactOptions contact_options;
  contact_options.tolerance_m = project.geometry.contact_m;
  const ContactGraph contacts = ComputeContactGraph(g, contact_options);
  auto probe = ProbeOf(project, g);
  if (!probe) return std::unexpected(probe.error());
  SequenceOptions options;
  options.touch_depth_m = project.geometry.touch_depth_m;
  const ProposedSequence seq = ProposeSequence(g, contacts, &*probe, options);
  if (!seq.ok()) {
    std::string names;
    for (int p : seq.interlocked) names += (names.empty() ? "'" : ", '") + g.name(p) + "'";
    return Fail(ErrorCode::kInfeasible,
                "no assembly sequence: the parts " + names +
                    " are interlocked (none of them, nor a touching pair, can leave the others)");
  }
  return StepsOf(project, seq);
}

Result<SuggestResult> SuggestFixes(const Project& project, const ProjectCheck& check,
                                   const fs::path& project_file) {
  SuggestResult out;
  out.edited = project;
  if (!check.tree) {
    return Fail(ErrorCode::kInvalidInput, "the project's assembly DAG is not well formed");
  }
  const GeometryReport report = CheckAssemblyGeometry(project, check, project_file.string());
  AssemblyGeometry g = AssemblyGeometry::FromProject(project, check);
  auto probe = ProbeOf(project, g);
  if (!probe) return std::unexpected(probe.error());

  // The DAG: a new order where inputs do not touch or an insertion has no free axis; else a
  // free axis per blocked step, and roles swapped where only the base can be held.
  bool reorder = false;
  for (const StepGeometry& sg : report.steps) {
    reorder = reorder || !sg.touch || (sg.blocked() && sg.free_axes.empty());
  }
  if (reorder && Reorder(project, g, report.contacts, &*probe, out.edited, out.suggestions)) {
    // the new steps carry their own axes and roles
  } else {
    for (const StepGeometry& sg : report.steps) {
      Mating& m = out.edited.steps[sg.step].mating;
      if (sg.blocked() && !sg.free_axes.empty()) {
        const Vec3 best = *std::max_element(
            sg.free_axes.begin(), sg.free_axes.end(),
            [](const Vec3& a, const Vec3& b) { return AxisPreference(a) < AxisPreference(b); });
        out.suggestions.push_back({StepPath(sg.step) + ".mating.axis",
                                   "use " + FormatDirection(best) + " instead of " +
                                       FormatDirection(m.axis.normalized()) +
                                       " (blocked; free: the first of " +
                                       std::to_string(sg.free_axes.size()) + " free directions "
                                       "by preference, from above first)"});
        m.axis = best;
      }
      const auto& moved = check.tree->nodes[sg.moved].parts;
      const auto& base = check.tree->nodes[sg.base].parts;
      const int mg = ClearGrasps(&*probe, 0, moved, base);
      const int bg = ClearGrasps(&*probe, 0, base, moved);
      if (mg == 0 && bg > 0) {
        out.suggestions.push_back(
            {StepPath(sg.step) + ".mating",
             "swap moved and base: no grasp of '" + m.moved + "' clears '" + m.base +
                 "' where mated, " + std::to_string(bg) + " of '" + m.base + "' clear it"});
        std::swap(m.moved, m.base);
        m.axis = -m.axis;
      }
    }
  }

  // The start: parts that overlap, or that no robot can pick, get new places.
  std::set<int> relayout;
  for (const StartOverlap& o : report.start_overlaps) relayout.insert(o.b);
  ProjectCheck edited_check = check;
  edited_check.tree.reset();
  {
    Diagnostics d;
    AssemblyTree tree;
    if (BuildAssemblyTree(out.edited, project_file.string(), d, tree)) edited_check.tree = tree;
  }
  if (!edited_check.tree) return out;
  PreprocessOptions pre_options;
  pre_options.project_file = project_file;
  RunContext pre_ctx(project.planner.seed);
  if (auto pre = Preprocess(out.edited, edited_check, pre_options, pre_ctx)) {
    TaskPlannerOptions task;
    task.project_file = project_file;
    if (auto un = UnpickableAtStart(out.edited, edited_check, *pre, task)) {
      for (const UnpickablePart& u : *un) relayout.insert(u.part);
    }
  }
  if (!relayout.empty()) {
    LayoutOptions options;
    options.parts.assign(relayout.begin(), relayout.end());
    auto layout = LayOutParts(out.edited, edited_check, project_file, options);
    if (!layout) return std::unexpected(layout.error());
    for (int p : options.parts) {
      out.suggestions.push_back(
          {"parts[" + std::to_string(p) + "].initial_pose",
           "move '" + project.parts[p].name + "' (it overlaps another part or no robot can pick "
           "it where it starts) to a stable placement a robot can pick"});
    }
    for (const std::string& d : layout->decisions) out.suggestions.push_back({"", d});
  }
  return out;
}

}  // namespace wrap
