// Triangle meshes and their mass properties (the geometry stage's plain data).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/pose.h"

namespace wrap {

/// An indexed triangle mesh in metres, in the frame of the part it belongs to.
struct TriangleMesh {
  std::vector<Vec3> vertices;              ///< Vertex positions [m].
  std::vector<Eigen::Vector3i> triangles;  ///< Vertex indices, counter-clockwise seen from outside.

  bool empty() const { return triangles.empty(); }
};

/// Axis-aligned bounding box [m].
struct Aabb {
  Vec3 min = Vec3::Zero();  ///< Lower corner [m].
  Vec3 max = Vec3::Zero();  ///< Upper corner [m].
  Vec3 size() const { return max - min; }
};

/// Topological facts about a mesh, used by validation.
struct MeshTopology {
  int boundary_edges = 0;        ///< Edges used by exactly one triangle (0 for a closed mesh).
  int non_manifold_edges = 0;    ///< Edges used by more than two triangles.
  int degenerate_triangles = 0;  ///< Triangles of (near) zero area.
  bool closed() const { return boundary_edges == 0 && non_manifold_edges == 0; }
};

/// Mass properties of a solid of uniform density bounded by a closed mesh.
struct MassProperties {
  double volume_m3 = 0.0;           ///< Enclosed volume [m^3] (positive if outward).
  Vec3 com = Vec3::Zero();          ///< Centre of mass in the mesh frame [m].
  Mat3 inertia_com = Mat3::Zero();  ///< Inertia tensor per unit density about the COM,
                                    ///< axes of the mesh frame [m^5]; times density
                                    ///< [kg/m^3] gives kg m^2.
};

/// Bounding box of the vertices (zero box for an empty mesh).
Aabb ComputeAabb(const TriangleMesh& mesh);

/// Surface area [m^2].
double SurfaceArea(const TriangleMesh& mesh);

/// Boundary, non-manifold and degenerate counts; `area_eps` [m^2] is the degenerate threshold.
MeshTopology AnalyzeTopology(const TriangleMesh& mesh, double area_eps = 1e-14);

/// Volume, centre of mass and inertia of the solid bounded by `mesh` (divergence theorem over
/// signed tetrahedra, exact for closed meshes). Inward-facing meshes give a negative volume (and a
/// negated inertia); the caller decides what to do with that. With no enclosed volume (an open
/// sheet, a flat mesh) the COM is the box centre and the inertia zero.
MassProperties ComputeMassProperties(const TriangleMesh& mesh);

/// The mesh with every vertex mapped through `X` (triangles unchanged).
TriangleMesh Transformed(const TriangleMesh& mesh, const Iso3& X);

/// Closed box from `lo` to `hi` [m]: 8 vertices, 12 triangles counter-clockwise seen from outside.
TriangleMesh BoxMesh(const Vec3& lo, const Vec3& hi);

}  // namespace wrap
