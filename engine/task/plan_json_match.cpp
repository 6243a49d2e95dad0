// Matching a parsed plan against its project (task/plan_json.h): CheckPlanMatchesProject, the
// same robots, parts and nodes, milestones that are steps, indices in range, joint vectors of the
// catalog robots' sizes and keyframes whose objects hold every part once.
#include <algorithm>

#include "robot/catalog.h"
#include "task/plan_json.h"
#include "task/plan_json_internal.h"

namespace wrap {

namespace {

using plan_json_internal::Index;
using plan_json_internal::Join;

std::string NameList(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return list.empty() ? "none" : list;
}

// The same names in the same order; else which entry differs, with both lists.
Result<void> SameNames(const std::vector<std::string>& plan_names,
                       const std::vector<std::string>& project_names, const char* key,
                       const char* what, const std::string& plan_file,
                       const std::string& project_name) {
  const size_t n = std::max(plan_names.size(), project_names.size());
  for (size_t i = 0; i < n; ++i) {
    if (i < plan_names.size() && i < project_names.size() && plan_names[i] == project_names[i]) {
      continue;
    }
    std::string problem;
    if (i >= plan_names.size()) {
      problem = "the plan has no " + std::string(what) + " " + std::to_string(i) +
                ", the project "
                "has '" +
                project_names[i] + "'";
    } else if (i >= project_names.size()) {
      problem = std::string(what) + " '" + plan_names[i] + "' is not in the project";
    } else {
      problem = "plan " + std::string(what) + " '" + plan_names[i] + "' where the project has '" +
                project_names[i] + "'";
    }
    return Fail(ErrorCode::kInvalidInput, plan_file + ": " + Index(key, i) + ": " + problem +
                                              ": the plan is for other " + key + " (" +
                                              NameList(plan_names) + ") than project '" +
                                              project_name + "' (" + NameList(project_names) + ")");
  }
  return {};
}

// Every part lies in exactly one object of the keyframe.
Result<void> CheckPartition(const Plan& plan, const Keyframe& k, const AssemblyTree& tree,
                            const std::string& path, const std::string& plan_file) {
  std::vector<int> owner(plan.parts.size(), -1);
  for (const PlanObject& o : k.objects) {
    if (o.node < 0 || o.node >= static_cast<int>(tree.nodes.size())) {
      return Fail(ErrorCode::kInvalidInput, plan_file + ": " + Join(path, "objects") + ": node " +
                                                std::to_string(o.node) + " is not in the project");
    }
    for (int p : tree.nodes[o.node].parts) {
      if (p < 0 || p >= static_cast<int>(owner.size())) continue;
      if (owner[p] >= 0) {
        return Fail(ErrorCode::kInvalidInput, plan_file + ": " + Join(path, "objects") +
                                                  ": part '" + plan.parts[p] + "' is in both '" +
                                                  plan.nodes[owner[p]] + "' and '" +
                                                  plan.nodes[o.node] + "'");
      }
      owner[p] = o.node;
    }
  }
  for (size_t p = 0; p < owner.size(); ++p) {
    if (owner[p] < 0) {
      return Fail(ErrorCode::kInvalidInput, plan_file + ": " + Join(path, "objects") + ": part '" +
                                                plan.parts[p] +
                                                "' is in no object (every part must be in one)");
    }
  }
  return {};
}

Result<void> CheckKeyframe(const Plan& plan, const Keyframe& k, const AssemblyTree& tree,
                           const std::vector<int>& dof, const std::vector<std::string>& models,
                           const std::string& path, const std::string& plan_file) {
  if (k.q.size() != plan.robots.size()) {
    return Fail(ErrorCode::kInvalidInput, plan_file + ": " + Join(path, "q") +
                                              ": expected joint values of " +
                                              std::to_string(plan.robots.size()) +
                                              " robots, found " + std::to_string(k.q.size()));
  }
  for (size_t r = 0; r < k.q.size(); ++r) {
    if (dof[r] < 0 || k.q[r].size() == dof[r]) continue;
    return Fail(ErrorCode::kInvalidInput,
                plan_file + ": " + Join(Join(path, "q"), plan.robots[r]) + ": expected " +
                    std::to_string(dof[r]) + " numbers (robot model '" + models[r] + "' has " +
                    std::to_string(dof[r]) + " joints), found " + std::to_string(k.q[r].size()));
  }
  return CheckPartition(plan, k, tree, path, plan_file);
}

}  // namespace

Result<void> CheckPlanMatchesProject(const Plan& plan, const Project& project,
                                     const AssemblyTree& tree, const std::string& plan_file) {
  std::vector<std::string> robots, parts, nodes;
  for (const Robot& r : project.robots) robots.push_back(r.name);
  for (const Part& p : project.parts) parts.push_back(p.name);
  for (const AssemblyNode& n : tree.nodes) nodes.push_back(n.name);
  if (auto ok = SameNames(plan.robots, robots, "robots", "robot", plan_file, project.name); !ok) {
    return ok;
  }
  if (auto ok = SameNames(plan.parts, parts, "parts", "part", plan_file, project.name); !ok) {
    return ok;
  }
  if (auto ok = SameNames(plan.nodes, nodes, "nodes", "node", plan_file, project.name); !ok) {
    return ok;
  }
  for (size_t i = 0; i < plan.milestone_steps.size(); ++i) {
    const int s = plan.milestone_steps[i];
    if (s < 0 || s >= static_cast<int>(tree.nodes.size()) || tree.nodes[s].step < 0) {
      return Fail(ErrorCode::kInvalidInput, plan_file + ": " + Index("milestones", i) +
                                                ": not an assembly step of the project");
    }
  }

  // Joint-vector sizes of catalog robots (a URDF robot's chain is not loaded here: -1).
  std::vector<int> dof(robots.size(), -1);
  std::vector<std::string> models(robots.size());
  for (size_t r = 0; r < project.robots.size(); ++r) {
    models[r] = project.robots[r].model;
    if (models[r].empty()) continue;
    if (auto chain = LoadRobotModel(models[r])) dof[r] = chain->dof();
  }
  if (auto ok = CheckKeyframe(plan, plan.initial, tree, dof, models, "initial", plan_file); !ok) {
    return ok;
  }
  const int n_nodes = static_cast<int>(tree.nodes.size());
  const int n_parts = static_cast<int>(parts.size());
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    const PlanAction& a = plan.actions[i];
    const std::string at = Index("actions", i);
    auto bad = [&](const std::string& path, const std::string& problem) {
      return Fail(ErrorCode::kInvalidInput, plan_file + ": " + path + ": " + problem);
    };
    for (size_t k = 0; k < a.robots.size(); ++k) {
      if (a.robots[k] < 0 || a.robots[k] >= static_cast<int>(robots.size())) {
        return bad(Index(Join(at, "robots"), k), "robot index out of range");
      }
    }
    for (size_t k = 0; k < a.objects.size(); ++k) {
      if (a.objects[k] < 0 || a.objects[k] >= n_nodes) {
        return bad(Index(Join(at, "objects"), k), "node index out of range");
      }
    }
    for (size_t k = 0; k < a.grasps.size(); ++k) {
      const PlanGrasp& g = a.grasps[k].grasp;
      const std::string g_at = Index(Join(at, "grasps"), k);
      if (g.subassembly < 0 || g.subassembly >= n_nodes) {
        return bad(Join(g_at, "subassembly"), "node index out of range");
      }
      if (g.part < 0 || g.part >= n_parts) return bad(Join(g_at, "part"), "part out of range");
      const std::vector<int>& in = tree.nodes[g.subassembly].parts;
      if (std::find(in.begin(), in.end(), g.part) == in.end()) {
        return bad(Join(g_at, "part"), "part '" + parts[g.part] + "' is not in subassembly '" +
                                           nodes[g.subassembly] + "'");
      }
    }
    if (a.milestone < -1 || a.milestone >= static_cast<int>(plan.milestone_steps.size())) {
      return bad(Join(at, "milestone"), "milestone index out of range");
    }
    if (auto ok =
            CheckKeyframe(plan, a.keyframe, tree, dof, models, Join(at, "keyframe"), plan_file);
        !ok) {
      return ok;
    }
    if (a.approach) {
      if (auto ok =
              CheckKeyframe(plan, *a.approach, tree, dof, models, Join(at, "approach"), plan_file);
          !ok) {
        return ok;
      }
    }
  }
  return {};
}

}  // namespace wrap
