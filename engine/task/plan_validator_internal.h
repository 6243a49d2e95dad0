// The plan validator's insides, shared by its three files: plan_validator.cpp (the front door,
// the validator's own model of the project, the plan's names and indices),
// plan_validator_keyframe.cpp (what one keyframe must satisfy: object poses, joints, FK,
// collisions, clearance, the insertion path, the wrench gates) and plan_validator_replay.cpp (the
// replay of who holds what, one function per action type). Not part of the plan module's API.
#pragma once

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/frames.h"
#include "core/result.h"
#include "geometry/mesh.h"
#include "mating/assembly_geometry.h"
#include "model/project.h"
#include "model/validate.h"
#include "robot/catalog.h"
#include "robot/cell.h"
#include "robot/kinematics.h"
#include "robot/project_chain.h"
#include "task/plan.h"
#include "task/plan_validator.h"
#include "wrench/wrench.h"

namespace wrap::plan_validator_internal {

// The fingers are checked this much wider than the grasp on each side (the grasp sampler's
// clearance): a two-finger gripper holding a part is drawn open to width + 2 mm.
inline constexpr double kFingerClearanceM = 1e-3;
// Most colliding pairs reported per keyframe.
inline constexpr int kMaxCollisionPairsReported = 4;
// The validator sweeps an insertion path in steps of this length [m].
inline constexpr double kInsertionStep_m = 2.5e-4;

// Words for the issues: 'name', "1.5 mm", "2.0 deg", "%.4g".
std::string Quote(std::string_view s);
std::string Mm(double m);
std::string Deg(double rad);
std::string Num(double v);

// Translation and rotation-angle difference of two frames.
struct PoseError {
  double position_m = 0.0;
  double rotation_rad = 0.0;
};

PoseError Difference(const Iso3& a, const Iso3& b);

// A robot as the validator sees it.
struct RobotModel {
  std::string name;
  Chain chain;
  EndEffector ee;
  Iso3 X_WB = Iso3::Identity();
  WrenchLimits limits;
  std::vector<Iso3> reference_frames;  // link frames at home, for the cell's own-contact filter
};

// Where the two inputs of a step meet (computed from the part boxes in the assembly frame).
struct Interface {
  const Step* step = nullptr;
  int moved_node = -1;
  int base_node = -1;
  int moved_part = -1;
  int base_part = -1;
  Vec3 p_A = Vec3::Zero();       // interface point in A
  Vec3 axis_A = Vec3::UnitZ();   // unit insertion direction in A
  Iso3 X_AC = Iso3::Identity();  // connection frame: origin p_A, z along the axis
  WrenchBounds limits;
};

// An object of the replayed world.
struct ObjectState {
  Iso3 X_WA = Iso3::Identity();
  bool resting = true;
  bool at_rest_pose = true;  // rests, or was picked and has not moved since: may touch the table
  std::vector<PlanHold> holders;
};

// What one keyframe may show, relative to the state before the action.
struct Moment {
  std::set<int> moving;  // objects the action may move (their holders may move too)
  std::vector<std::pair<int, PlanHold>> new_holds;  // grasps closed at this keyframe: (node, hold)
  std::set<int> rest_check;                         // objects that must rest on the table here
  std::set<int> acted;                              // the action's objects (flags not compared)
  std::vector<std::pair<int, int>> allowed_pairs;   // objects allowed to touch each other
  std::map<int, std::pair<Iso3, std::string>> required;  // node -> pose it must have, and why
};

// One validation run: the validator's own model of the project (Setup), the replayed state and
// the issues found so far.
class Validator {
 public:
  Validator(const Project& project, const ProjectCheck& check, const Plan& plan,
            const PlanValidationOptions& options)
      : project_(project), check_(check), tree_(*check.tree), plan_(plan), options_(options) {}

  Result<void> Setup(const std::filesystem::path& project_file);
  Result<void> CheckInterpretable() const;
  PlanValidation Run();

 private:
  void Issue(int action, std::string gate, std::string message) {
    out_.issues.push_back({action, std::move(gate), std::move(message)});
  }
  const std::string& NodeName(int node) const { return tree_.nodes[node].name; }
  const std::string& RobotName(int r) const { return robots_[r].name; }
  const std::string& PartName(int p) const { return project_.parts[p].name; }
  bool NodeHasPart(int node, int part) const {
    const std::vector<int>& parts = tree_.nodes[node].parts;
    return std::binary_search(parts.begin(), parts.end(), part);
  }

  // Setup (plan_validator.cpp).
  void SetupParts();
  void SetupInterfaces();
  void CheckNames();

