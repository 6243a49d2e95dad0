// Tests of ImportMesh: every format from small files written in the test, errors, a real mesh.
#include "geometry/mesh_import.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/file_io.h"
#include "geometry/mesh_export.h"
#include "test_meshes.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;
using test_meshes::MakeBox;

constexpr double kMm = 0.001;  // the scale of a file in millimetres

/// Each test gets a fresh folder under the test temporary directory, removed afterwards.
class MeshImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("wrap_mesh_import_" + std::to_string(::getpid()) +
                                             "_" + info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Writes `contents` to `name` in the test folder and returns its path.
  fs::path Write(const std::string& name, const std::string& contents) {
    const fs::path path = dir_ / name;
    EXPECT_TRUE(WriteFileAtomic(path, contents).has_value());
    return path;
  }

  fs::path dir_;
};

/// Checks that `mesh` is a closed box from `lo` to `hi` [m] with 8 welded vertices.
/// `tol` bounds the corner error [m], `volume_rel` the relative volume error.
void ExpectBox(const Result<TriangleMesh>& mesh, const Vec3& lo, const Vec3& hi, double tol,
               double volume_rel = 1e-6) {
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
  EXPECT_EQ(mesh->triangles.size(), 12u);
  EXPECT_EQ(mesh->vertices.size(), 8u);
  EXPECT_TRUE(AnalyzeTopology(*mesh).closed());
  const Aabb box = ComputeAabb(*mesh);
  EXPECT_LE((box.min - lo).cwiseAbs().maxCoeff(), tol) << box.min.transpose();
  EXPECT_LE((box.max - hi).cwiseAbs().maxCoeff(), tol) << box.max.transpose();
  const Vec3 size = hi - lo;
  const double volume = size.prod();
  EXPECT_NEAR(ComputeMassProperties(*mesh).volume_m3, volume, volume_rel * volume);
}

/// Expects a failure with `code` whose message names `path` and contains `phrase`.
void ExpectError(const Result<TriangleMesh>& mesh, ErrorCode code, const fs::path& path,
                 const std::string& phrase) {
  ASSERT_FALSE(mesh.has_value()) << path;
  EXPECT_EQ(mesh.error().code, code) << mesh.error().message;
  EXPECT_NE(mesh.error().message.find(path.string()), std::string::npos) << mesh.error().message;
  EXPECT_NE(mesh.error().message.find(phrase), std::string::npos) << mesh.error().message;
}

// A box of 20 x 30 x 40 mm, away from the origin, in millimetres and in metres.
const Vec3 kLoMm(10, -20, 5), kHiMm(30, 10, 45);
const Vec3 kLo = kLoMm * kMm, kHi = kHiMm * kMm;

TEST_F(MeshImportTest, BinaryStlInMillimetres) {
  // Binary STL repeats every corner per triangle: 36 corners weld back to 8 vertices.
  ASSERT_TRUE(WriteStl(dir_ / "box.stl", MakeBox(kLo, kHi), 1000.0).has_value());
  ExpectBox(ImportMesh(dir_ / "box.stl", {.scale = kMm}), kLo, kHi, 1e-9);
  ExpectBox(ImportMesh(dir_ / "box.stl"), kLoMm, kHiMm, 1e-6);
}

TEST_F(MeshImportTest, AsciiStl) {
  const TriangleMesh box = MakeBox(kLoMm, kHiMm);
  std::string text = "solid box\n";
  for (const Eigen::Vector3i& t : box.triangles) {
    text += " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const Vec3& v = box.vertices[static_cast<size_t>(t[k])];
      text += "   vertex " + std::to_string(v.x()) + " " + std::to_string(v.y()) + " " +
              std::to_string(v.z()) + "\n";
    }
    text += "  endloop\n endfacet\n";
  }
  text += "endsolid box\n";
  ExpectBox(ImportMesh(Write("box_ascii.stl", text), {.scale = kMm}), kLo, kHi, 1e-9);
}

TEST_F(MeshImportTest, ObjFromWriter) {
  ASSERT_TRUE(WriteObj(dir_ / "box.obj", MakeBox(kLo, kHi), 1000.0).has_value());
  ExpectBox(ImportMesh(dir_ / "box.obj", {.scale = kMm}), kLo, kHi, 1e-9);
}

