#include "geometry/mesh_offset.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

namespace wrap {

namespace {

constexpr double kSamePlaneCos = 0.9848;  // cos 10 deg: normals this close are one plane
constexpr double kMaxStretch = 3.0;       // a vertex moves at most this times the depth

// Interior angle of triangle t at its corner c.
double CornerAngle(const TriangleMesh& mesh, const Eigen::Vector3i& t, int c) {
  const Vec3& p = mesh.vertices[t[c]];
  const Vec3 u = mesh.vertices[t[(c + 1) % 3]] - p;
  const Vec3 v = mesh.vertices[t[(c + 2) % 3]] - p;
  const double nu = u.norm(), nv = v.norm();
  if (nu <= 0.0 || nv <= 0.0) return 0.0;
  return std::acos(std::clamp(u.dot(v) / (nu * nv), -1.0, 1.0));
}

// The distinct planes around one vertex: angle-weighted mean normals of its faces, faces closer
// than kSamePlaneCos merged.
struct VertexPlanes {
  std::vector<Vec3> sums;  // weighted normal sums, one per plane
  void Add(const Vec3& n, double weight) {
    if (!(weight > 0.0)) return;
    for (Vec3& s : sums) {
      if (s.normalized().dot(n) >= kSamePlaneCos) {
        s += weight * n;
        return;
      }
    }
    sums.push_back(weight * n);
  }
};

// The displacement that moves every plane by `depth` inward: the least-squares solution of
// n_i . d = -depth of least norm (a pseudo-inverse), so that directions no plane constrains (along
// an edge) stay put.
Vec3 MiterDisplacement(const VertexPlanes& planes, double depth) {
  if (planes.sums.empty()) return Vec3::Zero();
  if (planes.sums.size() == 1) return -depth * planes.sums[0].normalized();
  Mat3 A = Mat3::Zero();
  Vec3 b = Vec3::Zero();
  for (const Vec3& s : planes.sums) {
    const Vec3 n = s.normalized();
    A += n * n.transpose();
    b -= depth * n;
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(A);
  Vec3 d = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    const double lambda = eig.eigenvalues()[i];
    if (lambda > 1e-9) {
      const Vec3 v = eig.eigenvectors().col(i);
      d += (v.dot(b) / lambda) * v;
    }
  }
  const double cap = kMaxStretch * std::abs(depth);
  if (!d.allFinite()) return Vec3::Zero();
  if (d.norm() > cap) d *= cap / d.norm();
  return d;
}

}  // namespace

TriangleMesh InsetMesh(const TriangleMesh& mesh, double depth_m) {
  TriangleMesh out = mesh;
  if (depth_m == 0.0 || mesh.triangles.empty()) return out;
  const double orientation = ComputeMassProperties(mesh).volume_m3 < 0.0 ? -1.0 : 1.0;
  std::vector<VertexPlanes> planes(mesh.vertices.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Vec3 cr =
        (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    const double norm = cr.norm();
    if (!(norm > 0.0)) continue;
    const Vec3 n = orientation * cr / norm;
    for (int c = 0; c < 3; ++c) planes[t[c]].Add(n, CornerAngle(mesh, t, c));
  }
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    out.vertices[v] += MiterDisplacement(planes[v], depth_m);
  }
  return out;
}

}  // namespace wrap
