#include "grasp/subassembly.h"

#include <limits>

namespace wrap {

Result<std::vector<Subassembly>> BuildSubassemblies(const Project& project,
                                                    const ProjectCheck& check) {
  if (!check.tree) {
    return Fail(ErrorCode::kInvalidInput,
                "preprocess: project '" + project.name +
                    "' has no usable assembly DAG (run 'wrap validate' for the reason)");
  }
  if (check.parts.size() != project.parts.size()) {
    return Fail(ErrorCode::kInvalidInput, "preprocess: project '" + project.name +
                                              "' was validated without its meshes (" +
                                              std::to_string(check.parts.size()) + " loaded for " +
                                              std::to_string(project.parts.size()) + " parts)");
  }
  for (size_t i = 0; i < project.parts.size(); ++i) {
    if (!check.parts[i].loaded || check.parts[i].mesh.empty()) {
      return Fail(ErrorCode::kInvalidInput, "preprocess: part '" + project.parts[i].name +
                                                "': mesh not loaded (missing or unreadable file)");
    }
    if (!(check.parts[i].mass_kg > 0.0)) {
      return Fail(ErrorCode::kInvalidInput,
                  "preprocess: part '" + project.parts[i].name +
                      "': no positive mass (an open mesh with no mass given?)");
    }
  }
  const AssemblyTree& tree = *check.tree;
  std::vector<Subassembly> out;
  out.reserve(tree.nodes.size());
  for (int id = 0; id < static_cast<int>(tree.nodes.size()); ++id) {
    const AssemblyNode& node = tree.nodes[id];
    Subassembly s;
    s.name = node.name;
    s.node = id;
    s.parts = node.parts;
    Vec3 moment = Vec3::Zero();
    s.aabb_A.min = Vec3::Constant(std::numeric_limits<double>::infinity());
    s.aabb_A.max = -s.aabb_A.min;
    for (int p : s.parts) {
      const PartGeometry& g = check.parts[p];
      const Iso3 X_AP = ToIsometry(project.parts[p].assembled_pose);
      s.X_AP.push_back(X_AP);
      s.mass_kg += g.mass_kg;
      moment += g.mass_kg * (X_AP * g.mass_properties.com);
      for (const Vec3& v : g.mesh.vertices) {
        const Vec3 v_A = X_AP * v;
        s.aabb_A.min = s.aabb_A.min.cwiseMin(v_A);
        s.aabb_A.max = s.aabb_A.max.cwiseMax(v_A);
      }
    }
    if (s.parts.empty()) {
      return Fail(ErrorCode::kInvalidInput,
                  "preprocess: DAG vertex '" + s.name + "' holds no parts");
    }
    s.com_A = moment / s.mass_kg;
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace wrap
