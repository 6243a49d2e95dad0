// The types of two-finger grasp (full-pad, partial-pad, fingertip), apart from the rest of
// grasp.h so that the plan's data can name them without the project model.
#pragma once

#include <string_view>

namespace wrap {

/// How a two-finger grasp touches its part (docs/algorithms.md "Grasp types"). Vacuum grasps are
/// always kFullPad (the cup's whole disc rests on the part).
enum class GraspType {
  kFullPad,     ///< Both pads touch over at least the full-pad contact (default 1 cm^2).
  kPartialPad,  ///< Pads centred on the contacts, touching less than that (but above the floor).
  kFingertip,   ///< Only the pads' tips touch: the contacts lie near the fingertips, so the
                ///< gripper body stays farther from what surrounds the held feature.
};

/// "full_pad", "partial_pad", "fingertip".
std::string_view ToString(GraspType type);

/// The number of grasp types (for per-type counts, indexed by the enum's value).
inline constexpr int kGraspTypes = 3;

}  // namespace wrap
