// The vertices of the uncertainty set U of external wrenches (paper §IV-A "Robust
// satisfaction"), in a flat layout for the LP loop. Internal to the wrench stage.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "wrench/wrench.h"

namespace wrap::detail {

/// What generated a vertex set.
enum class VertexKind {
  kGravity,    ///< One vertex: gravity alone.
  kMating,     ///< Gravity + mating wrench; signs (e1, e2, d1, d2) of transverse and offset.
  kTransport,  ///< Gravity + d'Alembert load of an acceleration; signs (x, y, z, 0).
};

/// The vertices: for vertex v, body k, w[(v * bodies + k) * 6 + i] is component i of the
/// external wrench on body k (moments about the reference point O, world frame).
struct VertexSet {
  VertexKind kind = VertexKind::kGravity;         ///< What generated the set.
  int count = 0;                                  ///< Number of vertices.
  int bodies = 0;                                 ///< Bodies per vertex.
  std::vector<double> w;                          ///< count * bodies * 6 wrench components.
  std::vector<std::array<std::int8_t, 4>> signs;  ///< Per vertex: the +-1 of each parameter.
  bool transverse = false;                        ///< Mating: transverse components present.
  bool offset = false;                            ///< Mating: application-point offset present.
  Vec3 t1 = Vec3::UnitX();                        ///< Mating: first transverse direction.
  Vec3 t2 = Vec3::UnitY();                        ///< Mating: second transverse direction.

  /// The external wrenches of vertex v (bodies * 6 values).
  const double* vertex(int v) const { return w.data() + static_cast<std::size_t>(v) * bodies * 6; }
};

/// Fills `out` with the vertices of U for a validated configuration; moments about p_WO.
void BuildVertices(const StepConfiguration& config, const WrenchQuery& query, const Vec3& p_WO,
                   VertexSet& out);

/// Human-readable description of vertex v, e.g. "transverse +x -y, offset +x +y".
std::string VertexLabel(const VertexSet& set, int v);

/// Name of a direction: "+x", "-z" when it is a world axis, else "(0.71, 0.71, 0.00)".
std::string DirectionName(const Vec3& d);

/// Two unit directions t1, t2 with (t1, t2, a) right-handed and orthonormal; t1 is world x
/// projected onto the plane normal to `a` (world y when a is nearly along x).
void TransverseBasis(const Vec3& a, Vec3& t1, Vec3& t2);

}  // namespace wrap::detail
