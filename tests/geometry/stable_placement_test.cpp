// Tests of the convex hull adapter and of stable placements (paper §IV-B "Preprocessing").
#include "geometry/stable_placement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "geometry/convex_hull.h"
#include "test_meshes.h"

namespace wrap {
namespace {

using test_meshes::MakeBox;
using test_meshes::MakeCylinder;

// Centre of mass of a closed mesh of uniform density.
Vec3 Com(const TriangleMesh& mesh) { return ComputeMassProperties(mesh).com; }

// The placement whose support facet has outward normal `n` (in A), or nullptr.
const StablePlacement* WithNormal(const std::vector<StablePlacement>& ps, const Vec3& n) {
  for (const StablePlacement& p : ps) {
    if (p.normal_A.dot(n.normalized()) > 1.0 - 1e-9) return &p;
  }
  return nullptr;
}

// Checks the invariants every placement must hold: the facet rests on z = 0 of T, the COM sits
// above T's origin at com_height, the support polygon lies on the table, is counter-clockwise
// seen from above and holds the origin with the recorded margin.
void ExpectConsistent(const StablePlacement& p, const Vec3& com_A) {
  const Vec3 com_T = p.X_TA * com_A;
  EXPECT_NEAR(com_T.x(), 0.0, 1e-9);
  EXPECT_NEAR(com_T.y(), 0.0, 1e-9);
  EXPECT_NEAR(com_T.z(), p.com_height_m, 1e-9);
  EXPECT_GT(p.com_height_m, 0.0);
  EXPECT_NEAR((p.X_TA.linear() * p.normal_A - Vec3(0, 0, -1)).norm(), 0.0, 1e-9);
  ASSERT_EQ(p.support_A.size(), p.support_T.size());
  ASSERT_GE(p.support_T.size(), 3u);
  double area2 = 0.0;
  for (size_t i = 0; i < p.support_A.size(); ++i) {
    const Vec3 q = p.X_TA * p.support_A[i];
    EXPECT_NEAR(q.z(), 0.0, 1e-6);
    EXPECT_NEAR((q.head<2>() - p.support_T[i]).norm(), 0.0, 1e-9);
    const Eigen::Vector2d& a = p.support_T[i];
    const Eigen::Vector2d& b = p.support_T[(i + 1) % p.support_T.size()];
    area2 += a.x() * b.y() - a.y() * b.x();
  }
  EXPECT_GT(area2, 0.0) << "support polygon must be counter-clockwise seen from above";
  EXPECT_NEAR(0.5 * area2, p.area_m2, 1e-6 * std::max(1.0, p.area_m2));
  EXPECT_NEAR(PolygonMargin(p.support_T, Eigen::Vector2d::Zero()), p.margin_m, 1e-12);
  EXPECT_GT(p.margin_m, 0.0);
  EXPECT_NEAR(p.tip_angle_rad, std::atan2(p.margin_m, p.com_height_m), 1e-12);
}

TEST(ConvexHull, BoxHasEightCornersAndSixSquareFacets) {
  const TriangleMesh box = MakeBox(Vec3(-0.03, -0.03, -0.03), Vec3(0.03, 0.03, 0.03));
  auto hull = ComputeConvexHull(box);
  ASSERT_TRUE(hull) << hull.error().message;
  EXPECT_EQ(hull->mesh.vertices.size(), 8u);
  EXPECT_EQ(hull->mesh.triangles.size(), 12u);
  EXPECT_TRUE(AnalyzeTopology(hull->mesh).closed());
  EXPECT_NEAR(hull->volume_m3, 0.06 * 0.06 * 0.06, 1e-12);
  ASSERT_EQ(hull->facets.size(), 6u);
  for (const HullFacet& f : hull->facets) {
    EXPECT_EQ(f.polygon.size(), 4u);
    EXPECT_EQ(f.triangles.size(), 2u);
    EXPECT_NEAR(f.area_m2, 0.0036, 1e-12);
    EXPECT_NEAR(f.offset, 0.03, 1e-12);
    EXPECT_NEAR(f.normal.cwiseAbs().maxCoeff(), 1.0, 1e-12);
  }
}

TEST(ConvexHull, InteriorPointsAreDropped) {
  std::vector<Vec3> points = MakeBox(Vec3(0.1, 0.2, 0.3)).vertices;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.01, 0.09);
  for (int i = 0; i < 1000; ++i) points.emplace_back(u(rng), 2 * u(rng), 3 * u(rng));
  auto hull = ComputeConvexHull(points);
  ASSERT_TRUE(hull) << hull.error().message;
  EXPECT_EQ(hull->mesh.vertices.size(), 8u);
  EXPECT_EQ(hull->facets.size(), 6u);
  EXPECT_NEAR(hull->volume_m3, 0.006, 1e-12);
}

TEST(ConvexHull, CylinderFacetsStayApartAndCapsMerge) {
  auto hull = ComputeConvexHull(MakeCylinder(0.01, 0.2, 48));
  ASSERT_TRUE(hull) << hull.error().message;
  ASSERT_EQ(hull->facets.size(), 50u);  // 48 sides + 2 caps
  // Largest first: the two caps (pi r^2 = 3.1 cm^2) before the sides (200 x 1.3 mm).
  EXPECT_EQ(hull->facets[0].polygon.size(), 48u);
  EXPECT_EQ(hull->facets[1].polygon.size(), 48u);
  EXPECT_EQ(hull->facets.back().polygon.size(), 4u);
}

TEST(ConvexHull, NoisyPlanarFaceIsOneFacet) {
  TriangleMesh box = MakeBox(Vec3(0.1, 0.1, 0.1));
  // Split the top face with extra points slightly off the plane (float noise of a real file).
  std::vector<Vec3> points = box.vertices;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 0.1), noise(-1e-7, 0.0);
  for (int i = 0; i < 200; ++i) points.emplace_back(u(rng), u(rng), 0.1 + noise(rng));
  auto hull = ComputeConvexHull(points);
  ASSERT_TRUE(hull) << hull.error().message;
  EXPECT_EQ(hull->facets.size(), 6u);
}