TEST_F(MeshImportTest, ObjWithQuadsIsTriangulated) {
  // A unit cube of six counter-clockwise quads, with normals and two objects.
  const std::string text =
      "# quads\n"
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "vn 0 0 -1\nvn 0 0 1\n"
      "o bottom_top\n"
      "f 1//1 4//1 3//1 2//1\nf 5//2 6//2 7//2 8//2\n"
      "o sides\n"
      "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  ExpectBox(ImportMesh(Write("quads.obj", text), {.scale = 0.05}), Vec3::Zero(),
            Vec3(0.05, 0.05, 0.05), 1e-12);
}

TEST_F(MeshImportTest, PlyFromWriter) {
  ASSERT_TRUE(WritePly(dir_ / "box.ply", MakeBox(kLo, kHi), 1000.0).has_value());
  ExpectBox(ImportMesh(dir_ / "box.ply", {.scale = kMm}), kLo, kHi, 1e-9);
}

TEST_F(MeshImportTest, OffFromWriter) {
  ASSERT_TRUE(WriteOff(dir_ / "box.off", MakeBox(kLo, kHi), 1000.0).has_value());
  ExpectBox(ImportMesh(dir_ / "box.off", {.scale = kMm}), kLo, kHi, 1e-9);
}

/// Standard base64 (RFC 4648) with padding.
std::string Base64(const std::string& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t chunk = 0;
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    for (size_t k = 0; k < 3; ++k) {
      chunk = (chunk << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    }
    for (size_t k = 0; k < 4; ++k) {
      out += k <= n ? kAlphabet[(chunk >> (18 - 6 * k)) & 63u] : '=';
    }
  }
  return out;
}

/// A glTF 2.0 file with the box from (-5, -10, -15) to (5, 10, 15) as mesh 0 in an embedded
/// base64 buffer, and the given node list (root node 0).
std::string CubeGltf(const std::string& nodes_json) {
  const TriangleMesh box = MakeBox(Vec3(-5, -10, -15), Vec3(5, 10, 15));
  std::string buffer;
  for (const Vec3& v : box.vertices) {
    for (int k = 0; k < 3; ++k) {
      const float f = static_cast<float>(v[k]);
      buffer.append(reinterpret_cast<const char*>(&f), sizeof f);  // little-endian hosts only
    }
  }
  for (const Eigen::Vector3i& t : box.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto i = static_cast<uint16_t>(t[k]);
      buffer.append(reinterpret_cast<const char*>(&i), sizeof i);
    }
  }
  return R"({"asset": {"version": "2.0", "generator": "wrap test"},
  "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": )" +
         nodes_json + R"(,
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
  "buffers": [{"byteLength": 168, "uri": "data:application/octet-stream;base64,)" +
         Base64(buffer) + R"("}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96, "target": 34962},
                  {"buffer": 0, "byteOffset": 96, "byteLength": 72, "target": 34963}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
                 "min": [-5, -10, -15], "max": [5, 10, 15]},
                {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}]}
)";
}

TEST(Base64Test, KnownVectors) {
  EXPECT_EQ(Base64(""), "");
  EXPECT_EQ(Base64("f"), "Zg==");
  EXPECT_EQ(Base64("fo"), "Zm8=");
  EXPECT_EQ(Base64("foo"), "Zm9v");
  EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
}

