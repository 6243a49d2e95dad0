// Home ("ready") configurations: where a robot rests when no plan moves it, e.g. in renders of
// the initial scene and the goal, and where an idle robot can park.
#pragma once

#include "robot/chain.h"
#include "robot/kinematics.h"

namespace wrap {

/// A ready pose of `chain`, chosen by its catalog name (`Chain::name`), within its limits:
///
/// - "ur5e", "ur10e": q = (pi, -1.85, 1.55, -1.27, -pi/2, 0). With the catalog's base frame (DH
///   frame 0, whose +x the example projects point at the table centre), q1 = pi turns the arm
///   towards the table; the upper arm leans back from vertical, the elbow folds the forearm
///   forward and down, and the wrist points the tool straight down (q2 + q3 + q4 = -pi/2): the
///   TCP hovers over the table edge, above the base, clear of the parts and of the other arms.
/// - "openarm": q = (0, -0.5, 0, 2.3, 0, 0, 0.6). The arm leans back from its base (the zero pose
///   is straight up) with the elbow folded 132 deg towards the base's +x (the table centre in the
///   example projects) and the hand tilted by joint 7: the hand stays near its own base, clear of
///   the neighbouring arms in cross_openarm.
/// - any other chain (URDF imports): the zero configuration clamped into the joint limits.
JointVector HomeConfiguration(const Chain& chain);

/// HomeConfiguration, or that with the first (revolute) joint turned by pi when the flange then
/// comes nearer `target` in the horizontal plane (e.g. the table centre, for arms on a mobile
/// base whose mount frames do not face the table). `X_WB` is the robot base in the world.
JointVector FacingHomeConfiguration(const Chain& chain, const Iso3& X_WB, const Vec3& target);

}  // namespace wrap
