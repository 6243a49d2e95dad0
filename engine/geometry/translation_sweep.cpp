#include "geometry/translation_sweep.h"

#include <algorithm>
#include <limits>

namespace wrap {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kLeafSize = 2;
// Boxes are padded so that rounding in the box test never prunes a pair that the triangle test
// would find in contact [m].
constexpr double kBoxPad_m = 1e-9;
// Normals closer to parallel than this (squared sine) take the in-plane axes as well.
constexpr double kParallelSin2 = 1e-8;

// Narrows [lo, hi] to the t at which the projections of a + t d and b on `axis` overlap: a
// projection moves by t (axis . d) along the axis, so the overlap is one interval of t. An
// axis perpendicular to d separates for every t or for none; a zero axis never separates.
inline void NarrowOnAxis(const Vec3& axis, const std::array<Vec3, 3>& a,
                         const std::array<Vec3, 3>& b, const Vec3& d, double& lo, double& hi) {
  const double a0 = axis.dot(a[0]), a1 = axis.dot(a[1]), a2 = axis.dot(a[2]);
  const double b0 = axis.dot(b[0]), b1 = axis.dot(b[1]), b2 = axis.dot(b[2]);
  const double a_min = std::min({a0, a1, a2}), a_max = std::max({a0, a1, a2});
  const double b_min = std::min({b0, b1, b2}), b_max = std::max({b0, b1, b2});
  const double k = axis.dot(d);
  if (k > 0.0) {
    lo = std::max(lo, (b_min - a_max) / k);
    hi = std::min(hi, (b_max - a_min) / k);
  } else if (k < 0.0) {
    lo = std::max(lo, (b_max - a_min) / k);
    hi = std::min(hi, (b_min - a_max) / k);
  } else if (a_min > b_max || a_max < b_min) {
    lo = kInf;
    hi = -kInf;
  }
}

}  // namespace

TravelInterval TriangleTravelInterval(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b,
                                      const Vec3& d, double t_min, double t_max) {
  // Separating axes of two triangles (faces of the Minkowski difference): the two normals and
  // the nine cross products of their edges; for triangles in parallel planes, the directions
  // in the plane across each edge as well. None depends on t, so the triangles meet exactly on
  // the intersection of the per-axis intervals.
  TravelInterval iv{t_min, t_max};
  const std::array<Vec3, 3> ea = {a[1] - a[0], a[2] - a[1], a[0] - a[2]};
  const std::array<Vec3, 3> eb = {b[1] - b[0], b[2] - b[1], b[0] - b[2]};
  const Vec3 na = ea[0].cross(ea[1]);
  const Vec3 nb = eb[0].cross(eb[1]);
  NarrowOnAxis(nb, a, b, d, iv.lo, iv.hi);
  if (iv.empty()) return iv;
  NarrowOnAxis(na, a, b, d, iv.lo, iv.hi);
  if (iv.empty()) return iv;
  for (const Vec3& u : ea) {
    for (const Vec3& v : eb) {
      NarrowOnAxis(u.cross(v), a, b, d, iv.lo, iv.hi);
      if (iv.empty()) return iv;
    }
  }
  const double na2 = na.squaredNorm(), nb2 = nb.squaredNorm();
  if (na.cross(nb).squaredNorm() <= kParallelSin2 * na2 * nb2) {
    const Vec3& n = na2 >= nb2 ? na : nb;
    for (int i = 0; i < 3 && !iv.empty(); ++i) {
      NarrowOnAxis(n.cross(ea[i]), a, b, d, iv.lo, iv.hi);
      NarrowOnAxis(n.cross(eb[i]), a, b, d, iv.lo, iv.hi);
    }
  }
  return iv;
}

