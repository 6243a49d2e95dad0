// Two small meshers for the team's part generator: solids made of axis-aligned boxes (cells of a
// non-uniform rectilinear grid) and solids of revolution (cylinder stacks with flat caps).
#pragma once

#include <span>
#include <string_view>
#include <vector>

#include "core/result.h"
#include "geometry/mesh.h"

namespace wrap::partgen {

/// An axis-aligned box given by its lower and upper corners (any consistent length unit).
struct Box {
  Vec3 min = Vec3::Zero();  ///< Lower corner.
  Vec3 max = Vec3::Zero();  ///< Upper corner (each coordinate > the lower one).
};

/// The box centred at `center` with side lengths `size`.
Box CenteredBox(const Vec3& center, const Vec3& size);

/// A solid built by applying box unions and subtractions in order (later steps win). The boundary
/// planes of all boxes form a rectilinear grid; a cell is filled when the last step containing its
/// centre is a union.
class BoxSolid {
 public:
  /// Adds the box to the solid.
  void Add(const Box& box) { steps_.push_back({box, true}); }
  /// Cuts the box out of the solid (pockets, grooves).
  void Subtract(const Box& box) { steps_.push_back({box, false}); }

  /// Whether the point lies in a filled part of the solid (points on box faces are ambiguous).
  bool Contains(const Vec3& p) const;

  /// The boundary as a closed, outward-oriented triangle mesh: one quad (two triangles) per face
  /// between a filled and an empty grid cell. Fails with kInvalidInput on an empty or inverted
  /// box and with kInternal when the cells meet only along an edge (the boundary would not be
  /// manifold).
  Result<TriangleMesh> Mesh() const;

 private:
  struct Step {
    Box box;
    bool add = true;
  };
  std::vector<Step> steps_;
};

/// A point of a revolution profile: radius `r` > 0 and height `z` (same unit as r).
struct ProfilePoint {
  double r = 0.0;  ///< Distance from the z axis.
  double z = 0.0;  ///< Height along the z axis.
};

/// The solid swept by revolving `profile` (listed from the bottom cap to the top cap, the solid on
/// the axis side) about the z axis, approximated by `segments` facets (a multiple of 4 so that the
/// polygon is symmetric about both axes), closed by flat caps at the first and last point.
/// Fails with kInvalidInput on fewer than two points, a non-positive radius, repeated consecutive
/// points or a bad segment count.
Result<TriangleMesh> MeshRevolved(std::span<const ProfilePoint> profile, int segments);

/// Checks that every edge is shared by exactly two triangles running it in opposite directions
/// (closed, manifold, consistently oriented) and that no triangle is degenerate. kInternal
/// otherwise, naming `what`.
Result<void> CheckClosedOriented(const TriangleMesh& mesh, std::string_view what);

/// The mesh with every vertex multiplied by `factor` (e.g. 0.001 from mm to m).
TriangleMesh Scaled(const TriangleMesh& mesh, double factor);

}  // namespace wrap::partgen
