// Shapes of the collision world: how a Shape (sphere, capsule, cylinder, box, mesh) becomes the
// narrowphase's data and FCL geometry, and the process-wide cache of mesh trees.
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <utility>

#include "robot/detail/collision_impl.h"

namespace wrap::detail {
namespace {

// The FCL trees of meshes, shared by every world that adds the same mesh: cells are built per
// task plan, per set of finger openings and per check, and building the tree of a Fabrica part
// costs milliseconds. An entry lives while some world uses its tree; the mesh is compared
// exactly, not by its hash alone.
class MeshTreeCache {
 public:
  using Tree = fcl::BVHModel<fcl::OBBRSSd>;
  /// The tree of (vertices, triangles), built when no world holds one; null when FCL fails.
  std::shared_ptr<const Tree> Get(const std::vector<fcl::Vector3d>& vertices,
                                  const std::vector<fcl::Triangle>& triangles) {
    std::uint64_t h = 1469598103934665603ULL;
    auto mix = [&h](const void* data, std::size_t bytes) {
      const auto* p = static_cast<const unsigned char*>(data);
      for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ULL;
    };
    for (const fcl::Vector3d& v : vertices) mix(v.data(), 3 * sizeof(double));
    for (const fcl::Triangle& t : triangles) {
      const std::size_t idx[3] = {t[0], t[1], t[2]};
      mix(idx, sizeof idx);
    }
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Entry>& bucket = entries_[h];
    std::erase_if(bucket, [](const Entry& e) { return e.tree.expired(); });
    for (const Entry& e : bucket) {
      if (e.vertices == vertices && e.triangles.size() == triangles.size() &&
          std::equal(e.triangles.begin(), e.triangles.end(), triangles.begin(),
                     [](const fcl::Triangle& a, const fcl::Triangle& b) {
                       return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
                     })) {
        if (auto tree = e.tree.lock()) return tree;
      }
    }
    auto model = std::make_shared<Tree>();
    if (model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(vertices.size())) !=
            fcl::BVH_OK ||
        model->addSubModel(vertices, triangles) != fcl::BVH_OK ||
        model->endModel() != fcl::BVH_OK) {
      return nullptr;
    }
    model->computeLocalAABB();
    bucket.push_back({model, vertices, triangles});
    return model;
  }

  int Live() {
    std::lock_guard<std::mutex> lock(mutex_);
    int n = 0;
    for (const auto& [h, bucket] : entries_) {
      for (const Entry& e : bucket) n += !e.tree.expired();
    }
    return n;
  }

 private:
  struct Entry {
    std::weak_ptr<const Tree> tree;
    std::vector<fcl::Vector3d> vertices;
    std::vector<fcl::Triangle> triangles;
  };
  std::mutex mutex_;
  std::unordered_map<std::uint64_t, std::vector<Entry>> entries_;
};

MeshTreeCache& MeshTrees() {
  static MeshTreeCache cache;
  return cache;
}

// A capsule or cylinder of FCL lies along its local z, centred at the origin: the frame that puts
// it on segment p0-p1.
Iso3 SegmentFrame(const Vec3& p0, const Vec3& p1) {
  Iso3 X = Iso3::Identity();
  X.translation() = 0.5 * (p0 + p1);
  const Vec3 axis = p1 - p0;
  if (axis.norm() > 0.0) {
    X.linear() = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis).toRotationMatrix();
  }
  return X;
}

bool AllFinite(const Vec3& v) { return v.allFinite(); }

// A sphere or capsule (a swept sphere; a capsule of zero length is a sphere). `at` names it.
Result<void> MakeSwept(const Shape& shape, const std::string& at, ShapeData& s) {
  if (!(shape.radius > 0.0) || !std::isfinite(shape.radius) || !AllFinite(shape.p0) ||
      (shape.type == Shape::Type::kCapsule && !AllFinite(shape.p1))) {
    return Fail(ErrorCode::kInvalidInput,
                at + ": needs a positive finite radius and finite end points, got radius " +
                    std::to_string(shape.radius));
  }
  s.kind = ShapeKind::kSwept;
  s.radius = shape.radius;
  s.a_B = shape.p0;
  s.b_B = shape.type == Shape::Type::kSphere ? shape.p0 : shape.p1;
  const double length = (s.b_B - s.a_B).norm();
  if (length > 0.0) {
    s.X_BS = SegmentFrame(s.a_B, s.b_B);
    s.geom = std::make_shared<fcl::Capsuled>(s.radius, length);
  } else {
    s.X_BS.translation() = s.a_B;
    s.geom = std::make_shared<fcl::Sphered>(s.radius);
  }
  s.h_S = Vec3(s.radius, s.radius, 0.5 * length + s.radius);
  s.w_B = s.a_B;
  s.w_r = s.radius;
  return {};
}

