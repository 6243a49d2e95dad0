#include "generator/solid_meshers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <utility>

namespace wrap::partgen {

namespace {

/// Sorted distinct coordinates of all box faces along `axis`.
std::vector<double> Breakpoints(const std::vector<Box>& boxes, int axis) {
  std::vector<double> v;
  v.reserve(2 * boxes.size());
  for (const Box& b : boxes) {
    v.push_back(b.min[axis]);
    v.push_back(b.max[axis]);
  }
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

/// Appends the quad a-b-c-d (counter-clockwise seen from outside) as two triangles.
void AddQuad(TriangleMesh& mesh, int a, int b, int c, int d) {
  mesh.triangles.emplace_back(a, b, c);
  mesh.triangles.emplace_back(a, c, d);
}

}  // namespace

Box CenteredBox(const Vec3& center, const Vec3& size) {
  return Box{center - 0.5 * size, center + 0.5 * size};
}

bool BoxSolid::Contains(const Vec3& p) const {
  bool inside = false;
  for (const Step& s : steps_) {
    if ((p.array() > s.box.min.array()).all() && (p.array() < s.box.max.array()).all()) {
      inside = s.add;
    }
  }
  return inside;
}

Result<TriangleMesh> BoxSolid::Mesh() const {
  if (steps_.empty()) return Fail(ErrorCode::kInvalidInput, "box solid: no boxes");
  std::vector<Box> boxes;
  for (const Step& s : steps_) {
    if (!(s.box.max.array() > s.box.min.array()).all()) {
      return Fail(ErrorCode::kInvalidInput, "box solid: a box has a non-positive side length");
    }
    boxes.push_back(s.box);
  }
  const std::array<std::vector<double>, 3> grid = {Breakpoints(boxes, 0), Breakpoints(boxes, 1),
                                                   Breakpoints(boxes, 2)};
  const std::array<int, 3> cells = {static_cast<int>(grid[0].size()) - 1,
                                    static_cast<int>(grid[1].size()) - 1,
                                    static_cast<int>(grid[2].size()) - 1};

  // Classify every cell by its centre (never on a box face: all faces are grid planes).
  const auto cell_index = [&](int i, int j, int k) { return i + cells[0] * (j + cells[1] * k); };
  std::vector<uint8_t> filled(static_cast<size_t>(cells[0]) * cells[1] * cells[2], 0);
  for (int k = 0; k < cells[2]; ++k) {
    for (int j = 0; j < cells[1]; ++j) {
      for (int i = 0; i < cells[0]; ++i) {
        const Vec3 c(0.5 * (grid[0][i] + grid[0][i + 1]), 0.5 * (grid[1][j] + grid[1][j + 1]),
                     0.5 * (grid[2][k] + grid[2][k + 1]));
        filled[cell_index(i, j, k)] = Contains(c) ? 1 : 0;
      }
    }
  }
  const auto is_filled = [&](std::array<int, 3> c) {
    for (int a = 0; a < 3; ++a) {
      if (c[a] < 0 || c[a] >= cells[a]) return false;
    }
    return filled[cell_index(c[0], c[1], c[2])] != 0;
  };

  // Grid nodes become vertices in order of first use, so the output is deterministic.
  TriangleMesh mesh;
  const std::array<int, 3> nodes = {cells[0] + 1, cells[1] + 1, cells[2] + 1};
  std::vector<int> vertex_of_node(static_cast<size_t>(nodes[0]) * nodes[1] * nodes[2], -1);
  const auto vertex = [&](std::array<int, 3> n) {
    int& id = vertex_of_node[n[0] + nodes[0] * (n[1] + nodes[1] * n[2])];
    if (id < 0) {
      id = static_cast<int>(mesh.vertices.size());
      mesh.vertices.emplace_back(grid[0][n[0]], grid[1][n[1]], grid[2][n[2]]);
    }
    return id;
  };

  for (int k = 0; k < cells[2]; ++k) {
    for (int j = 0; j < cells[1]; ++j) {
      for (int i = 0; i < cells[0]; ++i) {
        const std::array<int, 3> cell = {i, j, k};
        if (!is_filled(cell)) continue;
        for (int a = 0; a < 3; ++a) {
          for (int side = 0; side < 2; ++side) {
            std::array<int, 3> nb = cell;
            nb[a] += side == 0 ? -1 : 1;
            if (is_filled(nb)) continue;
            // The face lies on node plane cell[a] + side; (b, c) span it so that b x c = +a.
            const int b = (a + 1) % 3;
            const int c = (a + 2) % 3;
            std::array<std::array<int, 3>, 4> q;
            for (auto& n : q) n = cell;
            for (auto& n : q) n[a] += side;
            q[1][b] += 1;
            q[2][b] += 1;
            q[2][c] += 1;
            q[3][c] += 1;
            const int v0 = vertex(q[0]), v1 = vertex(q[1]), v2 = vertex(q[2]), v3 = vertex(q[3]);
            if (side == 1) {
              AddQuad(mesh, v0, v1, v2, v3);  // normal +a
            } else {
              AddQuad(mesh, v0, v3, v2, v1);  // normal -a
            }
          }
        }
      }
    }
  }
  if (auto ok = CheckClosedOriented(mesh, "box solid"); !ok) return std::unexpected(ok.error());
  return mesh;
}

Result<TriangleMesh> MeshRevolved(std::span<const ProfilePoint> profile, int segments) {
  if (profile.size() < 2) {
    return Fail(ErrorCode::kInvalidInput, "revolved solid: the profile needs at least 2 points");
  }
  if (segments < 8 || segments % 4 != 0) {
    return Fail(ErrorCode::kInvalidInput, "revolved solid: segments " + std::to_string(segments) +
                                              " must be a multiple of 4, at least 8");
  }
  for (size_t i = 0; i < profile.size(); ++i) {
    if (!(profile[i].r > 0.0)) {
      return Fail(ErrorCode::kInvalidInput,
                  "revolved solid: profile point " + std::to_string(i) + " has radius <= 0");
    }
    if (i > 0 && profile[i].r == profile[i - 1].r && profile[i].z == profile[i - 1].z) {
      return Fail(ErrorCode::kInvalidInput,
                  "revolved solid: profile point " + std::to_string(i) + " repeats the previous");
    }
  }

  // Unit circle from the first quadrant by symmetry: exact 0 and +-1 on the axes, and the same
  // bytes whatever the platform's rounding of sin/cos in the other quadrants.
  const int quarter = segments / 4;
  std::vector<double> cs(segments), sn(segments);
  for (int k = 0; k < segments; ++k) {
    const int r = k % quarter;
    const double t = 0.5 * std::numbers::pi * r / quarter;
    const double c = r == 0 ? 1.0 : std::cos(t);
    const double s = r == 0 ? 0.0 : std::sin(t);
    // Rotate the first-quadrant point by k / quarter right angles; "+ 0.0" turns -0 into +0.
    const std::array<std::array<double, 2>, 4> turned = {{{c, s}, {-s, c}, {-c, -s}, {s, -c}}};
    cs[k] = turned[k / quarter][0] + 0.0;
    sn[k] = turned[k / quarter][1] + 0.0;
  }

  TriangleMesh mesh;
  const int rings = static_cast<int>(profile.size());
  for (int i = 0; i < rings; ++i) {
    for (int k = 0; k < segments; ++k) {
      mesh.vertices.emplace_back(profile[i].r * cs[k], profile[i].r * sn[k], profile[i].z);
    }
  }
  const int bottom = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0, 0.0, profile.front().z);
  const int top = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0, 0.0, profile.back().z);

