// The names a project may use for robot models, end effectors and mobile-base presets.
// Kinematics and shapes live in the robot stage; this is what validation and `wrap info` need.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/pose.h"
#include "model/project.h"

namespace wrap {

/// Catalog facts about a robot arm model (../shared/robots).
struct RobotModelInfo {
  std::string name;         ///< Catalog key, e.g. "ur5e".
  std::string title;        ///< Display name, e.g. "Universal Robots UR5e".
  int dof = 0;              ///< Number of joints.
  double reach_m = 0.0;     ///< Horizontal reach of the flange from the first joint axis [m].
  double payload_kg = 0.0;  ///< Rated payload [kg].
};

/// Catalog facts about an end effector.
struct EndEffectorInfo {
  std::string name;                                    ///< Catalog key, e.g. "robotiq_2f85".
  std::string title;                                   ///< Display name.
  EndEffectorKind kind = EndEffectorKind::kTwoFinger;  ///< Decides grasps and wrench model.
  double tcp_offset_m = 0.0;  ///< Flange to TCP along the approach axis [m].
};

/// A mount point of a mobile-base preset.
struct MountInfo {
  std::string name;  ///< e.g. "left".
  Pose X_BM;         ///< Mount frame (robot base at identity base_pose) in the base frame,
                     ///< which lies on the floor under the base's centre.
};

/// Catalog facts about a mobile-base preset.
struct MobileBaseInfo {
  std::string name;               ///< Catalog key, e.g. "husky_dual_ur5e".
  std::string title;              ///< Display name.
  std::vector<MountInfo> mounts;  ///< Where arms attach.
};

/// All robot models, end effectors and base presets known to this build.
const std::vector<RobotModelInfo>& RobotModels();
const std::vector<EndEffectorInfo>& EndEffectors();
const std::vector<MobileBaseInfo>& MobileBasePresets();

/// Look-ups by catalog key; nullptr when unknown.
const RobotModelInfo* FindRobotModel(std::string_view name);
const EndEffectorInfo* FindEndEffector(std::string_view name);
const MobileBaseInfo* FindMobileBasePreset(std::string_view name);

/// Comma-separated keys, for error messages ("ur5e, ur10e, openarm").
std::string RobotModelNames();
std::string EndEffectorNames();
std::string MobileBasePresetNames();

/// Short name of an end-effector kind: "two-finger" or "vacuum".
std::string_view ToString(EndEffectorKind kind);

}  // namespace wrap
