#include "robot/home.h"

#include <numbers>

namespace wrap {

JointVector HomeConfiguration(const Chain& chain) {
  constexpr double kPi = std::numbers::pi;
  JointVector q = ZeroConfiguration(chain);
  if ((chain.name == "ur5e" || chain.name == "ur10e") && chain.dof() == 6) {
    const double shoulder = -1.85;
    const double elbow = 1.55;
    q << kPi, shoulder, elbow, -kPi / 2 - shoulder - elbow, -kPi / 2, 0.0;
  } else if (chain.name == "openarm" && chain.dof() == 7) {
    q << 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 1.3;
  }
  return ClampToLimits(chain, q);
}

}  // namespace wrap
