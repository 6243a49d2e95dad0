// The one FCL adapter. See collision.h for the query pipeline; notes on FCL 0.7 behaviour that
// this file works around are next to the code that does it (and in ../shared/STACK.md).
#include "robot/collision.h"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/geometry/shape/triangle_p.h>
#include <fcl/math/bv/OBB.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/detail/convexity_based_algorithm/gjk.h>
#include <fcl/narrowphase/detail/convexity_based_algorithm/minkowski_diff.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <source_location>
#include <sstream>
#include <unordered_map>
#include <utility>

namespace wrap {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// An always-on assert for bugs (a bad id, a group out of range): file, line, what failed.
[[noreturn]] void Fatal(const char* what, const std::source_location& loc) {
  std::fprintf(stderr, "%s:%u: collision world: %s\n", loc.file_name(),
               static_cast<unsigned>(loc.line()), what);
  std::abort();
}
inline void Check(bool ok, const char* what,
                  const std::source_location& loc = std::source_location::current()) {
  if (!ok) Fatal(what, loc);
}

// The FCL trees of meshes, shared by every world that adds the same mesh: cells are built per
// task plan, per set of finger openings and per check, and building the tree of a Fabrica part
// costs milliseconds. An entry lives while some world uses its tree; the mesh is compared
// exactly, not by its hash alone.
class MeshTreeCache {
 public:
  using Tree = fcl::BVHModel<fcl::OBBRSSd>;
  /// The tree of (vertices, triangles), built when no world holds one; null when FCL fails.
  std::shared_ptr<const Tree> Get(const std::vector<fcl::Vector3d>& vertices,
                                  const std::vector<fcl::Triangle>& triangles) {
    std::uint64_t h = 1469598103934665603ULL;
    auto mix = [&h](const void* data, std::size_t bytes) {
      const auto* p = static_cast<const unsigned char*>(data);
      for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ULL;
    };
    for (const fcl::Vector3d& v : vertices) mix(v.data(), 3 * sizeof(double));
    for (const fcl::Triangle& t : triangles) {
      const std::size_t idx[3] = {t[0], t[1], t[2]};
      mix(idx, sizeof idx);
    }
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Entry>& bucket = entries_[h];
    std::erase_if(bucket, [](const Entry& e) { return e.tree.expired(); });
    for (const Entry& e : bucket) {
      if (e.vertices == vertices && e.triangles.size() == triangles.size() &&
          std::equal(e.triangles.begin(), e.triangles.end(), triangles.begin(),
                     [](const fcl::Triangle& a, const fcl::Triangle& b) {
                       return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
                     })) {
        if (auto tree = e.tree.lock()) return tree;
      }
    }
    auto model = std::make_shared<Tree>();
    if (model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(vertices.size())) !=
            fcl::BVH_OK ||
        model->addSubModel(vertices, triangles) != fcl::BVH_OK ||
        model->endModel() != fcl::BVH_OK) {
      return nullptr;
    }
    model->computeLocalAABB();
    bucket.push_back({model, vertices, triangles});
    return model;
  }

  int Live() {
    std::lock_guard<std::mutex> lock(mutex_);
    int n = 0;
    for (const auto& [h, bucket] : entries_) {
      for (const Entry& e : bucket) n += !e.tree.expired();
    }
    return n;
  }

 private:
  struct Entry {
    std::weak_ptr<const Tree> tree;
    std::vector<fcl::Vector3d> vertices;
    std::vector<fcl::Triangle> triangles;
  };
  std::mutex mutex_;
  std::unordered_map<std::uint64_t, std::vector<Entry>> entries_;
};

MeshTreeCache& MeshTrees() {
  static MeshTreeCache cache;
  return cache;
}

// How a shape takes part in the narrowphase: a swept sphere (sphere or capsule: closed forms), a
// convex FCL primitive (box, cylinder: GJK), or an FCL mesh (OBBRSS tree).
enum class Kind : std::uint8_t { kSwept, kConvex, kMesh };

struct ShapeData {
  Kind kind = Kind::kSwept;
  Shape::Type type = Shape::Type::kCapsule;
  std::string name;
  // Body-frame geometry: the axis segment a-b and radius of spheres, capsules and cylinders.
  Vec3 a_B = Vec3::Zero();
  Vec3 b_B = Vec3::Zero();
  double radius = 0.0;
  // Frame S of the FCL geometry in the body frame, and the box (centre, half size) bounding the
  // geometry in S (exact for boxes).
  Iso3 X_BS = Iso3::Identity();
  Vec3 c_S = Vec3::Zero();
  Vec3 h_S = Vec3::Zero();
  std::shared_ptr<const fcl::CollisionGeometryd> geom;
  int body = 0;  // index of the owning body
  // A ball inside the shape (centre in B, radius): distances between such balls bound distances
  // between bodies from above, which prunes MinDistance.
  Vec3 w_B = Vec3::Zero();
  double w_r = 0.0;
  // World state, refreshed when the body moves. X_WS only when a narrowphase needs it for
  // spheres, capsules and cylinders (their boxes come from the axis end points).
  Vec3 a_W = Vec3::Zero();
  Vec3 b_W = Vec3::Zero();
  mutable Iso3 X_WS = Iso3::Identity();
  mutable bool pose_stale = true;
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
};

struct BodyData {
  std::string name;
  int group = 0;
  bool enabled = true;
  bool dirty = true;
  std::uint64_t changed_at = 0;  // Impl::epoch when the pose last changed (see Impl::clean)
  Iso3 X_WB = Iso3::Identity();
  int first = 0;  // first shape in Impl::shapes
  int count = 0;  // number of shapes
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
  Vec3 w_W = Vec3::Zero();  // the first shape's inner ball, world frame
  double w_r = 0.0;
  bool active() const { return enabled && count > 0; }
};

