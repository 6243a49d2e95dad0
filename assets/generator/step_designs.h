// The team's STEP assemblies: B-rep designs written as STEP files through OpenCASCADE
// (geometry/step_import.h), for the example project built from a CAD assembly and for tests.
#pragma once

#include "geometry/step_import.h"

namespace wrap::partgen {

/// Dimensions of the peg-and-hole stool [m] (the paper's stool, with round pockets).
struct StepStoolDesign {
  double seat_side = 0.240;       ///< Seat: square plate side.
  double seat_thickness = 0.025;  ///< Seat thickness.
  double leg_offset = 0.085;      ///< Legs at (+-offset, +-offset) from the seat centre.
  double pocket_radius = 0.010;   ///< Round blind pockets from below.
  double pocket_depth = 0.015;    ///< Pocket depth.
  double leg_radius = 0.0125;     ///< Leg body radius.
  double leg_length = 0.185;      ///< Leg body length (floor to seat underside).
  double peg_radius = 0.0095;     ///< Peg on the leg's top (0.5 mm lateral clearance).
  double peg_length = 0.014;      ///< Peg length (1 mm from the pocket floor).
};

/// The stool as a STEP assembly: product "seat" (pockets from below, frame at the centre of its
/// underside) and product "leg" (frame at the centre of its foot), instanced as "seat" at
/// z = leg_length and four times as "leg_1" ... "leg_4" at (+-offset, +-offset, 0), in
/// millimetres (`unit` "MM") or another unit the writer takes.
StepDocumentSpec StepStoolSpec(const StepStoolDesign& design = {}, const std::string& unit = "MM");

/// Where the example project's STEP file lives under assets/parts.
inline constexpr const char* kStepStoolFile = "step/stool.step";

}  // namespace wrap::partgen
