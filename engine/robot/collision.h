// The collision world: rigid bodies made of shapes, their world poses, collision groups, an
// allowed-pair filter, and collision and distance queries. The one FCL adapter: FCL is included
// only by the world's sources (collision.cpp, collision_shapes.cpp, collision_narrowphase.cpp,
// collision_query.cpp, distance_query.cpp) and their internal header detail/collision_impl.h.
//
// Queries run a sweep-and-prune broadphase over body bounding boxes, then box tests per shape
// pair, then the narrowphase: exact closed forms for sphere/capsule pairs (most robot links), an
// oriented-box rejection and FCL's GJK for the other convex primitive pairs, FCL's OBBRSS trees
// for meshes. Collision queries allocate nothing once the scratch buffers have grown; distance
// queries neither, except for a primitive-vs-mesh pair, for which FCL allocates two small
// buffers per narrowphase call (it fits a bounding volume to the primitive).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "geometry/mesh.h"
#include "robot/chain.h"

namespace wrap {

/// Index of a body in its CollisionWorld: dense from 0 in the order of AddBody.
struct BodyId {
  int value = -1;  ///< Index, -1 for "no body".
  /// True for an id returned by AddBody (not checked against a particular world).
  bool valid() const { return value >= 0; }
  friend bool operator==(BodyId, BodyId) = default;
};

/// How many collision groups a world knows: group ids lie in [0, kMaxCollisionGroups).
inline constexpr int kMaxCollisionGroups = 64;

/// A symmetric set of unordered group pairs {g, h} (g == h allowed), g, h in
/// [0, kMaxCollisionGroups). Out-of-range groups are a bug (assert).
class GroupPairSet {
 public:
  /// Adds {g, h} (and so {h, g}).
  void Add(int g, int h);
  /// Removes {g, h}.
  void Remove(int g, int h);
  /// True when {g, h} is in the set.
  bool Contains(int g, int h) const;
  /// True when no pair is in the set.
  bool empty() const;

 private:
  std::array<std::uint64_t, kMaxCollisionGroups> rows_{};
};

/// A body to add: a set of shapes rigidly attached to the body frame B.
struct BodyDef {
  std::string name;           ///< For messages, e.g. "robot0/forearm".
  int group = 0;              ///< Collision group in [0, kMaxCollisionGroups), e.g. one per robot.
  std::vector<Shape> shapes;  ///< Shapes in the body frame B (may be empty: never collides).
  Iso3 X_WB = Iso3::Identity();  ///< Initial pose of B in the world W.
};

/// Options of a collision query (FCL's Request).
struct CollisionRequest {
  /// Shapes closer than this count as colliding [m]; 0: only touching or overlapping shapes.
  double margin_m = 0.0;
  /// Collect every colliding pair (up to `max_pairs`) instead of stopping at the first.
  bool all_pairs = false;
  /// Most pairs collected when `all_pairs`.
  int max_pairs = 64;
  /// Only pairs with at least one body in a group whose bit is set are tested (bit g = group g);
  /// default all groups. Use it to check only the robots that moved.
  std::uint64_t group_mask = ~std::uint64_t{0};
};

/// One pair of shapes of two bodies, with the body poses needed to replay the query.
struct ShapePair {
  BodyId body_a;                 ///< First body.
  BodyId body_b;                 ///< Second body.
  int shape_a = -1;              ///< Index of the shape in body_a's shapes.
  int shape_b = -1;              ///< Index of the shape in body_b's shapes.
  Iso3 X_WA = Iso3::Identity();  ///< Pose of body_a in the world at query time.
  Iso3 X_WB = Iso3::Identity();  ///< Pose of body_b in the world at query time.
};

/// Outcome of a collision query (FCL's Result). Reuse one object across queries: Clear() keeps
/// the capacity of `pairs`, so steady-state queries do not allocate.
struct CollisionResult {
  bool collision = false;        ///< True when some tested pair collides.
  ShapePair first;               ///< The first colliding pair found (valid when `collision`).
  std::vector<ShapePair> pairs;  ///< Every colliding pair found, when the request asked for all.
  int narrowphase_tests = 0;     ///< Shape pairs that reached the narrowphase (statistics).
  /// Resets to "no collision", keeping the capacity of `pairs`.
  void Clear();
};

/// Options of a distance query.
struct DistanceRequest {
  /// Fill the nearest points of the result.
  bool nearest_points = true;
  /// Pairs whose bounding boxes are at least this far apart [m] are not computed; when every
  /// pair is that far, the result is `upper_bound_m` with no pair ("at least this").
  double upper_bound_m = std::numeric_limits<double>::infinity();
};

/// Outcome of a distance query.
struct DistanceResult {
  /// Minimum distance [m] over the pairs considered, >= 0: 0 when some pair touches or overlaps
  /// (no penetration depth); `upper_bound_m` (default +inf) when no pair was nearer than that.
  double distance = std::numeric_limits<double>::infinity();
  ShapePair pair;             ///< The nearest pair; body ids invalid when none was computed.
  Vec3 p_A_W = Vec3::Zero();  ///< Nearest point on pair.shape_a, world frame [m].
  Vec3 p_B_W = Vec3::Zero();  ///< Nearest point on pair.shape_b, world frame [m]; equal to
                              ///< p_A_W when the shapes overlap (a point of the overlap region).
  int narrowphase_tests = 0;  ///< Shape pairs whose distance was computed (statistics).
  /// True when a pair was found nearer than the upper bound.
  bool has_pair() const { return pair.body_a.valid(); }
};

/// A set of bodies with poses, groups and an allowed-pair filter, answering "does anything
/// collide?" and "how far apart are these groups?". Geometry is immutable once added and shared by
/// copies, so copy a world per thread: queries use internal scratch buffers and are not
/// thread-safe (like mjData, a world is per-thread working data).
class CollisionWorld {
 public:
  /// An empty world.
  CollisionWorld();
  ~CollisionWorld();
  /// Copies poses and filters; shares the (immutable) geometry. The copy's scratch buffers grow
  /// again on its first queries.
  CollisionWorld(const CollisionWorld& other);
  /// Same as the copy constructor.
  CollisionWorld& operator=(const CollisionWorld& other);
  /// Moves; the moved-from world may only be destroyed or assigned to.
  CollisionWorld(CollisionWorld&&) noexcept;
  /// Moves; the moved-from world may only be destroyed or assigned to.
  CollisionWorld& operator=(CollisionWorld&&) noexcept;