// Squared distance between two boxes (0 when they overlap): a lower bound of the squared
// distance between anything inside them.
inline double BoxDistance2(const Vec3& lo_a, const Vec3& hi_a, const Vec3& lo_b, const Vec3& hi_b) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double gap = std::max(lo_b[k] - hi_a[k], lo_a[k] - hi_b[k]);
    if (gap > 0.0) d2 += gap * gap;
  }
  return d2;
}

inline bool BoxesOverlap(const Vec3& lo_a, const Vec3& hi_a, const Vec3& lo_b, const Vec3& hi_b,
                         double margin) {
  return lo_a.x() <= hi_b.x() + margin && lo_b.x() <= hi_a.x() + margin &&
         lo_a.y() <= hi_b.y() + margin && lo_b.y() <= hi_a.y() + margin &&
         lo_a.z() <= hi_b.z() + margin && lo_b.z() <= hi_a.z() + margin;
}

// Closest points of segments p1-q1 and p2-q2 (Ericson, Real-Time Collision Detection, 5.1.9),
// robust for degenerate and parallel segments. Returns the squared distance.
double ClosestSegmentSegment(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2,
                             Vec3* c1, Vec3* c2) {
  const Vec3 d1 = q1 - p1;
  const Vec3 d2 = q2 - p2;
  const Vec3 r = p1 - p2;
  const double a = d1.squaredNorm();
  const double e = d2.squaredNorm();
  const double f = d2.dot(r);
  constexpr double kEps = 1e-24;  // [m^2]: a segment shorter than 1e-12 m is a point
  double s = 0.0;
  double t = 0.0;
  if (a <= kEps && e <= kEps) {
    s = t = 0.0;
  } else if (a <= kEps) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= kEps) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      // Nearly parallel: any s works; take 0 and let the clamping below pick the partner.
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  *c1 = p1 + s * d1;
  *c2 = p2 + t * d2;
  return (*c1 - *c2).squaredNorm();
}

// A capsule or cylinder of FCL lies along its local z, centred at the origin: the frame that puts
// it on segment p0-p1.
Iso3 SegmentFrame(const Vec3& p0, const Vec3& p1) {
  Iso3 X = Iso3::Identity();
  X.translation() = 0.5 * (p0 + p1);
  const Vec3 axis = p1 - p0;
  if (axis.norm() > 0.0) {
    X.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis).toRotationMatrix();
  }
  return X;
}

bool AllFinite(const Vec3& v) { return v.allFinite(); }

