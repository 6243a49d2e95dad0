#include "core/pose.h"

#include <cmath>

namespace wrap {

Mat3 RotationFromRpy(const Vec3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

Vec3 RpyFromRotation(const Mat3& R) {
  // R = Rz(y) Ry(p) Rx(r): R(2,0) = -sin p.
  const double sp = std::clamp(-R(2, 0), -1.0, 1.0);
  const double pitch = std::asin(sp);
  double roll = 0.0;
  double yaw = 0.0;
  if (std::abs(sp) < 1.0 - 1e-12) {
    roll = std::atan2(R(2, 1), R(2, 2));
    yaw = std::atan2(R(1, 0), R(0, 0));
  } else {
    // Gimbal lock: only roll - yaw (or roll + yaw) is defined; put it all into yaw.
    yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  return Vec3(roll, pitch, yaw);
}

Iso3 ToIsometry(const Pose& pose) {
  Iso3 X = Iso3::Identity();
  X.linear() = RotationFromRpy(pose.rpy);
  X.translation() = pose.xyz;
  return X;
}

Pose FromIsometry(const Iso3& X) {
  Pose p;
  p.xyz = X.translation();
  p.rpy = RpyFromRotation(X.linear());
  return p;
}

}  // namespace wrap
