// The Project: everything the planner and the GUI need, as plain structs (format version 1).
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/pose.h"
#include "geometry/step_import.h"

namespace wrap {

/// RGBA colour, each channel in [0, 1].
using Rgba = std::array<double, 4>;

/// A symmetric box of wrenches: |f_i| <= force_N[i], |m_i| <= torque_Nm[i], in a named frame.
struct WrenchBox {
  Vec3 force_N = Vec3::Zero();    ///< Force bounds along x, y, z [N].
  Vec3 torque_Nm = Vec3::Zero();  ///< Torque bounds about x, y, z [N m].
  bool operator==(const WrenchBox& o) const {
    return force_N == o.force_N && torque_Nm == o.torque_Nm;
  }
};

/// One rigid part: a mesh and where it is before and after assembly.
struct Part {
  std::string name;                   ///< Unique among parts and steps.
  std::string mesh;                   ///< Mesh path as written (relative to the project file;
                                      ///< may use ${NAME} from Project::paths); STL, OBJ, ...
                                      ///< or STEP (.step, .stp).
  std::string solid;                  ///< STEP only: the solid or part of the file to use, in
                                      ///< its own frame; empty: the whole file as assembled.
  double scale = 1.0;                 ///< Mesh units to metres (0.001 for mm, 0.01 for cm);
                                      ///< STEP files come in metres (1).
  std::optional<double> mass_kg;      ///< Mass [kg]; when absent, density * mesh volume.
  double density_kg_m3 = 1240.0;      ///< Density [kg/m^3] (PLA) used when mass is absent.
  Pose assembled_pose;                ///< X_AP: part frame in the assembly frame (default
                                      ///< identity: the mesh is modelled in place).
  Pose initial_pose;                  ///< X_WP: part frame in the world, resting on the table.
  Rgba color = {0.8, 0.8, 0.8, 1.0};  ///< Display colour.
  bool operator==(const Part&) const = default;
};

/// How one step's moved input meets its base input (paper §III: the mating wrench w_i and the
/// connection's wrench set T_pq).
struct Mating {
  std::string moved;                 ///< The input carried onto the other (a part or step name).
  std::string base;                  ///< The input it is mated onto.
  std::vector<Pose> final_poses;     ///< Valid X_BM (moved input in base input frame, both in
                                     ///< assembly coordinates); empty = from assembled poses.
  Vec3 axis = Vec3::UnitZ();         ///< Insertion direction of the moved input, assembly frame
                                     ///< (unit after load; the direction the moved part travels).
  double force_N = 10.0;             ///< Nominal mating force along the axis [N].
  double torque_Nm = 0.0;            ///< Nominal torque about the axis (screw motions) [N m].
  double transverse_fraction = 0.0;  ///< Transverse force bound as a fraction of force_N.
  double offset_m = 0.0;             ///< Bound on the application-point offset [m].
  double approach_m = 0.03;          ///< Straight approach distance along the axis [m].
  /// The final travel [m] in which the inputs may interfere (snap and press fits): within it the
  /// geometry checks allow `interference_depth_m` of overlap, before it only touching.
  double interference_travel_m = 1e-3;
  double interference_depth_m = 5e-4;          ///< Most overlap allowed in that final travel [m].
  std::optional<WrenchBox> connection_limits;  ///< T_pq in the mating frame; default: project's.
  bool operator==(const Mating&) const = default;
};

/// One assembly step: joins two inputs (parts or earlier steps) into the subassembly `name`.
struct Step {
  std::string name;                 ///< Name of the subassembly this step builds.
  std::vector<std::string> inputs;  ///< Exactly two inputs (part or step names).
  std::vector<std::string> parts;   ///< Optional declared part set; when given it must equal
                                    ///< the disjoint union of the inputs' parts.
  Mating mating;                    ///< How the inputs are joined.
  bool operator==(const Step&) const = default;
};

/// The kind of an end effector: what decides its grasp sampler and wrench model.
enum class EndEffectorKind { kTwoFinger, kVacuum };

/// Wrench limits of the end effectors (paper table "wrench limits"); boxes in the grasp frame.
struct WrenchLimits {
  WrenchBox two_finger{Vec3(50.0, 39.7, 50.0), Vec3(4.7, 4.5, 3.0)};  ///< Adopted values.
  WrenchBox vacuum_assembly{Vec3(0.0, 0.0, 110.0), Vec3::Zero()};     ///< Only Fz while mating.
  WrenchBox vacuum_transport{Vec3(67.4, 67.4, 110.0), Vec3(5.0, 5.0, 2.1)};
  bool operator==(const WrenchLimits&) const = default;
};

/// A mobile base (e.g. a Husky) that robots can be mounted on.
struct MobileBase {
  std::string name;   ///< Unique base name.
  std::string model;  ///< Catalog preset, e.g. "husky_dual_ur5e".
  Pose pose;          ///< X_W(base_link), on the floor.
  bool operator==(const MobileBase&) const = default;
};

/// One robot arm with its end effector.
struct Robot {
  std::string name;          ///< Unique robot name.
  std::string model;         ///< Catalog model ("ur5e", "ur10e", "openarm"); empty if urdf.
  std::string urdf;          ///< URDF path relative to the project file; empty if model.
  std::string urdf_root;     ///< URDF: base link of the chain (empty: the URDF's root).
  std::string urdf_tip;      ///< URDF: tip link = flange (empty: the only tip).
  std::string end_effector;  ///< Catalog end effector ("robotiq_2f85", "vacuum_cup", ...).
  std::string mounted_on;    ///< Name of a mobile base, or empty for the world.
  std::string mount;         ///< Mount point on that base ("left", "right").
  Pose base_pose;            ///< Robot base in the world, or in the mount frame.
  std::optional<WrenchLimits> wrench_limits;  ///< Overrides the project's limits for this robot.
  bool operator==(const Robot&) const = default;
};

/// The table every part starts on.
struct Table {
  Vec3 size = Vec3(1.6, 1.2, 0.05);  ///< Box side lengths [m]; the top is at z = height.
  Vec3 center_xy = Vec3::Zero();     ///< Centre of the top in the world (z ignored) [m].
  double height = 0.75;              ///< World z of the table top [m].
  double friction = 0.4;             ///< Coulomb coefficient part/table (PLA on wood, nominal).
  bool operator==(const Table&) const = default;
};

/// How the geometry checks (engine/mating) read the meshes: what counts as touching.
struct GeometryTolerances {
  double contact_m = 1e-3;  ///< Surfaces this close touch: the contact graph, and a step's inputs
                            ///< must touch at the mating pose [m].
  /// Overlap still read as touching [m]: tessellated curved faces that touch in the CAD model
  /// cut into each other by their chords' sag.
  double touch_depth_m = 2e-4;
  bool operator==(const GeometryTolerances&) const = default;
};

/// Planner defaults stored with the project (the CLI can override them).
struct PlannerDefaults {
  int grasps = 20;             ///< Grasp-set size per subassembly and end-effector kind.
  bool widen_grasps = true;    ///< Widen the grasp subset when a milestone fails.
  double time_limit_s = 60.0;  ///< Total planner time limit [s].
  std::uint64_t seed = 0;      ///< Random seed: same seed, same plan.
  bool operator==(const PlannerDefaults&) const = default;
};

/// A path variable: `${name}` in mesh or URDF paths expands to the environment variable `env`
/// when set, else to `default_value` (relative to the project file).
struct PathVariable {
  std::string default_value;  ///< Fallback path, relative to the project file.
  std::string env;            ///< Environment variable that overrides it (may be empty).
  std::string hint;           ///< Where to get the files, shown when they are missing.
  bool operator==(const PathVariable&) const = default;
};

/// A whole assembly project. Names of parts and steps share one namespace.
struct Project {
  static constexpr int kFormatVersion = 1;  ///< The version this build reads and writes.

