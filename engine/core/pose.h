// Eigen aliases and the pose type used in files: a translation and roll-pitch-yaw angles.
#pragma once

#include <Eigen/Geometry>

namespace wrap {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Iso3 = Eigen::Isometry3d;

/// A rigid pose as written in project files: translation in m, then rotation as roll, pitch, yaw
/// in rad, applied as R = Rz(yaw) * Ry(pitch) * Rx(roll) (the URDF convention).
struct Pose {
  Vec3 xyz = Vec3::Zero();  ///< Translation [m].
  Vec3 rpy = Vec3::Zero();  ///< Roll, pitch, yaw [rad].

  bool operator==(const Pose& o) const { return xyz == o.xyz && rpy == o.rpy; }
};

/// Rotation matrix of roll, pitch, yaw [rad]: Rz(yaw) * Ry(pitch) * Rx(roll).
Mat3 RotationFromRpy(const Vec3& rpy);

/// Roll, pitch, yaw [rad] of a rotation matrix; pitch in [-pi/2, pi/2].
Vec3 RpyFromRotation(const Mat3& R);

/// The isometry of a file pose.
Iso3 ToIsometry(const Pose& pose);

/// The file pose of an isometry (rotation as roll, pitch, yaw).
Pose FromIsometry(const Iso3& X);

}  // namespace wrap
