// Tests of the mesh data, its topology checks, mass properties and the mesh writers.
#include "geometry/mesh.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Eigenvalues>

#include <bit>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "core/file_io.h"
#include "geometry/mesh_export.h"
#include "test_meshes.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;
using test_meshes::Flipped;
using test_meshes::MakeBox;
using test_meshes::MakeCylinder;

/// Expects two matrices equal to within `tol` in every entry, printing both on failure.
void ExpectNear(const Mat3& actual, const Mat3& expected, double tol) {
  EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), tol) << "actual:\n"
                                                            << actual << "\nexpected:\n"
                                                            << expected;
}

void ExpectNear(const Vec3& actual, const Vec3& expected, double tol) {
  EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), tol)
      << "actual: " << actual.transpose() << "\nexpected: " << expected.transpose();
}

/// A rotation about an oblique axis and a translation far from the origin.
Iso3 SomeRigidTransform() {
  Iso3 X = Iso3::Identity();
  X.linear() = RotationFromRpy(Vec3(0.3, -0.5, 1.2));
  X.translation() = Vec3(1.5, -2.0, 0.75);
  return X;
}

TEST(MeshTest, AabbOfBoxAndEmptyMesh) {
  const Aabb box = ComputeAabb(MakeBox(Vec3(-1, -2, -3), Vec3(4, 5, 6)));
  ExpectNear(box.min, Vec3(-1, -2, -3), 0.0);
  ExpectNear(box.max, Vec3(4, 5, 6), 0.0);
  ExpectNear(box.size(), Vec3(5, 7, 9), 0.0);

  const Aabb empty = ComputeAabb(TriangleMesh{});
  ExpectNear(empty.min, Vec3::Zero(), 0.0);
  ExpectNear(empty.max, Vec3::Zero(), 0.0);
}

TEST(MeshTest, SurfaceAreaOfBox) {
  const double a = 0.2, b = 0.3, c = 0.5;
  EXPECT_NEAR(SurfaceArea(MakeBox(Vec3(a, b, c))), 2 * (a * b + b * c + c * a), 1e-15);
  EXPECT_EQ(SurfaceArea(TriangleMesh{}), 0.0);
}

TEST(MeshTest, BoxMassProperties) {
  const double a = 0.2, b = 0.3, c = 0.5;
  const MassProperties mp = ComputeMassProperties(MakeBox(Vec3(a, b, c)));
  const double m = a * b * c;  // unit density
  EXPECT_NEAR(mp.volume_m3, m, 1e-16);
  ExpectNear(mp.com, Vec3(a / 2, b / 2, c / 2), 1e-15);
  const Mat3 expected =
      Vec3(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12)
          .asDiagonal();
  ExpectNear(mp.inertia_com, expected, 1e-16);
}

TEST(MeshTest, BoxMassPropertiesFollowRigidTransform) {
  const TriangleMesh box = MakeBox(Vec3(0.2, 0.3, 0.5));
  const MassProperties local = ComputeMassProperties(box);
  const Iso3 X = SomeRigidTransform();
  const MassProperties moved = ComputeMassProperties(Transformed(box, X));
  const Mat3& R = X.linear();
  EXPECT_NEAR(moved.volume_m3, local.volume_m3, 1e-15);
  ExpectNear(moved.com, X * local.com, 1e-14);
  ExpectNear(moved.inertia_com, R * local.inertia_com * R.transpose(), 1e-15);
  // Still a rotated box: off-diagonal products of inertia appear, eigenvalues stay.
  EXPECT_GT(std::abs(moved.inertia_com(0, 1)), 1e-6);
  Eigen::SelfAdjointEigenSolver<Mat3> eig(moved.inertia_com);
  Eigen::SelfAdjointEigenSolver<Mat3> eig0(local.inertia_com);
  ExpectNear(eig.eigenvalues(), eig0.eigenvalues(), 1e-15);
}