SweepMesh::SweepMesh(const TriangleMesh& mesh, const Iso3& X_FM) {
  const int n = static_cast<int>(mesh.triangles.size());
  if (n == 0) return;
  std::vector<Triangle> placed(n);
  BuildInput in;
  in.lo.resize(n);
  in.hi.resize(n);
  in.centroid.resize(n);
  for (int i = 0; i < n; ++i) {
    Triangle& t = placed[i];
    for (int k = 0; k < 3; ++k) t.v[k] = X_FM * mesh.vertices[mesh.triangles[i][k]];
    in.lo[i] = t.v[0].cwiseMin(t.v[1]).cwiseMin(t.v[2]);
    in.hi[i] = t.v[0].cwiseMax(t.v[1]).cwiseMax(t.v[2]);
    in.centroid[i] = (t.v[0] + t.v[1] + t.v[2]) / 3.0;
  }
  index_.resize(n);
  for (int i = 0; i < n; ++i) index_[i] = i;
  nodes_.reserve(2 * n);
  nodes_.emplace_back();
  Build(0, 0, n, in);
  // The triangles in leaf order, so that a leaf's triangles lie side by side.
  triangles_.resize(n);
  for (int s = 0; s < n; ++s) triangles_[s] = placed[index_[s]];
}

void SweepMesh::Build(int node, int begin, int end, const BuildInput& in) {
  if (end - begin <= kLeafSize) {
    Vec3 lo = Vec3::Constant(kInf), hi = Vec3::Constant(-kInf);
    for (int s = begin; s < end; ++s) {
      lo = lo.cwiseMin(in.lo[index_[s]]);
      hi = hi.cwiseMax(in.hi[index_[s]]);
    }
    nodes_[node].lo = lo.array() - kBoxPad_m;
    nodes_[node].hi = hi.array() + kBoxPad_m;
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    return;
  }
  // Split at the middle of the centroids' longest extent (one pass); where that leaves a side
  // nearly empty, at their median instead (ties by index: deterministic either way).
  Vec3 c_lo = Vec3::Constant(kInf), c_hi = Vec3::Constant(-kInf);
  for (int s = begin; s < end; ++s) {
    c_lo = c_lo.cwiseMin(in.centroid[index_[s]]);
    c_hi = c_hi.cwiseMax(in.centroid[index_[s]]);
  }
  int axis = 0;
  (c_hi - c_lo).maxCoeff(&axis);
  const double middle = 0.5 * (c_lo[axis] + c_hi[axis]);
  const auto split = std::partition(index_.begin() + begin, index_.begin() + end,
                                    [&](int i) { return in.centroid[i][axis] < middle; });
  int mid = static_cast<int>(split - index_.begin());
  const int least = (end - begin) / 8;
  if (mid - begin <= least || end - mid <= least) {
    mid = (begin + end) / 2;
    std::nth_element(index_.begin() + begin, index_.begin() + mid, index_.begin() + end,
                     [&](int i, int j) {
                       const double ci = in.centroid[i][axis], cj = in.centroid[j][axis];
                       return ci < cj || (ci == cj && i < j);
                     });
  }
  const int first = static_cast<int>(nodes_.size());
  nodes_[node].first = first;
  nodes_.emplace_back();
  nodes_.emplace_back();
  Build(first, begin, mid, in);
  Build(first + 1, mid, end, in);
  // An inner box is the union of its children's (already padded).
  nodes_[node].lo = nodes_[first].lo.cwiseMin(nodes_[first + 1].lo);
  nodes_[node].hi = nodes_[first].hi.cwiseMax(nodes_[first + 1].hi);
}

Aabb SweepMesh::box() const {
  Aabb box;
  if (nodes_.empty()) return box;
  box.min = nodes_[0].lo.array() + kBoxPad_m;
  box.max = nodes_[0].hi.array() - kBoxPad_m;
  return box;
}

// The traversal of two trees for the first contact: box pairs whose travel intervals start
// before the best contact found so far, the earliest first; leaves' triangle pairs tested exactly.
// The last contact is the first one of the reversed travel (t -> -t, d -> -d).
class SweepTraversal {
 public:
  SweepTraversal(const SweepMesh& moving, const SweepMesh& fixed, const SweepQuery& query,
                 SweepContactStats* stats)
      : m_(moving), f_(fixed), stats_(stats) {
    sign_ = query.last ? -1.0 : 1.0;
    d_ = sign_ * query.d_F;
    t_min_ = query.last ? -query.t_max : query.t_min;
    t_max_ = query.last ? -query.t_min : query.t_max;
  }

