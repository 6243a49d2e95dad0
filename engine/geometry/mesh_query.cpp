#include "geometry/mesh_query.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace wrap {

namespace {

constexpr int kLeafSize = 4;
constexpr int kSahDepth = 48;   // deeper nodes split at the median
constexpr int kMaxDepth = 128;  // kSahDepth + log2(2^31 triangles) + slack: the traversal stack

// Slab test: the entry distance of the ray into the box if it enters within (t_min, t_max).
bool RayBox(const Vec3& o, const Vec3& inv_d, const Vec3& lo, const Vec3& hi, double t_min,
            double t_max, double* t_enter) {
  double t0 = t_min, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    double ta = (lo[a] - o[a]) * inv_d[a];
    double tb = (hi[a] - o[a]) * inv_d[a];
    if (ta > tb) std::swap(ta, tb);
    // NaN (0 * inf on a slab boundary) compares false and leaves the bound alone.
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
    if (t0 > t1) return false;
  }
  *t_enter = t0;
  return true;
}

// Moller-Trumbore, both sides: the distance to the triangle's plane crossing or -1.
double RayTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return -1.0;
  const double inv = 1.0 / det;
  const Vec3 s = o - a;
  const double u = s.dot(p) * inv;
  if (u < 0.0 || u > 1.0) return -1.0;
  const Vec3 q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return -1.0;
  return e2.dot(q) * inv;
}

// Squared distance from p to the box [lo, hi] (0 inside).
double BoxDistance2(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 d = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  return d.squaredNorm();
}

// The point of triangle abc nearest to p (the Voronoi-region walk of Ericson, Real-Time Collision
// Detection, 5.1.5).
Vec3 ClosestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0.0)) return a;  // degenerate triangle
  const double v = vb / denom, w = vc / denom;
  return a + v * ab + w * ac;
}

}  // namespace

MeshQuery::MeshQuery(const TriangleMesh& mesh) : mesh_(mesh) {
  const int n = static_cast<int>(mesh_.triangles.size());
  normals_.resize(n);
  cumulative_area_.resize(n);
  std::vector<Vec3> centroids(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3i& t = mesh_.triangles[i];
    const Vec3& a = mesh_.vertices[t[0]];
    const Vec3& b = mesh_.vertices[t[1]];
    const Vec3& c = mesh_.vertices[t[2]];
    const Vec3 cr = (b - a).cross(c - a);
    const double area = 0.5 * cr.norm();
    normals_[i] = area > 0.0 ? Vec3(cr.normalized()) : Vec3::Zero();
    total_area_ += area;
    cumulative_area_[i] = total_area_;
    centroids[i] = (a + b + c) / 3.0;
  }
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(2 * n / kLeafSize + 2);
  nodes_.emplace_back();
  if (n > 0) Build(0, n, centroids);
}