TEST(MeshTest, CylinderMassPropertiesMatchPolygonAndCircle) {
  const double r = 0.04, h = 0.1;
  const int n = 256;
  const MassProperties mp = ComputeMassProperties(MakeCylinder(r, h, n));

  // Exact values for the prism over the inscribed regular n-gon: area A = n r^2 sin(t) / 2 and
  // polar second moment J = n r^4 sin(t) (2 + cos(t)) / 12 with t = 2 pi / n.
  const double t = 2 * std::numbers::pi / n;
  const double A = n * r * r * std::sin(t) / 2;
  const double J = n * r * r * r * r * std::sin(t) * (2 + std::cos(t)) / 12;
  const double V = A * h;
  EXPECT_NEAR(mp.volume_m3, V, 1e-12 * V);
  ExpectNear(mp.com, Vec3::Zero(), 1e-15);
  const Mat3 polygon =
      Vec3(h * J / 2 + V * h * h / 12, h * J / 2 + V * h * h / 12, h * J).asDiagonal();
  ExpectNear(mp.inertia_com, polygon, 1e-12 * polygon.maxCoeff());

  // The circle: the polygon misses a relative area of 1 - sin(t)/t ~ t^2/6 (1e-4 for n = 256)
  // and a relative polar moment of about 2 t^2 / 3 (4e-4); allow 1.5 times that.
  const double Vc = std::numbers::pi * r * r * h;
  const double rel_area = t * t / 6, rel_polar = 2 * t * t / 3;
  EXPECT_NEAR(mp.volume_m3, Vc, 1.5 * rel_area * Vc);
  EXPECT_LT(mp.volume_m3, Vc);  // inscribed
  const double Ixx = Vc * (3 * r * r + h * h) / 12, Izz = Vc * r * r / 2;
  EXPECT_NEAR(mp.inertia_com(0, 0), Ixx, 1.5 * rel_polar * Ixx);
  EXPECT_NEAR(mp.inertia_com(1, 1), Ixx, 1.5 * rel_polar * Ixx);
  EXPECT_NEAR(mp.inertia_com(2, 2), Izz, 1.5 * rel_polar * Izz);
  EXPECT_NEAR(mp.inertia_com(0, 1), 0.0, 1e-12 * Izz);
  EXPECT_NEAR(mp.inertia_com(0, 2), 0.0, 1e-12 * Izz);
  EXPECT_NEAR(mp.inertia_com(1, 2), 0.0, 1e-12 * Izz);
}

TEST(MeshTest, CylinderMassPropertiesFollowRigidTransformFarFromOrigin) {
  const TriangleMesh cyl = MakeCylinder(0.04, 0.1, 256);
  const MassProperties local = ComputeMassProperties(cyl);
  Iso3 X = SomeRigidTransform();
  X.translation() = Vec3(25.0, -40.0, 10.0);  // tens of metres: tests the numerics
  const MassProperties moved = ComputeMassProperties(Transformed(cyl, X));
  const Mat3& R = X.linear();
  EXPECT_NEAR(moved.volume_m3, local.volume_m3, 1e-12 * local.volume_m3);
  ExpectNear(moved.com, X.translation(), 1e-12);
  ExpectNear(moved.inertia_com, R * local.inertia_com * R.transpose(),
             1e-10 * local.inertia_com.maxCoeff());
}

TEST(MeshTest, InwardMeshHasNegativeVolume) {
  const TriangleMesh box = MakeBox(Vec3(1, 2, 3), Vec3(1.2, 2.3, 3.5));
  const MassProperties out = ComputeMassProperties(box);
  const MassProperties in = ComputeMassProperties(Flipped(box));
  EXPECT_NEAR(out.volume_m3, 0.2 * 0.3 * 0.5, 1e-14);
  EXPECT_NEAR(in.volume_m3, -out.volume_m3, 1e-14);
  ExpectNear(in.com, out.com, 1e-13);
  ExpectNear(in.inertia_com, -out.inertia_com, 1e-15);
}

TEST(MeshTest, OpenSheetHasNoVolumeAndFiniteResult) {
  TriangleMesh sheet;
  sheet.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  sheet.triangles = {Eigen::Vector3i(0, 1, 2)};
  const MassProperties mp = ComputeMassProperties(sheet);
  EXPECT_EQ(mp.volume_m3, 0.0);
  EXPECT_TRUE(mp.com.allFinite());
  EXPECT_TRUE(mp.inertia_com.isZero());
  const MassProperties none = ComputeMassProperties(TriangleMesh{});
  EXPECT_EQ(none.volume_m3, 0.0);
}