TEST_F(MeshImportTest, GltfNodeHierarchyIsApplied) {
  // Root "assembly" lifted by 10 mm; child a moved by +5 mm in x; child b instancing the same
  // mesh, turned 90 degrees about z and moved by -50 mm in x.
  const std::string nodes = R"([
    {"name": "assembly", "translation": [0, 0, 10], "children": [1, 2]},
    {"name": "a", "mesh": 0, "translation": [5, 0, 0]},
    {"name": "b", "mesh": 0, "translation": [-50, 0, 0],
     "rotation": [0, 0, 0.7071067811865476, 0.7071067811865476]}])";
  const Result<TriangleMesh> mesh =
      ImportMesh(Write("cubes.gltf", CubeGltf(nodes)), {.scale = kMm});
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
  EXPECT_EQ(mesh->triangles.size(), 24u);
  EXPECT_EQ(mesh->vertices.size(), 16u);
  EXPECT_TRUE(AnalyzeTopology(*mesh).closed());
  const Aabb box = ComputeAabb(*mesh);
  EXPECT_LE((box.min - Vec3(-60, -10, -5) * kMm).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LE((box.max - Vec3(10, 10, 25) * kMm).cwiseAbs().maxCoeff(), 1e-9);
  const double volume = 2 * 10 * 20 * 30 * kMm * kMm * kMm;
  EXPECT_NEAR(ComputeMassProperties(*mesh).volume_m3, volume, 1e-6 * volume);
}

TEST_F(MeshImportTest, MirroringNodeKeepsOutwardOrientation) {
  const std::string nodes = R"([{"mesh": 0, "scale": [-1, 1, 1], "translation": [100, 0, 0]}])";
  const Result<TriangleMesh> mesh = ImportMesh(Write("mirror.gltf", CubeGltf(nodes)));
  ExpectBox(mesh, Vec3(95, -10, -15), Vec3(105, 10, 15), 1e-9);
}

/// Turns a mesh in a file into an assimp scene whose root node holds transform `X`, for the
/// exporter tests.
std::unique_ptr<aiScene> SceneWithRootTransform(const fs::path& obj, const Iso3& X) {
  Assimp::Importer importer;
  if (importer.ReadFile(obj.string(), aiProcess_Triangulate) == nullptr) return nullptr;
  std::unique_ptr<aiScene> scene(importer.GetOrphanedScene());
  const Eigen::Matrix4d M = X.matrix();
  aiMatrix4x4& T = scene->mRootNode->mTransformation;
  T = aiMatrix4x4(M(0, 0), M(0, 1), M(0, 2), M(0, 3), M(1, 0), M(1, 1), M(1, 2), M(1, 3), M(2, 0),
                  M(2, 1), M(2, 2), M(2, 3), 0, 0, 0, 1);
  return scene;
}

/// Exports `scene` with assimp's exporter `format_id` to `path`.
::testing::AssertionResult Export(const aiScene& scene, const char* format_id,
                                  const fs::path& path) {
  Assimp::Exporter exporter;
  if (exporter.Export(&scene, format_id, path.string()) != aiReturn_SUCCESS) {
    return ::testing::AssertionFailure()
           << "assimp export '" << format_id << "' failed: " << exporter.GetErrorString();
  }
  return ::testing::AssertionSuccess();
}

/// The 20 x 30 x 40 mm box turned 90 degrees about z and moved, in mm, as the exporters see it.
class ExportedSceneTest : public MeshImportTest {
 protected:
  void SetUp() override {
    MeshImportTest::SetUp();
    ASSERT_TRUE(WriteObj(dir_ / "box.obj", MakeBox(kLoMm, kHiMm)).has_value());
    X_.linear() = Eigen::AngleAxisd(0.5 * std::numbers::pi, Vec3::UnitZ()).toRotationMatrix();
    X_.translation() = Vec3(100, 200, 300);
    scene_ = SceneWithRootTransform(dir_ / "box.obj", X_);
    ASSERT_NE(scene_, nullptr);
    plain_ = SceneWithRootTransform(dir_ / "box.obj", Iso3::Identity());
    ASSERT_NE(plain_, nullptr);
    // (x, y) -> (-y, x), then the translation.
    lo_ = (Vec3(-kHiMm.y(), kLoMm.x(), kLoMm.z()) + X_.translation()) * kMm;
    hi_ = (Vec3(-kLoMm.y(), kHiMm.x(), kHiMm.z()) + X_.translation()) * kMm;
  }

  Iso3 X_ = Iso3::Identity();
  std::unique_ptr<aiScene> scene_, plain_;
  Vec3 lo_ = Vec3::Zero(), hi_ = Vec3::Zero();
};

