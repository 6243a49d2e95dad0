// Small closed meshes built in code for the geometry tests.
#pragma once

#include <cmath>
#include <numbers>

#include "geometry/mesh.h"

namespace wrap::test_meshes {

/// Closed box from `lo` to `hi` [m]: 8 vertices, 12 outward triangles.
inline TriangleMesh MakeBox(const Vec3& lo, const Vec3& hi) { return BoxMesh(lo, hi); }

/// Closed box with sides `size` [m] and one corner at the origin.
inline TriangleMesh MakeBox(const Vec3& size) { return MakeBox(Vec3::Zero(), size); }

/// Closed prism over a regular `n`-gon inscribed in a circle of radius `r` [m], axis z, from
/// z = -h/2 to h/2: the usual polygonal approximation of a cylinder.
inline TriangleMesh MakeCylinder(double r, double h, int n) {
  TriangleMesh mesh;
  mesh.vertices.emplace_back(0.0, 0.0, -0.5 * h);  // 0: bottom centre
  mesh.vertices.emplace_back(0.0, 0.0, 0.5 * h);   // 1: top centre
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * std::numbers::pi * i / n;
    mesh.vertices.emplace_back(r * std::cos(a), r * std::sin(a), -0.5 * h);  // 2 + 2i
    mesh.vertices.emplace_back(r * std::cos(a), r * std::sin(a), 0.5 * h);   // 3 + 2i
  }
  for (int i = 0; i < n; ++i) {
    const int b0 = 2 + 2 * i, t0 = b0 + 1;
    const int b1 = 2 + 2 * ((i + 1) % n), t1 = b1 + 1;
    mesh.triangles.emplace_back(0, b1, b0);  // bottom, facing -z
    mesh.triangles.emplace_back(1, t0, t1);  // top, facing +z
    mesh.triangles.emplace_back(b0, b1, t1);
    mesh.triangles.emplace_back(b0, t1, t0);
  }
  return mesh;
}

/// The mesh with every triangle's orientation reversed (normals pointing inwards).
inline TriangleMesh Flipped(TriangleMesh mesh) {
  for (Eigen::Vector3i& t : mesh.triangles) std::swap(t[1], t[2]);
  return mesh;
}

}  // namespace wrap::test_meshes