TEST(MeshTest, TopologyOfClosedBox) {
  const MeshTopology topo = AnalyzeTopology(MakeBox(Vec3(1, 1, 1)));
  EXPECT_EQ(topo.boundary_edges, 0);
  EXPECT_EQ(topo.non_manifold_edges, 0);
  EXPECT_EQ(topo.degenerate_triangles, 0);
  EXPECT_TRUE(topo.closed());
  EXPECT_TRUE(AnalyzeTopology(MakeCylinder(1, 1, 16)).closed());
}

TEST(MeshTest, TopologyOfBoxMissingAFace) {
  TriangleMesh box = MakeBox(Vec3(1, 1, 1));
  box.triangles.resize(10);  // drop the two triangles of the last face
  const MeshTopology topo = AnalyzeTopology(box);
  EXPECT_EQ(topo.boundary_edges, 4);
  EXPECT_EQ(topo.non_manifold_edges, 0);
  EXPECT_FALSE(topo.closed());
}

TEST(MeshTest, TopologyCountsNonManifoldAndDegenerate) {
  TriangleMesh box = MakeBox(Vec3(1, 1, 1));
  // A fin on the diagonal edge (0, 3) of the bottom face: that edge is now used three times.
  box.vertices.emplace_back(0.5, 0.5, -1.0);  // 8
  box.triangles.emplace_back(0, 3, 8);
  // A sliver: vertex 9 lies on the edge from vertex 0 to vertex 1.
  box.vertices.emplace_back(0.5, 0.0, 0.0);  // 9
  box.triangles.emplace_back(0, 1, 9);
  // A triangle with a repeated corner.
  box.triangles.emplace_back(2, 2, 5);
  const MeshTopology topo = AnalyzeTopology(box);
  EXPECT_EQ(topo.degenerate_triangles, 2);
  EXPECT_EQ(topo.non_manifold_edges, 2);  // (0,3) by the fin, (0,1) by the sliver
  // The fin's two free edges, and the sliver's two half edges.
  EXPECT_EQ(topo.boundary_edges, 4);
  EXPECT_FALSE(topo.closed());
}

TEST(MeshTest, DegenerateThresholdIsAnArea) {
  TriangleMesh tiny;
  tiny.vertices = {Vec3(0, 0, 0), Vec3(1e-4, 0, 0), Vec3(0, 1e-4, 0)};  // area 5e-9 m^2
  tiny.triangles = {Eigen::Vector3i(0, 1, 2)};
  EXPECT_EQ(AnalyzeTopology(tiny).degenerate_triangles, 0);
  EXPECT_EQ(AnalyzeTopology(tiny, 1e-8).degenerate_triangles, 1);
}

TEST(MeshTest, TransformedMovesVerticesKeepsTriangles) {
  const TriangleMesh box = MakeBox(Vec3(1, 2, 3));
  const Iso3 X = SomeRigidTransform();
  const TriangleMesh moved = Transformed(box, X);
  ASSERT_EQ(moved.vertices.size(), box.vertices.size());
  EXPECT_EQ(moved.triangles, box.triangles);
  for (size_t i = 0; i < box.vertices.size(); ++i) {
    ExpectNear(moved.vertices[i], X * box.vertices[i], 1e-15);
  }
  EXPECT_NEAR(SurfaceArea(moved), SurfaceArea(box), 1e-13);
}

/// A fresh folder under the test temporary directory, removed at the end of the test.
class MeshExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("wrap_mesh_export_" + std::to_string(::getpid()) +
                                             "_" + info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Read(const fs::path& path) {
    Result<std::string> text = ReadFile(path);
    EXPECT_TRUE(text.has_value()) << text.error().message;
    return text.value_or("");
  }

  fs::path dir_;
};