TEST(AssimpExporterTest, FormatsUsedByTheseTestsExist) {
  Assimp::Exporter exporter;
  std::vector<std::string> ids;
  for (size_t i = 0; i < exporter.GetExportFormatCount(); ++i) {
    ids.emplace_back(exporter.GetExportFormatDescription(i)->id);
  }
  for (const char* id : {"collada", "glb2", "gltf2", "3mf", "stlb", "obj"}) {
    EXPECT_NE(std::find(ids.begin(), ids.end(), id), ids.end()) << id;
  }
}

TEST_F(ExportedSceneTest, Glb) {
  ASSERT_TRUE(Export(*scene_, "glb2", dir_ / "box.glb"));
  ExpectBox(ImportMesh(dir_ / "box.glb", {.scale = kMm}), lo_, hi_, 1e-9);
}

TEST_F(ExportedSceneTest, GltfWithSeparateBuffer) {
  ASSERT_TRUE(Export(*scene_, "gltf2", dir_ / "box.gltf"));
  ExpectBox(ImportMesh(dir_ / "box.gltf", {.scale = kMm}), lo_, hi_, 1e-9);
}

TEST_F(ExportedSceneTest, Collada) {
  ASSERT_TRUE(Export(*scene_, "collada", dir_ / "box.dae"));
  ExpectBox(ImportMesh(dir_ / "box.dae", {.scale = kMm}), lo_, hi_, 1e-9);
}

TEST_F(ExportedSceneTest, ColladaUnitIsAppliedAndUpAxisIgnored) {
  ASSERT_TRUE(Export(*plain_, "collada", dir_ / "box.dae"));
  Result<std::string> text = ReadFile(dir_ / "box.dae");
  ASSERT_TRUE(text.has_value());
  // Declare the file in millimetres and Z-up: assimp scales by the unit itself; we keep the
  // coordinates as written instead of turning Z-up into Y-up.
  const std::pair<std::string, std::string> edits[] = {
      {"meter=\"1\"", "meter=\"0.001\""}, {"<up_axis>Y_UP</up_axis>", "<up_axis>Z_UP</up_axis>"}};
  for (const auto& [from, to] : edits) {
    const size_t at = text->find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text->replace(at, from.size(), to);
  }
  // assimp applies the unit in single precision: 5e-8 relative.
  ExpectBox(ImportMesh(Write("box_mm_zup.dae", *text)), kLo, kHi, 1e-8);
}

TEST_F(ExportedSceneTest, ThreeMf) {
  // assimp 5.2's 3MF exporter drops node transforms (its importer does read build-item
  // transforms), so this round trip is of the plain box.
  ASSERT_TRUE(Export(*plain_, "3mf", dir_ / "box.3mf"));
  ExpectBox(ImportMesh(dir_ / "box.3mf", {.scale = kMm}), kLo, kHi, 1e-9);
}

TEST_F(ExportedSceneTest, DamagedThreeMfFailsInsteadOfAborting) {
  // Renaming the model part inside the zip (same length: offsets and CRCs stay valid) trips an
  // internal check of assimp's 3MF reader, which Debian's build turns into an abort().
  ASSERT_TRUE(Export(*plain_, "3mf", dir_ / "box.3mf"));
  Result<std::string> zip = ReadFile(dir_ / "box.3mf");
  ASSERT_TRUE(zip.has_value());
  const std::string part = "3D/3DModel.model";
  int renamed = 0;
  for (size_t at = zip->find(part); at != std::string::npos; at = zip->find(part, at)) {
    zip->replace(at, part.size(), "3D/3DModel.modeX");
    ++renamed;
  }
  ASSERT_GE(renamed, 2);  // local header and central directory
  ExpectError(ImportMesh(Write("damaged.3mf", *zip)), ErrorCode::kInvalidInput,
              dir_ / "damaged.3mf", "cannot read");
}

TEST_F(ExportedSceneTest, ColladaWithControlCharacterIsRejected) {
  // assimp 5.2 loops for ever on some of these (seen: byte 0x18 inside a <p> index list).
  ASSERT_TRUE(Export(*plain_, "collada", dir_ / "box.dae"));
  Result<std::string> text = ReadFile(dir_ / "box.dae");
  ASSERT_TRUE(text.has_value());
  const size_t at = text->find("<p>");
  ASSERT_NE(at, std::string::npos);
  (*text)[at + 4] = '\x18';
  ExpectError(ImportMesh(Write("damaged.dae", *text)), ErrorCode::kInvalidInput,
              dir_ / "damaged.dae", "control character");
}

