// CollisionWorld on constructed cases with known answers: touching and separated capsules, a box
// on a table, meshes, groups and filters, the nearest points of every shape kind.
#include "robot/collision.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "scenes.h"

namespace wrap {
namespace {

using testing::Box;
using testing::BoxMesh;
using testing::Capsule;
using testing::Cylinder;
using testing::MeshShape;
using testing::Pose;
using testing::Sphere;
using testing::Translation;

constexpr double kExact = 1e-12;  // closed forms
constexpr double kGjk = 1e-6;     // FCL's GJK tolerance

BodyId Add(CollisionWorld& w, const std::string& name, int group, std::vector<Shape> shapes,
           const Iso3& X_WB = Iso3::Identity()) {
  auto id = w.AddBody(BodyDef{name, group, std::move(shapes), X_WB});
  EXPECT_TRUE(id.has_value()) << (id ? "" : id.error().message);
  return id.value_or(BodyId{});
}

TEST(CollisionWorld, CapsulesTouchingCollide) {
  CollisionWorld w;
  // Parallel capsules along x, axes 0.2 apart, radii 0.1 + 0.1: touching along a line.
  const BodyId a = Add(w, "a", 0, {Capsule({-0.5, 0, 0}, {0.5, 0, 0}, 0.1)});
  const BodyId b =
      Add(w, "b", 1, {Capsule({-0.5, 0, 0}, {0.5, 0, 0}, 0.1)}, Translation(0, 0.2, 0));
  CollisionResult result;
  EXPECT_TRUE(w.AnyCollision({}, &result));
  EXPECT_TRUE(result.collision);
  EXPECT_EQ(result.first.body_a, a);
  EXPECT_EQ(result.first.body_b, b);
  EXPECT_EQ(w.Distance(a, b).distance, 0.0);
  EXPECT_EQ(w.MinDistance(0, 1).distance, 0.0);
  // A hair apart: no collision, and the distance is the hair.
  w.SetPose(b, Translation(0, 0.2 + 1e-9, 0));
  EXPECT_FALSE(w.AnyCollision());
  EXPECT_NEAR(w.Distance(a, b).distance, 1e-9, kExact);
}

TEST(CollisionWorld, CapsulesKnownGapExactDistanceAndPoints) {
  CollisionWorld w;
  // Crossed capsules: A along x at z = 0 (r 0.1); B along y at z = 0.5 (r 0.05). Gap 0.35.
  const BodyId a = Add(w, "a", 0, {Capsule({-1, 0, 0}, {1, 0, 0}, 0.1, "a/tube")});
  const BodyId b =
      Add(w, "b", 1, {Capsule({0, -1, 0}, {0, 1, 0}, 0.05, "b/tube")}, Translation(0, 0, 0.5));
  DistanceResult d = w.Distance(a, b);
  EXPECT_NEAR(d.distance, 0.35, kExact);
  EXPECT_TRUE(d.p_A_W.isApprox(Vec3(0, 0, 0.1), kExact));
  EXPECT_TRUE(d.p_B_W.isApprox(Vec3(0, 0, 0.45), kExact));
  EXPECT_FALSE(w.AnyCollision());

  // The same pair moved and turned as a whole: same distance.
  const Iso3 X = Pose({0.3, -2.0, 1.1}, {0.4, -0.2, 1.3});
  w.SetPose(a, X);
  w.SetPose(b, X * Translation(0, 0, 0.5));
  d = w.MinDistance(0, 1);
  EXPECT_NEAR(d.distance, 0.35, kExact);
  EXPECT_TRUE(d.p_A_W.isApprox(X * Vec3(0, 0, 0.1), 1e-9));
  EXPECT_EQ(w.shape_name(d.pair.body_a, d.pair.shape_a), "a/tube");

  // End to end along one line: a gap between the caps.
  w.SetPose(a, Iso3::Identity());
  w.SetPose(b, Pose({2.0 + 0.1 + 0.05 + 0.123, 0, 0}, {0, 0, std::numbers::pi / 2}));
  EXPECT_NEAR(w.Distance(a, b).distance, 0.123, kExact);

  // Margin: closer than the margin counts as a collision.
  CollisionRequest req;
  req.margin_m = 0.13;
  EXPECT_TRUE(w.AnyCollision(req));
  req.margin_m = 0.12;
  EXPECT_FALSE(w.AnyCollision(req));
}

// Segment distance against dense sampling, including parallel and degenerate segments.
TEST(CollisionWorld, CapsuleDistanceMatchesSampling) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto sample_distance = [](const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
    double best = 1e9;
    constexpr int kN = 400;
    for (int i = 0; i <= kN; ++i) {
      const Vec3 p = p0 + (p1 - p0) * (double(i) / kN);
      // For a point, the nearest point of a segment in closed form.
      const Vec3 d = q1 - q0;
      const double t =
          d.squaredNorm() > 0 ? std::clamp((p - q0).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
      best = std::min(best, (p - (q0 + t * d)).norm());
    }
    return best;
  };
  for (int trial = 0; trial < 300; ++trial) {
    Vec3 p0(u(rng), u(rng), u(rng)), p1(u(rng), u(rng), u(rng));
    Vec3 q0(u(rng), u(rng), u(rng)), q1(u(rng), u(rng), u(rng));
    if (trial % 5 == 0) q1 = q0 + 0.7 * (p1 - p0);  // parallel
    if (trial % 7 == 0) p1 = p0;                    // a sphere
    CollisionWorld w;
    const BodyId a = Add(w, "a", 0, {Capsule(p0, p1, 0.01)});
    const BodyId b = Add(w, "b", 0, {Capsule(q0, q1, 0.02)});
    const double expected = std::max(0.0, sample_distance(p0, p1, q0, q1) - 0.03);
    const DistanceResult d = w.Distance(a, b);
    // The exact distance is at most the sampled one and within the sampling step of it.
    EXPECT_LE(d.distance, expected + 1e-12) << trial;
    EXPECT_NEAR(d.distance, expected, 2e-2) << trial;
    if (d.distance > 0) {
      EXPECT_NEAR((d.p_A_W - d.p_B_W).norm(), d.distance, 1e-9) << trial;
    }
    EXPECT_EQ(w.AnyCollision(), d.distance == 0.0) << trial;
  }
}

TEST(CollisionWorld, BoxOnTableAllowedAndPenetratingReported) {
  CollisionWorld w;
  // Table: top at z = 0.75. A box resting on it, a second box pushed 1 cm into it.
  const BodyId table = Add(w, "table", 0, {Box({0, 0, 0.725}, {0.8, 0.6, 0.025}, "top")});
  const BodyId resting =
      Add(w, "resting", 1, {Box({0, 0, 0.05}, {0.05, 0.05, 0.05})}, Translation(0.2, 0, 0.75));
  EXPECT_TRUE(w.AnyCollision());  // touching counts
  w.SetAllowed(resting, table, true);
  EXPECT_TRUE(w.IsAllowed(table, resting));
  EXPECT_FALSE(w.AnyCollision());

  const BodyId sunk = Add(w, "sunk", 2, {Box({0, 0, 0.05}, {0.05, 0.05, 0.05}, "sunk/box")},
                          Translation(-0.3, 0.1, 0.74));
  CollisionResult result;
  ASSERT_TRUE(w.AnyCollision({}, &result));
  EXPECT_EQ(result.first.body_a, table);
  EXPECT_EQ(result.first.body_b, sunk);
  const std::string text = w.Describe(result.first);
  EXPECT_NE(text.find("'table'"), std::string::npos) << text;
  EXPECT_NE(text.find("'sunk/box'"), std::string::npos) << text;
  EXPECT_NE(text.find("xyz=(-0.3, 0.1, 0.74)"), std::string::npos) << text;
  EXPECT_EQ(w.Distance(table, sunk).distance, 0.0);

  // Lifted by 2 cm: 1 cm above the table, exactly (GJK on boxes).
  w.SetPose(sunk, Translation(-0.3, 0.1, 0.76));
  EXPECT_FALSE(w.AnyCollision());
  const DistanceResult d = w.Distance(table, sunk);
  EXPECT_NEAR(d.distance, 0.01, kGjk);
  EXPECT_NEAR(d.p_A_W.z(), 0.75, kGjk);
  EXPECT_NEAR(d.p_B_W.z(), 0.76, kGjk);

  // Group rule: every group-2 body may touch the table.
  w.SetPose(sunk, Translation(-0.3, 0.1, 0.74));
  w.SetGroupPairAllowed(0, 2, true);
  EXPECT_FALSE(w.AnyCollision());
  w.SetGroupPairAllowed(0, 2, false);
  EXPECT_TRUE(w.AnyCollision());
  w.SetEnabled(sunk, false);
  EXPECT_FALSE(w.AnyCollision());
  EXPECT_TRUE(w.Collide(table, sunk));  // explicit pairs ignore the flags
}

TEST(CollisionWorld, PrimitivePairsViaGjk) {
  CollisionWorld w;
  const BodyId box = Add(w, "box", 0, {Box({0, 0, 0}, {0.1, 0.1, 0.1})});
  // Capsule standing above the box: gap 0.15.
  const BodyId cap = Add(w, "cap", 1, {Capsule({0, 0, 0.3}, {0, 0, 0.5}, 0.05)});
  // Cylinder (flat end) beside and above the box: from its bottom rim to the box's top edge
  // (0.15, 0.2) -> 0.25 (a capsule there would be nearer).
  const BodyId cyl =
      Add(w, "cyl", 2, {Cylinder({0, 0, 0.3}, {0, 0, 0.6}, 0.05)}, Translation(0.3, 0, 0));
  EXPECT_NEAR(w.Distance(box, cap).distance, 0.15, kGjk);
  EXPECT_NEAR(w.Distance(box, cyl).distance, 0.25, kGjk);
  EXPECT_NEAR(w.Distance(cap, cyl).distance, 0.2, kGjk);
  EXPECT_FALSE(w.AnyCollision());
  w.SetPose(cap, Translation(0, 0, -0.16));  // capsule bottom 0.01 into the box
  EXPECT_TRUE(w.AnyCollision());
  w.SetPose(cap, Translation(0, 0, -0.14));  // 0.01 above
  EXPECT_FALSE(w.AnyCollision());
  w.SetPose(cyl, Translation(0.1, 0, -0.21));  // cylinder rim 0.01 into the box
  EXPECT_TRUE(w.Collide(box, cyl));
  w.SetPose(cyl, Translation(0.1, 0, -0.19));
  EXPECT_FALSE(w.Collide(box, cyl));
  EXPECT_NEAR(w.Distance(box, cyl).distance, 0.01, kGjk);
  // Sphere against a turned box, through a corner: distance to the corner is known.
  CollisionWorld v;
  const BodyId b2 = Add(v, "b2", 0, {Box({0, 0, 0}, {0.1, 0.1, 0.1})});
  const BodyId s2 = Add(v, "s2", 1, {Sphere({0, 0, 0}, 0.05)}, Translation(0.3, 0.3, 0.3));
  EXPECT_NEAR(v.Distance(b2, s2).distance, std::sqrt(3 * 0.2 * 0.2) - 0.05, kGjk);
}

TEST(CollisionWorld, MeshVsMesh) {
  CollisionWorld w;
  const BodyId a = Add(w, "a", 0, {MeshShape(BoxMesh({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}))});
  const BodyId b = Add(w, "b", 1, {MeshShape(BoxMesh({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}))},
                       Translation(0.5, 0, 0));
  DistanceResult d = w.Distance(a, b);
  EXPECT_NEAR(d.distance, 0.3, kGjk);
  EXPECT_NEAR(d.p_A_W.x(), 0.1, kGjk);
  EXPECT_NEAR(d.p_B_W.x(), 0.4, kGjk);
  EXPECT_FALSE(w.AnyCollision());
  // Overlapping by 1 cm, turned.
  w.SetPose(b, Pose({0.19, 0.02, 0}, {0, 0, 0.0}));
  EXPECT_TRUE(w.AnyCollision());
  EXPECT_EQ(w.MinDistance(0, 1).distance, 0.0);
  w.SetPose(b, Pose({0.4, 0, 0}, {0, 0, std::numbers::pi / 4}));
  // Nearest: the turned cube's edge at x = 0.4 - 0.1 * sqrt(2).
  EXPECT_NEAR(w.Distance(a, b).distance, 0.4 - 0.1 * std::sqrt(2.0) - 0.1, kGjk);
}

// Equal meshes share one FCL tree across worlds (cells are rebuilt per task plan and finger
// opening); a different mesh gets its own; trees go when no world holds them.
TEST(CollisionWorld, EqualMeshesShareOneTree) {
  const int before = CollisionWorld::LiveMeshTrees();
  {
    const TriangleMesh m = BoxMesh({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1});
    CollisionWorld w1;
    Add(w1, "a", 0, {MeshShape(m)});
    Add(w1, "b", 0, {MeshShape(m)}, Translation(1, 0, 0));
    EXPECT_EQ(CollisionWorld::LiveMeshTrees(), before + 1);
    CollisionWorld w2;
    Add(w2, "a", 0, {MeshShape(m)});
    EXPECT_EQ(CollisionWorld::LiveMeshTrees(), before + 1);
    Add(w2, "c", 0, {MeshShape(BoxMesh({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.2}))});
    EXPECT_EQ(CollisionWorld::LiveMeshTrees(), before + 2);
    // The shared tree answers for both worlds.
    w2.SetPose(w2.FindBody("a"), Translation(0.15, 0, 0));
    EXPECT_TRUE(w2.AnyCollision());
    EXPECT_FALSE(w1.AnyCollision());
  }
  EXPECT_EQ(CollisionWorld::LiveMeshTrees(), before);
}

// A pair found apart is not tested again until one of its bodies moves: moving either one into
// the other is still found, and so is a pair whose contact is forbidden again.
TEST(CollisionWorld, PairsFoundApartAreRetestedWhenABodyMoves) {
  CollisionWorld w;
  const BodyId a = Add(w, "a", 0, {MeshShape(BoxMesh({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}))});
  // b turned 45 degrees next to a's corner: their boxes overlap, the cubes are 4 cm apart.
  const Iso3 apart = Pose({0.2, 0.2, 0}, {0, 0, std::numbers::pi / 4});
  const BodyId b = Add(w, "b", 1, {MeshShape(BoxMesh({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}))}, apart);
  EXPECT_FALSE(w.AnyCollision());
  EXPECT_FALSE(w.AnyCollision());
  w.SetPose(b, apart);  // the same pose: nothing moved
  EXPECT_FALSE(w.AnyCollision());
  w.SetPose(b, Translation(0.15, 0.0, 0.0));
  EXPECT_TRUE(w.AnyCollision());
  w.SetPose(b, apart);
  EXPECT_FALSE(w.AnyCollision());
  w.SetPose(a, Translation(0.1, 0.1, 0.0));  // now the other one moves in
  EXPECT_TRUE(w.AnyCollision());
  w.SetAllowed(a, b, true);
  EXPECT_FALSE(w.AnyCollision());
  w.SetAllowed(a, b, false);
  EXPECT_TRUE(w.AnyCollision());
  // Whatever the margin, the answer is the exact one plus the margin's.
  w.SetPose(a, Iso3::Identity());
  CollisionRequest near;
  near.margin_m = 0.2;
  EXPECT_FALSE(w.AnyCollision());
  EXPECT_TRUE(w.AnyCollision(near));
}

// Nearest points of primitive-vs-mesh pairs come back in the world frame and in argument order,
// whatever FCL's conventions for the pair (STACK.md quirks).
TEST(CollisionWorld, MeshVsPrimitiveNearestPointsInWorldFrame) {
  const std::vector<Shape> primitives = {
      Sphere({0, 0, 0}, 0.1, "sphere"), Capsule({0, 0, -0.2}, {0, 0, 0.2}, 0.1, "capsule"),
      Cylinder({0, 0, -0.2}, {0, 0, 0.2}, 0.1, "cylinder"), Box({0, 0, 0}, {0.1, 0.1, 0.1}, "box")};
  for (const Shape& prim : primitives) {
    for (bool mesh_first : {true, false}) {
      CollisionWorld w;
      // Off-origin frames so that a local-frame point would show.
      const Iso3 X_WP = Translation(0.0, 5.0, 0.0);
      const Iso3 X_WM = Translation(1.0, 5.0, 0.0);
      const Shape mesh = MeshShape(BoxMesh({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}));
      BodyId p, m;
      if (mesh_first) {
        m = Add(w, "mesh", 0, {mesh}, X_WM);
        p = Add(w, "prim", 1, {prim}, X_WP);
      } else {
        p = Add(w, "prim", 1, {prim}, X_WP);
        m = Add(w, "mesh", 0, {mesh}, X_WM);
      }
      const DistanceResult d = w.Distance(p, m);
      SCOPED_TRACE(prim.name + (mesh_first ? " mesh added first" : " primitive added first"));
      EXPECT_NEAR(d.distance, 0.8, kGjk);
      EXPECT_NEAR(d.p_A_W.x(), 0.1, kGjk);
      EXPECT_NEAR(d.p_A_W.y(), 5.0, 0.1 + kGjk);
      EXPECT_NEAR(d.p_B_W.x(), 0.9, kGjk);
      EXPECT_NEAR(d.p_B_W.y(), 5.0, 0.1 + kGjk);
      const DistanceResult e = w.Distance(m, p);
      EXPECT_NEAR(e.p_A_W.x(), 0.9, kGjk);
      EXPECT_NEAR(e.p_B_W.x(), 0.1, kGjk);
      EXPECT_FALSE(w.AnyCollision());
      w.SetPose(p, Translation(0.85, 5.0, 0.0));
      EXPECT_TRUE(w.AnyCollision());
      EXPECT_EQ(w.Distance(p, m).distance, 0.0);
    }
  }
}

TEST(CollisionWorld, MinDistanceOverGroupsFiltersAndBounds) {
  CollisionWorld w;
  // Three "robots" (groups 1, 2, 3) of one sphere each along x, plus a near object in group 0.
  const BodyId r1 = Add(w, "r1", 1, {Sphere({0, 0, 0}, 0.1)}, Translation(0, 0, 0));
  const BodyId r2 = Add(w, "r2", 2, {Sphere({0, 0, 0}, 0.1)}, Translation(1.0, 0, 0));
  const BodyId r3 = Add(w, "r3", 3, {Sphere({0, 0, 0}, 0.1)}, Translation(1.5, 0, 0));
  const BodyId obj = Add(w, "obj", 0, {Sphere({0, 0, 0}, 0.1)}, Translation(0, 0.25, 0));
  EXPECT_NEAR(w.MinDistance(1, 2).distance, 0.8, kExact);
  EXPECT_NEAR(w.MinDistance(2, 3).distance, 0.3, kExact);
  EXPECT_NEAR(w.MinDistance(1, 0).distance, 0.05, kExact);

  GroupPairSet robots;
  robots.Add(1, 2);
  robots.Add(1, 3);
  robots.Add(2, 3);
  DistanceResult d = w.MinDistance(robots);
  EXPECT_NEAR(d.distance, 0.3, kExact);
  EXPECT_EQ(d.pair.body_a, r2);
  EXPECT_EQ(d.pair.body_b, r3);
  EXPECT_GE(d.narrowphase_tests, 1);

  // Allowed and disabled pairs do not count.
  w.SetAllowed(r2, r3, true);
  EXPECT_NEAR(w.MinDistance(robots).distance, 0.8, kExact);
  w.SetAllowed(r2, r3, false);
  w.SetEnabled(r3, false);
  EXPECT_NEAR(w.MinDistance(robots).distance, 0.8, kExact);
  w.SetEnabled(r3, true);

  // Upper bound: nothing nearer than 0.2 -> "at least 0.2", no pair.
  DistanceRequest req;
  req.upper_bound_m = 0.2;
  d = w.MinDistance(robots, req);
  EXPECT_EQ(d.distance, 0.2);
  EXPECT_FALSE(d.has_pair());
  req.upper_bound_m = 0.5;
  EXPECT_NEAR(w.MinDistance(robots, req).distance, 0.3, kExact);

  // One group against itself: pairs within it.
  const BodyId r1b = Add(w, "r1b", 1, {Sphere({0, 0, 0}, 0.1)}, Translation(0, -0.6, 0));
  EXPECT_NEAR(w.MinDistance(1, 1).distance, 0.4, kExact);
  EXPECT_EQ(w.FindBody("r1b"), r1b);
  EXPECT_EQ(w.FindBody("nope"), BodyId{});
  (void)obj;
  (void)r1;
}

TEST(CollisionWorld, AllPairsAndGroupMask) {
  CollisionWorld w;
  // A row of overlapping spheres in groups 0, 1, 2, 3: three colliding neighbour pairs.
  for (int g = 0; g < 4; ++g) {
    Add(w, "s" + std::to_string(g), g, {Sphere({0, 0, 0}, 0.1)}, Translation(0.15 * g, 0, 0));
  }
  CollisionRequest all;
  all.all_pairs = true;
  CollisionResult result;
  EXPECT_TRUE(w.AnyCollision(all, &result));
  EXPECT_EQ(result.pairs.size(), 3u);
  all.max_pairs = 2;
  w.AnyCollision(all, &result);
  EXPECT_EQ(result.pairs.size(), 2u);

  // Only pairs touching group 3: one.
  CollisionRequest masked;
  masked.all_pairs = true;
  masked.group_mask = std::uint64_t{1} << 3;
  EXPECT_TRUE(w.AnyCollision(masked, &result));
  ASSERT_EQ(result.pairs.size(), 1u);
  EXPECT_EQ(w.body_name(result.pairs[0].body_b), "s3");
  masked.group_mask = 0;
  EXPECT_FALSE(w.AnyCollision(masked));
}

TEST(CollisionWorld, CopiesAreIndependent) {
  CollisionWorld w;
  const BodyId a = Add(w, "a", 0, {MeshShape(BoxMesh({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}))});
  const BodyId b = Add(w, "b", 1, {Capsule({0, 0, 0}, {0, 0, 0.3}, 0.05)}, Translation(1, 0, 0));
  CollisionWorld copy = w;
  copy.SetPose(b, Translation(0.1, 0, 0));
  EXPECT_TRUE(copy.AnyCollision());
  EXPECT_FALSE(w.AnyCollision());
  EXPECT_NEAR(w.Distance(a, b).distance, 0.85, kGjk);
  CollisionWorld moved = std::move(copy);
  EXPECT_TRUE(moved.AnyCollision());
}

TEST(CollisionWorld, BadShapesAreInvalidInput) {
  CollisionWorld w;
  auto r = w.AddBody(BodyDef{"arm", 0, {Capsule({0, 0, 0}, {1, 0, 0}, -0.1, "tube")}});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(r.error().message.find("'arm'"), std::string::npos);
  EXPECT_NE(r.error().message.find("'tube'"), std::string::npos);

  r = w.AddBody(BodyDef{"part", 0, {MeshShape(TriangleMesh{}, "empty")}});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("no triangles"), std::string::npos);

  r = w.AddBody(BodyDef{"g", kMaxCollisionGroups, {}});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("group"), std::string::npos);

  r = w.AddBody(BodyDef{"cyl", 0, {Cylinder({0, 0, 0}, {0, 0, 0}, 0.1)}});
  ASSERT_FALSE(r);
  r = w.AddBody(BodyDef{"box", 0, {Box({0, 0, 0}, {0.1, 0.0, 0.1})}});
  ASSERT_FALSE(r);
  EXPECT_EQ(w.num_bodies(), 0);

  // A body with no shapes is fine and never collides.
  r = w.AddBody(BodyDef{"frame", 0, {}});
  ASSERT_TRUE(r);
  EXPECT_FALSE(w.AnyCollision());
  EXPECT_EQ(w.num_shapes(*r), 0);
}

}  // namespace
}  // namespace wrap
