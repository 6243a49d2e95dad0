// The exact sweep of a translation: travel intervals of hand-made triangle pairs, and the first and
// last contacts of hand-made meshes (boxes, a peg in a hole, a tilted axis, a thin wall), each
// computed by hand.
#include <gtest/gtest.h>

#include <numbers>

#include "geometry/mesh.h"
#include "geometry/translation_sweep.h"

namespace wrap {
namespace {

constexpr double kTol = 1e-9;

using Tri = std::array<Vec3, 3>;

TravelInterval Interval(const Tri& a, const Tri& b, const Vec3& d) {
  return TriangleTravelInterval(a, b, d, -100.0, 100.0);
}

// a = the unit right triangle in z = 0; b stands in x = 3 across z = 0 with its edge along z.
TEST(TriangleTravelInterval, VertexIntoFaceAndOut) {
  const Tri a = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Tri b = {Vec3(3, 0, -1), Vec3(3, 0, 1), Vec3(3, 1, 0)};
  // a's vertex (1, 0, 0) reaches b's edge at (3, 0, 0) at t = 2; a's edge x = 0 leaves it at 3.
  const TravelInterval iv = Interval(a, b, Vec3::UnitX());
  EXPECT_NEAR(iv.lo, 2.0, kTol);
  EXPECT_NEAR(iv.hi, 3.0, kTol);
  // Travelling twice as fast halves t; backwards, t is negated.
  const TravelInterval fast = Interval(a, b, Vec3(2, 0, 0));
  EXPECT_NEAR(fast.lo, 1.0, kTol);
  EXPECT_NEAR(fast.hi, 1.5, kTol);
  const TravelInterval back = Interval(a, b, -Vec3::UnitX());
  EXPECT_NEAR(back.lo, -3.0, kTol);
  EXPECT_NEAR(back.hi, -2.0, kTol);
  // The range clips it.
  const TravelInterval clipped = TriangleTravelInterval(a, b, Vec3::UnitX(), 2.5, 10.0);
  EXPECT_NEAR(clipped.lo, 2.5, kTol);
  EXPECT_NEAR(clipped.hi, 3.0, kTol);
  EXPECT_TRUE(TriangleTravelInterval(a, b, Vec3::UnitX(), 3.5, 10.0).empty());
  // b lifted above a's plane by more than its half height: never met.
  const Tri high = {Vec3(3, 0, 1.5), Vec3(3, 0, 3.5), Vec3(3, 1, 2.5)};
  EXPECT_TRUE(Interval(a, high, Vec3::UnitX()).empty());
}

TEST(TriangleTravelInterval, EdgeAcrossEdge) {
  // a's edge x = 0 runs along y, b's edge x = 2 along z: they cross at (2, 0, 0) at t = 2; a's
  // far vertex (-1, 0, 0) passes b's far vertex (3, 0, 0) at t = 4.
  const Tri a = {Vec3(0, -1, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0)};
  const Tri b = {Vec3(2, 0, -1), Vec3(2, 0, 1), Vec3(3, 0, 0)};
  const TravelInterval iv = Interval(a, b, Vec3::UnitX());
  EXPECT_NEAR(iv.lo, 2.0, kTol);
  EXPECT_NEAR(iv.hi, 4.0, kTol);
  // Moved 1.5 along z, a's plane misses b (whose half height is 1).
  const Tri a_high = {Vec3(0, -1, 1.5), Vec3(0, 1, 1.5), Vec3(-1, 0, 1.5)};
  EXPECT_TRUE(Interval(a_high, b, Vec3::UnitX()).empty());
}

TEST(TriangleTravelInterval, CoplanarTrianglesSlideIntoEachOther) {
  // Both in z = 0; along y = 0 a covers [t, t + 1] and b [3, 4]: they share points for t in
  // [2, 4]. Only the in-plane axes see this.
  const Tri a = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Tri b = {Vec3(3, 0, 0), Vec3(4, 0, 0), Vec3(3, 1, 0)};
  const TravelInterval iv = Interval(a, b, Vec3::UnitX());
  EXPECT_NEAR(iv.lo, 2.0, kTol);
  EXPECT_NEAR(iv.hi, 4.0, kTol);
  // b moved 1.5 along y, beside a's path in the same plane: never met.
  const Tri beside = {Vec3(3, 1.5, 0), Vec3(4, 1.5, 0), Vec3(3, 2.5, 0)};
  EXPECT_TRUE(Interval(a, beside, Vec3::UnitX()).empty());
  // b in the parallel plane z = 0.5: never met.
  const Tri above = {Vec3(3, 0, 0.5), Vec3(4, 0, 0.5), Vec3(3, 1, 0.5)};
  EXPECT_TRUE(Interval(a, above, Vec3::UnitX()).empty());
}

TEST(TriangleTravelInterval, ParallelEdgesInCrossingPlanes) {
  // a in z = 0 with its edge along x; b upright in y = 0 with its lower edge along x at z = 1
  // (x from 0.2 to 0.8) and its apex at z = 2. Rising along z, a's edge meets b's lower edge at
  // t = 1 and leaves b's apex at t = 2 (zero cross products of the parallel edges are skipped).
  const Tri a = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Tri b = {Vec3(0.2, 0, 1), Vec3(0.8, 0, 1), Vec3(0.5, 0, 2)};
  const TravelInterval iv = Interval(a, b, Vec3::UnitZ());
  EXPECT_NEAR(iv.lo, 1.0, kTol);
  EXPECT_NEAR(iv.hi, 2.0, kTol);
  // b moved to x >= 1.2, beyond a's edge: never met.
  const Tri off = {Vec3(1.2, 0, 1), Vec3(1.8, 0, 1), Vec3(1.5, 0, 2)};
  EXPECT_TRUE(Interval(a, off, Vec3::UnitZ()).empty());
}

TEST(TriangleTravelInterval, TravelAlongTheSharedPlaneNeverReachesAParallelOne) {
  // d lies in a's plane, b is in a parallel plane: no axis is moved along, and the normal
  // separates for every t.
  const Tri a = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Tri b = {Vec3(0, 0, 1e-6), Vec3(1, 0, 1e-6), Vec3(0, 1, 1e-6)};
  EXPECT_TRUE(Interval(a, b, Vec3(1, 1, 0)).empty());
}

std::optional<SweepContactHit> Sweep(const TriangleMesh& moving, const TriangleMesh& fixed,
                                     const Vec3& d, double t_min, double t_max, bool last,
                                     const Iso3& X = Iso3::Identity()) {
  const SweepMesh m(moving, X), f(fixed, X);
  SweepQuery q;
  q.d_F = X.linear() * d;
  q.t_min = t_min;
  q.t_max = t_max;
  q.last = last;
  return SweepContact(m, f, q);
}

TEST(SweepContact, BoxSlidingIntoABox) {
  const TriangleMesh moving = BoxMesh(Vec3(0, 0, 0), Vec3(1, 1, 1));
  const TriangleMesh fixed = BoxMesh(Vec3(3, 0.5, 0.2), Vec3(4, 1.5, 0.8));
  // Faces meet at t = 2; the moving box's back face leaves the fixed one at t = 4.
  const auto first = Sweep(moving, fixed, Vec3::UnitX(), 0.0, 10.0, false);
  ASSERT_TRUE(first);
  EXPECT_NEAR(first->t, 2.0, kTol);
  const auto last = Sweep(moving, fixed, Vec3::UnitX(), 0.0, 10.0, true);
  ASSERT_TRUE(last);
  EXPECT_NEAR(last->t, 4.0, kTol);
  // Starting inside the contact, the first contact is the start of the range.
  const auto inside = Sweep(moving, fixed, Vec3::UnitX(), 2.5, 10.0, false);
  ASSERT_TRUE(inside);
  EXPECT_NEAR(inside->t, 2.5, kTol);
  EXPECT_FALSE(Sweep(moving, fixed, Vec3::UnitX(), 0.0, 1.9, false));
  EXPECT_FALSE(Sweep(moving, fixed, Vec3::UnitX(), 4.1, 10.0, true));
  // Away from it along y: never met.
  EXPECT_FALSE(Sweep(moving, fixed, Vec3::UnitY(), 0.0, 10.0, false));
}

TEST(SweepContact, FacesSlidingAlongEachOtherTouch) {
  // The fixed box's face y = 1 lies in the moving box's face y = 1: closed surfaces touch from
  // t = 2 to t = 4; a micrometre apart they never meet.
  const TriangleMesh moving = BoxMesh(Vec3(0, 0, 0), Vec3(1, 1, 1));
  const auto touch =
      Sweep(moving, BoxMesh(Vec3(3, 1, 0), Vec3(4, 2, 1)), Vec3::UnitX(), 0.0, 10.0, false);
  ASSERT_TRUE(touch);
  EXPECT_NEAR(touch->t, 2.0, kTol);
  EXPECT_FALSE(
      Sweep(moving, BoxMesh(Vec3(3, 1 + 1e-6, 0), Vec3(4, 2, 1)), Vec3::UnitX(), 0.0, 10.0, false));
}

// A 20 x 20 hole through a tube of 5-thick walls from z = 0 to 20, and a peg from z = 25 to 55.
TriangleMesh Tube() {
  TriangleMesh tube;
  for (const auto& [lo, hi] : {std::pair{Vec3(-15, -15, 0), Vec3(-10, 15, 20)},
                               std::pair{Vec3(10, -15, 0), Vec3(15, 15, 20)},
                               std::pair{Vec3(-10, -15, 0), Vec3(10, -10, 20)},
                               std::pair{Vec3(-10, 10, 0), Vec3(10, 15, 20)}}) {
    const TriangleMesh wall = BoxMesh(lo, hi);
    const int offset = static_cast<int>(tube.vertices.size());
    tube.vertices.insert(tube.vertices.end(), wall.vertices.begin(), wall.vertices.end());
    for (const Eigen::Vector3i& t : wall.triangles) {
      tube.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
    }
  }
  return tube;
}

TEST(SweepContact, PegThroughAHoleWithClearance) {
  const TriangleMesh tube = Tube();
  // 0.5 of clearance all round: the peg passes through from t = 0 to 60 untouched.
  const TriangleMesh peg = BoxMesh(Vec3(-9.5, -9.5, 25), Vec3(9.5, 9.5, 55));
  EXPECT_FALSE(Sweep(peg, tube, -Vec3::UnitZ(), 0.0, 60.0, false));
  EXPECT_FALSE(Sweep(peg, tube, -Vec3::UnitZ(), 0.0, 60.0, true));
  // 0.7 off centre the peg overlaps the wall x >= 10 by 0.2: its bottom meets the wall's top
  // (z = 20) at t = 5, its top leaves the wall's bottom (z = 0) at t = 55.
  const TriangleMesh off = BoxMesh(Vec3(-8.8, -9.5, 25), Vec3(10.2, 9.5, 55));
  const auto first = Sweep(off, tube, -Vec3::UnitZ(), 0.0, 60.0, false);
  ASSERT_TRUE(first);
  EXPECT_NEAR(first->t, 5.0, kTol);
  const auto last = Sweep(off, tube, -Vec3::UnitZ(), 0.0, 60.0, true);
  ASSERT_TRUE(last);
  EXPECT_NEAR(last->t, 55.0, kTol);
}

TEST(SweepContact, TiltedAxisGivesTheSameContacts) {
  // The off-centre peg and the tube turned 30 degrees about x, travelling along the turned axis
  // at twice the speed: the same contacts at half the t.
  Iso3 X = Iso3::Identity();
  X.linear() = Eigen::AngleAxisd(std::numbers::pi / 6, Vec3::UnitX()).toRotationMatrix();
  const TriangleMesh off = BoxMesh(Vec3(-8.8, -9.5, 25), Vec3(10.2, 9.5, 55));
  const auto first = Sweep(off, Tube(), Vec3(0, 0, -2), 0.0, 30.0, false, X);
  ASSERT_TRUE(first);
  EXPECT_NEAR(first->t, 2.5, kTol);
  const auto last = Sweep(off, Tube(), Vec3(0, 0, -2), 0.0, 30.0, true, X);
  ASSERT_TRUE(last);
  EXPECT_NEAR(last->t, 27.5, kTol);
  const TriangleMesh centred = BoxMesh(Vec3(-9.5, -9.5, 25), Vec3(9.5, 9.5, 55));
  EXPECT_FALSE(Sweep(centred, Tube(), Vec3(0, 0, -2), 0.0, 30.0, false, X));
}

TEST(SweepContact, ThinWallIsNotSteppedOver) {
  // A 0.05-thick sheet, wider than the wall, crossing a 0.08-thick wall: their surfaces cross
  // only for t in [10.05, 10.18], between two stations of a 0.2 grid from 0 (10.0, 10.2).
  const TriangleMesh sheet = BoxMesh(Vec3(0, 0, 0), Vec3(0.05, 3, 1));
  const TriangleMesh wall = BoxMesh(Vec3(10.1, -1, -1), Vec3(10.18, 2, 2));
  const auto first = Sweep(sheet, wall, Vec3::UnitX(), 0.0, 30.0, false);
  ASSERT_TRUE(first);
  EXPECT_NEAR(first->t, 10.05, kTol);
  const auto last = Sweep(sheet, wall, Vec3::UnitX(), 0.0, 30.0, true);
  ASSERT_TRUE(last);
  EXPECT_NEAR(last->t, 10.18, kTol);
}

TEST(SweepContact, OnlySurfacesMeet) {
  // A box wholly inside another for every t of the range meets no surface (documented: the
  // callers start outside).
  const TriangleMesh inner = BoxMesh(Vec3(1, 1, 1), Vec3(2, 2, 2));
  const TriangleMesh outer = BoxMesh(Vec3(0, 0, 0), Vec3(10, 3, 3));
  EXPECT_FALSE(Sweep(inner, outer, Vec3::UnitX(), 0.0, 7.0, false));
  const auto out = Sweep(inner, outer, Vec3::UnitX(), 0.0, 20.0, false);
  ASSERT_TRUE(out);
  EXPECT_NEAR(out->t, 8.0, kTol);  // its face x = 2 reaches the outer face x = 10
}

TEST(SweepMesh, BoxIsInTheGivenFrame) {
  Iso3 X = Iso3::Identity();
  X.translation() = Vec3(1, 2, 3);
  const SweepMesh m(BoxMesh(Vec3(0, 0, 0), Vec3(1, 1, 1)), X);
  EXPECT_EQ(m.num_triangles(), 12);
  EXPECT_TRUE(m.box().min.isApprox(Vec3(1, 2, 3)));
  EXPECT_TRUE(m.box().max.isApprox(Vec3(2, 3, 4)));
  EXPECT_TRUE(SweepMesh(TriangleMesh{}, X).empty());
}

}  // namespace
}  // namespace wrap
