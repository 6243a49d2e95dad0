// The cell: robots with their end effectors, the parts (objects) and the table as one collision
// world, with the default filters of a work cell and the two questions the planner asks of every
// keyframe and motion sample: is anything in collision, and how close do the robots come (the
// clearance constraint of paper §IV-D, IK and keyframe optimisation).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "geometry/mesh.h"
#include "robot/chain.h"
#include "robot/collision.h"

namespace wrap {

/// End-effector geometry as the cell sees it: rigid collision shapes and the tool centre point.
struct CellEndEffector {
  std::string name;              ///< e.g. "robotiq_2f85".
  std::vector<Shape> collision;  ///< Collision shapes in the flange frame F (may be empty).
  Iso3 X_FT = Iso3::Identity();  ///< Tool centre point T in the flange frame F.
};

/// One robot of the cell.
struct CellRobot {
  std::string name;              ///< Unique among the cell's robots, e.g. "r0".
  Chain chain;                   ///< Links with their collision shapes in the link frames.
  Iso3 X_WB = Iso3::Identity();  ///< Robot base frame B in the world W.
  CellEndEffector end_effector;  ///< Mounted at the flange (chain.X_LF in the last link).
  /// Optional link frames X_WL at a reference configuration such as home, in the world with this
  /// X_WB (as SetConfiguration takes them). Pairs of this robot's own bodies (links, end effector)
  /// that touch there are allowed from then on, like MoveIt's "default" pairs: geometry that
  /// overlaps by construction, e.g. the UR5e wrist_2 capsule, which reaches 1.1 mm past the flange
  /// into any gripper body.
  std::vector<Iso3> reference_link_frames;
};

/// A rigid object: a part or a subassembly.
struct CellObject {
  std::string name;              ///< Unique among the cell's objects.
  TriangleMesh mesh;             ///< Collision mesh in the object frame O [m].
  Iso3 X_WO = Iso3::Identity();  ///< Initial pose of O in the world.
};

/// The table: a box whose top face is centred at `top_center` (same fields as the project's
/// Table: size, centre xy and height).
struct CellTable {
  bool present = true;                 ///< False: no table in the cell.
  Vec3 size = Vec3(1.6, 1.2, 0.05);    ///< Side lengths [m].
  Vec3 top_center = Vec3(0, 0, 0.75);  ///< Centre of the top face in the world [m].
};

/// Everything the cell is built from.
struct CellDef {
  std::vector<CellRobot> robots;    ///< Robots, indexed 0..n-1 in this order.
  std::vector<CellObject> objects;  ///< Objects, indexed 0..m-1 in this order.
  CellTable table;                  ///< The table.
};

/// Default filters of a cell.
struct CellOptions {
  /// Links i and j of one robot with |i - j| <= gap are not checked against each other (adjacent
  /// links touch at their joint). The end effector counts as link dof + 1. Default 1.
  int adjacent_link_gap = 1;
  /// Link 0 (the base) of every robot is not checked against the table (it stands on or next to
  /// it). Default true.
  bool base_touches_table = true;
  /// Objects are not checked against the table (they rest on it; placements come from stable
  /// poses above it). Default true.
  bool objects_touch_table = true;
  /// MinRobotClearance measures the end effectors as well as the links. Default true.
  bool clearance_includes_end_effectors = true;
};

/// Collision groups of a cell's bodies.
inline constexpr int kCellTableGroup = 0;   ///< The table.
inline constexpr int kCellObjectGroup = 1;  ///< Every object.
/// Links of robot r.
constexpr int CellLinkGroup(int robot) { return 2 + 2 * robot; }
/// End effector of robot r.
constexpr int CellEndEffectorGroup(int robot) { return 3 + 2 * robot; }
/// Most robots in one cell (two collision groups each).
inline constexpr int kMaxCellRobots = (kMaxCollisionGroups - 2) / 2;

/// Robots, end effectors, objects and the table in one CollisionWorld. Bodies: every link of every
/// robot, one end-effector body per robot, one body per object, the table. Objects attach to a
/// robot's TCP and then move with it. Like CollisionWorld, a cell is per-thread working data:
/// copy it per thread.
class Cell {
 public:
  /// Builds the world with the default filters of `options`; every link frame of a robot starts at
  /// its base pose (call SetConfiguration). Fails with kInvalidInput naming the robot, object or
  /// shape: duplicate names, a chain whose link count is not dof + 1, too many robots, a bad
  /// shape or an empty object mesh, a table with a non-positive size, too few reference frames.
  static Result<Cell> Build(const CellDef& def, const CellOptions& options = {});

  /// Number of robots.
  int num_robots() const { return static_cast<int>(robots_.size()); }
  /// Number of objects.
  int num_objects() const { return static_cast<int>(objects_.size()); }

