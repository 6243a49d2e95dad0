#include "generator/step_designs.h"

namespace wrap::partgen {

StepDocumentSpec StepStoolSpec(const StepStoolDesign& d, const std::string& unit) {
  using Kind = StepPrimitive::Kind;
  StepProductSpec seat{"seat", {}, std::array<double, 4>{0.949, 0.557, 0.169, 1.0}};
  std::vector<StepPrimitive> plate = {{.kind = Kind::kBox,
                                       .origin = Vec3(-d.seat_side / 2, -d.seat_side / 2, 0.0),
                                       .size = Vec3(d.seat_side, d.seat_side, d.seat_thickness)}};
  for (const double x : {d.leg_offset, -d.leg_offset}) {
    for (const double y : {d.leg_offset, -d.leg_offset}) {
      // From a little below the underside, so that the cut opens the pocket cleanly.
      plate.push_back({.kind = Kind::kCylinder,
                       .subtract = true,
                       .origin = Vec3(x, y, -0.001),
                       .radius = d.pocket_radius,
                       .height = d.pocket_depth + 0.001});
    }
  }
  seat.solids.push_back(plate);

  StepProductSpec leg{"leg", {}, std::array<double, 4>{0.306, 0.475, 0.655, 1.0}};
  leg.solids.push_back(
      {{.kind = Kind::kCylinder,
        .origin = Vec3::Zero(),
        .radius = d.leg_radius,
        .height = d.leg_length},
       {.kind = Kind::kCylinder,
        .origin = Vec3(0, 0, d.leg_length - 0.001),  // overlaps the body: one fused solid
        .radius = d.peg_radius,
        .height = d.peg_length + 0.001}});

  StepDocumentSpec spec;
  spec.name = "stool";
  spec.unit = unit;
  spec.products = {seat, leg};
  Iso3 X_seat = Iso3::Identity();
  X_seat.translation() = Vec3(0, 0, d.leg_length);
  spec.instances.push_back({"seat", 0, X_seat});
  const Vec3 corners[4] = {{d.leg_offset, d.leg_offset, 0},
                           {-d.leg_offset, d.leg_offset, 0},
                           {-d.leg_offset, -d.leg_offset, 0},
                           {d.leg_offset, -d.leg_offset, 0}};
  for (int i = 0; i < 4; ++i) {
    Iso3 X = Iso3::Identity();
    X.translation() = corners[i];
    spec.instances.push_back({"leg_" + std::to_string(i + 1), 1, X});
  }
  return spec;
}

}  // namespace wrap::partgen