void MeshQuery::Build(int begin, int end, std::vector<Vec3>& centroids) {
  // Iterative over an explicit stack: node 0 is the root and already allocated.
  struct Task {
    int node, begin, end, depth;
  };
  std::vector<Task> stack = {{0, begin, end, 0}};
  while (!stack.empty()) {
    const Task task = stack.back();
    stack.pop_back();
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
    Vec3 clo = lo, chi = hi;
    for (int k = task.begin; k < task.end; ++k) {
      const Eigen::Vector3i& t = mesh_.triangles[order_[k]];
      for (int c = 0; c < 3; ++c) {
        lo = lo.cwiseMin(mesh_.vertices[t[c]]);
        hi = hi.cwiseMax(mesh_.vertices[t[c]]);
      }
      clo = clo.cwiseMin(centroids[order_[k]]);
      chi = chi.cwiseMax(centroids[order_[k]]);
    }
    Node& node = nodes_[task.node];
    node.lo = lo;
    node.hi = hi;
    const int count = task.end - task.begin;
    int axis = 0;
    (chi - clo).maxCoeff(&axis);
    if (count <= kLeafSize || chi[axis] - clo[axis] <= 0.0) {
      node.left = task.begin;
      node.count = count;
      continue;
    }
    // Binned surface-area heuristic along the longest centroid axis: CAD meshes are full of
    // long slivers, for which median splits give boxes that overlap a lot.
    constexpr int kBins = 16;
    struct Bin {
      Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
      Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
      int count = 0;
    };
    std::array<Bin, kBins> bins;
    const double scale = kBins / (chi[axis] - clo[axis]);
    auto bin_of = [&](int tri) {
      return std::min(kBins - 1, static_cast<int>((centroids[tri][axis] - clo[axis]) * scale));
    };
    for (int k = task.begin; k < task.end; ++k) {
      Bin& b = bins[bin_of(order_[k])];
      const Eigen::Vector3i& t = mesh_.triangles[order_[k]];
      for (int c = 0; c < 3; ++c) {
        b.lo = b.lo.cwiseMin(mesh_.vertices[t[c]]);
        b.hi = b.hi.cwiseMax(mesh_.vertices[t[c]]);
      }
      ++b.count;
    }
    auto half_area = [](const Vec3& box_lo, const Vec3& box_hi) {
      if (box_lo.x() > box_hi.x()) return 0.0;
      const Vec3 e = box_hi - box_lo;
      return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
    };
    std::array<double, kBins> right_cost{};
    Bin acc;
    for (int b = kBins - 1; b > 0; --b) {
      acc.lo = acc.lo.cwiseMin(bins[b].lo);
      acc.hi = acc.hi.cwiseMax(bins[b].hi);
      acc.count += bins[b].count;
      right_cost[b] = half_area(acc.lo, acc.hi) * acc.count;
    }
    int best_split = -1;
    double best_cost = std::numeric_limits<double>::infinity();
    acc = Bin();
    for (int b = 0; b < kBins - 1; ++b) {
      acc.lo = acc.lo.cwiseMin(bins[b].lo);
      acc.hi = acc.hi.cwiseMax(bins[b].hi);
      acc.count += bins[b].count;
      if (acc.count == 0 || acc.count == count) continue;
      const double cost = half_area(acc.lo, acc.hi) * acc.count + right_cost[b + 1];
      if (cost < best_cost) {
        best_cost = cost;
        best_split = b;
      }
    }
    int mid = task.begin + count / 2;
    // Past kSahDepth levels only median splits: the depth stays below kMaxDepth for any mesh.
    if (best_split >= 0 && task.depth < kSahDepth) {
      mid = static_cast<int>(
          std::stable_partition(order_.begin() + task.begin, order_.begin() + task.end,
                                [&](int tri) { return bin_of(tri) <= best_split; }) -
          order_.begin());
    }
    if (mid == task.begin || mid == task.end) {
      mid = task.begin + count / 2;
      std::nth_element(order_.begin() + task.begin, order_.begin() + mid, order_.begin() + task.end,
                       [&](int a, int b) {
                         return centroids[a][axis] < centroids[b][axis] ||
                                (centroids[a][axis] == centroids[b][axis] && a < b);
                       });
    }
    const int left = static_cast<int>(nodes_.size());
    nodes_[task.node].left = left;
    nodes_[task.node].count = 0;
    nodes_.emplace_back();
    nodes_.emplace_back();
    stack.push_back({left + 1, mid, task.end, task.depth + 1});
    stack.push_back({left, task.begin, mid, task.depth + 1});
  }
}

std::optional<RayHit> MeshQuery::Cast(const Vec3& origin, const Vec3& dir, double t_min,
                                          double t_max) const {
  if (mesh_.triangles.empty()) return std::nullopt;
  const Vec3 inv_d(1.0 / dir.x(), 1.0 / dir.y(), 1.0 / dir.z());
  RayHit best;
  double best_t = t_max;
  std::array<int, kMaxDepth + 2> stack;
  int top = 0;
  double t_enter = 0.0;
  if (!RayBox(origin, inv_d, nodes_[0].lo, nodes_[0].hi, t_min, best_t, &t_enter)) {
    return std::nullopt;
  }
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.count > 0) {
      for (int k = node.left; k < node.left + node.count; ++k) {
        const Eigen::Vector3i& t = mesh_.triangles[order_[k]];
        const double h = RayTriangle(origin, dir, mesh_.vertices[t[0]], mesh_.vertices[t[1]],
                                     mesh_.vertices[t[2]]);
        if (h > t_min && h < best_t) {
          best_t = h;
          best.t = h;
          best.triangle = order_[k];
        }
      }
      continue;
    }
    double ta = 0.0, tb = 0.0;
    const bool hit_a =
        RayBox(origin, inv_d, nodes_[node.left].lo, nodes_[node.left].hi, t_min, best_t, &ta);
    const bool hit_b = RayBox(origin, inv_d, nodes_[node.left + 1].lo, nodes_[node.left + 1].hi,
                              t_min, best_t, &tb);
    // Push the farther child first so that the nearer one is visited first.
    if (hit_a && hit_b) {
      const bool a_first = ta <= tb;
      stack[top++] = a_first ? node.left + 1 : node.left;
      stack[top++] = a_first ? node.left : node.left + 1;
    } else if (hit_a) {
      stack[top++] = node.left;
    } else if (hit_b) {
      stack[top++] = node.left + 1;
    }
  }
  if (best.triangle < 0) return std::nullopt;
  return best;
}

