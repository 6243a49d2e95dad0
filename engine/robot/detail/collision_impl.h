// Internals of the collision world shared by its source files (collision.cpp: the world and its
// bodies; collision_shapes.cpp: shapes and the mesh-tree cache; collision_narrowphase.cpp:
// shape pairs; collision_query.cpp and distance_query.cpp: whole-world queries). With those
// files, the only place that includes FCL.
#pragma once

#include <fcl/geometry/collision_geometry.h>
#include <fcl/narrowphase/collision_request.h>
#include <fcl/narrowphase/collision_result.h>
#include <fcl/narrowphase/distance_request.h>
#include <fcl/narrowphase/distance_result.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <source_location>
#include <string>
#include <vector>

#include "robot/collision.h"

namespace wrap::detail {

/// An always-on assert for bugs (a bad id, a group out of range): file, line, what failed.
[[noreturn]] void CollisionFatal(const char* what, const std::source_location& loc);
/// Calls CollisionFatal when `ok` is false.
inline void CollisionCheck(bool ok, const char* what,
                           const std::source_location& loc = std::source_location::current()) {
  if (!ok) CollisionFatal(what, loc);
}

/// How a shape takes part in the narrowphase: a swept sphere (sphere or capsule: closed forms), a
/// convex FCL primitive (box, cylinder: GJK), or an FCL mesh (OBBRSS tree).
enum class ShapeKind : std::uint8_t { kSwept, kConvex, kMesh };

/// A shape of a body as the queries use it.
struct ShapeData {
  ShapeKind kind = ShapeKind::kSwept;
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

/// A body: its pose, filter state, shapes (a range of Impl::shapes) and world bounds.
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

/// Shape k of a body (`where` names the body for messages) as query data with its FCL geometry;
/// fails with kInvalidInput naming the shape (see CollisionWorld::AddBody).
Result<ShapeData> MakeShapeData(const Shape& shape, std::size_t k, const std::string& where);

/// Mesh trees alive in the process (collision_shapes.cpp's cache).
int LiveMeshTreeCount();

/// Squared distance between two boxes (0 when they overlap): a lower bound of the squared
/// distance between anything inside them.
inline double BoxDistance2(const Vec3& lo_a, const Vec3& hi_a, const Vec3& lo_b, const Vec3& hi_b) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double gap = std::max(lo_b[k] - hi_a[k], lo_a[k] - hi_b[k]);
    if (gap > 0.0) d2 += gap * gap;
  }
  return d2;
}

/// True when the boxes, the first grown by `margin`, overlap.
inline bool BoxesOverlap(const Vec3& lo_a, const Vec3& hi_a, const Vec3& lo_b, const Vec3& hi_b,
                         double margin) {
  return lo_a.x() <= hi_b.x() + margin && lo_b.x() <= hi_a.x() + margin &&
         lo_a.y() <= hi_b.y() + margin && lo_b.y() <= hi_a.y() + margin &&
         lo_a.z() <= hi_b.z() + margin && lo_b.z() <= hi_a.z() + margin;
}

}  // namespace wrap::detail

namespace wrap {

struct CollisionWorld::Impl {
  using ShapeData = detail::ShapeData;
  using BodyData = detail::BodyData;

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
    detail::CollisionCheck(id.value >= 0 && id.value < n(), "body id out of range");
    return bodies[id.value];
  }
  BodyData& body(BodyId id) {
    detail::CollisionCheck(id.value >= 0 && id.value < n(), "body id out of range");
    return bodies[id.value];
  }
  bool Allowed(int a, int b) const {
    return allowed[static_cast<std::size_t>(a) * bodies.size() + b] != 0 ||
           allowed_groups.Contains(bodies[a].group, bodies[b].group);
  }

  // ---- bounds (collision.cpp) ----

  // Refreshes a shape's world state and box for the body pose X_WB.
  void UpdateShape(ShapeData& s, const Iso3& X_WB);
  // Refreshes the boxes of every body that moved or changed its enabled flag.
  void UpdateBounds();
  // Refreshes the shapes of bodies a and b even when disabled (queries that bypass the flags).
  void UpdatePair(BodyId a, BodyId b);

  // World pose of a shape's FCL geometry, computed on first use after a move.
  const Iso3& ShapePose(const ShapeData& s) const {
    if (s.pose_stale) {
      s.X_WS = bodies[s.body].X_WB * s.X_BS;
      s.pose_stale = false;
    }
    return s.X_WS;
  }

  // ---- narrowphase (collision_narrowphase.cpp) ----

  // Cheap exact rejection before GJK: the shapes' oriented boxes (the first grown by `margin`)
  // are disjoint. Capsules' and cylinders' boxes hug them but for the rounded ends.
  bool BoxesDisjoint(const ShapeData& A, const ShapeData& B, double margin) const;
  // GJK (FCL's own, without the EPA that fcl::collide runs on every hit: 4 us and two
  // allocations there) on two convex primitives. Falls back to FCL's full query if GJK fails.
  bool ConvexIntersect(const ShapeData& A, const ShapeData& B);
  // A convex primitive P against a mesh M: P's box descends M's tree, GJK decides at the leaves.
  bool ConvexMeshIntersect(const ShapeData& P, const ShapeData& M);
  // FCL's full collision query.
  bool FclCollide(const ShapeData& A, const ShapeData& B);

  struct PairDistance {
    double d = std::numeric_limits<double>::infinity();
    Vec3 p_a = Vec3::Zero();
    Vec3 p_b = Vec3::Zero();
  };
  // Distance between two shapes (0 when they touch or overlap), with nearest points when
  // `points`.
  PairDistance ShapeDistance(const ShapeData& A, const ShapeData& B, bool points);
  // True when two shapes are closer than `margin` (touching counts).
  bool ShapesCollide(const ShapeData& A, const ShapeData& B, double margin);

  // ---- collision queries (collision_query.cpp) ----

  // Tests the shape pairs of bodies i and j; records hits. Returns true when the query is done
  // (a hit and not all pairs wanted, or the pair budget is used up).
  // `body_boxes`: prefilter with body j's box (false when a disabled body is tested explicitly).
  bool BodyPairCollide(int i, int j, const CollisionRequest& request, CollisionResult* result,
                       bool* hit, bool body_boxes = true);
  // Sweep and prune along x over the body boxes, then BodyPairCollide.
  bool AnyCollision(const CollisionRequest& request, CollisionResult* result);

  // ---- distance queries (distance_query.cpp) ----

  // Branch and bound over the body pairs whose groups `keep` accepts.
  template <typename PairFilter>
  DistanceResult MinDistance(PairFilter&& keep, const DistanceRequest& request);
  // The nearest shape pair of bodies i and j nearer than *best, into *best and *out.
  void BodyPairDistance(int i, int j, const DistanceRequest& request, double* best,
                        DistanceResult* out);
};

}  // namespace wrap