TEST_F(ExportedSceneTest, ColladaWithLetterInIndexListIsRejected) {
  // assimp 5.2 loops for ever on this one.
  ASSERT_TRUE(Export(*plain_, "collada", dir_ / "box.dae"));
  Result<std::string> text = ReadFile(dir_ / "box.dae");
  ASSERT_TRUE(text.has_value());
  const size_t at = text->find("<p>");
  ASSERT_NE(at, std::string::npos);
  const size_t space = text->find(' ', at + 4);
  ASSERT_NE(space, std::string::npos);
  (*text)[space] = 'T';
  ExpectError(ImportMesh(Write("damaged.dae", *text)), ErrorCode::kInvalidInput,
              dir_ / "damaged.dae", "index list");
}

TEST_F(ExportedSceneTest, GlbWithWrongChunkLengthIsRejected) {
  // One flipped bit in the JSON chunk length made assimp allocate 1.3 GB before failing.
  ASSERT_TRUE(Export(*plain_, "glb2", dir_ / "box.glb"));
  Result<std::string> bytes = ReadFile(dir_ / "box.glb");
  ASSERT_TRUE(bytes.has_value());
  ASSERT_GT(bytes->size(), 20u);
  (*bytes)[15] = '\x4d';
  ExpectError(ImportMesh(Write("damaged.glb", *bytes)), ErrorCode::kInvalidInput,
              dir_ / "damaged.glb", "GLB header");
  // Cut short: the header claims more than there is.
  ASSERT_TRUE(Export(*plain_, "glb2", dir_ / "box.glb"));
  bytes = ReadFile(dir_ / "box.glb");
  ASSERT_TRUE(bytes.has_value());
  ExpectError(ImportMesh(Write("short.glb", bytes->substr(0, bytes->size() / 2))),
              ErrorCode::kInvalidInput, dir_ / "short.glb", "GLB header");
}

TEST_F(MeshImportTest, OffWithHugeCountIsRejected) {
  ASSERT_TRUE(WriteOff(dir_ / "box.off", MakeBox(kLo, kHi)).has_value());
  Result<std::string> text = ReadFile(dir_ / "box.off");
  ASSERT_TRUE(text.has_value());
  ASSERT_TRUE(text->starts_with("OFF\n8 12 0\n"));
  text->replace(4, 4, "8 12999999");
  ExpectError(ImportMesh(Write("many.off", *text)), ErrorCode::kInvalidInput, dir_ / "many.off",
              "faces");
}

TEST_F(MeshImportTest, SpecialFileIsIoError) {
  ExpectError(ImportMesh("/dev/zero"), ErrorCode::kIo, "/dev/zero", "not a regular file");
}

TEST_F(MeshImportTest, PlyWithoutEndHeaderIsRejected) {
  // assimp 5.2 loops for ever on a PLY header cut short (a truncated download).
  ASSERT_TRUE(WritePly(dir_ / "box.ply", MakeBox(kLo, kHi)).has_value());
  Result<std::string> text = ReadFile(dir_ / "box.ply");
  ASSERT_TRUE(text.has_value());
  const size_t end = text->find("end_header");
  ASSERT_NE(end, std::string::npos);
  for (const size_t keep : {size_t{5}, size_t{30}, end, end + 5}) {
    const std::string name = "cut" + std::to_string(keep) + ".ply";
    ExpectError(ImportMesh(Write(name, text->substr(0, keep))), ErrorCode::kInvalidInput,
                dir_ / name, "end_header");
  }
  // A face count with extra digits: assimp 5.2 would grind for minutes.
  std::string many = *text;
  const size_t faces = many.find("element face 12");
  ASSERT_NE(faces, std::string::npos);
  many.insert(faces + 15, "88888");
  ExpectError(ImportMesh(Write("many.ply", many)), ErrorCode::kInvalidInput, dir_ / "many.ply",
              "elements");
  // Cut after the header: assimp reports the missing data itself.
  const std::string name = "cut_body.ply";
  ExpectError(ImportMesh(Write(name, text->substr(0, end + 11 + 30))), ErrorCode::kInvalidInput,
              dir_ / name, "");
}

