// The parts of an assembly as the geometry checks see them: each part's mesh and assembled pose,
// and what the checks derive from a mesh on demand (a query structure, surface samples, inward
// offsets, box trees for exact sweeps, a collision world of all parts).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/pose.h"
#include "geometry/mesh.h"
#include "geometry/mesh_query.h"
#include "geometry/translation_sweep.h"
#include "model/project.h"
#include "model/validate.h"
#include "robot/collision.h"

namespace wrap {

/// The parts' meshes (part frames, metres) and their assembled poses X_AP, with lazily derived
/// data. Not thread-safe: one per thread.
class AssemblyGeometry {
 public:
  /// One entry per part; a part whose mesh is empty takes part in no check.
  AssemblyGeometry(std::vector<std::string> names, std::vector<TriangleMesh> meshes,
                   std::vector<Iso3> X_AP);
  /// The project's parts with the meshes validation loaded (absent ones empty).
  static AssemblyGeometry FromProject(const Project& project, const ProjectCheck& check);

  /// Number of parts.
  int num_parts() const { return static_cast<int>(names_.size()); }
  /// A part's name.
  const std::string& name(int part) const { return names_[part]; }
  /// A part's mesh in its own frame.
  const TriangleMesh& mesh(int part) const { return meshes_[part]; }
  /// True when the part has a mesh to check.
  bool has_mesh(int part) const { return !meshes_[part].empty(); }
  /// The part's assembled pose in the assembly frame A.
  const Iso3& X_AP(int part) const { return X_AP_[part]; }
  /// Box of the part at pose X (part frame to the frame of the box) [m].
  Aabb Box(int part, const Iso3& X) const;

  /// Ray, closest-point and inside queries on the part's mesh (part frame).
  const MeshQuery& query(int part);
  /// Points spread uniformly over the part's surface (part frame), the same for every call:
  /// about one per `spacing` squared of area, at least 500 and at most 6000.
  const std::vector<Vec3>& samples(int part);

  /// The part's mesh moved inward by `inset_m` (0: the mesh itself), part frame. Cached by depth.
  const TriangleMesh& inset_mesh(int part, double inset_m);
  /// The part's mesh moved inward by `inset_m` at its assembled pose, frame A, with its box tree
  /// for SweepContact. Cached by depth.
  const SweepMesh& sweep_mesh(int part, double inset_m);

  /// A world whose body i is part i moved inward by `inset_m` (0: the mesh itself), every body at
  /// its assembled pose when first built. Parts without a mesh have no shapes. Cached by depth.
  CollisionWorld& world(double inset_m);

 private:
  std::vector<std::string> names_;
  std::vector<TriangleMesh> meshes_;
  std::vector<Iso3> X_AP_;
  std::vector<std::unique_ptr<MeshQuery>> queries_;
  std::vector<std::vector<Vec3>> samples_;
  // By inset in nanometres, then part.
  std::map<std::pair<long long, int>, std::unique_ptr<TriangleMesh>> inset_meshes_;
  std::map<std::pair<long long, int>, std::unique_ptr<SweepMesh>> sweep_meshes_;
  std::map<long long, std::unique_ptr<CollisionWorld>> worlds_;  // by inset in nanometres
};

}  // namespace wrap