  // The replay (plan_validator_replay.cpp). `i` is the action's index in the plan.
  void CheckInitial();
  void CheckComplete(int last);
  void ReplayAction(int i);
  // The action's robot, object and grasp counts, and its inputs exist; false stops the replay.
  bool ActionShapeOk(int index, const PlanAction& a);
  // One function per action type: preconditions, the keyframe (`m` says what it may show), the
  // wrench gate, the effects on the replayed state.
  void ReplayPick(int i, const PlanAction& a, Moment& m);
  void ReplayPlace(int i, const PlanAction& a, Moment& m);
  void ReplayHandover(int i, const PlanAction& a, Moment& m);
  void ReplayAddGrasp(int i, const PlanAction& a, Moment& m);
  void ReplayRelease(int i, const PlanAction& a, Moment& m);
  // False when the replay stops at this assemble (its inputs are not a step's).
  bool ReplayAssemble(int i, const PlanAction& a, Moment& m);
  // Parts of ReplayAssemble; M: the moved input, B: the base input, S: the step they build.
  int AssembledStep(int i, const PlanAction& a);
  void CheckAssembleInputs(int i, const PlanAction& a, int S);
  void CheckApproach(int i, const PlanAction& a, const Moment& m, const Interface& f,
                     const Iso3& X_WB, bool base_moves);
  void RunAssemblyGate(int i, int M, int B, const Interface& f, const std::map<int, Iso3>& X);
  // The assembled object S replaces its two inputs; their holders hold it.
  void JoinInputs(int M, int B, int S, const std::map<int, Iso3>& X);
  const PlanHold* HoldOf(int node, int robot) const;
  bool GraspMatches(int index, int node, const PlanHold& hold);
  void RequireFree(int index, int robot, std::string_view role);
  void Detach(int robot);

  // Keyframe checks (plan_validator_keyframe.cpp).
  // Checks one keyframe against the state before the action; returns every object's pose at it.
  std::map<int, Iso3> CheckKeyframe(int index, const std::string& label, const Keyframe& kf,
                                    const Moment& m);
  // The keyframe's object list and the poses of the objects that may not move (or must reach a
  // required pose); returns every object's pose at the keyframe.
  std::map<int, Iso3> CheckObjects(int index, const std::string& label, const Keyframe& kf,
                                   const Moment& m);
  // Joint limits; robots that may not move keep their joints.
  void CheckJoints(int index, const std::string& label, const Keyframe& kf, const Moment& m);
  // FK of every grasp held at this moment, the new ones included; returns those grasps.
  std::vector<std::pair<int, PlanHold>> CheckGrasps(int index, const std::string& label,
                                                    const Keyframe& kf, const Moment& m,
                                                    const std::map<int, Iso3>& X_WA);
  void CheckRest(int index, const std::string& label, int node, const Iso3& X_WA);
  // Where part p at X_WP touches the table: the convex hull of its vertices within the table
  // tolerance of the top, clipped to the table's rectangle (a part may overhang the edge).
  std::vector<Eigen::Vector2d> SupportPolygon(int part, const Iso3& X_WP) const;
  void CheckCollisions(int index, const std::string& label, const Keyframe& kf, const Moment& m,
                       const std::map<int, Iso3>& X_WA,
                       const std::vector<std::pair<int, PlanHold>>& holds);
  // Puts the robots and objects of the keyframe into `cell` and allows the contacts of the
  // moment (a holding gripper with its part, the moment's object pairs, objects on the table).
  void PoseCell(Cell& cell, const Keyframe& kf, const Moment& m, const std::map<int, Iso3>& X_WA,
                const std::vector<int>& held_part);
  void ReportCollisions(int index, const std::string& label, Cell& cell);
  void CheckClearance(int index, const std::string& label, Cell& cell);
  Cell* CellFor(const std::vector<double>& openings);
  // The moved input's straight path from its approach pose into its mating pose on B (at X_WB),
  // swept against B's meshes every kInsertionStep_m: the validator's own sweep (the planner's
  // is the geometry checks' conservative advancement).
  void CheckInsertionPath(int index, const Interface& f, const Iso3& X_WB);

  // Wrench configurations (plan_validator_keyframe.cpp).
  void AddObject(int node, const Iso3& X_WA, const std::vector<PlanHold>& holders, bool on_table,
                 StepConfiguration& config, std::vector<int>& body_of_part) const;
  void RunGate(int index, WrenchGate gate, const StepConfiguration& config, std::string what);

  const Project& project_;
  const ProjectCheck& check_;
  const AssemblyTree& tree_;
  const Plan& plan_;
  const PlanValidationOptions& options_;

  std::vector<RobotModel> robots_;
  std::vector<Iso3> X_AP_;                 // per part
  std::vector<std::vector<Vec3>> hull_P_;  // per part: hull (or mesh) vertices in P
  std::vector<Aabb> box_A_;                // per part: box in A
  std::vector<Interface> interfaces_;      // per node (valid for steps)
  std::map<std::vector<long long>, Cell> cells_;
  std::optional<AssemblyGeometry> geometry_;  // the parts' meshes, for the insertion sweeps
  bool cells_failed_ = false;
  std::optional<WrenchChecker> checker_;

  // The replayed state.
  std::map<int, ObjectState> objects_;
  std::vector<JointVector> q_;
  std::vector<int> holding_;    // node held by each robot, -1 when free
  std::vector<char> may_move_;  // freed by the last action: may park anywhere at the next keyframe
  std::set<int> freed_now_;     // robots freed by the action being replayed

  PlanValidation out_;
};

}  // namespace wrap::plan_validator_internal