TEST_F(MeshImportTest, WeldToleranceClosesJitteredMesh) {
  // Every triangle gets its own copy of its corners, moved by up to 1 um (in metres).
  const TriangleMesh box = MakeBox(kLo, kHi);
  TriangleMesh soup;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-1e-6, 1e-6);
  for (const Eigen::Vector3i& t : box.triangles) {
    const int base = static_cast<int>(soup.vertices.size());
    for (int k = 0; k < 3; ++k) {
      soup.vertices.push_back(box.vertices[static_cast<size_t>(t[k])] +
                              Vec3(jitter(rng), jitter(rng), jitter(rng)));
    }
    soup.triangles.emplace_back(base, base + 1, base + 2);
  }
  ASSERT_TRUE(WritePly(dir_ / "soup.ply", soup).has_value());

  const Result<TriangleMesh> exact = ImportMesh(dir_ / "soup.ply");
  ASSERT_TRUE(exact.has_value()) << exact.error().message;
  EXPECT_EQ(exact->vertices.size(), 36u);
  EXPECT_EQ(AnalyzeTopology(*exact).boundary_edges, 36);

  // Corners move by up to 1.7 um, the 20 mm sides by up to 2 um: volume within 3e-4.
  ExpectBox(ImportMesh(dir_ / "soup.ply", {.weld_tolerance = 1e-5}), kLo, kHi, 2e-6, 3e-4);
}

TEST_F(MeshImportTest, MissingFileIsIoError) {
  const fs::path path = dir_ / "no_such_part.stl";
  ExpectError(ImportMesh(path), ErrorCode::kIo, path, "not found");
}

TEST_F(MeshImportTest, DirectoryIsIoError) {
  fs::create_directories(dir_ / "folder.stl");
  ExpectError(ImportMesh(dir_ / "folder.stl"), ErrorCode::kIo, dir_ / "folder.stl", "directory");
}

TEST_F(MeshImportTest, EmptyFilesAreInvalidInput) {
  for (const char* name : {"empty.stl", "empty.obj", "empty.ply", "empty.off", "empty.gltf",
                           "empty.glb", "empty.3mf", "empty.dae", "empty.xyz"}) {
    ExpectError(ImportMesh(Write(name, "")), ErrorCode::kInvalidInput, dir_ / name, "empty");
  }
}

TEST_F(MeshImportTest, RandomBytesAreInvalidInput) {
  std::mt19937 rng(1234);
  std::string bytes(4096, '\0');
  for (char& c : bytes) c = static_cast<char>(rng() & 0xffu);
  for (const char* name : {"random.stl", "random.obj", "random.ply", "random.off", "random.gltf",
                           "random.glb", "random.3mf", "random.dae", "random.bin"}) {
    ExpectError(ImportMesh(Write(name, bytes)), ErrorCode::kInvalidInput, dir_ / name, "");
  }
}

TEST_F(MeshImportTest, TextFilesAreInvalidInput) {
  const std::string text = "These are not the triangles you are looking for.\n";
  ExpectError(ImportMesh(Write("notes.ply", text)), ErrorCode::kInvalidInput, dir_ / "notes.ply",
              "cannot read");
  ExpectError(ImportMesh(Write("notes.stl", text)), ErrorCode::kInvalidInput, dir_ / "notes.stl",
              "cannot read");
  // The OBJ reader skips lines it does not know: what is left has no faces.
  ExpectError(ImportMesh(Write("notes.obj", text)), ErrorCode::kInvalidInput, dir_ / "notes.obj",
              "contains no triangles");
}

