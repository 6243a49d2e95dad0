#include "core/frames.h"

#include <cmath>

namespace wrap {

Mat3 RotationWithZ(const Vec3& z_axis) {
  const Vec3 z = z_axis.normalized();
  const Vec3 helper = std::abs(z.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 x = (helper - helper.dot(z) * z).normalized();
  Mat3 R;
  R.col(0) = x;
  R.col(1) = z.cross(x);
  R.col(2) = z;
  return R;
}

}  // namespace wrap