Result<void> MakeCylinder(const Shape& shape, const std::string& at, ShapeData& s) {
  const double length = (shape.p1 - shape.p0).norm();
  if (!(shape.radius > 0.0) || !std::isfinite(shape.radius) || !AllFinite(shape.p0) ||
      !AllFinite(shape.p1) || !(length > 0.0)) {
    return Fail(ErrorCode::kInvalidInput,
                at + ": a cylinder needs a positive finite radius and distinct end points");
  }
  s.kind = ShapeKind::kConvex;
  s.radius = shape.radius;
  s.a_B = shape.p0;
  s.b_B = shape.p1;
  s.X_BS = SegmentFrame(s.a_B, s.b_B);
  s.geom = std::make_shared<fcl::Cylinderd>(s.radius, length);
  s.h_S = Vec3(s.radius, s.radius, 0.5 * length);
  s.w_B = 0.5 * (s.a_B + s.b_B);
  s.w_r = std::min(s.radius, 0.5 * length);
  return {};
}

Result<void> MakeBox(const Shape& shape, const std::string& at, ShapeData& s) {
  if (!(shape.half_extents.array() > 0.0).all() || !AllFinite(shape.half_extents) ||
      !shape.X_LS.matrix().allFinite()) {
    return Fail(ErrorCode::kInvalidInput,
                at + ": a box needs positive finite half extents and a finite pose");
  }
  s.kind = ShapeKind::kConvex;
  s.X_BS = shape.X_LS;
  s.h_S = shape.half_extents;
  // fcl::Box takes full side lengths.
  s.geom = std::make_shared<fcl::Boxd>(2.0 * shape.half_extents);
  s.w_B = s.X_BS.translation();
  s.w_r = shape.half_extents.minCoeff();
  return {};
}

// A mesh: its tree from the shared cache (built there when no world holds it yet).
Result<void> MakeMesh(const Shape& shape, const std::string& at, ShapeData& s) {
  const TriangleMesh& mesh = shape.mesh;
  if (mesh.triangles.empty()) {
    return Fail(ErrorCode::kInvalidInput, at + ": the mesh has no triangles");
  }
  const int nv = static_cast<int>(mesh.vertices.size());
  std::vector<fcl::Vector3d> vertices(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    if ((t.array() < 0).any() || (t.array() >= nv).any()) {
      return Fail(ErrorCode::kInvalidInput,
                  at + ": a triangle indexes a vertex outside [0, " + std::to_string(nv) + ")");
    }
    triangles.emplace_back(t[0], t[1], t[2]);
  }
  for (const Vec3& v : mesh.vertices) {
    if (!AllFinite(v)) return Fail(ErrorCode::kInvalidInput, at + ": a vertex is not finite");
  }
  auto model = MeshTrees().Get(vertices, triangles);
  if (!model) {
    return Fail(ErrorCode::kInvalidInput, at + ": FCL could not build the mesh's tree");
  }
  const Aabb box = ComputeAabb(mesh);
  s.kind = ShapeKind::kMesh;
  s.w_B = mesh.vertices[mesh.triangles[0][0]];  // on the surface: a ball of radius 0
  s.c_S = 0.5 * (box.min + box.max);
  s.h_S = 0.5 * (box.max - box.min);
  s.geom = std::move(model);
  return {};
}

}  // namespace

Result<ShapeData> MakeShapeData(const Shape& shape, std::size_t k, const std::string& where) {
  ShapeData s;
  s.type = shape.type;
  s.name = shape.name.empty() ? "shape" + std::to_string(k) : shape.name;
  const std::string at = where + ", shape '" + s.name + "'";
  Result<void> made;
  switch (shape.type) {
    case Shape::Type::kSphere:
    case Shape::Type::kCapsule:
      made = MakeSwept(shape, at, s);
      break;
    case Shape::Type::kCylinder:
      made = MakeCylinder(shape, at, s);
      break;
    case Shape::Type::kBox:
      made = MakeBox(shape, at, s);
      break;
    case Shape::Type::kMesh:
      made = MakeMesh(shape, at, s);
      break;
  }
  if (!made) return std::unexpected(made.error());
  // (Mesh trees come from the shared cache with their boxes computed.)
  if (s.kind != ShapeKind::kMesh) {
    std::const_pointer_cast<fcl::CollisionGeometryd>(s.geom)->computeLocalAABB();
  }
  return s;
}

int LiveMeshTreeCount() { return MeshTrees().Live(); }

}  // namespace wrap::detail
