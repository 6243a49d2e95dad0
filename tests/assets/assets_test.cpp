// The generated part meshes: the committed copy under assets/parts matches the generator byte for
// byte, every mesh is a closed solid, and every designed peg fits its pocket.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "generator/part_designs.h"
#include "generator/solid_meshers.h"
#include "geometry/mesh.h"
#include "geometry/mesh_import.h"
#include "model/assembly.h"
#include "model/project_io.h"

namespace wrap::partgen {
namespace {

namespace fs = std::filesystem;

const fs::path kCommittedDir = fs::path(WRAP_SOURCE_DIR) / "assets" / "parts";
const fs::path kProjectsDir = fs::path(WRAP_SOURCE_DIR) / "projects";
constexpr char kRegenerateHint[] =
    "regenerate the committed meshes: build, then run "
    "`build/assets/generator/wrap_make_parts assets/parts` in the repository root";

const std::vector<GeneratedPart>& Parts() {
  static const std::vector<GeneratedPart> parts = [] {
    auto generated = GenerateParts();
    EXPECT_TRUE(generated.has_value()) << generated.error().message;
    return generated ? *generated : std::vector<GeneratedPart>{};
  }();
  return parts;
}

const TriangleMesh& MeshOf(const std::string& key) {
  for (const GeneratedPart& p : Parts()) {
    if (p.Key() == key) return p.mesh;
  }
  ADD_FAILURE() << "no generated part " << key;
  static const TriangleMesh empty;
  return empty;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string Str(const Vec3& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

/// Point-in-solid test by the parity of crossings of a vertical ray, with the triangles binned by
/// their xy extent. Query points must not lie on a face or above an edge (callers use irrational
/// offsets).
class InsideTester {
 public:
  explicit InsideTester(const TriangleMesh& mesh) : mesh_(mesh), box_(ComputeAabb(mesh)) {
    cells_.resize(kBins * kBins);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
      for (int k = 0; k < 3; ++k) {
        lo = lo.cwiseMin(mesh.vertices[mesh.triangles[t][k]]);
        hi = hi.cwiseMax(mesh.vertices[mesh.triangles[t][k]]);
      }
      const auto [i0, j0] = Bin(lo);
      const auto [i1, j1] = Bin(hi);
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) cells_[i + kBins * j].push_back(static_cast<int>(t));
      }
    }
  }

  bool Inside(const Vec3& p) const {
    if ((p.array() <= box_.min.array()).any() || (p.array() >= box_.max.array()).any()) {
      return false;
    }
    const auto [i, j] = Bin(p);
    int crossings = 0;
    for (int t : cells_[i + kBins * j]) {
      const Vec3& a = mesh_.vertices[mesh_.triangles[t][0]];
      const Vec3& b = mesh_.vertices[mesh_.triangles[t][1]];
      const Vec3& c = mesh_.vertices[mesh_.triangles[t][2]];
      // Barycentric coordinates of p's xy in the triangle's xy projection.
      const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
      if (std::abs(det) < 1e-18) continue;  // vertical triangle: the ray cannot cross it
      const double u =
          ((p.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (p.y() - a.y())) / det;
      const double v =
          ((b.x() - a.x()) * (p.y() - a.y()) - (p.x() - a.x()) * (b.y() - a.y())) / det;
      if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
      const double z = a.z() + u * (b.z() - a.z()) + v * (c.z() - a.z());
      if (z > p.z()) ++crossings;
    }
    return crossings % 2 == 1;
  }

 private:
  static constexpr int kBins = 48;
  std::pair<int, int> Bin(const Vec3& p) const {
    const Vec3 s = box_.size();
    const auto bin = [](double t) { return std::clamp(static_cast<int>(t * kBins), 0, kBins - 1); };
    return {bin((p.x() - box_.min.x()) / s.x()), bin((p.y() - box_.min.y()) / s.y())};
  }
  const TriangleMesh& mesh_;
  Aabb box_;
  std::vector<std::vector<int>> cells_;
};

/// Lattice points with spacing `step` [m] inside `box`, shifted off the mm grid so that no point
/// lies on a face of a generated part.
std::vector<Vec3> Lattice(const Aabb& box, double step) {
  std::vector<Vec3> points;
  const Vec3 shift(0.1234567e-3, 0.2345678e-3, 0.3456789e-3);
  for (double z = box.min.z() + std::fmod(shift.z(), step); z < box.max.z(); z += step) {
    for (double y = box.min.y() + std::fmod(shift.y(), step); y < box.max.y(); y += step) {
      for (double x = box.min.x() + std::fmod(shift.x(), step); x < box.max.x(); x += step) {
        points.emplace_back(x, y, z);
      }
    }
  }
  return points;
}

Aabb Intersection(const Aabb& a, const Aabb& b) {
  return Aabb{a.min.cwiseMax(b.min), a.max.cwiseMin(b.max)};
}

bool IsEmpty(const Aabb& b) { return (b.max.array() <= b.min.array()).any(); }

TEST(AssetsTest, CommittedMeshesMatchTheGenerator) {
  ASSERT_FALSE(Parts().empty());
  const fs::path out =
      fs::path(::testing::TempDir()) / ("wrap_assets_test_parts_" + std::to_string(::getpid()));
  fs::remove_all(out);
  std::set<fs::path> generated;
  for (const GeneratedPart& part : Parts()) {
    ASSERT_TRUE(WritePart(out, part).has_value()) << part.Key();
    generated.insert(part.RelativePath());
    const fs::path committed = kCommittedDir / part.RelativePath();
    ASSERT_TRUE(fs::exists(committed)) << committed << " is missing: " << kRegenerateHint;
    EXPECT_TRUE(ReadBytes(out / part.RelativePath()) == ReadBytes(committed))
        << committed << " differs from the generator's output: " << kRegenerateHint;
  }
  // No stale meshes that the generator no longer writes.
  for (const auto& entry : fs::recursive_directory_iterator(kCommittedDir)) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), kCommittedDir);
    if (rel.extension() == ".stl" || rel.extension() == ".obj") {
      EXPECT_TRUE(generated.contains(rel)) << entry.path() << " is not written by the generator";
    }
  }
  fs::remove_all(out);
}