  /// Sets robot r's joint positions q (kept for messages) and its link frames X_WL in the world,
  /// link 0 first: what ForwardKinematics(chain, X_WB(r), q, X_WL) computes. One frame per chain
  /// link; extra trailing frames are ignored. Moves the end effector and every object the robot
  /// carries. Fewer frames than links is a bug (assert). No allocation.
  void SetConfiguration(int robot, std::span<const double> q, std::span<const Iso3> X_WL);

  /// Moves a free object. For a held object the grasp is re-anchored: it now follows its
  /// carrier at this pose relative to the carrier's TCP.
  void SetObjectPose(int object, const Iso3& X_WO);
  /// Current pose of an object in the world.
  const Iso3& object_pose(int object) const;
  /// Takes an object out of (or back into) the cell, e.g. parts replaced by their subassembly.
  void SetObjectEnabled(int object, bool enabled);

  /// Robot `robot` grasps `object` at its current pose: the object keeps its pose relative to the
  /// TCP, and contact between it and the robot's end effector is allowed. Several robots may hold
  /// one object (handover, assembly): the first holder carries it; the others only stop
  /// colliding with it. Attaching again by the carrier re-anchors the grasp.
  void Attach(int object, int robot);
  /// Same with the grasp given: the object's frame O at X_TO in the TCP frame T.
  void Attach(int object, int robot, const Iso3& X_TO);
  /// Robot `robot` lets go of `object`; it stays where it is (another holder, if any, carries it
  /// from then on) and is checked against that end effector again, so a gripper still around the
  /// part collides with it until it retreats (allow the pair meanwhile if the plan needs to).
  /// No-op when the robot does not hold it.
  void Detach(int object, int robot);
  /// The robot carrying an object, or -1 when it is free.
  int carrier(int object) const;

  /// Allows or forbids contact between two objects (e.g. mated parts during an assembly action).
  void SetObjectPairAllowed(int object_a, int object_b, bool allowed);

  /// True when any pair not filtered out collides. Fills `result` when given (see
  /// CollisionWorld::AnyCollision). Describe(result->first) names the bodies, poses and q.
  bool InCollision(CollisionResult* result = nullptr, const CollisionRequest& request = {});

  /// Minimum distance between any two different robots (their links, and their end effectors
  /// when the options say so) [m]; +inf with fewer than two robots. 0 when two robots touch.
  DistanceResult MinRobotClearance(const DistanceRequest& request = {});

  /// Pose of robot r's base frame in the world (as built).
  const Iso3& X_WB(int robot) const;
  /// World pose of robot r's TCP (after the last SetConfiguration).
  const Iso3& X_WT(int robot) const;
  /// World pose of robot r's flange.
  const Iso3& X_WF(int robot) const;
  /// World frame of link i of robot r.
  const Iso3& X_WL(int robot, int link) const;

  /// Body of link i of robot r.
  BodyId link_body(int robot, int link) const;
  /// Body of robot r's end effector.
  BodyId end_effector_body(int robot) const;
  /// Body of an object.
  BodyId object_body(int object) const;
  /// Body of the table (invalid when there is none).
  BodyId table_body() const { return table_body_; }
  /// Robot index owning a body (link or end effector), or -1.
  int robot_of(BodyId body) const;

  /// The world, for custom filters and queries (group ids: kCellTableGroup, CellLinkGroup, ...).
  CollisionWorld& world() { return world_; }
  /// The world, read-only.
  const CollisionWorld& world() const { return world_; }

  /// CollisionWorld::Describe plus the joint positions of the robots involved: enough to replay.
  std::string Describe(const ShapePair& pair) const;

 private:
  struct RobotState {
    std::string name;
    int dof = 0;
    Iso3 X_WB = Iso3::Identity();
    Iso3 X_LF = Iso3::Identity();
    Iso3 X_FT = Iso3::Identity();
    int first_body = 0;  // links 0..dof, then the end effector
    std::vector<double> q;
    std::vector<Iso3> X_WL;
    Iso3 X_WF = Iso3::Identity();
    Iso3 X_WT = Iso3::Identity();
  };
  struct ObjectState {
    std::string name;
    BodyId body;
    Iso3 X_WO = Iso3::Identity();
    std::vector<int> holders;      // robots holding it; holders[0] carries it
    Iso3 X_TO = Iso3::Identity();  // pose in the carrier's TCP frame
  };

  void MoveObject(ObjectState& o, const Iso3& X_WO);

  CollisionWorld world_;
  std::vector<RobotState> robots_;
  std::vector<ObjectState> objects_;
  BodyId table_body_;
  GroupPairSet robot_pairs_;  // group pairs measured by MinRobotClearance
};

}  // namespace wrap
