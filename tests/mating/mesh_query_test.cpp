// Closest points, inside tests and inward offsets on hand-made meshes.
#include <gtest/gtest.h>

#include "geometry/mesh_offset.h"
#include "geometry/mesh_query.h"
#include "scenes.h"

namespace wrap {
namespace {

using test::Mm;

TEST(MeshQuery, ClosestPointOfABox) {
  const MeshQuery q(BoxMesh(Mm(0, 0, 0), Mm(10, 10, 10)));
  // Outside a face, beyond an edge, beyond a corner.
  auto face = q.Closest(Mm(5, 5, 13), 1.0);
  ASSERT_TRUE(face);
  EXPECT_NEAR(face->distance, 3e-3, 1e-12);
  EXPECT_TRUE(face->point.isApprox(Mm(5, 5, 10), 1e-12));
  auto edge = q.Closest(Mm(13, 5, 14), 1.0);
  ASSERT_TRUE(edge);
  EXPECT_NEAR(edge->distance, 5e-3, 1e-12);
  auto corner = q.Closest(Mm(11, 12, 12), 1.0);
  ASSERT_TRUE(corner);
  EXPECT_NEAR(corner->distance, 3e-3, 1e-12);
  // Inside: the nearest face.
  auto inside = q.Closest(Mm(2, 5, 5), 1.0);
  ASSERT_TRUE(inside);
  EXPECT_NEAR(inside->distance, 2e-3, 1e-12);
  // Beyond the search radius: nothing.
  EXPECT_FALSE(q.Closest(Mm(5, 5, 13), 2e-3));
}

TEST(MeshQuery, InsideAndDepth) {
  const MeshQuery q(BoxMesh(Mm(0, 0, 0), Mm(10, 10, 10)));
  EXPECT_TRUE(q.Contains(Mm(5, 5, 5)));
  EXPECT_TRUE(q.Contains(Mm(0.1, 9.9, 0.1)));
  EXPECT_FALSE(q.Contains(Mm(-0.1, 5, 5)));
  EXPECT_FALSE(q.Contains(Mm(15, 15, 15)));
  EXPECT_NEAR(q.Depth(Mm(5, 5, 5), 1.0), 5e-3, 1e-12);
  EXPECT_NEAR(q.Depth(Mm(1, 5, 5), 1.0), 1e-3, 1e-12);
  EXPECT_EQ(q.Depth(Mm(12, 5, 5), 1.0), 0.0);
}

TEST(MeshOffset, InsetBoxShrinksEveryFace) {
  const TriangleMesh box = BoxMesh(Mm(0, 0, 0), Mm(10, 20, 30));
  const Aabb inner = ComputeAabb(InsetMesh(box, 1e-3));
  EXPECT_TRUE(inner.min.isApprox(Mm(1, 1, 1), 1e-9));
  EXPECT_TRUE(inner.max.isApprox(Mm(9, 19, 29), 1e-9));
  const Aabb outer = ComputeAabb(InsetMesh(box, -1e-3));
  EXPECT_TRUE(outer.min.isApprox(Mm(-1, -1, -1), 1e-9));
  EXPECT_TRUE(outer.max.isApprox(Mm(11, 21, 31), 1e-9));
  // Same triangles, volume of the 8 x 18 x 28 mm box.
  const TriangleMesh in = InsetMesh(box, 1e-3);
  EXPECT_EQ(in.triangles, box.triangles);
  EXPECT_NEAR(ComputeMassProperties(in).volume_m3, 8e-3 * 18e-3 * 28e-3, 1e-12);
}

}  // namespace
}  // namespace wrap
