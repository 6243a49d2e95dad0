// The cell as a scene to draw (and later to simulate): the table, the robots with their shapes and
// end effectors, mobile bases and the parts, plus the state that moves them (joint positions,
// finger openings, part poses). Built from a validated project; plain data, no MuJoCo, no GL.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "geometry/mesh.h"
#include "model/project.h"
#include "model/validate.h"
#include "robot/catalog.h"
#include "robot/chain.h"
#include "robot/kinematics.h"

namespace wrap {

/// A robot arm of the scene with its end effector.
struct SceneRobot {
  std::string name;              ///< The project's robot name.
  Chain chain;                   ///< Links with their visual shapes in the link frames.
  EndEffector end_effector;      ///< Mounted at the flange F (chain.X_LF in the last link).
  Iso3 X_WB = Iso3::Identity();  ///< Robot base frame B in the world W.
  JointVector home;              ///< Home configuration facing the table [rad or m]: the
                                 ///< chain's HomeConfiguration (robot/home.h), its first joint
                                 ///< turned by pi when that brings the flange nearer the table.
  bool mounted = false;          ///< Mounted on a mobile base (never gets a pedestal).
  /// Pedestal under the base: a cylinder of this radius [m] from z = pedestal_bottom_z [m] (the
  /// table top, or the floor when the base is off the table) up to the base. 0: no pedestal
  /// (the base stands on the table or floor, or on a mobile base).
  double pedestal_radius_m = 0.0;
  double pedestal_bottom_z = 0.0;  ///< World z where the pedestal starts [m].
};

/// A mobile base of the scene (e.g. a Husky) with its display shapes.
struct SceneMobileBase {
  std::string name;              ///< The project's base name.
  MobileBaseModel model;         ///< Catalog preset: shapes in its frame B on the floor.
  Iso3 X_WB = Iso3::Identity();  ///< Frame B in the world.
};

/// A part of the scene.
struct ScenePart {
  std::string name;                          ///< The project's part name.
  std::shared_ptr<const TriangleMesh> mesh;  ///< Mesh in the part frame P [m]; parts made from
                                             ///< the same file share one mesh.
  Rgba color = {0.8, 0.8, 0.8, 1.0};         ///< Display colour.
  Iso3 X_WP_initial = Iso3::Identity();      ///< Where it starts, on the table.
  Iso3 X_AP = Iso3::Identity();              ///< Where it sits in the assembly frame A.
  double mass_kg = 0.0;                      ///< Mass [kg] (physics; 0 when unknown).
  Vec3 com_P = Vec3::Zero();                 ///< Centre of mass in the part frame [m].
  Mat3 inertia_com = Mat3::Zero();           ///< Inertia about the COM, part axes [kg m^2].
};

/// One assembly step, as far as drawing needs it (the exploded goal).
struct SceneStep {
  std::string name;              ///< The step's name.
  std::vector<int> moved_parts;  ///< Indices into CellScene::parts of the moved input.
  Vec3 axis_A = Vec3::UnitZ();   ///< Unit insertion direction of the moved input, in A.
};

/// The table: a box whose top face is centred at `top_center`.
struct SceneTable {
  Vec3 size = Vec3(1.6, 1.2, 0.05);    ///< Side lengths [m].
  Vec3 top_center = Vec3(0, 0, 0.75);  ///< Centre of the top face in the world [m].
  double friction = 0.4;               ///< Coulomb coefficient part/table (physics).
};

/// Everything drawn, indexed like the project (robots, parts, steps in file order).
struct CellScene {
  std::string name;                           ///< Project name (captions, titles).
  SceneTable table;                           ///< The table.
  std::vector<SceneRobot> robots;             ///< Robot arms.
  std::vector<SceneMobileBase> mobile_bases;  ///< Mobile bases.
  std::vector<ScenePart> parts;               ///< Parts.
  std::vector<SceneStep> steps;               ///< Assembly steps.
};

/// What moves in a scene: one entry per robot and per part of its CellScene.
struct SceneState {
  std::vector<JointVector> q;     ///< Joint positions per robot [rad or m].
  std::vector<double> opening_m;  ///< Finger opening per robot [m] (vacuum grippers ignore it).
  std::vector<Iso3> X_WP;         ///< Pose of each part in the world.
};

/// Builds the scene of a project that LoadProject (or the CLI's LoadChecked) accepted: robots
/// from the catalog or their URDF (resolved against `project_file`), home configurations,
/// pedestals, mobile bases, part meshes from `check.parts` and the steps from `check.tree`.
/// Fails with kInvalidInput naming the robot, part or mesh when something the validation lets
/// through cannot be drawn (an unknown model, a URDF that does not import, a part without a
/// loaded mesh).
Result<CellScene> BuildCellScene(const Project& project, const ProjectCheck& check,
                                 const std::filesystem::path& project_file);

/// The initial scene: robots at home with open grippers, parts at their initial poses.
SceneState InitialState(const CellScene& scene);

/// Options of GoalState.
struct GoalOptions {
  /// Exploded view: each step's moved input is drawn back along its insertion axis by this
  /// fraction of the assembly's largest side (steps add up along the DAG). 0: assembled.
  double explode = 0.0;
};

/// The assembled goal: robots at home, the whole assembly centred on the table and resting on
/// its top (lowest vertex at the table height), exploded when `options.explode` > 0. Fails with
/// kInvalidInput for a negative or non-finite explode factor.
Result<SceneState> GoalState(const CellScene& scene, const GoalOptions& options = {});

/// Axis-aligned box in the world around what is drawn at `state`: the table top, the robots
/// (links, end effectors, pedestals), mobile bases and parts; not the floor and table legs.
Aabb SceneBounds(const CellScene& scene, const SceneState& state);

/// Axis-aligned box of a shape whose link frame is at X_WL in the world [m].
Aabb ShapeBounds(const Shape& shape, const Iso3& X_WL);

}  // namespace wrap