TEST(ConvexHull, DegenerateInputIsRejected) {
  std::vector<Vec3> three = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  auto r = ComputeConvexHull(three);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(r.error().message.find("at least 4"), std::string::npos);

  std::vector<Vec3> flat;
  for (int i = 0; i < 20; ++i) flat.emplace_back(std::cos(i), std::sin(i), 0.0);
  r = ComputeConvexHull(flat);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput) << r.error().message;

  std::vector<Vec3> bad = MakeBox(Vec3(1, 1, 1)).vertices;
  bad[3].x() = std::nan("");
  r = ComputeConvexHull(bad);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
}

TEST(ConvexHull2d, SquareWithCollinearAndInteriorPoints) {
  std::vector<Eigen::Vector2d> pts = {{0, 0}, {1, 0}, {0.5, 0}, {1, 1}, {0, 1}, {0.5, 0.5}, {1, 1}};
  const std::vector<int> h = ConvexHull2d(pts);
  ASSERT_EQ(h.size(), 4u);
  double area2 = 0.0;
  for (size_t i = 0; i < h.size(); ++i) {
    const auto& a = pts[h[i]];
    const auto& b = pts[h[(i + 1) % h.size()]];
    area2 += a.x() * b.y() - a.y() * b.x();
  }
  EXPECT_NEAR(area2, 2.0, 1e-12);  // counter-clockwise, unit square
}

TEST(StablePlacements, CubeHasExactlySixClasses) {
  const TriangleMesh cube = MakeBox(Vec3(-0.03, -0.03, -0.03), Vec3(0.03, 0.03, 0.03));
  auto hull = ComputeConvexHull(cube);
  ASSERT_TRUE(hull);
  const Vec3 com = Com(cube);
  const auto ps = ComputeStablePlacements(*hull, com);
  ASSERT_EQ(ps.size(), 6u);
  for (int axis = 0; axis < 3; ++axis) {
    const Vec3 n = Vec3::Unit(axis);
    for (double s : {1.0, -1.0}) {
      const StablePlacement* p = WithNormal(ps, s * n);
      ASSERT_NE(p, nullptr) << (s * n).transpose();
      EXPECT_NEAR(p->margin_m, 0.03, 1e-12);
      EXPECT_NEAR(p->com_height_m, 0.03, 1e-12);
      EXPECT_NEAR(p->area_m2, 0.0036, 1e-12);
      EXPECT_EQ(p->support_T.size(), 4u);
      EXPECT_EQ(p->equivalent_facets.size(), 1u);
      ExpectConsistent(*p, com);
    }
  }
}

TEST(StablePlacements, OffsetCubeFrameDoesNotMatter) {
  // The same cube modelled away from its frame's origin: the COM moves with it.
  const TriangleMesh cube = MakeBox(Vec3(0.5, 0.2, -0.1), Vec3(0.56, 0.26, -0.04));
  auto hull = ComputeConvexHull(cube);
  ASSERT_TRUE(hull);
  const auto ps = ComputeStablePlacements(*hull, Com(cube));
  ASSERT_EQ(ps.size(), 6u);
  for (const StablePlacement& p : ps) ExpectConsistent(p, Com(cube));
}

