#include "robot/home.h"

#include <cmath>
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
    q << 0.0, -0.5, 0.0, 2.3, 0.0, 0.0, 0.6;
  }
  return ClampToLimits(chain, q);
}

JointVector FacingHomeConfiguration(const Chain& chain, const Iso3& X_WB, const Vec3& target) {
  JointVector best = HomeConfiguration(chain);
  if (chain.dof() == 0 || chain.joints[0].type != Joint::Type::kRevolute) return best;
  auto distance = [&](const JointVector& q) {
    const Vec3 d = FlangePose(chain, X_WB, q).translation() - target;
    return std::hypot(d.x(), d.y());
  };
  double best_distance = distance(best);
  const JointVector home = best;
  for (double turn : {std::numbers::pi, -std::numbers::pi}) {
    JointVector q = home;
    q[0] += turn;
    if (!WithinLimits(chain, q)) continue;
    if (const double d = distance(q); d < best_distance - 1e-6) {
      best = q;
      best_distance = d;
    }
  }
  return best;
}

}  // namespace wrap