  const auto at = [&](int ring, int k) { return ring * segments + k % segments; };
  for (int k = 0; k < segments; ++k) {
    mesh.triangles.emplace_back(bottom, at(0, k + 1), at(0, k));  // facing -z
  }
  for (int i = 0; i + 1 < rings; ++i) {
    for (int k = 0; k < segments; ++k) {
      AddQuad(mesh, at(i, k), at(i, k + 1), at(i + 1, k + 1), at(i + 1, k));
    }
  }
  for (int k = 0; k < segments; ++k) {
    mesh.triangles.emplace_back(top, at(rings - 1, k), at(rings - 1, k + 1));  // facing +z
  }
  if (auto ok = CheckClosedOriented(mesh, "revolved solid"); !ok) {
    return std::unexpected(ok.error());
  }
  return mesh;
}

Result<void> CheckClosedOriented(const TriangleMesh& mesh, std::string_view what) {
  // Directed edge -> number of uses; a closed, oriented 2-manifold uses each exactly once and its
  // reverse exactly once.
  std::map<std::pair<int, int>, int> directed;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const Vec3 n = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
                       .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
    if (!(n.norm() > 1e-12)) {
      return Fail(ErrorCode::kInternal,
                  std::string(what) + ": triangle " + std::to_string(t) + " is degenerate");
    }
    for (int e = 0; e < 3; ++e) ++directed[{tri[e], tri[(e + 1) % 3]}];
  }
  for (const auto& [edge, uses] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    if (uses != 1 || reverse == directed.end() || reverse->second != 1) {
      return Fail(ErrorCode::kInternal, std::string(what) + ": edge " + std::to_string(edge.first) +
                                            "-" + std::to_string(edge.second) +
                                            " is not shared by exactly two opposite triangles");
    }
  }
  return {};
}

TriangleMesh Scaled(const TriangleMesh& mesh, double factor) {
  TriangleMesh out = mesh;
  for (Vec3& v : out.vertices) v *= factor;
  return out;
}

}  // namespace wrap::partgen