TEST(AssetsTest, GeneratorIsDeterministic) {
  const auto again = GenerateParts();
  ASSERT_TRUE(again.has_value()) << again.error().message;
  ASSERT_EQ(again->size(), Parts().size());
  for (size_t i = 0; i < Parts().size(); ++i) {
    EXPECT_EQ((*again)[i].mesh.vertices, Parts()[i].mesh.vertices) << Parts()[i].Key();
    EXPECT_EQ((*again)[i].mesh.triangles, Parts()[i].mesh.triangles) << Parts()[i].Key();
  }
}

TEST(AssetsTest, MeshesAreClosedOrientedSolidsOfModelSize) {
  for (const GeneratedPart& part : Parts()) {
    SCOPED_TRACE(part.Key());
    const MeshTopology topo = AnalyzeTopology(part.mesh);
    EXPECT_TRUE(topo.closed()) << topo.boundary_edges << " boundary, " << topo.non_manifold_edges
                               << " non-manifold edges";
    EXPECT_EQ(topo.degenerate_triangles, 0);
    EXPECT_TRUE(CheckClosedOriented(part.mesh, part.Key()).has_value());

    const MassProperties mp = ComputeMassProperties(part.mesh);
    const Aabb box = ComputeAabb(part.mesh);
    EXPECT_GT(mp.volume_m3, 0.0);
    EXPECT_LT(mp.volume_m3, box.size().prod());
    EXPECT_TRUE((mp.com.array() > box.min.array()).all() &&
                (mp.com.array() < box.max.array()).all())
        << "centre of mass " << Str(mp.com) << " outside the box";
    // Small 3D-printed models: 5 to 30 cm along the longest side.
    EXPECT_GE(box.size().maxCoeff(), 0.05);
    EXPECT_LE(box.size().maxCoeff(), 0.30);
  }
}

TEST(AssetsTest, CommittedMeshesImportAsTheSameSolids) {
  for (const GeneratedPart& part : Parts()) {
    SCOPED_TRACE(part.Key());
    const auto imported = ImportMesh(kCommittedDir / part.RelativePath(), {.scale = 0.001});
    ASSERT_TRUE(imported.has_value()) << imported.error().message;
    EXPECT_EQ(imported->triangles.size(), part.mesh.triangles.size());
    EXPECT_TRUE(AnalyzeTopology(*imported).closed());
    const double volume = ComputeMassProperties(part.mesh).volume_m3;
    EXPECT_NEAR(ComputeMassProperties(*imported).volume_m3, volume, 1e-6 * volume);
  }
}

