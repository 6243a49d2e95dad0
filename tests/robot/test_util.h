// Helpers shared by the robot tests.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "robot/catalog.h"
#include "robot/kinematics.h"

namespace wrap::testing {

/// The catalog model `name`; fails the test when it does not load.
inline Chain LoadOrDie(std::string_view name) {
  Result<Chain> chain = LoadRobotModel(name);
  EXPECT_TRUE(chain.has_value()) << (chain ? "" : chain.error().message);
  return chain ? *chain : Chain{};
}

/// Angle of the rotation between two poses [rad].
inline double RotationError(const Iso3& a, const Iso3& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle();
}

/// Distance between the origins of two poses [m].
inline double PositionError(const Iso3& a, const Iso3& b) {
  return (a.translation() - b.translation()).norm();
}

/// A pose from translation and roll-pitch-yaw.
inline Iso3 MakePose(const Vec3& xyz, const Vec3& rpy) { return ToIsometry(Pose{xyz, rpy}); }

}  // namespace wrap::testing
