// The wrench limits of a grasp: the grasp types' names, the physical model that scales a reduced
// two-finger grasp's torque limits from its contact patch, and the one function that turns a
// grasp into its wrench box (docs/algorithms.md "Grasp types").
#include <algorithm>
#include <cmath>

#include "grasp/grasp.h"

namespace wrap {

std::string_view ToString(GraspType type) {
  switch (type) {
    case GraspType::kFullPad:
      return "full_pad";
    case GraspType::kPartialPad:
      return "partial_pad";
    case GraspType::kFingertip:
      return "fingertip";
  }
  return "full_pad";
}

Vec3 GraspTorqueScale(const PadPatch& patch, double full_area_m2, const Vec3& closing_G,
                      const Vec3& approach_G) {
  if (!(full_area_m2 > 0.0)) return Vec3::Ones();
  // The reference: a square patch of the full-pad area carries the adopted box.
  const double side = std::sqrt(full_area_m2);
  const double radius =
      std::clamp(std::sqrt(std::max(0.0, patch.area_m2) / full_area_m2), 0.0, 1.0);
  const double along_length = std::clamp(patch.length_m / side, 0.0, 1.0);
  const double across_width = std::clamp(patch.width_m / side, 0.0, 1.0);
  const Vec3 width_G = closing_G.cross(approach_G);
  // Torque about the closing axis: torsional friction over the patch (radius). About the pad's
  // width axis: the pressure moment along the pad's length. About the approach axis: the
  // pressure moment across its width. The axes are G's, so each term lands on one component.
  const Vec3 scale = closing_G.cwiseAbs() * radius + width_G.cwiseAbs() * along_length +
                     approach_G.cwiseAbs() * across_width;
  return scale.cwiseMin(1.0).cwiseMax(0.0);
}

WrenchLimits GraspLimits(const WrenchLimits& limits, const Vec3& torque_scale) {
  WrenchLimits out = limits;
  out.two_finger.torque_Nm = limits.two_finger.torque_Nm.cwiseProduct(torque_scale);
  return out;
}

}  // namespace wrap
