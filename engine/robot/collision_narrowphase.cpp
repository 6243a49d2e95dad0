// The narrowphase of the collision world, one shape pair at a time: exact closed forms for swept
// spheres (spheres, capsules), an oriented-box rejection and GJK for convex primitives, a tree
// descent with GJK at the leaves for a primitive against a mesh, FCL for the rest; and the
// distance between two shapes with their nearest points.
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/triangle_p.h>
#include <fcl/math/bv/OBB.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/detail/convexity_based_algorithm/gjk.h>
#include <fcl/narrowphase/detail/convexity_based_algorithm/minkowski_diff.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>

#include "robot/detail/collision_impl.h"

namespace wrap {
namespace {

using detail::ShapeData;
using detail::ShapeKind;

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

}  // namespace

bool CollisionWorld::Impl::BoxesDisjoint(const ShapeData& A, const ShapeData& B,
                                         double margin) const {
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

bool CollisionWorld::Impl::ConvexIntersect(const ShapeData& A, const ShapeData& B) {
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

// fcl::collide fits a bounding volume to P on every call (two allocations) and runs EPA on every
// touching triangle; here P's exact local box is put in M's frame once and the tree is descended
// with FCL's OBB test, GJK deciding at the leaves. Like FCL, only the mesh's triangles are
// tested: a primitive wholly inside a closed mesh is missed.
bool CollisionWorld::Impl::ConvexMeshIntersect(const ShapeData& P, const ShapeData& M) {
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

bool CollisionWorld::Impl::FclCollide(const ShapeData& A, const ShapeData& B) {
  fcl_collision_result.clear();
  fcl::collide(A.geom.get(), ShapePose(A), B.geom.get(), ShapePose(B), fcl_collision_request,
               fcl_collision_result);
  return fcl_collision_result.isCollision();
}

CollisionWorld::Impl::PairDistance CollisionWorld::Impl::ShapeDistance(const ShapeData& A,
                                                                       const ShapeData& B,
                                                                       bool points) {
  PairDistance out;
  if (A.kind == ShapeKind::kSwept && B.kind == ShapeKind::kSwept) {
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
  const bool swap = B.kind == ShapeKind::kMesh && A.kind != ShapeKind::kMesh;
  const ShapeData& first = swap ? B : A;
  const ShapeData& second = swap ? A : B;
  fcl_distance_request.enable_nearest_points = points;
  fcl_distance_result.clear();
  double d = fcl::distance(first.geom.get(), ShapePose(first), second.geom.get(), ShapePose(second),
                           fcl_distance_request, fcl_distance_result);
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
    if (first.kind == ShapeKind::kMesh && second.kind != ShapeKind::kMesh &&
        second.geom->getNodeType() == fcl::GEOM_SPHERE) {
      p_first = ShapePose(first) * p_first;
      p_second = ShapePose(second) * p_second;
    }
    out.p_a = swap ? p_second : p_first;
    out.p_b = swap ? p_first : p_second;
  }
  return out;
}

bool CollisionWorld::Impl::ShapesCollide(const ShapeData& A, const ShapeData& B, double margin) {
  if (A.kind == ShapeKind::kSwept && B.kind == ShapeKind::kSwept) {
    Vec3 ca;
    Vec3 cb;
    const double d2 = ClosestSegmentSegment(A.a_W, A.b_W, B.a_W, B.b_W, &ca, &cb);
    const double reach = A.radius + B.radius + margin;
    return d2 <= reach * reach;
  }
  if (A.kind != ShapeKind::kMesh && B.kind != ShapeKind::kMesh && BoxesDisjoint(A, B, margin)) {
    return false;
  }
  if (margin > 0.0) return ShapeDistance(A, B, false).d <= margin;
  if (A.kind != ShapeKind::kMesh && B.kind != ShapeKind::kMesh) return ConvexIntersect(A, B);
  if (A.kind == ShapeKind::kMesh && B.kind == ShapeKind::kMesh) return FclCollide(A, B);
  return A.kind == ShapeKind::kMesh ? ConvexMeshIntersect(B, A) : ConvexMeshIntersect(A, B);
}

}  // namespace wrap
