// The dependency DAG of a project as a tree of subassemblies (paper §III).
#pragma once

#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "model/project.h"

namespace wrap {

/// One vertex of the DAG: a part (a leaf) or the subassembly a step builds.
struct AssemblyNode {
  std::string name;         ///< Part or step name.
  int part = -1;            ///< Index into Project::parts for a leaf, else -1.
  int step = -1;            ///< Index into Project::steps for a step, else -1.
  std::vector<int> inputs;  ///< Node ids of the step's inputs (empty for a part).
  std::vector<int> parts;   ///< Indices of every part in this subassembly, ascending.
  int consumer = -1;        ///< Node id of the step that uses this node as input; -1 for root.
};

/// The DAG with parts and steps as nodes. Node ids: parts first (same order as
/// Project::parts), then steps (same order as Project::steps).
struct AssemblyTree {
  std::vector<AssemblyNode> nodes;  ///< All vertices.
  int root = -1;                    ///< The whole assembly.
  std::vector<int> step_order;      ///< Step node ids in a topological order (inputs first).

  /// Node id of a part or step name, or -1.
  int Find(const std::string& name) const;
};

/// Builds the tree, reporting into `diags` (with JSON paths, file `file`): unknown input names,
/// steps without exactly two inputs, a node used by two steps, a part in both inputs of a step,
/// a declared part set the inputs do not partition, cycles, and zero or several roots. Returns
/// true when the tree is usable (no errors found here).
bool BuildAssemblyTree(const Project& project, const std::string& file, Diagnostics& diags,
                       AssemblyTree& tree);

}  // namespace wrap