TEST(AssetsTest, PegsFitTheirPocketsWithClearance) {
  const auto joints = DesignedJoints();
  ASSERT_FALSE(joints.empty());
  for (const Joint& joint : joints) {
    SCOPED_TRACE(joint.base + " <- " + joint.moved + " at " + Str(joint.X_BM.translation()));
    const TriangleMesh& base = MeshOf(joint.base);
    const TriangleMesh moved_B = Transformed(MeshOf(joint.moved), joint.X_BM);
    const Aabb base_box = ComputeAabb(base);
    int axis = 0;
    joint.axis_B.cwiseAbs().maxCoeff(&axis);
    ASSERT_NEAR(std::abs(joint.axis_B[axis]), 1.0, 1e-12) << "axis-aligned insertions only";
    const bool forward = joint.axis_B[axis] > 0.0;

    // Every vertex of the moved part that enters the base's box is a peg inside a pocket, at least
    // the designed clearance from the pocket's walls and floor; the tightest gaps are the design's.
    double min_lateral = 1.0, min_floor = 1.0;
    std::vector<int> vertices_in_pocket(joint.pockets_B.size(), 0);
    for (const Vec3& v : moved_B.vertices) {
      if ((v.array() <= base_box.min.array() + 1e-6).any() ||
          (v.array() >= base_box.max.array() - 1e-6).any()) {
        continue;
      }
      bool in_pocket = false;
      for (size_t k = 0; k < joint.pockets_B.size(); ++k) {
        const Aabb& pocket = joint.pockets_B[k];
        if ((v.array() < pocket.min.array() - 1e-9).any() ||
            (v.array() > pocket.max.array() + 1e-9).any()) {
          continue;
        }
        in_pocket = true;
        ++vertices_in_pocket[k];
        for (int a = 0; a < 3; ++a) {
          if (a == axis) continue;
          min_lateral = std::min({min_lateral, v[a] - pocket.min[a], pocket.max[a] - v[a]});
        }
        min_floor =
            std::min(min_floor, forward ? pocket.max[axis] - v[axis] : v[axis] - pocket.min[axis]);
      }
      EXPECT_TRUE(in_pocket) << "vertex " << Str(v) << " enters the base outside every pocket";
    }
    for (size_t k = 0; k < vertices_in_pocket.size(); ++k) {
      EXPECT_GT(vertices_in_pocket[k], 0) << "no peg in pocket " << k;
    }
    EXPECT_NEAR(min_lateral, joint.lateral_clearance_m, 1e-7);
    EXPECT_NEAR(min_floor, joint.floor_clearance_m, 1e-7);
    EXPECT_GE(joint.lateral_clearance_m, 0.19e-3);
    EXPECT_GE(joint.floor_clearance_m, 0.5e-3);

    // The pockets are blind cavities of the base mesh: empty inside, solid just past the floor.
    const InsideTester base_inside(base);
    for (const Aabb& pocket : joint.pockets_B) {
      Aabb beyond = pocket;
      if (forward) {
        beyond.min[axis] = pocket.max[axis] + 0.2e-3;
        beyond.max[axis] = pocket.max[axis] + 0.7e-3;
      } else {
        beyond.max[axis] = pocket.min[axis] - 0.2e-3;
        beyond.min[axis] = pocket.min[axis] - 0.7e-3;
      }
      for (const Vec3& p : Lattice(pocket, 1e-3)) {
        EXPECT_FALSE(base_inside.Inside(p)) << "pocket point " << Str(p) << " is solid";
      }
      for (const Vec3& p : Lattice(beyond, 1e-3)) {
        EXPECT_TRUE(base_inside.Inside(p)) << "point " << Str(p) << " past the floor is empty";
      }
    }

    // The moved part rests on the base: some of its vertices lie on the pockets' mouth plane,
    // outside the pockets (a shoulder or a face), within the base's footprint.
    const double mouth = forward ? joint.pockets_B[0].min[axis] : joint.pockets_B[0].max[axis];
    int resting = 0;
    for (const Vec3& v : moved_B.vertices) {
      if (std::abs(v[axis] - mouth) > 1e-9) continue;
      bool over_pocket = false, over_base = true;
      for (int a = 0; a < 3; ++a) {
        if (a == axis) continue;
        over_base = over_base && v[a] >= base_box.min[a] && v[a] <= base_box.max[a];
      }
      for (const Aabb& pocket : joint.pockets_B) {
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
          if (a != axis) inside = inside && v[a] >= pocket.min[a] && v[a] <= pocket.max[a];
        }
        over_pocket = over_pocket || inside;
      }
      if (over_base && !over_pocket) ++resting;
    }
    EXPECT_GT(resting, 0) << "the moved part does not rest on the base";

    // No interference when assembled, nor anywhere along the way in along the insertion axis.
    const InsideTester moved_inside(moved_B);
    const Aabb moved_box = ComputeAabb(moved_B);
    int sampled = 0;
    for (double back = 0.0; back <= 17e-3; back += 1e-3) {
      const Vec3 shift = -back * joint.axis_B;
      const Aabb region =
          Intersection(base_box, Aabb{moved_box.min + shift, moved_box.max + shift});
      if (IsEmpty(region)) continue;
      int overlapping = 0;
      for (const Vec3& p : Lattice(region, 0.5e-3)) {
        ++sampled;
        if (base_inside.Inside(p) && moved_inside.Inside(p - shift)) ++overlapping;
      }
      EXPECT_EQ(overlapping, 0) << "parts overlap with the moved part " << back * 1e3
                                << " mm back along the insertion axis";
    }
    EXPECT_GT(sampled, 1000);
  }
}

