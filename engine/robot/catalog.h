// The robot catalog: arm models, end effectors and mobile-base presets, read from the JSON files
// of assets/robots that are compiled into the library. The names are those of model/catalog.h.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "model/project.h"
#include "robot/chain.h"

namespace wrap {

/// The two fingers of a parallel gripper as boxes that slide along the closing axis.
struct FingerGeometry {
  Vec3 closing_axis_F = Vec3::UnitX();  ///< Unit axis the fingers close along, in F.
  Vec3 center_F = Vec3::Zero();         ///< Midpoint between the fingers' inner faces, in F [m].
  Vec3 half_extents = Vec3::Zero();     ///< Half sizes of one finger box along F's axes [m].
};

/// An end effector: its TCP, collision shapes and grasp and wrench facts. Frames: F is the robot
/// flange (z = approach), T the TCP (the grasp frame G when holding a part).
struct EndEffector {
  std::string name;                                    ///< Catalog key, e.g. "robotiq_2f85".
  std::string title;                                   ///< Display name.
  EndEffectorKind kind = EndEffectorKind::kTwoFinger;  ///< Two-finger or vacuum.
  Iso3 X_FT = Iso3::Identity();                        ///< TCP in the flange frame.
  double mass_kg = 0.0;                                ///< Mass [kg], 0 when unknown.
  /// Collision shapes in F; for a two-finger gripper the fingers are included, fully open (the
  /// widest, the conservative default). `EndEffectorShapesAt` moves them to another opening.
  std::vector<Shape> collision;
  std::vector<Shape> visual;  ///< Display shapes in F (the collision shapes in the catalog).
  /// Indices in `collision` (and `visual`) of the two finger boxes, -1 for a vacuum gripper.
  std::array<int, 2> finger_shapes = {-1, -1};
  FingerGeometry fingers;     ///< Finger boxes (two-finger only).
  double stroke_m = 0.0;      ///< Largest opening between the fingers' inner faces [m]; 0 vacuum.
  double pad_width_m = 0.0;   ///< Finger pad size across the approach axis [m] (two-finger).
  double pad_length_m = 0.0;  ///< Finger pad size along the approach axis [m] (two-finger).
  Vec3 pad_center_F = Vec3::Zero();  ///< Midpoint between the two pads, in F [m].
  double cup_diameter_m = 0.0;       ///< Suction cup diameter [m] (vacuum only).
  /// Wrench the gripper transmits without slipping while mating (paper table "wrench limits"),
  /// a box in the TCP frame [N, N m]. Two-finger: the same as transport.
  WrenchBox wrench_assembly;
  WrenchBox wrench_transport;  ///< Wrench limits while carrying a part, TCP frame [N, N m].
};

/// Where an arm attaches to a mobile base.
struct MobileBaseMount {
  std::string name;              ///< e.g. "left".
  Iso3 X_BM = Iso3::Identity();  ///< Mount frame in the base frame B (on the floor).
};

/// A mobile-base preset: the base's collision shapes and the mounts for arms. Frame B lies on the
/// floor under the base's centre, z up (a project's mobile-base pose places it); the URDF's
/// base_link is B raised by `base_height_m`.
struct MobileBaseModel {
  std::string name;              ///< Catalog key, e.g. "husky_dual_ur5e".
  std::string title;             ///< Display name.
  double base_height_m = 0.0;    ///< Height of the URDF's base_link above B (the floor) [m].
  double mass_kg = 0.0;          ///< Mass of the base [kg].
  std::vector<Shape> collision;  ///< Collision shapes in B.
  std::vector<Shape> visual;     ///< Display shapes in B.
  /// Mount frames in B. A mount frame is the ROS base_link of the arm there; a catalog UR chain's
  /// base is DH frame 0, which is that frame rotated pi about z (base_pose rpy (0, 0, pi)
  /// reproduces the real robot; identity only shifts q1 by pi).
  std::vector<MobileBaseMount> mounts;
  std::string arm_model;         ///< The arm the preset is built for, e.g. "ur5e".
  std::string end_effector;      ///< Its end effector, e.g. "robotiq_2f85".
  double tool_coupling_m = 0.0;  ///< Spacer between flange and end effector [m].
};

/// The arm model `name` ("ur5e", "ur10e", "openarm"). Parses the embedded JSON on each call: keep
/// the result. Fails with kInvalidInput naming the known models when `name` is unknown.
Result<Chain> LoadRobotModel(std::string_view name);

/// The end effector `name` ("robotiq_2f85", "vacuum_cup", "openarm_hand"); kInvalidInput when
/// unknown.
Result<EndEffector> LoadEndEffector(std::string_view name);

/// The mobile-base preset `name` ("husky_dual_ur5e"); kInvalidInput when unknown.
Result<MobileBaseModel> LoadMobileBase(std::string_view name);

/// Names of the embedded robot models, end effectors and mobile bases, in catalog order.
std::vector<std::string> CatalogRobotModelNames();
std::vector<std::string> CatalogEndEffectorNames();
std::vector<std::string> CatalogMobileBaseNames();

/// Parses a robot-model JSON document (schema "wrap.robot_model/1", see assets/robots/ur5e.json
/// and openarm.json). `origin` names the document in messages. Fails with kInvalidInput naming
/// the JSON path and the problem.
Result<Chain> ParseRobotModel(std::string_view json_text, std::string_view origin);

/// Parses an end-effector JSON document (schema "wrap.end_effector/1").
Result<EndEffector> ParseEndEffector(std::string_view json_text, std::string_view origin);

/// Parses a mobile-base JSON document (schema "wrap.mobile_base/1").
Result<MobileBaseModel> ParseMobileBase(std::string_view json_text, std::string_view origin);

/// The collision shapes of `ee` in F with the fingers at `opening_m` between their inner faces
/// (clamped to [0, stroke]); a vacuum gripper's shapes unchanged.
std::vector<Shape> EndEffectorShapesAt(const EndEffector& ee, double opening_m);

}  // namespace wrap
