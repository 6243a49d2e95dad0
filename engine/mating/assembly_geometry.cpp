#include "mating/assembly_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "geometry/mesh_offset.h"

namespace wrap {

namespace {

constexpr int kMinSamples = 500;
constexpr int kMaxSamples = 6000;
constexpr double kSampleSpacing_m = 1e-3;

}  // namespace

AssemblyGeometry::AssemblyGeometry(std::vector<std::string> names, std::vector<TriangleMesh> meshes,
                                   std::vector<Iso3> X_AP)
    : names_(std::move(names)), meshes_(std::move(meshes)), X_AP_(std::move(X_AP)) {
  queries_.resize(names_.size());
  samples_.resize(names_.size());
}

AssemblyGeometry AssemblyGeometry::FromProject(const Project& project, const ProjectCheck& check) {
  std::vector<std::string> names;
  std::vector<TriangleMesh> meshes;
  std::vector<Iso3> poses;
  for (size_t p = 0; p < project.parts.size(); ++p) {
    names.push_back(project.parts[p].name);
    const bool loaded = p < check.parts.size() && check.parts[p].loaded;
    meshes.push_back(loaded ? check.parts[p].mesh : TriangleMesh{});
    poses.push_back(ToIsometry(project.parts[p].assembled_pose));
  }
  return AssemblyGeometry(std::move(names), std::move(meshes), std::move(poses));
}

Aabb AssemblyGeometry::Box(int part, const Iso3& X) const {
  Aabb box;
  box.min = Vec3::Constant(std::numeric_limits<double>::infinity());
  box.max = -box.min;
  for (const Vec3& v : meshes_[part].vertices) {
    const Vec3 w = X * v;
    box.min = box.min.cwiseMin(w);
    box.max = box.max.cwiseMax(w);
  }
  if (meshes_[part].vertices.empty()) box.min = box.max = X.translation();
  return box;
}

const MeshQuery& AssemblyGeometry::query(int part) {
  if (!queries_[part]) queries_[part] = std::make_unique<MeshQuery>(meshes_[part]);
  return *queries_[part];
}

const std::vector<Vec3>& AssemblyGeometry::samples(int part) {
  std::vector<Vec3>& out = samples_[part];
  if (!out.empty() || meshes_[part].empty()) return out;
  const MeshQuery& q = query(part);
  const int n = std::clamp(static_cast<int>(q.area() / (kSampleSpacing_m * kSampleSpacing_m)),
                           kMinSamples, kMaxSamples);
  std::mt19937_64 rng(0x5eed0000ULL + static_cast<unsigned long long>(part));
  out.reserve(n);
  for (int i = 0; i < n; ++i) out.push_back(q.SamplePoint(rng, nullptr));
  return out;
}

const TriangleMesh& AssemblyGeometry::inset_mesh(int part, double inset_m) {
  const long long depth_nm = std::llround(inset_m * 1e9);
  if (depth_nm == 0) return meshes_[part];
  std::unique_ptr<TriangleMesh>& slot = inset_meshes_[{depth_nm, part}];
  if (!slot) slot = std::make_unique<TriangleMesh>(InsetMesh(meshes_[part], inset_m));
  return *slot;
}

const SweepMesh& AssemblyGeometry::sweep_mesh(int part, double inset_m) {
  const long long depth_nm = std::llround(inset_m * 1e9);
  std::unique_ptr<SweepMesh>& slot = sweep_meshes_[{depth_nm, part}];
  if (!slot) slot = std::make_unique<SweepMesh>(inset_mesh(part, inset_m), X_AP_[part]);
  return *slot;
}

CollisionWorld& AssemblyGeometry::world(double inset_m) {
  const long long key = std::llround(inset_m * 1e9);
  auto it = worlds_.find(key);
  if (it != worlds_.end()) return *it->second;
  auto world = std::make_unique<CollisionWorld>();
  for (int p = 0; p < num_parts(); ++p) {
    BodyDef def;
    def.name = names_[p];
    def.X_WB = X_AP_[p];
    if (!meshes_[p].empty()) {
      Shape shape;
      shape.type = Shape::Type::kMesh;
      shape.mesh = inset_mesh(p, inset_m);
      shape.name = names_[p];
      def.shapes.push_back(std::move(shape));
    }
    // Body i must be part i: a mesh FCL refuses (it cannot be one validation loaded) becomes a
    // body without shapes, which no check sees.
    if (!world->AddBody(def)) {
      def.shapes.clear();
      (void)world->AddBody(def);
    }
  }
  return *worlds_.emplace(key, std::move(world)).first->second;
}

}  // namespace wrap