TEST(StablePlacements, LongCylinderRestsOnItsSideAsOneClassAndOnItsEnds) {
  const double r = 0.01, h = 0.2;
  const int n = 48;
  const TriangleMesh cyl = MakeCylinder(r, h, n);
  auto hull = ComputeConvexHull(cyl);
  ASSERT_TRUE(hull);
  const Vec3 com = Com(cyl);
  const auto ps = ComputeStablePlacements(*hull, com);
  ASSERT_EQ(ps.size(), 3u);
  // Ends first (largest tip angle), then the side.
  const StablePlacement* bottom = WithNormal(ps, -Vec3::UnitZ());
  const StablePlacement* top = WithNormal(ps, Vec3::UnitZ());
  ASSERT_TRUE(bottom && top);
  EXPECT_NEAR(bottom->margin_m, r * std::cos(std::numbers::pi / n), 1e-9);
  EXPECT_NEAR(bottom->com_height_m, h / 2, 1e-9);
  const StablePlacement& side = ps.back();
  EXPECT_NEAR(side.normal_A.z(), 0.0, 1e-9);
  EXPECT_EQ(side.equivalent_facets.size(), static_cast<size_t>(n));
  EXPECT_NEAR(side.margin_m, r * std::sin(std::numbers::pi / n), 1e-9);
  EXPECT_NEAR(side.com_height_m, r * std::cos(std::numbers::pi / n), 1e-9);
  for (const StablePlacement& p : ps) ExpectConsistent(p, com);

  // A stricter margin leaves the ends only: the thin side facets cannot hold the COM with it.
  StablePlacementOptions strict;
  strict.min_margin_m = 0.002;
  EXPECT_EQ(ComputeStablePlacements(*hull, com, strict).size(), 2u);
  // Without symmetry merging every side facet is its own orientation.
  StablePlacementOptions unmerged;
  unmerged.merge_symmetric = false;
  EXPECT_EQ(ComputeStablePlacements(*hull, com, unmerged).size(), static_cast<size_t>(n + 2));
}

TEST(StablePlacements, PencilDoesNotStandOnItsTip) {
  // A cylinder whose top cap is pulled into a cone: the point has no support polygon.
  TriangleMesh pencil = MakeCylinder(0.008, 0.15, 32);
  pencil.vertices[1] = Vec3(0, 0, 0.075 + 0.03);  // top centre becomes the apex
  auto hull = ComputeConvexHull(pencil);
  ASSERT_TRUE(hull);
  const Vec3 com = Com(pencil);
  const auto ps = ComputeStablePlacements(*hull, com);
  ASSERT_EQ(ps.size(), 2u);  // the flat end and the side (one class)
  EXPECT_NE(WithNormal(ps, -Vec3::UnitZ()), nullptr);
  EXPECT_EQ(WithNormal(ps, Vec3::UnitZ()), nullptr);
  for (const StablePlacement& p : ps) ExpectConsistent(p, com);
}

TEST(StablePlacements, LShapeRestsOnlyWhereItsComIsSupported) {
  // An L in the xz plane: a foot along x (120 x 20 mm) and a post along z (20 x 80 mm above it),
  // 20 mm deep. COM at (40, 0, 30) mm: over the foot's bottom, the post's back, the slanted hull
  // facet and both sides, but not under the post's top or the foot's end.
  const TriangleMesh foot = MakeBox(Vec3(0, -0.01, 0), Vec3(0.12, 0.01, 0.02));
  const TriangleMesh post = MakeBox(Vec3(0, -0.01, 0.02), Vec3(0.02, 0.01, 0.1));
  std::vector<Vec3> points = foot.vertices;
  points.insert(points.end(), post.vertices.begin(), post.vertices.end());
  const double v1 = 0.12 * 0.02 * 0.02, v2 = 0.02 * 0.02 * 0.08;
  const Vec3 com = (v1 * Com(foot) + v2 * Com(post)) / (v1 + v2);
  EXPECT_NEAR((com - Vec3(0.04, 0, 0.03)).norm(), 0.0, 1e-12);
  auto hull = ComputeConvexHull(points);
  ASSERT_TRUE(hull) << hull.error().message;
  const auto ps = ComputeStablePlacements(*hull, com);
  EXPECT_EQ(ps.size(), 5u);
  EXPECT_NE(WithNormal(ps, -Vec3::UnitZ()), nullptr);      // on the foot
  EXPECT_NE(WithNormal(ps, -Vec3::UnitX()), nullptr);      // on the post's back
  EXPECT_NE(WithNormal(ps, Vec3(0.08, 0, 0.1)), nullptr);  // on the tips of foot and post
  EXPECT_NE(WithNormal(ps, Vec3::UnitY()), nullptr);
  EXPECT_NE(WithNormal(ps, -Vec3::UnitY()), nullptr);
  EXPECT_EQ(WithNormal(ps, Vec3::UnitZ()), nullptr);  // the post's top: COM beyond it
  EXPECT_EQ(WithNormal(ps, Vec3::UnitX()), nullptr);  // the foot's end: COM above it
  const StablePlacement* bottom = WithNormal(ps, -Vec3::UnitZ());
  EXPECT_NEAR(bottom->margin_m, 0.01, 1e-12);  // 10 mm to the foot's long edges
  for (const StablePlacement& p : ps) ExpectConsistent(p, com);
}

TEST(StablePlacements, ComOutsideTheHullRestsNowhere) {
  auto hull = ComputeConvexHull(MakeBox(Vec3(0.1, 0.1, 0.1)));
  ASSERT_TRUE(hull);
  EXPECT_TRUE(ComputeStablePlacements(*hull, Vec3(1, 1, 1)).empty());
}

}  // namespace
}  // namespace wrap