Vec3 MeshQuery::SamplePoint(std::mt19937_64& rng, int* triangle) const {
  const double u = Uniform01(rng) * total_area_;
  int i = static_cast<int>(std::upper_bound(cumulative_area_.begin(), cumulative_area_.end(), u) -
                           cumulative_area_.begin());
  i = std::min(i, static_cast<int>(cumulative_area_.size()) - 1);
  double r1 = Uniform01(rng), r2 = Uniform01(rng);
  if (r1 + r2 > 1.0) {
    r1 = 1.0 - r1;
    r2 = 1.0 - r2;
  }
  const Eigen::Vector3i& t = mesh_.triangles[i];
  if (triangle) *triangle = i;
  return mesh_.vertices[t[0]] + r1 * (mesh_.vertices[t[1]] - mesh_.vertices[t[0]]) +
         r2 * (mesh_.vertices[t[2]] - mesh_.vertices[t[0]]);
}

std::optional<ClosestPoint> MeshQuery::Closest(const Vec3& p, double max_distance) const {
  if (mesh_.triangles.empty() || !(max_distance >= 0.0)) return std::nullopt;
  double best2 = max_distance * max_distance;
  ClosestPoint best;
  std::array<int, kMaxDepth + 2> stack;
  int top = 0;
  if (BoxDistance2(p, nodes_[0].lo, nodes_[0].hi) > best2) return std::nullopt;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (BoxDistance2(p, node.lo, node.hi) > best2) continue;
    if (node.count > 0) {
      for (int k = node.left; k < node.left + node.count; ++k) {
        const Eigen::Vector3i& t = mesh_.triangles[order_[k]];
        const Vec3 q = ClosestOnTriangle(p, mesh_.vertices[t[0]], mesh_.vertices[t[1]],
                                         mesh_.vertices[t[2]]);
        const double d2 = (q - p).squaredNorm();
        if (d2 <= best2) {
          best2 = d2;
          best.point = q;
          best.triangle = order_[k];
        }
      }
      continue;
    }
    const int a = node.left, b = node.left + 1;
    const double da = BoxDistance2(p, nodes_[a].lo, nodes_[a].hi);
    const double db = BoxDistance2(p, nodes_[b].lo, nodes_[b].hi);
    // Visit the nearer child first: it tightens the bound for the farther one.
    if (da <= db) {
      if (db <= best2) stack[top++] = b;
      if (da <= best2) stack[top++] = a;
    } else {
      if (da <= best2) stack[top++] = a;
      if (db <= best2) stack[top++] = b;
    }
  }
  if (best.triangle < 0) return std::nullopt;
  best.distance = std::sqrt(best2);
  return best;
}

int MeshQuery::CountCrossings(const Vec3& origin, const Vec3& dir) const {
  const Vec3 inv_d(1.0 / dir.x(), 1.0 / dir.y(), 1.0 / dir.z());
  const double t_max = std::numeric_limits<double>::infinity();
  std::array<int, kMaxDepth + 2> stack;
  int top = 0, crossings = 0;
  double t_enter = 0.0;
  if (!RayBox(origin, inv_d, nodes_[0].lo, nodes_[0].hi, 0.0, t_max, &t_enter)) return 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.count > 0) {
      for (int k = node.left; k < node.left + node.count; ++k) {
        const Eigen::Vector3i& t = mesh_.triangles[order_[k]];
        const double h = RayTriangle(origin, dir, mesh_.vertices[t[0]], mesh_.vertices[t[1]],
                                     mesh_.vertices[t[2]]);
        if (h > 0.0) ++crossings;
      }
      continue;
    }
    for (int child : {node.left, node.left + 1}) {
      if (RayBox(origin, inv_d, nodes_[child].lo, nodes_[child].hi, 0.0, t_max, &t_enter)) {
        stack[top++] = child;
      }
    }
  }
  return crossings;
}

bool MeshQuery::Contains(const Vec3& p) const {
  if (mesh_.triangles.empty()) return false;
  // Directions no CAD edge or face is likely to be parallel to.
  static const std::array<Vec3, 3> kDirs = {Vec3(0.5773, 0.5774, 0.5774).normalized(),
                                            Vec3(-0.6123, 0.2041, 0.7638).normalized(),
                                            Vec3(0.1313, -0.9712, 0.1987).normalized()};
  int votes = 0;
  for (int i = 0; i < 3; ++i) {
    votes += CountCrossings(p, kDirs[i]) % 2;
    if (votes == 2 || votes + (2 - i) < 2) break;  // decided
  }
  return votes >= 2;
}

double MeshQuery::Depth(const Vec3& p, double max_depth) const {
  if (!Contains(p)) return 0.0;
  const std::optional<ClosestPoint> c = Closest(p, max_depth);
  return c ? c->distance : max_depth;
}

}  // namespace wrap
