// Wrench sets from the project's types: gripper boxes, connection boxes, the mating load.
#include <limits>

#include "wrench/wrench.h"

namespace wrap {

WrenchBounds BoundsFromBox(const WrenchBox& box) {
  WrenchBounds b;
  b.upper << box.force_N, box.torque_Nm;
  b.lower = -b.upper;
  return b;
}

WrenchBounds CompressionOnlyZ(const WrenchBox& box) {
  WrenchBounds b = BoundsFromBox(box);
  b.lower[2] = 0.0;
  return b;
}

WrenchBounds UnboundedWrench() {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  WrenchBounds b;
  b.lower.setConstant(-kInf);
  b.upper.setConstant(kInf);
  return b;
}

WrenchGripper MakeGripper(std::string name, int body, const Iso3& X_WG, EndEffectorKind kind,
                          const WrenchLimits& limits) {
  WrenchGripper g;
  g.name = std::move(name);
  g.body = body;
  g.X_WG = X_WG;
  g.kind = kind;
  if (kind == EndEffectorKind::kVacuum) {
    g.assembly_limits = BoundsFromBox(limits.vacuum_assembly);
    g.transport_limits = BoundsFromBox(limits.vacuum_transport);
  } else {
    g.assembly_limits = BoundsFromBox(limits.two_finger);
    g.transport_limits = g.assembly_limits;
  }
  return g;
}

MatingLoad MatingLoadFromProject(const Mating& mating, const Iso3& X_WA, int moved, int base,
                                 const Vec3& p_WContact) {
  MatingLoad load;
  load.moved = moved;
  load.base = base;
  load.axis_W = X_WA.linear() * mating.axis;
  load.p_WContact = p_WContact;
  load.force_N = mating.force_N;
  load.torque_Nm = mating.torque_Nm;
  load.transverse_fraction = mating.transverse_fraction;
  load.offset_m = mating.offset_m;
  return load;
}

std::string_view ToString(WrenchGate gate) {
  switch (gate) {
    case WrenchGate::kAssembly:
      return "assembly";
    case WrenchGate::kTransport:
      return "transport";
    case WrenchGate::kRelease:
      return "release";
    case WrenchGate::kRest:
      return "rest";
  }
  return "assembly";
}

}  // namespace wrap