std::string PoseText(const Iso3& X) {
  const Vec3 p = X.translation();
  const Vec3 rpy = RpyFromRotation(X.linear());
  char buf[200];
  std::snprintf(buf, sizeof(buf), "xyz=(%.10g, %.10g, %.10g) rpy=(%.10g, %.10g, %.10g)", p.x(),
                p.y(), p.z(), rpy.x(), rpy.y(), rpy.z());
  return buf;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// GroupPairSet

void GroupPairSet::Add(int g, int h) {
  Check(g >= 0 && g < kMaxCollisionGroups && h >= 0 && h < kMaxCollisionGroups,
        "group id out of range");
  rows_[g] |= std::uint64_t{1} << h;
  rows_[h] |= std::uint64_t{1} << g;
}

void GroupPairSet::Remove(int g, int h) {
  Check(g >= 0 && g < kMaxCollisionGroups && h >= 0 && h < kMaxCollisionGroups,
        "group id out of range");
  rows_[g] &= ~(std::uint64_t{1} << h);
  rows_[h] &= ~(std::uint64_t{1} << g);
}

bool GroupPairSet::Contains(int g, int h) const {
  if (g < 0 || g >= kMaxCollisionGroups || h < 0 || h >= kMaxCollisionGroups) return false;
  return (rows_[g] >> h) & 1u;
}

bool GroupPairSet::empty() const {
  return std::all_of(rows_.begin(), rows_.end(), [](std::uint64_t r) { return r == 0; });
}

void CollisionResult::Clear() {
  collision = false;
  first = ShapePair{};
  pairs.clear();
  narrowphase_tests = 0;
}

// ---------------------------------------------------------------------------------------------
// Impl

struct CollisionWorld::Impl {
  std::vector<BodyData> bodies;
  std::vector<ShapeData> shapes;
  std::vector<std::uint8_t> allowed;  // num_bodies^2, symmetric
  // Pairs found apart by their last exact (margin 0) test: epoch + 1 at that test. A pair is
  // not tested again until one of its bodies moves (resting parts close to each other would
  // otherwise be tested tree against tree at every query). num_bodies^2, index a * n + b, a < b.
  std::vector<std::uint64_t> clean;
  std::uint64_t epoch = 1;  // counts pose changes
  GroupPairSet allowed_groups;
  bool any_dirty = true;

  // Scratch, sized at AddBody or on the first query, reused after that.
  std::vector<int> order;  // bodies sorted by box lower x (sweep and prune)
  struct Candidate {
    double lb2;  // squared box distance: lower bound of the squared body distance
    int a;
    int b;
  };
  std::vector<Candidate> candidates;
  std::vector<int> bvh_stack;  // node ids of a mesh's tree still to visit
  fcl::CollisionRequestd fcl_collision_request;
  fcl::CollisionResultd fcl_collision_result;
  fcl::DistanceRequestd fcl_distance_request;
  fcl::DistanceResultd fcl_distance_result;

  Impl() {
    fcl_collision_request.num_max_contacts = 1;
    fcl_collision_request.enable_contact = false;
    fcl_collision_request.gjk_solver_type = fcl::GST_INDEP;
    fcl_distance_request.enable_nearest_points = true;
    fcl_distance_request.enable_signed_distance = false;
    fcl_distance_request.gjk_solver_type = fcl::GST_INDEP;
    bvh_stack.reserve(256);
  }

  int n() const { return static_cast<int>(bodies.size()); }
  const BodyData& body(BodyId id) const {
    Check(id.value >= 0 && id.value < n(), "body id out of range");
    return bodies[id.value];
  }
  BodyData& body(BodyId id) {
    Check(id.value >= 0 && id.value < n(), "body id out of range");
    return bodies[id.value];
  }
  bool Allowed(int a, int b) const {
    return allowed[static_cast<std::size_t>(a) * bodies.size() + b] != 0 ||
           allowed_groups.Contains(bodies[a].group, bodies[b].group);
  }

  void UpdateShape(ShapeData& s, const Iso3& X_WB) {
    switch (s.kind) {
      case Kind::kSwept:
        s.pose_stale = true;
        s.a_W = X_WB * s.a_B;
        s.b_W = X_WB * s.b_B;
        s.lo = s.a_W.cwiseMin(s.b_W).array() - s.radius;
        s.hi = s.a_W.cwiseMax(s.b_W).array() + s.radius;
        return;
      case Kind::kConvex:
        if (s.type == Shape::Type::kCylinder) {
          // Exact box of a cylinder: the caps' discs reach r * sqrt(1 - u_k^2) along axis k.
          s.pose_stale = true;
          s.a_W = X_WB * s.a_B;
          s.b_W = X_WB * s.b_B;
          const Vec3 u = (s.b_W - s.a_W).normalized();
          const Vec3 ext = s.radius * (Vec3::Ones() - u.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
          s.lo = s.a_W.cwiseMin(s.b_W) - ext;
          s.hi = s.a_W.cwiseMax(s.b_W) + ext;
          return;
        }
        [[fallthrough]];
      case Kind::kMesh: {
        s.X_WS = X_WB * s.X_BS;
        s.pose_stale = false;
        const Vec3 c = s.X_WS * s.c_S;
        const Vec3 h = s.X_WS.linear().cwiseAbs() * s.h_S;
        s.lo = c - h;
        s.hi = c + h;
        return;
      }
    }
  }

  // World pose of a shape's FCL geometry, computed on first use after a move.
  const Iso3& ShapePose(const ShapeData& s) const {
    if (s.pose_stale) {
      s.X_WS = bodies[s.body].X_WB * s.X_BS;
      s.pose_stale = false;
    }
    return s.X_WS;
  }

  // Cheap exact rejection before GJK: the shapes' oriented boxes (the first grown by `margin`)
  // are disjoint. Capsules' and cylinders' boxes hug them but for the rounded ends.
  bool BoxesDisjoint(const ShapeData& A, const ShapeData& B, double margin) const {
    const Iso3& X_WA = ShapePose(A);
    const Iso3& X_WB = ShapePose(B);
    fcl::OBBd a;
    a.axis = X_WA.linear();
    a.To = X_WA * A.c_S;
    a.extent = A.h_S.array() + margin;
    fcl::OBBd b;
    b.axis = X_WB.linear();
    b.To = X_WB * B.c_S;
    b.extent = B.h_S;
    return !a.overlap(b);
  }

  void UpdateBounds() {
    if (!any_dirty) return;
    for (BodyData& b : bodies) {
      if (!b.dirty) continue;
      b.dirty = false;
      if (!b.active()) {
        // Sorts last in the sweep and overlaps nothing.
        b.lo = Vec3::Constant(kInf);
        b.hi = Vec3::Constant(-kInf);
        continue;
      }
      b.lo = Vec3::Constant(kInf);
      b.hi = Vec3::Constant(-kInf);
      for (int k = b.first; k < b.first + b.count; ++k) {
        UpdateShape(shapes[k], b.X_WB);
        b.lo = b.lo.cwiseMin(shapes[k].lo);
        b.hi = b.hi.cwiseMax(shapes[k].hi);
      }
      b.w_W = b.X_WB * shapes[b.first].w_B;
      b.w_r = shapes[b.first].w_r;
    }
    any_dirty = false;
  }

  // ---- narrowphase ----

  // GJK (FCL's own, without the EPA that fcl::collide runs on every hit: 4 us and two
  // allocations there) on two convex primitives. Falls back to FCL's full query if GJK fails.
  bool ConvexIntersect(const ShapeData& A, const ShapeData& B) {
    fcl::detail::MinkowskiDiff<double> md;
    md.shapes[0] = static_cast<const fcl::ShapeBased*>(A.geom.get());
    md.shapes[1] = static_cast<const fcl::ShapeBased*>(B.geom.get());
    const Iso3& X_WA = ShapePose(A);
    const Iso3& X_WB = ShapePose(B);
    md.toshape1.noalias() = X_WB.linear().transpose() * X_WA.linear();
    md.toshape0 = X_WA.inverse(Eigen::Isometry) * X_WB;
    // The Minkowski difference A - B lies around c_A - c_B; GJK's first support direction is
    // -guess, towards the origin.
    Vec3 guess = -md.toshape0.translation();
    if (guess.squaredNorm() < 1e-20) guess = Vec3::UnitX();
    fcl::detail::GJK<double> gjk(128, 1e-6);
    const auto status = gjk.evaluate(md, guess);
    if (status == fcl::detail::GJK<double>::Inside) return true;
    if (status == fcl::detail::GJK<double>::Valid) return false;
    return FclCollide(A, B);
  }

  // A convex primitive P against a mesh M. fcl::collide fits a bounding volume to P on every call
  // (two allocations) and runs EPA on every touching triangle; here P's exact local box is put in
  // M's frame once and the tree is descended with FCL's OBB test, GJK deciding at the leaves. Like
  // FCL, only the mesh's triangles are tested: a primitive wholly inside a closed mesh is missed.
  bool ConvexMeshIntersect(const ShapeData& P, const ShapeData& M) {
    const auto& model = static_cast<const fcl::BVHModel<fcl::OBBRSSd>&>(*M.geom);
    const Iso3 X_MP = ShapePose(M).inverse(Eigen::Isometry) * ShapePose(P);
    fcl::OBBd box;
    box.axis = X_MP.linear();
    box.To = X_MP * P.c_S;
    box.extent = P.h_S;
    fcl::detail::MinkowskiDiff<double> md;
    md.shapes[0] = static_cast<const fcl::ShapeBased*>(P.geom.get());
    md.toshape1 = X_MP.linear();
    md.toshape0 = X_MP.inverse(Eigen::Isometry);
    bvh_stack.clear();
    bvh_stack.push_back(0);
    while (!bvh_stack.empty()) {
      const auto& node = model.getBV(bvh_stack.back());
      bvh_stack.pop_back();
      if (!node.bv.obb.overlap(box)) continue;
      if (!node.isLeaf()) {
        bvh_stack.push_back(node.rightChild());
        bvh_stack.push_back(node.leftChild());
        continue;
      }
      const fcl::Triangle& t = model.tri_indices[node.primitiveId()];
      const fcl::TriangleP<double> tri(model.vertices[t[0]], model.vertices[t[1]],
                                       model.vertices[t[2]]);
      md.shapes[1] = &tri;
      Vec3 guess = tri.a - X_MP.translation();  // from P's origin towards the triangle
      if (guess.squaredNorm() < 1e-20) guess = Vec3::UnitX();
      fcl::detail::GJK<double> gjk(128, 1e-6);
      const auto status = gjk.evaluate(md, -(md.toshape0.linear() * guess));
      if (status == fcl::detail::GJK<double>::Inside) return true;
      if (status == fcl::detail::GJK<double>::Failed) return FclCollide(M, P);
    }
    return false;
  }

  bool FclCollide(const ShapeData& A, const ShapeData& B) {
    fcl_collision_result.clear();
    fcl::collide(A.geom.get(), ShapePose(A), B.geom.get(), ShapePose(B), fcl_collision_request,
                 fcl_collision_result);
    return fcl_collision_result.isCollision();
  }

  struct PairDistance {
    double d = kInf;
    Vec3 p_a = Vec3::Zero();
    Vec3 p_b = Vec3::Zero();
  };

  PairDistance ShapeDistance(const ShapeData& A, const ShapeData& B, bool points) {
    PairDistance out;
    if (A.kind == Kind::kSwept && B.kind == Kind::kSwept) {
      Vec3 ca;
      Vec3 cb;
      const double d2 = ClosestSegmentSegment(A.a_W, A.b_W, B.a_W, B.b_W, &ca, &cb);
      const double dc = std::sqrt(d2);
      out.d = std::max(0.0, dc - A.radius - B.radius);
      if (points) {
        if (out.d <= 0.0) {
          // Overlap: a point between the two axes, on the line joining their closest points.
          const double w =
              dc > 0.0 ? std::clamp((A.radius + 0.5 * (dc - A.radius - B.radius)) / dc, 0.0, 1.0)
                       : 0.5;
          out.p_a = out.p_b = ca + w * (cb - ca);
        } else {
          const Vec3 n = (cb - ca) / dc;
          out.p_a = ca + A.radius * n;
          out.p_b = cb - B.radius * n;
        }
      }
      return out;
    }
    // FCL: the mesh first. FCL 0.7 returns shape-vs-mesh nearest points as (mesh, shape) whatever
    // the argument order, and sphere-vs-mesh points in the two local frames (STACK.md).
    const bool swap = B.kind == Kind::kMesh && A.kind != Kind::kMesh;
    const ShapeData& first = swap ? B : A;
    const ShapeData& second = swap ? A : B;
    fcl_distance_request.enable_nearest_points = points;
    fcl_distance_result.clear();
    double d = fcl::distance(first.geom.get(), ShapePose(first), second.geom.get(),
                             ShapePose(second), fcl_distance_request, fcl_distance_result);
    if (!(d > 1e-12)) {
      // In collision: FCL gives -1 (primitives), 0 (meshes) or a denormal (sphere vs mesh), and
      // no meaningful points.
      out.d = 0.0;
      if (points) {
        out.p_a = out.p_b =
            0.5 * (A.lo.cwiseMax(B.lo) + A.hi.cwiseMin(B.hi));  // centre of the boxes' overlap
      }
      return out;
    }
    out.d = d;
    if (points) {
      Vec3 p_first = fcl_distance_result.nearest_points[0];
      Vec3 p_second = fcl_distance_result.nearest_points[1];
      if (first.kind == Kind::kMesh && second.kind != Kind::kMesh &&
          second.geom->getNodeType() == fcl::GEOM_SPHERE) {
        p_first = ShapePose(first) * p_first;
        p_second = ShapePose(second) * p_second;
      }
      out.p_a = swap ? p_second : p_first;
      out.p_b = swap ? p_first : p_second;
    }
    return out;
  }

  bool ShapesCollide(const ShapeData& A, const ShapeData& B, double margin) {
    if (A.kind == Kind::kSwept && B.kind == Kind::kSwept) {
      Vec3 ca;
      Vec3 cb;
      const double d2 = ClosestSegmentSegment(A.a_W, A.b_W, B.a_W, B.b_W, &ca, &cb);
      const double reach = A.radius + B.radius + margin;
      return d2 <= reach * reach;
    }
    if (A.kind != Kind::kMesh && B.kind != Kind::kMesh && BoxesDisjoint(A, B, margin)) {
      return false;
    }
    if (margin > 0.0) return ShapeDistance(A, B, false).d <= margin;
    if (A.kind != Kind::kMesh && B.kind != Kind::kMesh) return ConvexIntersect(A, B);
    if (A.kind == Kind::kMesh && B.kind == Kind::kMesh) return FclCollide(A, B);
    return A.kind == Kind::kMesh ? ConvexMeshIntersect(B, A) : ConvexMeshIntersect(A, B);
  }

  // Tests the shape pairs of bodies i and j; records hits. Returns true when the query is done
  // (a hit and not all pairs wanted, or the pair budget is used up).
  // `body_boxes`: prefilter with body j's box (false when a disabled body is tested explicitly).
  bool BodyPairCollide(int i, int j, const CollisionRequest& request, CollisionResult* result,
                       bool* hit, bool body_boxes = true) {
    const BodyData& bi = bodies[i];
    const BodyData& bj = bodies[j];
    for (int sa = bi.first; sa < bi.first + bi.count; ++sa) {
      const ShapeData& A = shapes[sa];
      if (body_boxes && !BoxesOverlap(A.lo, A.hi, bj.lo, bj.hi, request.margin_m)) continue;
      for (int sb = bj.first; sb < bj.first + bj.count; ++sb) {
        const ShapeData& B = shapes[sb];
        if (!BoxesOverlap(A.lo, A.hi, B.lo, B.hi, request.margin_m)) continue;
        if (result) ++result->narrowphase_tests;
        if (!ShapesCollide(A, B, request.margin_m)) continue;
        *hit = true;
        if (!result) return true;
        ShapePair pair{BodyId{i}, BodyId{j}, sa - bi.first, sb - bj.first, bi.X_WB, bj.X_WB};
        if (!result->collision) {
          result->collision = true;
          result->first = pair;
        }
        if (!request.all_pairs) return true;
        result->pairs.push_back(pair);
        if (static_cast<int>(result->pairs.size()) >= request.max_pairs) return true;
      }
    }
    return false;
  }

  // Sweep and prune along x over the body boxes; the order persists between queries, so the
  // insertion sort is near linear when bodies move a little.
  bool AnyCollision(const CollisionRequest& request, CollisionResult* result) {
    UpdateBounds();
    if (result) result->Clear();
    if (order.size() != bodies.size()) {
      order.resize(bodies.size());
      for (int k = 0; k < n(); ++k) order[k] = k;
    }
    for (std::size_t k = 1; k < order.size(); ++k) {
      const int v = order[k];
      const double key = bodies[v].lo.x();
      std::size_t m = k;
      while (m > 0 && bodies[order[m - 1]].lo.x() > key) {
        order[m] = order[m - 1];
        --m;
      }
      order[m] = v;
    }
    const double margin = request.margin_m;
    if (clean.size() != bodies.size() * bodies.size())
      clean.assign(bodies.size() * bodies.size(), 0);
    bool hit = false;
    for (std::size_t ii = 0; ii < order.size(); ++ii) {
      const int i = order[ii];
      const BodyData& bi = bodies[i];
      if (!bi.active()) break;  // inactive bodies sort last
      const bool i_masked = (request.group_mask >> bi.group) & 1u;
      for (std::size_t jj = ii + 1; jj < order.size(); ++jj) {
        const int j = order[jj];
        const BodyData& bj = bodies[j];
        if (bj.lo.x() > bi.hi.x() + margin) break;
        if (!i_masked && !((request.group_mask >> bj.group) & 1u)) continue;
        if (!BoxesOverlap(bi.lo, bi.hi, bj.lo, bj.hi, margin)) continue;
        if (Allowed(i, j)) continue;
        const int a = std::min(i, j);
        const int b = std::max(i, j);
        const std::size_t pair = static_cast<std::size_t>(a) * bodies.size() + b;
        if (margin == 0.0 && clean[pair] > std::max(bodies[a].changed_at, bodies[b].changed_at)) {
          continue;
        }
        bool pair_hit = false;
        const bool done = BodyPairCollide(a, b, request, result, &pair_hit);
        if (pair_hit) {
          hit = true;
        } else if (margin == 0.0) {
          clean[pair] = epoch + 1;
        }
        if (done) return true;
      }
    }
    return hit;
  }

  // Branch and bound: candidate body pairs sorted by box distance; stop when the next lower
  // bound is no better than the best distance found.
  template <typename PairFilter>
  DistanceResult MinDistance(PairFilter&& keep, const DistanceRequest& request) {
    UpdateBounds();
    DistanceResult out;
    out.distance = request.upper_bound_m;
    candidates.clear();
    // `bound`: the distance is at most this (the request's bound, or two inner balls' distance).
    double bound = request.upper_bound_m;
    for (int i = 0; i < n(); ++i) {
      const BodyData& bi = bodies[i];
      if (!bi.active()) continue;
      for (int j = i + 1; j < n(); ++j) {
        const BodyData& bj = bodies[j];
        if (!bj.active() || !keep(bi.group, bj.group) || Allowed(i, j)) continue;
        const double lb2 = BoxDistance2(bi.lo, bi.hi, bj.lo, bj.hi);
        if (lb2 > bound * bound) continue;
        const double balls = (bi.w_W - bj.w_W).norm() - bi.w_r - bj.w_r;
        bound = std::min(bound, std::max(0.0, balls));
        candidates.push_back({lb2, i, j});
      }
    }
    // Pairs kept before the bound tightened; then nearest boxes first.
    candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                    [&](const Candidate& c) { return c.lb2 > bound * bound; }),
                     candidates.end());
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& x, const Candidate& y) { return x.lb2 < y.lb2; });
    double best = request.upper_bound_m;
    for (const Candidate& c : candidates) {
      if (c.lb2 >= best * best) break;
      BodyPairDistance(c.a, c.b, request, &best, &out);
      if (best <= 0.0) break;
    }
    return out;
  }

  void BodyPairDistance(int i, int j, const DistanceRequest& request, double* best,
                        DistanceResult* out) {
    const BodyData& bi = bodies[i];
    const BodyData& bj = bodies[j];
    for (int sa = bi.first; sa < bi.first + bi.count; ++sa) {
      const ShapeData& A = shapes[sa];
      if (BoxDistance2(A.lo, A.hi, bj.lo, bj.hi) >= *best * *best) continue;
      for (int sb = bj.first; sb < bj.first + bj.count; ++sb) {
        const ShapeData& B = shapes[sb];
        if (BoxDistance2(A.lo, A.hi, B.lo, B.hi) >= *best * *best) continue;
        ++out->narrowphase_tests;
        const PairDistance pd = ShapeDistance(A, B, request.nearest_points);
        if (pd.d < *best) {
          *best = pd.d;
          out->distance = pd.d;
          out->pair =
              ShapePair{BodyId{i}, BodyId{j}, sa - bi.first, sb - bj.first, bi.X_WB, bj.X_WB};
          out->p_A_W = pd.p_a;
          out->p_B_W = pd.p_b;
          if (pd.d <= 0.0) return;
        }
      }
    }
  }
};