/// "<assembly>/<name>" of a project mesh path under assets/parts, e.g. "stool/leg".
std::string KeyOfMesh(const std::string& mesh) {
  const fs::path path(mesh);
  return path.parent_path().filename().string() + "/" + path.stem().string();
}

TEST(AssetsTest, ProjectsMateTheGeneratedPartsAsDesigned) {
  const auto joints = DesignedJoints();
  for (const char* name : {"stool", "chair", "cross", "cube", "cube_2x2x3", "half_stool"}) {
    SCOPED_TRACE(name);
    const ProjectParse parse = ReadProjectFile(kProjectsDir / (std::string(name) + ".json"));
    ASSERT_TRUE(parse.project.has_value());
    const Project& project = *parse.project;
    Diagnostics diagnostics;
    AssemblyTree tree;
    ASSERT_TRUE(BuildAssemblyTree(project, name, diagnostics, tree));

    // Every part uses a committed generated mesh, written in millimetres.
    std::vector<std::string> keys;
    std::vector<Aabb> boxes_A;
    std::vector<TriangleMesh> meshes_A;
    for (const Part& part : project.parts) {
      keys.push_back(KeyOfMesh(part.mesh));
      EXPECT_EQ(fs::path(part.mesh).parent_path().parent_path(), fs::path("../assets/parts"))
          << part.name;
      EXPECT_EQ(part.scale, 0.001) << part.name;
      meshes_A.push_back(Transformed(MeshOf(keys.back()), ToIsometry(part.assembled_pose)));
      boxes_A.push_back(ComputeAabb(meshes_A.back()));
    }

    // Each step brings a peg of the moved input into a pocket of the base input, at the designed
    // relative pose and along the designed direction.
    for (const Step& step : project.steps) {
      const AssemblyNode& moved = tree.nodes[tree.Find(step.mating.moved)];
      const AssemblyNode& base = tree.nodes[tree.Find(step.mating.base)];
      int matches = 0;
      for (int m : moved.parts) {
        for (int b : base.parts) {
          const Iso3 X_AB = ToIsometry(project.parts[b].assembled_pose);
          const Iso3 X_BM = X_AB.inverse() * ToIsometry(project.parts[m].assembled_pose);
          for (const Joint& joint : joints) {
            if (joint.base != keys[b] || joint.moved != keys[m] ||
                !(joint.X_BM.matrix() - X_BM.matrix()).isZero(1e-9)) {
              continue;
            }
            ++matches;
            const Vec3 axis_A = X_AB.linear() * joint.axis_B;
            EXPECT_TRUE((axis_A - step.mating.axis.normalized()).isZero(1e-9))
                << step.name << ": axis " << Str(step.mating.axis) << ", designed " << Str(axis_A);
          }
        }
      }
      EXPECT_GT(matches, 0) << step.name << ": no peg of " << step.mating.moved
                            << " sits in a pocket of " << step.mating.base;
    }

    // No two parts overlap in the assembled object.
    for (size_t i = 0; i < project.parts.size(); ++i) {
      const InsideTester inside_i(meshes_A[i]);
      for (size_t j = i + 1; j < project.parts.size(); ++j) {
        const Aabb region = Intersection(boxes_A[i], boxes_A[j]);
        if (IsEmpty(region)) continue;
        const InsideTester inside_j(meshes_A[j]);
        int overlapping = 0;
        for (const Vec3& p : Lattice(region, 1e-3)) {
          if (inside_i.Inside(p) && inside_j.Inside(p)) ++overlapping;
        }
        EXPECT_EQ(overlapping, 0) << project.parts[i].name << " overlaps " << project.parts[j].name;
      }
    }
  }
}

TEST(AssetsTest, DesignedJointsCoverEveryAssembly) {
  std::set<std::string> assemblies;
  for (const Joint& joint : DesignedJoints()) {
    assemblies.insert(joint.base.substr(0, joint.base.find('/')));
    EXPECT_EQ(joint.base.substr(0, joint.base.find('/')),
              joint.moved.substr(0, joint.moved.find('/')));
  }
  EXPECT_EQ(assemblies, (std::set<std::string>{"chair", "cross", "cube", "stool"}));
}

}  // namespace
}  // namespace wrap::partgen
