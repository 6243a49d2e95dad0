// The task planner's view of a preprocessed project: robots with their kinematics and IK, the
// parts in the assembly frame, the interface of every assembly step, and the collision cell.
// Built once per planner run; read-only afterwards (the cell is copied by whoever checks).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "grasp/preprocess.h"
#include "model/project.h"
#include "model/validate.h"
#include "robot/catalog.h"
#include "robot/cell.h"
#include "robot/chain.h"
#include "robot/ik.h"
#include "wrench/wrench.h"

namespace wrap {

/// A robot as the planner uses it.
struct TaskRobot {
  std::string name;                ///< Project robot name.
  Chain chain;                     ///< Kinematic chain with collision shapes.
  EndEffector end_effector;        ///< Its end effector.
  Iso3 X_WB = Iso3::Identity();    ///< Base in the world.
  Iso3 X_BW = Iso3::Identity();    ///< Inverse of X_WB.
  JointVector home;                ///< Home facing the table (free robots wait here).
  std::optional<UrAnalyticIk> ur;  ///< Closed-form IK when the chain is UR-like.
  WrenchLimits limits;             ///< Wrench limits (robot override or the project's).
  int grasp_set = -1;              ///< Index of its end effector in Preprocessed::end_effectors.
  Vec3 shoulder_W = Vec3::Zero();  ///< Centre of its reach sphere in the world [m].
  double reach_m = 0.0;            ///< Radius of the reach sphere around shoulder_W [m].
};

/// Where the two inputs of an assembly step meet.
struct StepInterface {
  int node = -1;                   ///< Step node id.
  int step = -1;                   ///< Index into Project::steps.
  int moved = -1;                  ///< Node id of the moved input.
  int base = -1;                   ///< Node id of the base input.
  int part_moved = -1;             ///< Part of the moved input at the interface.
  int part_base = -1;              ///< Part of the base input at the interface.
  Vec3 p_A = Vec3::Zero();         ///< Interface point in the assembly frame A [m].
  Vec3 axis_A = Vec3::UnitZ();     ///< Unit insertion direction of the moved input in A.
  Iso3 X_AC = Iso3::Identity();    ///< Connection frame in A: origin p_A, z along axis_A.
  WrenchBounds connection;         ///< T_pq once made, in C.
  double approach_m = 0.03;        ///< Straight approach distance [m].
  const Mating* mating = nullptr;  ///< The project's mating.
};

/// Static planning data of one run.
struct TaskWorld {
  const Project* project = nullptr;
  const ProjectCheck* check = nullptr;
  const AssemblyTree* tree = nullptr;
  const Preprocessed* pre = nullptr;
  std::vector<TaskRobot> robots;                ///< Project::robots order.
  int num_parts = 0;                            ///< Parts (node ids 0..num_parts-1).
  int num_nodes = 0;                            ///< DAG nodes.
  std::vector<Iso3> X_AP;                       ///< Each part in the assembly frame.
  std::vector<double> part_mass;                ///< Each part's mass [kg].
  std::vector<Vec3> part_com_A;                 ///< Each part's centre of mass in A [m].
  std::vector<Aabb> part_box_A;                 ///< Each part's box in A [m].
  std::vector<StepInterface> steps;             ///< By node id - num_parts.
  std::vector<std::vector<int>> subtree_steps;  ///< Per node: step node ids inside it.
  std::vector<Iso3> initial_X_WA;    ///< Per part: its assembly frame at the initial pose.
  double table_top = 0.75;           ///< World z of the table top [m].
  Vec3 table_center = Vec3::Zero();  ///< Centre of the table top [m].
  CellDef cell_def;                  ///< Robots, parts (objects = parts) and table.

  /// The step interface of a step node.
  const StepInterface& interface(int step_node) const { return steps[step_node - num_parts]; }
  /// Grasp set of a node for a robot's end effector, or nullptr.
  const GraspSet* grasp_set(int node, int robot) const;
  /// The root node id.
  int root() const { return tree->root; }
};

/// Builds the planner's world. Fails with kInvalidInput when a robot model or end effector does
/// not load or the preprocessing does not match the project.
Result<TaskWorld> BuildTaskWorld(const Project& project, const ProjectCheck& check,
                                 const Preprocessed& pre,
                                 const std::filesystem::path& project_file);

/// Hull vertices of a resting object this close to the table top bear on it: the wrench LP's
/// table supports (TableContacts), and the physics run's support spheres that match them [m].
inline constexpr double kTableContactReach_m = 2e-3;

/// Each part's own hull vertices that touch the table (within `tolerance_m`) when `node`'s frame
/// A is at X_WA, as the plan validator counts them: pairs (part index, world points on the
/// table top), at most 16 points per part (their 2-D hull, clipped to the table).
std::vector<std::pair<int, std::vector<Vec3>>> TableContacts(
    const TaskWorld& world, int node, const Iso3& X_WA, double tolerance_m = kTableContactReach_m);

/// Lowest world z of `node`'s hull with A at X_WA [m].
double LowestPoint(const TaskWorld& world, int node, const Iso3& X_WA);

}  // namespace wrap
