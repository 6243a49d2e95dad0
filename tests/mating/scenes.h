// Hand-made assemblies of boxes for the geometry checks: a cup (blind hole) or a tube (through
// hole) with a peg that fits it exactly, in millimetres.
#pragma once

#include <string>
#include <vector>

#include "core/pose.h"
#include "geometry/mesh.h"
#include "mating/assembly_geometry.h"

namespace wrap::test {

inline Vec3 Mm(double x, double y, double z) { return Vec3(x, y, z) * 1e-3; }

/// Parts in the assembly frame (meshes modelled in place, X_AP = identity unless rotated).
struct Scene {
  std::vector<std::string> names;
  std::vector<TriangleMesh> meshes;
  std::vector<Iso3> poses;
  int Add(const std::string& name, TriangleMesh mesh, const Iso3& X = Iso3::Identity()) {
    names.push_back(name);
    meshes.push_back(std::move(mesh));
    poses.push_back(X);
    return static_cast<int>(names.size()) - 1;
  }
  AssemblyGeometry Geometry() const { return AssemblyGeometry(names, meshes, poses); }
};

/// A 30 x 30 mm cup of 5 mm walls around a 20 x 20 x 20 mm hole (a bottom plate when `blind`,
/// four walls) and a 20 x 20 x 35 mm peg that fills the hole; everything moved by X.
/// Returns the base's part indices; the peg is the last part.
inline std::vector<int> CupAndPeg(Scene& s, bool blind, const Iso3& X = Iso3::Identity()) {
  std::vector<int> base;
  if (blind) base.push_back(s.Add("bottom", BoxMesh(Mm(-15, -15, 0), Mm(15, 15, 5)), X));
  base.push_back(s.Add("wall_xn", BoxMesh(Mm(-15, -15, 5), Mm(-10, 15, 25)), X));
  base.push_back(s.Add("wall_xp", BoxMesh(Mm(10, -15, 5), Mm(15, 15, 25)), X));
  base.push_back(s.Add("wall_yn", BoxMesh(Mm(-10, -15, 5), Mm(10, -10, 25)), X));
  base.push_back(s.Add("wall_yp", BoxMesh(Mm(-10, 10, 5), Mm(10, 15, 25)), X));
  s.Add("peg", BoxMesh(Mm(-10, -10, 5), Mm(10, 10, 40)), X);
  return base;
}

/// The union of two closed meshes as one (two shells).
inline TriangleMesh Merged(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh out = a;
  const int offset = static_cast<int>(a.vertices.size());
  out.vertices.insert(out.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const Eigen::Vector3i& t : b.triangles) {
    out.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
  }
  return out;
}

}  // namespace wrap::test
