#include "geometry/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace wrap {

namespace {

/// Twice the area vector of triangle `t` (its normal times twice its area) [m^2].
Vec3 DoubleAreaVector(const TriangleMesh& mesh, const Eigen::Vector3i& t) {
  const Vec3& a = mesh.vertices[static_cast<size_t>(t[0])];
  const Vec3& b = mesh.vertices[static_cast<size_t>(t[1])];
  const Vec3& c = mesh.vertices[static_cast<size_t>(t[2])];
  return (b - a).cross(c - a);
}

/// Polynomial sub-expressions of one coordinate of a triangle, Eberly "Polyhedral Mass
/// Properties (Revisited)" (2002), function Subexpressions.
struct Subexpressions {
  double f1 = 0.0, f2 = 0.0, f3 = 0.0;  ///< Sums for the first, second and third moments.
  double g0 = 0.0, g1 = 0.0, g2 = 0.0;  ///< Per-vertex sums for the products of inertia.
};

Subexpressions ComputeSubexpressions(double w0, double w1, double w2) {
  Subexpressions s;
  const double temp0 = w0 + w1;
  s.f1 = temp0 + w2;
  const double temp1 = w0 * w0;
  const double temp2 = temp1 + w1 * temp0;
  s.f2 = temp2 + w2 * s.f1;
  s.f3 = w0 * temp1 + w1 * temp2 + w2 * s.f2;
  s.g0 = s.f2 + w0 * (s.f1 + w0);
  s.g1 = s.f2 + w1 * (s.f1 + w1);
  s.g2 = s.f2 + w2 * (s.f1 + w2);
  return s;
}

}  // namespace

Aabb ComputeAabb(const TriangleMesh& mesh) {
  Aabb box;
  if (mesh.vertices.empty()) return box;
  box.min = box.max = mesh.vertices.front();
  for (const Vec3& v : mesh.vertices) {
    box.min = box.min.cwiseMin(v);
    box.max = box.max.cwiseMax(v);
  }
  return box;
}

double SurfaceArea(const TriangleMesh& mesh) {
  double twice_area = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) twice_area += DoubleAreaVector(mesh, t).norm();
  return 0.5 * twice_area;
}

MeshTopology AnalyzeTopology(const TriangleMesh& mesh, double area_eps) {
  MeshTopology topo;
  // Undirected edge (smaller index in the high half) -> number of triangles using it.
  std::unordered_map<uint64_t, int> edge_uses;
  edge_uses.reserve(mesh.triangles.size() * 2);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const bool repeated_index = t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
    if (repeated_index || 0.5 * DoubleAreaVector(mesh, t).norm() <= area_eps) {
      ++topo.degenerate_triangles;
    }
    // A triangle with a repeated index spans no surface: its edges bound nothing.
    if (repeated_index) continue;
    for (int k = 0; k < 3; ++k) {
      const auto i = static_cast<uint32_t>(t[k]);
      const auto j = static_cast<uint32_t>(t[(k + 1) % 3]);
      const uint64_t key = (uint64_t{std::min(i, j)} << 32) | std::max(i, j);
      ++edge_uses[key];
    }
  }
  for (const auto& [key, uses] : edge_uses) {
    if (uses == 1) ++topo.boundary_edges;
    if (uses > 2) ++topo.non_manifold_edges;
  }
  return topo;
}

MassProperties ComputeMassProperties(const TriangleMesh& mesh) {
  MassProperties props;
  if (mesh.triangles.empty()) return props;

  // Integrate about the box centre: the moments stay small and accurate for meshes far from the
  // origin; the inertia about the COM does not depend on this reference point.
  const Aabb box = ComputeAabb(mesh);
  const Vec3 ref = 0.5 * (box.min + box.max);

  // Integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx over the solid (Eberly 2002, function
  // Compute), accumulated per triangle as signed tetrahedra with the reference point.
  std::array<double, 10> in{};
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Vec3 p0 = mesh.vertices[static_cast<size_t>(t[0])] - ref;
    const Vec3 p1 = mesh.vertices[static_cast<size_t>(t[1])] - ref;
    const Vec3 p2 = mesh.vertices[static_cast<size_t>(t[2])] - ref;
    const Vec3 d = (p1 - p0).cross(p2 - p0);
    const Subexpressions sx = ComputeSubexpressions(p0.x(), p1.x(), p2.x());
    const Subexpressions sy = ComputeSubexpressions(p0.y(), p1.y(), p2.y());
    const Subexpressions sz = ComputeSubexpressions(p0.z(), p1.z(), p2.z());
    in[0] += d.x() * sx.f1;
    in[1] += d.x() * sx.f2;
    in[2] += d.y() * sy.f2;
    in[3] += d.z() * sz.f2;
    in[4] += d.x() * sx.f3;
    in[5] += d.y() * sy.f3;
    in[6] += d.z() * sz.f3;
    in[7] += d.x() * (p0.y() * sx.g0 + p1.y() * sx.g1 + p2.y() * sx.g2);
    in[8] += d.y() * (p0.z() * sy.g0 + p1.z() * sy.g1 + p2.z() * sy.g2);
    in[9] += d.z() * (p0.x() * sz.g0 + p1.x() * sz.g1 + p2.x() * sz.g2);
  }
  constexpr std::array<double, 10> kMult = {1.0 / 6,  1.0 / 24, 1.0 / 24,  1.0 / 24,  1.0 / 60,
                                            1.0 / 60, 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120};
  for (size_t k = 0; k < in.size(); ++k) in[k] *= kMult[k];

  const double volume = in[0];
  props.volume_m3 = volume;
  // With (numerically) no enclosed volume the COM is undefined: report the box centre and no
  // inertia rather than dividing by zero.
  const double diag = box.size().norm();
  if (!(std::abs(volume) > 1e-12 * diag * diag * diag)) {
    props.com = ref;
    return props;
  }
  const Vec3 c(in[1] / volume, in[2] / volume, in[3] / volume);
  props.com = ref + c;

  // Parallel-axis shift from the reference point to the COM.
  Mat3& I = props.inertia_com;
  I(0, 0) = in[5] + in[6] - volume * (c.y() * c.y() + c.z() * c.z());
  I(1, 1) = in[4] + in[6] - volume * (c.z() * c.z() + c.x() * c.x());
  I(2, 2) = in[4] + in[5] - volume * (c.x() * c.x() + c.y() * c.y());
  I(0, 1) = I(1, 0) = -(in[7] - volume * c.x() * c.y());
  I(1, 2) = I(2, 1) = -(in[8] - volume * c.y() * c.z());
  I(0, 2) = I(2, 0) = -(in[9] - volume * c.z() * c.x());
  return props;
}

TriangleMesh Transformed(const TriangleMesh& mesh, const Iso3& X) {
  TriangleMesh out;
  out.triangles = mesh.triangles;
  out.vertices.reserve(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) out.vertices.push_back(X * v);
  return out;
}

TriangleMesh BoxMesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh mesh;
  // Vertex k has x = hi.x when bit 0 of k is set, y when bit 1 is, z when bit 2 is.
  for (int k = 0; k < 8; ++k) {
    mesh.vertices.emplace_back((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(),
                               (k & 4) ? hi.z() : lo.z());
  }
  // Each face as a counter-clockwise quad seen from outside, split along its first diagonal.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return mesh;
}

}  // namespace wrap
