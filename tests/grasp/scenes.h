// Small projects built in code for the preprocessing tests: parts from meshes, a DAG, robots.
#pragma once

#include <string>
#include <vector>

#include "model/assembly.h"
#include "model/project.h"
#include "model/validate.h"

namespace wrap::test_scenes {

/// A project and the validation result Preprocess takes, built without files.
struct Scene {
  Project project;
  ProjectCheck check;
};

/// Adds a part with `mesh` (in its own frame, metres) at assembled pose X_AP.
inline void AddPart(Scene& s, const std::string& name, const TriangleMesh& mesh,
                    const Pose& X_AP = {}, double density_kg_m3 = 1000.0) {
  Part part;
  part.name = name;
  part.mesh = name + ".stl";
  part.assembled_pose = X_AP;
  part.density_kg_m3 = density_kg_m3;
  s.project.parts.push_back(part);
  PartGeometry g;
  g.loaded = true;
  g.mesh = mesh;
  g.topology = AnalyzeTopology(mesh);
  g.mass_properties = ComputeMassProperties(mesh);
  g.aabb = ComputeAabb(mesh);
  g.mass_kg = density_kg_m3 * g.mass_properties.volume_m3;
  s.check.parts.push_back(g);
}

/// Adds a step joining `moved` onto `base` into `name`.
inline void AddStep(Scene& s, const std::string& name, const std::string& moved,
                    const std::string& base) {
  Step step;
  step.name = name;
  step.inputs = {base, moved};
  step.mating.moved = moved;
  step.mating.base = base;
  s.project.steps.push_back(step);
}

/// Two UR5e arms at opposite corners of the default table, both with `end_effector`.
inline void AddRobots(Scene& s, const std::string& end_effector) {
  s.project.table.size = Vec3(1.2, 1.0, 0.05);
  s.project.table.height = 0.75;
  for (int k = 0; k < 2; ++k) {
    Robot r;
    r.name = k == 0 ? "a" : "b";
    r.model = "ur5e";
    r.end_effector = end_effector;
    r.base_pose.xyz = Vec3(k == 0 ? 0.45 : -0.45, k == 0 ? 0.35 : -0.35, 0.75);
    r.base_pose.rpy = Vec3(0, 0, k == 0 ? -2.48 : 0.66);
    s.project.robots.push_back(r);
  }
}

/// Builds the DAG into the check; false when the project's steps are malformed.
inline bool Finish(Scene& s) {
  AssemblyTree tree;
  if (!BuildAssemblyTree(s.project, "test", s.check.diagnostics, tree)) return false;
  s.check.tree = tree;
  return true;
}

}  // namespace wrap::test_scenes