  /// Adds a body and returns its id. Fails with kInvalidInput naming the body and the shape for
  /// a group outside [0, kMaxCollisionGroups), a non-positive or non-finite size, a degenerate
  /// cylinder axis or an empty mesh. Capsules of zero length are spheres. Sphere: centre p0.
  /// A mesh equal (vertex by vertex) to one that some world of the process already holds shares
  /// that world's FCL tree instead of building another.
  Result<BodyId> AddBody(const BodyDef& def);
  /// Mesh trees alive in the process (each shared by every world holding its mesh).
  static int LiveMeshTrees();

  /// Number of bodies.
  int num_bodies() const;
  /// Name of a body.
  const std::string& body_name(BodyId body) const;
  /// Group of a body.
  int body_group(BodyId body) const;
  /// Number of shapes of a body.
  int num_shapes(BodyId body) const;
  /// Name of shape `shape` of a body ("shape<k>" when the Shape had no name).
  const std::string& shape_name(BodyId body, int shape) const;
  /// The body named `name`, or an invalid id.
  BodyId FindBody(const std::string& name) const;

  /// Moves a body: X_WB is the pose of its frame in the world. Cheap (bounds update lazily).
  void SetPose(BodyId body, const Iso3& X_WB);
  /// Current pose of a body in the world.
  const Iso3& pose(BodyId body) const;
  /// Moves body i to X_WB[i] for every body (X_WB.size() must equal num_bodies()).
  void SetPoses(std::span<const Iso3> X_WB);

  /// Takes a body out of (or back into) every query, e.g. a part not in the scene yet.
  void SetEnabled(BodyId body, bool enabled);
  /// True when the body takes part in queries (default).
  bool enabled(BodyId body) const;

  /// Allows (true) or forbids (false) contact between two bodies: an allowed pair is skipped by
  /// AnyCollision and MinDistance (e.g. adjacent links, a gripper and the part it holds).
  void SetAllowed(BodyId a, BodyId b, bool allowed);
  /// Allows or forbids contact between every body of group g and every body of group h (g == h:
  /// within the group). A pair is skipped when either its bodies or its groups are allowed.
  void SetGroupPairAllowed(int g, int h, bool allowed);
  /// True when the pair is skipped by the filter (body rule or group rule).
  bool IsAllowed(BodyId a, BodyId b) const;

  /// True when some enabled, not-allowed pair of bodies collides (touching counts; closer than
  /// request.margin_m counts). Fills `result` when given: the first pair found and, when asked,
  /// all pairs. Never allocates in steady state with a reused result (see the file comment).
  bool AnyCollision(const CollisionRequest& request = {}, CollisionResult* result = nullptr);

  /// True when bodies a and b collide, ignoring the filter and the enabled flags.
  bool Collide(BodyId a, BodyId b, const CollisionRequest& request = {},
               CollisionResult* result = nullptr);

  /// Minimum distance between the bodies of group g and those of group h (g == h: between
  /// different bodies of that group), skipping allowed and disabled pairs. The planner's
  /// clearance between robots. Branch and bound over bounding boxes: far pairs cost nothing.
  DistanceResult MinDistance(int group_g, int group_h, const DistanceRequest& request = {});

  /// Minimum distance over every pair of bodies whose groups {g, h} are in `pairs`, e.g. every
  /// robot against every other robot in one call.
  DistanceResult MinDistance(const GroupPairSet& pairs, const DistanceRequest& request = {});

  /// Distance between bodies a and b (minimum over their shapes), ignoring the filter and the
  /// enabled flags.
  DistanceResult Distance(BodyId a, BodyId b, const DistanceRequest& request = {});

  /// World bounding box of a body's shapes (empty box at the body origin when it has none) [m].
  Aabb body_aabb(BodyId body);

  /// One line naming both bodies and shapes with their groups and world poses (xyz [m], rpy
  /// [rad], 10 significant digits), enough to rebuild the query; for messages and failing tests.
  std::string Describe(const ShapePair& pair) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wrap