  std::optional<SweepContactHit> Run() {
    if (m_.empty() || f_.empty() || !(t_min_ <= t_max_)) return std::nullopt;
    Push(0, 0);
    while (!stack_.empty()) {
      const Entry e = stack_.back();
      stack_.pop_back();
      if (e.lo >= best_) continue;  // found something at least as early meanwhile
      const SweepMesh::Node& a = m_.nodes_[e.m];
      const SweepMesh::Node& b = f_.nodes_[e.f];
      if (a.count > 0 && b.count > 0) {
        if (TestLeaves(a, b)) break;
        continue;
      }
      // Descend into the larger box (a leaf cannot be split).
      const bool split_moving = b.count > 0 || (a.count == 0 && (a.hi - a.lo).squaredNorm() >=
                                                                    (b.hi - b.lo).squaredNorm());
      const int m0 = split_moving ? a.first : e.m, m1 = split_moving ? a.first + 1 : e.m;
      const int f0 = split_moving ? e.f : b.first, f1 = split_moving ? e.f : b.first + 1;
      // The earlier child on top of the stack: it is explored first.
      double lo0 = 0.0, lo1 = 0.0;
      const bool in0 = Interval(m0, f0, &lo0), in1 = Interval(m1, f1, &lo1);
      if (in0 && in1) {
        if (lo0 <= lo1) {
          stack_.push_back({m1, f1, lo1});
          stack_.push_back({m0, f0, lo0});
        } else {
          stack_.push_back({m0, f0, lo0});
          stack_.push_back({m1, f1, lo1});
        }
      } else if (in0) {
        stack_.push_back({m0, f0, lo0});
      } else if (in1) {
        stack_.push_back({m1, f1, lo1});
      }
    }
    if (!found_) return std::nullopt;
    hit_.t = sign_ * best_;
    return hit_;
  }

 private:
  struct Entry {
    int m = 0;
    int f = 0;
    double lo = 0.0;  // first t at which the two boxes meet
  };

  // The first t in range (and before the best) at which box m + t d meets box f; false if none.
  bool Interval(int m, int f, double* lo_out) {
    if (stats_) ++stats_->box_tests;
    const SweepMesh::Node& a = m_.nodes_[m];
    const SweepMesh::Node& b = f_.nodes_[f];
    double lo = t_min_, hi = std::min(t_max_, best_);
    for (int i = 0; i < 3; ++i) {
      const double k = d_[i];
      if (k > 0.0) {
        lo = std::max(lo, (b.lo[i] - a.hi[i]) / k);
        hi = std::min(hi, (b.hi[i] - a.lo[i]) / k);
      } else if (k < 0.0) {
        lo = std::max(lo, (b.hi[i] - a.lo[i]) / k);
        hi = std::min(hi, (b.lo[i] - a.hi[i]) / k);
      } else if (a.lo[i] > b.hi[i] || a.hi[i] < b.lo[i]) {
        return false;
      }
    }
    *lo_out = lo;
    return lo <= hi && lo < best_;
  }

  void Push(int m, int f) {
    double lo = 0.0;
    if (Interval(m, f, &lo)) stack_.push_back({m, f, lo});
  }

  // Tests the triangle pairs of two leaves; true when a contact at t_min was found (nothing can
  // come earlier).
  bool TestLeaves(const SweepMesh::Node& a, const SweepMesh::Node& b) {
    for (int i = a.first; i < a.first + a.count; ++i) {
      for (int j = b.first; j < b.first + b.count; ++j) {
        if (stats_) ++stats_->triangle_tests;
        const TravelInterval iv = TriangleTravelInterval(m_.triangles_[i].v, f_.triangles_[j].v, d_,
                                                         t_min_, std::min(t_max_, best_));
        if (iv.empty() || !(iv.lo < best_)) continue;
        best_ = iv.lo;
        found_ = true;
        hit_.moving_triangle = m_.index_[i];
        hit_.fixed_triangle = f_.index_[j];
        if (best_ <= t_min_) return true;
      }
    }
    return false;
  }

  const SweepMesh& m_;
  const SweepMesh& f_;
  SweepContactStats* stats_;
  double sign_ = 1.0;
  Vec3 d_ = Vec3::Zero();
  double t_min_ = 0.0;
  double t_max_ = 0.0;
  double best_ = kInf;
  bool found_ = false;
  SweepContactHit hit_;
  std::vector<Entry> stack_;
};

std::optional<SweepContactHit> SweepContact(const SweepMesh& moving, const SweepMesh& fixed,
                                            const SweepQuery& query, SweepContactStats* stats) {
  return SweepTraversal(moving, fixed, query, stats).Run();
}

}  // namespace wrap