TEST_F(MeshImportTest, TruncatedStlIsInvalidInput) {
  ASSERT_TRUE(WriteStl(dir_ / "box.stl", MakeBox(kLo, kHi)).has_value());
  Result<std::string> bytes = ReadFile(dir_ / "box.stl");
  ASSERT_TRUE(bytes.has_value());
  for (const size_t keep : {size_t{40}, size_t{84}, size_t{84 + 50 * 5 + 17}}) {
    const std::string name = "cut" + std::to_string(keep) + ".stl";
    ExpectError(ImportMesh(Write(name, bytes->substr(0, keep))), ErrorCode::kInvalidInput,
                dir_ / name, "cannot read");
  }
  const std::string ascii = "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n";
  ExpectError(ImportMesh(Write("cut_ascii.stl", ascii)), ErrorCode::kInvalidInput,
              dir_ / "cut_ascii.stl", "cannot read");
}

TEST_F(MeshImportTest, PointsAndLinesHaveNoTriangles) {
  ExpectError(ImportMesh(Write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n")),
              ErrorCode::kInvalidInput, dir_ / "lines.obj", "contains no triangles");
  const std::string cloud =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  ExpectError(ImportMesh(Write("cloud.ply", cloud)), ErrorCode::kInvalidInput, dir_ / "cloud.ply",
              "contains no triangles");
  // Lines mixed with triangles: the lines are dropped.
  const Result<TriangleMesh> mixed =
      ImportMesh(Write("mixed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 3\n"));
  ASSERT_TRUE(mixed.has_value()) << mixed.error().message;
  EXPECT_EQ(mixed->triangles.size(), 1u);
  EXPECT_EQ(mixed->vertices.size(), 3u);
}

TEST_F(MeshImportTest, BadValuesAreInvalidInput) {
  ExpectError(ImportMesh(Write("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")),
              ErrorCode::kInvalidInput, dir_ / "nan.obj", "non-finite");
  ExpectError(ImportMesh(Write("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")),
              ErrorCode::kInvalidInput, dir_ / "index.obj", "cannot read");
  ASSERT_TRUE(WriteObj(dir_ / "box.obj", MakeBox(kLo, kHi)).has_value());
  ExpectError(ImportMesh(dir_ / "box.obj", {.scale = 0.0}), ErrorCode::kInvalidInput,
              dir_ / "box.obj", "scale");
  ExpectError(ImportMesh(dir_ / "box.obj", {.scale = -1.0}), ErrorCode::kInvalidInput,
              dir_ / "box.obj", "scale");
  ExpectError(ImportMesh(dir_ / "box.obj", {.weld_tolerance = -1e-6}), ErrorCode::kInvalidInput,
              dir_ / "box.obj", "weld tolerance");
}

TEST_F(MeshImportTest, LeavesAssimpLoggerSilent) {
  ASSERT_TRUE(WriteObj(dir_ / "box.obj", MakeBox(kLo, kHi)).has_value());
  ASSERT_TRUE(ImportMesh(dir_ / "box.obj").has_value());
  ASSERT_FALSE(ImportMesh(Write("bad.ply", "ply\nnonsense\n")).has_value());
  EXPECT_TRUE(Assimp::DefaultLogger::isNullLogger());
}

TEST(FabricaMeshTest, BeamPostImportsClosedInMetres) {
  const fs::path path = fs::path(WRAP_SHARED_DIR) / "fabrica" / "beam" / "2.obj";
  if (!fs::exists(path)) GTEST_SKIP() << path << " not present";
  const Result<TriangleMesh> mesh = ImportMesh(path, {.scale = 0.01});
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
  EXPECT_TRUE(AnalyzeTopology(*mesh).closed());
  const Aabb box = ComputeAabb(*mesh);
  EXPECT_NEAR(box.min.x(), -0.0502, 1e-4);
  EXPECT_NEAR(box.max.x(), -0.0387, 1e-4);
  EXPECT_NEAR(box.min.y(), -0.006, 1e-4);
  EXPECT_NEAR(box.max.y(), 0.006, 1e-4);
  EXPECT_NEAR(box.min.z(), 0.0, 1e-4);
  EXPECT_NEAR(box.max.z(), 0.0762, 1e-4);
  EXPECT_GT(ComputeMassProperties(*mesh).volume_m3, 0.0);
}

}  // namespace
}  // namespace wrap