TEST_F(MeshExportTest, BinaryStlLayout) {
  const TriangleMesh box = MakeBox(Vec3(0.01, 0.02, 0.03));
  ASSERT_TRUE(WriteStl(dir_ / "box.stl", box, 1000.0).has_value());
  const std::string bytes = Read(dir_ / "box.stl");
  ASSERT_EQ(bytes.size(), 84u + 50u * 12u);
  EXPECT_NE(bytes.substr(0, 5), "solid");  // or readers take it for ASCII
  EXPECT_NE(bytes.substr(0, 80).find("wrap"), std::string::npos);
  auto u32 = [&](size_t at) {
    uint32_t v = 0;
    for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  auto f32 = [&](size_t at) { return std::bit_cast<float>(u32(at)); };
  EXPECT_EQ(u32(80), 12u);
  // First triangle: (0, 2, 3) of the bottom face, normal -z, coordinates in mm.
  EXPECT_EQ(f32(84), 0.0f);
  EXPECT_EQ(f32(88), 0.0f);
  EXPECT_EQ(f32(92), -1.0f);
  EXPECT_EQ(f32(96 + 12 + 4), 20.0f);  // vertex 2 = (0, 20, 0) mm
  EXPECT_EQ(f32(96 + 24), 10.0f);      // vertex 3 = (10, 20, 0) mm
}

TEST_F(MeshExportTest, ObjLayout) {
  TriangleMesh tri;
  tri.vertices = {Vec3(0, 0, 0), Vec3(0.001, -0.0000001, 0), Vec3(0, 1.5, -2.25)};
  tri.triangles = {Eigen::Vector3i(0, 1, 2)};
  ASSERT_TRUE(WriteObj(dir_ / "t.obj", tri).has_value());
  EXPECT_EQ(Read(dir_ / "t.obj"),
            "# generated by wrap\n"
            "v 0.000000 0.000000 0.000000\n"
            "v 0.001000 0.000000 0.000000\n"
            "v 0.000000 1.500000 -2.250000\n"
            "f 1 2 3\n");
}

TEST_F(MeshExportTest, PlyAndOffLayout) {
  TriangleMesh tri;
  tri.vertices = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0, 0.25, -1)};
  tri.triangles = {Eigen::Vector3i(0, 1, 2)};
  ASSERT_TRUE(WriteOff(dir_ / "t.off", tri, 10.0).has_value());
  EXPECT_EQ(Read(dir_ / "t.off"), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 2.5 -10\n3 0 1 2\n");
  ASSERT_TRUE(WritePly(dir_ / "t.ply", tri).has_value());
  const std::string ply = Read(dir_ / "t.ply");
  EXPECT_EQ(ply.rfind("ply\nformat ascii 1.0\n", 0), 0u);
  EXPECT_NE(ply.find("element vertex 3\n"), std::string::npos);
  EXPECT_NE(ply.find("element face 1\n"), std::string::npos);
  EXPECT_NE(ply.find("end_header\n0 0 0\n0.1 0 0\n0 0.25 -1\n3 0 1 2\n"), std::string::npos);
}

TEST_F(MeshExportTest, OutputIsByteDeterministic) {
  const TriangleMesh cyl = MakeCylinder(0.03, 0.07, 40);
  const auto write_all = [&](const fs::path& sub) {
    fs::create_directories(dir_ / sub);
    ASSERT_TRUE(WriteStl(dir_ / sub / "m.stl", cyl).has_value());
    ASSERT_TRUE(WriteObj(dir_ / sub / "m.obj", cyl).has_value());
    ASSERT_TRUE(WritePly(dir_ / sub / "m.ply", cyl).has_value());
    ASSERT_TRUE(WriteOff(dir_ / sub / "m.off", cyl).has_value());
  };
  write_all("a");
  write_all("b");
  for (const char* name : {"m.stl", "m.obj", "m.ply", "m.off"}) {
    const std::string a = Read(dir_ / "a" / name);
    EXPECT_FALSE(a.empty()) << name;
    EXPECT_EQ(a, Read(dir_ / "b" / name)) << name;
  }
}

TEST_F(MeshExportTest, RejectsBadIndexAndScale) {
  TriangleMesh bad = MakeBox(Vec3(1, 1, 1));
  bad.triangles.emplace_back(0, 1, 8);
  for (auto* write : {&WriteStl, &WriteObj, &WritePly, &WriteOff}) {
    const Result<void> r = write(dir_ / "bad", bad, 1.0);
    ASSERT_FALSE(r.has_value());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
    EXPECT_NE(r.error().message.find("vertex 8"), std::string::npos) << r.error().message;
    const Result<void> s = write(dir_ / "bad", MakeBox(Vec3(1, 1, 1)), 0.0);
    ASSERT_FALSE(s.has_value());
    EXPECT_EQ(s.error().code, ErrorCode::kInvalidInput);
    EXPECT_NE(s.error().message.find("scale"), std::string::npos) << s.error().message;
  }
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

TEST_F(MeshExportTest, UnwritableFolderIsIoError) {
  const Result<void> r = WriteObj(dir_ / "no" / "such" / "dir" / "m.obj", MakeBox(Vec3(1, 1, 1)));
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kIo);
}

}  // namespace
}  // namespace wrap