// ---------------------------------------------------------------------------------------------
// CollisionWorld

CollisionWorld::CollisionWorld() : impl_(std::make_unique<Impl>()) {}
CollisionWorld::~CollisionWorld() = default;
CollisionWorld::CollisionWorld(const CollisionWorld& other)
    : impl_(std::make_unique<Impl>(*other.impl_)) {}
CollisionWorld& CollisionWorld::operator=(const CollisionWorld& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
CollisionWorld::CollisionWorld(CollisionWorld&&) noexcept = default;
CollisionWorld& CollisionWorld::operator=(CollisionWorld&&) noexcept = default;

int CollisionWorld::LiveMeshTrees() { return MeshTrees().Live(); }

Result<BodyId> CollisionWorld::AddBody(const BodyDef& def) {
  Impl& m = *impl_;
  const std::string where = "collision world: body '" + def.name + "'";
  if (def.group < 0 || def.group >= kMaxCollisionGroups) {
    return Fail(ErrorCode::kInvalidInput, where + ": group " + std::to_string(def.group) +
                                              " outside [0, " +
                                              std::to_string(kMaxCollisionGroups) + ")");
  }
  if (!def.X_WB.matrix().allFinite()) {
    return Fail(ErrorCode::kInvalidInput, where + ": pose is not finite");
  }
  std::vector<ShapeData> added;
  added.reserve(def.shapes.size());
  for (std::size_t k = 0; k < def.shapes.size(); ++k) {
    const Shape& shape = def.shapes[k];
    ShapeData s;
    s.type = shape.type;
    s.name = shape.name.empty() ? "shape" + std::to_string(k) : shape.name;
    const std::string at = where + ", shape '" + s.name + "'";
    switch (shape.type) {
      case Shape::Type::kSphere:
      case Shape::Type::kCapsule: {
        if (!(shape.radius > 0.0) || !std::isfinite(shape.radius) || !AllFinite(shape.p0) ||
            (shape.type == Shape::Type::kCapsule && !AllFinite(shape.p1))) {
          return Fail(ErrorCode::kInvalidInput,
                      at + ": needs a positive finite radius and finite end points, got radius " +
                          std::to_string(shape.radius));
        }
        s.kind = Kind::kSwept;
        s.radius = shape.radius;
        s.a_B = shape.p0;
        s.b_B = shape.type == Shape::Type::kSphere ? shape.p0 : shape.p1;
        const double length = (s.b_B - s.a_B).norm();
        if (length > 0.0) {
          s.X_BS = SegmentFrame(s.a_B, s.b_B);
          s.geom = std::make_shared<fcl::Capsuled>(s.radius, length);
        } else {
          s.X_BS.translation() = s.a_B;
          s.geom = std::make_shared<fcl::Sphered>(s.radius);
        }
        s.h_S = Vec3(s.radius, s.radius, 0.5 * length + s.radius);
        s.w_B = s.a_B;
        s.w_r = s.radius;
        break;
      }
      case Shape::Type::kCylinder: {
        const double length = (shape.p1 - shape.p0).norm();
        if (!(shape.radius > 0.0) || !std::isfinite(shape.radius) || !AllFinite(shape.p0) ||
            !AllFinite(shape.p1) || !(length > 0.0)) {
          return Fail(ErrorCode::kInvalidInput,
                      at + ": a cylinder needs a positive finite radius and distinct end points");
        }
        s.kind = Kind::kConvex;
        s.radius = shape.radius;
        s.a_B = shape.p0;
        s.b_B = shape.p1;
        s.X_BS = SegmentFrame(s.a_B, s.b_B);
        s.geom = std::make_shared<fcl::Cylinderd>(s.radius, length);
        s.h_S = Vec3(s.radius, s.radius, 0.5 * length);
        s.w_B = 0.5 * (s.a_B + s.b_B);
        s.w_r = std::min(s.radius, 0.5 * length);
        break;
      }
      case Shape::Type::kBox: {
        if (!(shape.half_extents.array() > 0.0).all() || !AllFinite(shape.half_extents) ||
            !shape.X_LS.matrix().allFinite()) {
          return Fail(ErrorCode::kInvalidInput,
                      at + ": a box needs positive finite half extents and a finite pose");
        }
        s.kind = Kind::kConvex;
        s.X_BS = shape.X_LS;
        s.h_S = shape.half_extents;
        // fcl::Box takes full side lengths.
        s.geom = std::make_shared<fcl::Boxd>(2.0 * shape.half_extents);
        s.w_B = s.X_BS.translation();
        s.w_r = shape.half_extents.minCoeff();
        break;
      }
      case Shape::Type::kMesh: {
        const TriangleMesh& mesh = shape.mesh;
        if (mesh.triangles.empty()) {
          return Fail(ErrorCode::kInvalidInput, at + ": the mesh has no triangles");
        }
        const int nv = static_cast<int>(mesh.vertices.size());
        std::vector<fcl::Vector3d> vertices(mesh.vertices.begin(), mesh.vertices.end());
        std::vector<fcl::Triangle> triangles;
        triangles.reserve(mesh.triangles.size());
        for (const Eigen::Vector3i& t : mesh.triangles) {
          if ((t.array() < 0).any() || (t.array() >= nv).any()) {
            return Fail(
                ErrorCode::kInvalidInput,
                at + ": a triangle indexes a vertex outside [0, " + std::to_string(nv) + ")");
          }
          triangles.emplace_back(t[0], t[1], t[2]);
        }
        for (const Vec3& v : mesh.vertices) {
          if (!AllFinite(v)) return Fail(ErrorCode::kInvalidInput, at + ": a vertex is not finite");
        }
        auto model = MeshTrees().Get(vertices, triangles);
        if (!model) {
          return Fail(ErrorCode::kInvalidInput, at + ": FCL could not build the mesh's tree");
        }
        const Aabb box = ComputeAabb(mesh);
        s.kind = Kind::kMesh;
        s.w_B = mesh.vertices[mesh.triangles[0][0]];  // on the surface: a ball of radius 0
        s.c_S = 0.5 * (box.min + box.max);
        s.h_S = 0.5 * (box.max - box.min);
        s.geom = std::move(model);
        break;
      }
    }
    // (Mesh trees come from the shared cache with their boxes computed.)
    if (s.kind != Kind::kMesh) {
      std::const_pointer_cast<fcl::CollisionGeometryd>(s.geom)->computeLocalAABB();
    }
    added.push_back(std::move(s));
  }

  const int id = m.n();
  BodyData b;
  b.name = def.name;
  b.group = def.group;
  b.X_WB = def.X_WB;
  b.first = static_cast<int>(m.shapes.size());
  b.count = static_cast<int>(added.size());
  for (ShapeData& s : added) {
    s.body = id;
    m.shapes.push_back(std::move(s));
  }
  m.bodies.push_back(std::move(b));

  // Grow the symmetric allowed matrix by one row and column.
  const std::size_t n_old = static_cast<std::size_t>(id);
  const std::size_t n_new = n_old + 1;
  std::vector<std::uint8_t> grown(n_new * n_new, 0);
  for (std::size_t r = 0; r < n_old; ++r) {
    std::copy_n(m.allowed.begin() + r * n_old, n_old, grown.begin() + r * n_new);
  }
  m.allowed = std::move(grown);
  m.order.clear();
  m.candidates.reserve(n_new * (n_new - 1) / 2);
  m.any_dirty = true;
  return BodyId{id};
}

int CollisionWorld::num_bodies() const { return impl_->n(); }
const std::string& CollisionWorld::body_name(BodyId body) const { return impl_->body(body).name; }
int CollisionWorld::body_group(BodyId body) const { return impl_->body(body).group; }
int CollisionWorld::num_shapes(BodyId body) const { return impl_->body(body).count; }

const std::string& CollisionWorld::shape_name(BodyId body, int shape) const {
  const BodyData& b = impl_->body(body);
  Check(shape >= 0 && shape < b.count, "shape index out of range");
  return impl_->shapes[b.first + shape].name;
}

BodyId CollisionWorld::FindBody(const std::string& name) const {
  for (int i = 0; i < impl_->n(); ++i) {
    if (impl_->bodies[i].name == name) return BodyId{i};
  }
  return BodyId{};
}

void CollisionWorld::SetPose(BodyId body, const Iso3& X_WB) {
  BodyData& b = impl_->body(body);
  if (b.X_WB.matrix() == X_WB.matrix()) return;
  b.X_WB = X_WB;
  b.dirty = true;
  b.changed_at = ++impl_->epoch;
  impl_->any_dirty = true;
}

const Iso3& CollisionWorld::pose(BodyId body) const { return impl_->body(body).X_WB; }

void CollisionWorld::SetPoses(std::span<const Iso3> X_WB) {
  Check(static_cast<int>(X_WB.size()) == impl_->n(), "SetPoses: one pose per body expected");
  for (int i = 0; i < impl_->n(); ++i) {
    BodyData& b = impl_->bodies[i];
    if (b.X_WB.matrix() == X_WB[i].matrix()) continue;
    b.X_WB = X_WB[i];
    b.dirty = true;
    b.changed_at = ++impl_->epoch;
  }
  impl_->any_dirty = true;
}

void CollisionWorld::SetEnabled(BodyId body, bool on) {
  BodyData& b = impl_->body(body);
  if (b.enabled == on) return;
  b.enabled = on;
  b.dirty = true;
  impl_->any_dirty = true;
}

bool CollisionWorld::enabled(BodyId body) const { return impl_->body(body).enabled; }

void CollisionWorld::SetAllowed(BodyId a, BodyId b, bool allowed) {
  impl_->body(a);
  impl_->body(b);
  const std::size_t n = impl_->bodies.size();
  const std::uint8_t v = allowed ? 1 : 0;
  impl_->allowed[a.value * n + b.value] = v;
  impl_->allowed[b.value * n + a.value] = v;
}

void CollisionWorld::SetGroupPairAllowed(int g, int h, bool allowed) {
  if (allowed) {
    impl_->allowed_groups.Add(g, h);
  } else {
    impl_->allowed_groups.Remove(g, h);
  }
}

bool CollisionWorld::IsAllowed(BodyId a, BodyId b) const {
  impl_->body(a);
  impl_->body(b);
  return impl_->Allowed(a.value, b.value);
}

bool CollisionWorld::AnyCollision(const CollisionRequest& request, CollisionResult* result) {
  return impl_->AnyCollision(request, result);
}

bool CollisionWorld::Collide(BodyId a, BodyId b, const CollisionRequest& request,
                             CollisionResult* result) {
  Impl& m = *impl_;
  m.body(a);
  m.body(b);
  // Bypasses the enabled flags: refresh the two bodies' shapes even when disabled.
  m.UpdateBounds();
  for (BodyId id : {a, b}) {
    const BodyData& bd = m.bodies[id.value];
    if (!bd.active()) {
      for (int k = bd.first; k < bd.first + bd.count; ++k) m.UpdateShape(m.shapes[k], bd.X_WB);
    }
  }
  if (result) result->Clear();
  bool hit = false;
  m.BodyPairCollide(a.value, b.value, request, result, &hit, /*body_boxes=*/false);
  return hit;
}

DistanceResult CollisionWorld::MinDistance(int group_g, int group_h,
                                           const DistanceRequest& request) {
  return impl_->MinDistance(
      [group_g, group_h](int g, int h) {
        return (g == group_g && h == group_h) || (g == group_h && h == group_g);
      },
      request);
}

DistanceResult CollisionWorld::MinDistance(const GroupPairSet& pairs,
                                           const DistanceRequest& request) {
  return impl_->MinDistance([&pairs](int g, int h) { return pairs.Contains(g, h); }, request);
}

DistanceResult CollisionWorld::Distance(BodyId a, BodyId b, const DistanceRequest& request) {
  Impl& m = *impl_;
  m.body(a);
  m.body(b);
  m.UpdateBounds();
  for (BodyId id : {a, b}) {
    const BodyData& bd = m.bodies[id.value];
    if (!bd.active()) {
      for (int k = bd.first; k < bd.first + bd.count; ++k) m.UpdateShape(m.shapes[k], bd.X_WB);
    }
  }
  DistanceResult out;
  out.distance = request.upper_bound_m;
  double best = request.upper_bound_m;
  // Body boxes of disabled bodies are empty: use the shape boxes only.
  const BodyData& ba = m.bodies[a.value];
  const BodyData& bb = m.bodies[b.value];
  for (int sa = ba.first; sa < ba.first + ba.count; ++sa) {
    for (int sb = bb.first; sb < bb.first + bb.count; ++sb) {
      const ShapeData& A = m.shapes[sa];
      const ShapeData& B = m.shapes[sb];
      if (BoxDistance2(A.lo, A.hi, B.lo, B.hi) >= best * best) continue;
      ++out.narrowphase_tests;
      const Impl::PairDistance pd = m.ShapeDistance(A, B, request.nearest_points);
      if (pd.d < best) {
        best = pd.d;
        out.distance = pd.d;
        out.pair = ShapePair{a, b, sa - ba.first, sb - bb.first, ba.X_WB, bb.X_WB};
        out.p_A_W = pd.p_a;
        out.p_B_W = pd.p_b;
      }
    }
  }
  return out;
}

Aabb CollisionWorld::body_aabb(BodyId body) {
  impl_->UpdateBounds();
  const BodyData& b = impl_->body(body);
  Aabb box;
  if (!b.active()) {
    box.min = box.max = b.X_WB.translation();
    if (b.count > 0) {
      // Disabled: still report where its shapes are.
      box.min = Vec3::Constant(kInf);
      box.max = Vec3::Constant(-kInf);
      for (int k = b.first; k < b.first + b.count; ++k) {
        impl_->UpdateShape(impl_->shapes[k], b.X_WB);
        box.min = box.min.cwiseMin(impl_->shapes[k].lo);
        box.max = box.max.cwiseMax(impl_->shapes[k].hi);
      }
    }
    return box;
  }
  box.min = b.lo;
  box.max = b.hi;
  return box;
}

std::string CollisionWorld::Describe(const ShapePair& pair) const {
  if (!pair.body_a.valid() || !pair.body_b.valid()) return "no pair";
  std::ostringstream os;
  auto one = [&](BodyId id, int shape, const Iso3& X) {
    const BodyData& b = impl_->body(id);
    os << "body '" << b.name << "' (id " << id.value << ", group " << b.group << ") shape '"
       << (shape >= 0 && shape < b.count ? impl_->shapes[b.first + shape].name : "?") << "' at "
       << PoseText(X);
  };
  one(pair.body_a, pair.shape_a, pair.X_WA);
  os << " vs ";
  one(pair.body_b, pair.shape_b, pair.X_WB);
  return os.str();
}

}  // namespace wrap
