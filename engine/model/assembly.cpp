// The assembly tree of a project: part and step nodes, their inputs, the step order and the root,
// with the diagnostics of a malformed tree.
#include "model/assembly.h"

#include <algorithm>
#include <map>
#include <set>

namespace wrap {

int AssemblyTree::Find(const std::string& name) const {
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

namespace {

std::string StepPath(int s) { return "steps[" + std::to_string(s) + "]"; }

std::string Quote(const std::string& s) { return "'" + s + "'"; }

// One node per part (ids 0..parts-1), then one per step; returns the node id of each name.
std::map<std::string, int> AddNodes(const Project& project, AssemblyTree& tree) {
  const int num_parts = static_cast<int>(project.parts.size());
  const int num_steps = static_cast<int>(project.steps.size());
  std::map<std::string, int> id_of;
  for (int i = 0; i < num_parts; ++i) {
    AssemblyNode n;
    n.name = project.parts[i].name;
    n.part = i;
    n.parts = {i};
    tree.nodes.push_back(n);
    id_of.emplace(n.name, i);  // Duplicate names are reported by validation.
  }
  for (int s = 0; s < num_steps; ++s) {
    AssemblyNode n;
    n.name = project.steps[s].name;
    n.step = s;
    tree.nodes.push_back(n);
    id_of.emplace(n.name, num_parts + s);
  }
  return id_of;
}

// Edges: inputs must exist, be distinct, not be the step itself, and be used only once.
void LinkInputs(const Project& project, const std::string& file,
                const std::map<std::string, int>& id_of, Diagnostics& diags, AssemblyTree& tree) {
  const int num_parts = static_cast<int>(project.parts.size());
  const int num_steps = static_cast<int>(project.steps.size());
  for (int s = 0; s < num_steps; ++s) {
    const Step& step = project.steps[s];
    const int self = num_parts + s;
    const std::string path = StepPath(s) + ".inputs";
    if (step.inputs.size() != 2) {
      diags.Error(file, path,
                  "a step joins exactly two inputs (one mating), found " +
                      std::to_string(step.inputs.size()));
    }
    for (size_t k = 0; k < step.inputs.size(); ++k) {
      const std::string& in = step.inputs[k];
      const std::string ipath = path + "[" + std::to_string(k) + "]";
      auto it = id_of.find(in);
      if (it == id_of.end()) {
        diags.Error(file, ipath, "unknown input " + Quote(in) + ": no part or step has this name");
        continue;
      }
      if (it->second == self) {
        diags.Error(file, ipath, "step " + Quote(step.name) + " cannot be an input of itself");
        continue;
      }
      auto& ins = tree.nodes[self].inputs;
      if (std::find(ins.begin(), ins.end(), it->second) != ins.end()) {
        diags.Error(file, ipath, "input " + Quote(in) + " is listed twice");
        continue;
      }
      AssemblyNode& child = tree.nodes[it->second];
      if (child.consumer >= 0) {
        diags.Error(file, ipath,
                    Quote(in) + " is already an input of step " +
                        Quote(tree.nodes[child.consumer].name) +
                        "; every part and subassembly is used by exactly one step");
        continue;
      }
      child.consumer = self;
      ins.push_back(it->second);
    }
  }
}

// The parts of step node `node`: the union of its inputs' parts, which must be disjoint, and
// equal to the step's declared parts when it lists them.
void CollectStepParts(const Project& project, const std::string& file,
                      const std::map<std::string, int>& id_of, Diagnostics& diags,
                      AssemblyTree& tree, AssemblyNode& node) {
  std::set<int> seen;
  for (int in : node.inputs) {
    for (int p : tree.nodes[in].parts) {
      if (!seen.insert(p).second) {
        diags.Error(file, StepPath(node.step) + ".inputs",
                    "part " + Quote(project.parts[p].name) + " is in both inputs of step " +
                        Quote(node.name));
      }
    }
  }
  node.parts.assign(seen.begin(), seen.end());
  const Step& step = project.steps[node.step];
  if (step.parts.empty()) return;
  std::set<int> declared;
  for (const std::string& name : step.parts) {
    auto it = id_of.find(name);
    if (it == id_of.end() || tree.nodes[it->second].part < 0) {
      diags.Error(file, StepPath(node.step) + ".parts", "unknown part " + Quote(name));
      continue;
    }
    declared.insert(tree.nodes[it->second].part);
  }
  for (int p : declared) {
    if (!seen.count(p)) {
      diags.Error(file, StepPath(node.step) + ".parts",
                  "the inputs do not partition the step's parts: part " +
                      Quote(project.parts[p].name) + " is in no input");
    }
  }
  for (int p : seen) {
    if (!declared.count(p)) {
      diags.Error(file, StepPath(node.step) + ".parts",
                  "the inputs do not partition the step's parts: input part " +
                      Quote(project.parts[p].name) + " is not listed");
    }
  }
}

// Topological order (Kahn) over steps into tree.step_order, collecting each step's parts on the
// way; returns which nodes were ordered (steps left over are on a cycle).
std::vector<bool> OrderSteps(const Project& project, const std::string& file,
                             const std::map<std::string, int>& id_of, Diagnostics& diags,
                             AssemblyTree& tree) {
  const int num_parts = static_cast<int>(project.parts.size());
  const int num_steps = static_cast<int>(project.steps.size());
  std::vector<int> pending(tree.nodes.size(), 0);
  for (int s = 0; s < num_steps; ++s) {
    for (int in : tree.nodes[num_parts + s].inputs) {
      if (tree.nodes[in].step >= 0) ++pending[num_parts + s];
    }
  }
  std::vector<int> ready;
  for (int s = num_steps - 1; s >= 0; --s) {
    if (pending[num_parts + s] == 0) ready.push_back(num_parts + s);
  }
  std::vector<bool> done(tree.nodes.size(), false);
  while (!ready.empty()) {
    const int id = ready.back();
    ready.pop_back();
    done[id] = true;
    tree.step_order.push_back(id);
    AssemblyNode& node = tree.nodes[id];
    CollectStepParts(project, file, id_of, diags, tree, node);
    if (node.consumer >= 0 && --pending[node.consumer] == 0) ready.push_back(node.consumer);
  }
  return done;
}

// The root: the one node nobody consumes (`cycle`: the steps on a cycle, already reported).
void FindRoot(const std::string& file, const std::vector<bool>& done, const std::string& cycle,
              Diagnostics& diags, AssemblyTree& tree) {
  std::vector<int> roots;
  for (size_t i = 0; i < tree.nodes.size(); ++i) {
    if (tree.nodes[i].consumer < 0 && (tree.nodes[i].step < 0 || done[i])) {
      roots.push_back(static_cast<int>(i));
    }
  }
  if (roots.size() == 1) {
    tree.root = roots[0];
  } else if (roots.size() > 1 && cycle.empty()) {
    std::string names;
    for (int r : roots) names += (names.empty() ? "" : ", ") + Quote(tree.nodes[r].name);
    diags.Error(file, "steps",
                "more than one root (" + names +
                    "): every part and step but the final assembly must be an input of a step");
  } else if (roots.empty() && cycle.empty()) {
    diags.Error(file, "parts", "the project has no parts");
  }
}

}  // namespace

bool BuildAssemblyTree(const Project& project, const std::string& file, Diagnostics& diags,
                       AssemblyTree& tree) {
  const int errors_before = diags.error_count();
  tree = AssemblyTree{};
  const int num_parts = static_cast<int>(project.parts.size());
  const int num_steps = static_cast<int>(project.steps.size());
  const std::map<std::string, int> id_of = AddNodes(project, tree);
  LinkInputs(project, file, id_of, diags, tree);
  const std::vector<bool> done = OrderSteps(project, file, id_of, diags, tree);
  std::string cycle;
  for (int s = 0; s < num_steps; ++s) {
    if (!done[num_parts + s]) cycle += (cycle.empty() ? "" : ", ") + Quote(project.steps[s].name);
  }
  if (!cycle.empty()) {
    diags.Error(file, "steps", "the dependency graph has a cycle through steps " + cycle);
  }
  FindRoot(file, done, cycle, diags, tree);
  return diags.error_count() == errors_before && tree.root >= 0;
}

}  // namespace wrap