  std::string name;                           ///< Display name.
  std::string description;                    ///< Free text.
  std::map<std::string, PathVariable> paths;  ///< Path variables for meshes and URDFs.
  std::vector<Part> parts;                    ///< The parts, in file order.
  std::vector<Step> steps;                    ///< The dependency DAG as steps, in file order.
  WrenchBox connection_limits{Vec3(200.0, 200.0, 200.0), Vec3(10.0, 10.0, 10.0)};  ///< T_pq.
  WrenchLimits wrench_limits;            ///< End-effector limits for all robots.
  std::vector<MobileBase> mobile_bases;  ///< Bases robots can be mounted on.
  std::vector<Robot> robots;             ///< The robots around the table.
  Table table;                           ///< The table.
  GeometryTolerances geometry;           ///< What the geometry checks count as touching.
  PlannerDefaults planner;               ///< Planner defaults.
  StepTessellation tessellation;         ///< How STEP meshes are tessellated.
  bool operator==(const Project&) const = default;
};

/// The step named `name`, or null.
inline const Step* FindStep(const Project& project, const std::string& name) {
  for (const Step& step : project.steps) {
    if (step.name == name) return &step;
  }
  return nullptr;
}
/// The step named `name`, or null (to edit it).
inline Step* FindStep(Project& project, const std::string& name) {
  return const_cast<Step*>(FindStep(std::as_const(project), name));
}

}  // namespace wrap
