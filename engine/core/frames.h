// Frames defined by one axis, shared by the stages that must agree on them.
#pragma once

#include "core/pose.h"

namespace wrap {

/// A rotation whose z axis is `z_axis` (normalised here; nonzero), x the projection of world x
/// (world y when z is near x) onto the plane normal to z: the frame of a connection, whose z is
/// the insertion axis, as the planner, the plan validator and the simulator all define it.
Mat3 RotationWithZ(const Vec3& z_axis);

}  // namespace wrap
