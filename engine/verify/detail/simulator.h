// The physics run of a plan (verify/simulate.h) as one class whose members are defined in four
// files: the driver (simulate.cpp: the MuJoCo model, the stepping loop, the robots' TCPs), the
// events (sim_events.cpp: grips, releases and their fades at each action's moment, the mating
// wrench during an insertion, connections welded), the measurements (sim_measure.cpp: grippers'
// and connections' loads against their limits, the table's friction, drift from the plan, the
// final assembly) and the collision judging (sim_contacts.cpp: the contacts allowed at each
// moment, insertion overlaps). Internal to verify/.
#pragma once

#include <mujoco/mujoco.h>

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/result.h"
#include "core/run_context.h"
#include "mating/assembly_geometry.h"
#include "model/assembly.h"
#include "model/project.h"
#include "model/validate.h"
#include "sim/mjcf.h"
#include "sim/scene.h"
#include "task/plan.h"
#include "task/plan_state.h"
#include "task/world.h"
#include "verify/detail/collisions.h"
#include "verify/simulate.h"
#include "wrench/lp.h"
#include "wrench/wrench.h"

namespace wrap::detail {

inline constexpr int kWeldRows = 6;  // a weld constrains 3 positions and 3 rotations
// A released object may touch its gripper this long [s].
inline constexpr double kReleaseGrace_s = 0.5;
// A gripper lets go over this long before its release's moment (Simulator::Fade) [s].
inline constexpr double kReleaseRamp_s = 0.1;
// BestSplit: an object's vertices this close to the table top may bear on it [m]; at most this
// many corners of their hull are used.
inline constexpr double kSupportReach_m = 0.001;
inline constexpr size_t kMaxSupportPoints = 16;
// RestingSupportSets: hull vertices this close to the table top carry a resting part, as the
// planner's table supports count them (task/world.h TableContacts) [m] ...
inline constexpr double kRestReach_m = kTableContactReach_m;
// ... of which those this close to the lowest touch it [m] ...
inline constexpr double kTouchReach_m = 1e-4;
// ... two closer than this are one [m] ...
inline constexpr double kSamePoint_m = 1e-5;
// ... and two resting orientations whose up directions differ by less than this are one [rad].
inline constexpr double kSameOrientation_rad = 1e-3;
// A part's support spheres of an orientation meet the table while its up direction is within
// this of that orientation's [rad] (a part turned further has failed: drift_tolerance_rad).
inline constexpr double kSupportTilt_rad = 0.3;

/// The angle of a rotation [rad].
double AngleOf(const Mat3& R);
/// A number in words for messages ("%.*g").
std::string Num(double v, int digits = 3);

/// Where the two inputs of a step meet, chosen as the planner does (task/world.cpp): the pair
/// of parts whose boxes in A overlap most, the centre of that overlap as the contact point.
struct Interface {
  int part_moved = -1;
  int part_base = -1;
  Vec3 p_A = Vec3::Zero();
  Vec3 axis_A = Vec3::UnitZ();
  double force_N = 0.0;
  double torque_Nm = 0.0;
  WrenchBox limits;  // T_pq of the connection, in its frame C
};

/// The interface of step inputs `moved` and `base` (node ids) with the step's mating.
Interface FindInterface(const CellScene& scene, const AssemblyTree& tree, const Mating& mating,
                        int moved, int base);

/// The support spheres of a part in one resting orientation.
struct SupportSet {
  Vec3 up_P = Vec3::UnitZ();    ///< The table's normal (world up) in the part frame P.
  std::vector<Vec3> centres_P;  ///< Sphere centres, part frame [m].
};

/// Per part of `scene`, the points of its frame P on which `plan` rests it on the table, by
/// orientation: in every state of the plan where its object rests (ReplayPlanStates), the
/// part's convex hull vertices that touch the table (within kRestReach_m of its top, as the
/// wrench LP's table supports, and within kTouchReach_m of the part's lowest) and are corners
/// of their 2-D hull (at most kMaxSupportPoints, spread along it),
/// each raised by kSupportSphereRadius_m along the table's normal: the centres of the physics
/// model's contact spheres (MjcfOptions::support_points_P), which touch the table where the
/// corners do.
std::vector<std::vector<SupportSet>> RestingSupportSets(const CellScene& scene,
                                                        const AssemblyTree& tree, const Plan& plan);

/// Utilisation of a wrench (force, torque) against a symmetric box: the largest |component| /
/// bound, a zero bound taken as the floor.
double BoxUtilisation(const Vec3& f, const Vec3& tau, const WrenchBox& box, double floor_N,
                      double floor_Nm);

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

/// Runs a timed plan in MuJoCo and judges it (see simulate.h).
class Simulator {
 public:
  Simulator(const Project& project, const ProjectCheck& check, const CellScene& scene,
            const AssemblyTree& tree, const Plan& plan, bool keyframes, const SimOptions& options,
            RunContext& ctx);

  /// Builds the model, steps it through the plan and returns the verdict.
  Result<SimReport> Run();

 private:
  // A gripper being let go of, from kReleaseRamp_s before its release's moment (its fingers
  // open, its cup vents, while the plan holds it still): from t0 its weld is off and the wrench
  // the weld last exerted on the part is applied instead, falling linearly to nothing over
  // kReleaseRamp_s, so that the object's other holders or the table take the load over
  // gradually. (Softening the weld instead does not hand the load over: at rest a MuJoCo
  // constraint resists through its impedance whatever its stiffness, and the load stepped over
  // at the cut; MuJoCo's critically damped constraints overshoot a step: a co-holder at 82% of
  // its limits read 102% for 20 ms.)
  struct Fade {
    int robot = -1;
    int part = -1;
    double t0 = 0.0;  // starts [s]
    bool started = false;
    Vec3 f_W = Vec3::Zero();    // the weld's last force on the part, world
    Vec3 tau_W = Vec3::Zero();  // and torque, about the part's origin
  };
  // A time window in which robots may touch objects (and, for an insertion, the two inputs
  // each other).
  struct Window {
    double t0 = 0.0, t1 = 0.0;
    std::vector<int> robots;
    std::vector<int> nodes;
    bool pair = false;  // the two nodes may touch each other too (an insertion)
    int step = -1;      // an insertion's step node: nodes[0] moves into nodes[1]
  };
  // A connection made: the weld that joins two parts.
  struct Join {
    int eq = -1;      // weld id
    int part = -1;    // its body2
    int action = -1;  // the assemble that made it
  };

  // Driver (simulate.cpp).
  Result<void> Setup();
  Result<void> BuildModel(const SceneState& state);
  Result<void> FindBodies(const MjcfDocument& doc);
  void PrepareActions();
  Result<void> Loop();
  int CurrentAction() const;
  Iso3 Tcp(int r, double t) const;
  void SetTcps(double t);
  void SwitchSupports();  // support_points.cpp
  Iso3 BodyPose(int body) const;
  Iso3 PartPose(int p) const { return BodyPose(part_body_[p]); }
  Iso3 TcpBodyPose(int r) const;
  SceneState CurrentState(double t) const;
  int NodeOfPart(int p) const;
  // Where robot r's TCP has the object it grips now (its assembly frame).
  Iso3 CarriedX_WA(int r) const;
  // Where the plan has object `node` now: carried by its first holder, else where it was left.
  Iso3 ExpectedX_WA(int node, const PlanObject& o) const;
  void Failed(int action, const std::string& reason, const std::string& detail, double t);

  // Events (sim_events.cpp).
  void Weld(int eq, const Iso3& X_W1, const Iso3& X_W2);
  const Fade* FadeOf(int r) const;
  void StopFade(int r);
  static double FadeLeft(const Fade& f, double t);
  void FadeBeforeReleases(double t);
  void ApplyFades(double t);
  void Grip(int r, const PlanGrasp& g);
  void Release(int r);
  void Event(int i, double t);
  void TakeHold(int r, const PlanGrasp& g);
  std::optional<Iso3> LetGo(int r, int node, const PlanState& at, double t);
  bool Mate(int i, double t);
  std::vector<int> Insertions(double t) const;
  void ApplyMating(int i);

  // Measurements (sim_measure.cpp).
  void WeldWrench(int eq, int p, Vec3& f_W, Vec3& tau_W) const;
  void GripWrench(int r, Vec3& f_G, Vec3& tau_G, double t) const;
  void AverageWrench(int r, Vec3& f, Vec3& tau);
  double GripperUtilisation(int r, const Vec3& f, const Vec3& tau, int insert_action);
  // Robot r's wrench limits with the grasp its weld holds (GraspLimits: a reduced grasp's box is
  // smaller). The weld itself is rigid; the box is what its measured wrench is judged against.
  WrenchLimits HeldLimits(int r) const;
  bool MeasureGripper(int r, double t, const std::vector<int>& inserting, int current);
  void MeasureTable();
  void MeasureConnections();
  std::optional<std::map<int, double>> BestSplit(int node);
  void MeasureDrift(double t, int current);
  void Measure(double t, const std::vector<int>& inserting);
  void CheckFinal(double t);

  // Collision judging (sim_contacts.cpp).
  void ContactWindows();
  ContactRules Rules(double t) const;
  int ActionOfRobot(int r, double t) const;
  Result<void> CheckCollisions(double t);
  void BlameCollision(const CollisionHit& h, double t);
  void CheckInsertionOverlaps(double t, const std::vector<Iso3>& X_WP);
  int ActionOfInsertion(int step) const;

  const Project& project_;
  AssemblyGeometry geometry_;  // the parts' meshes: insertion overlaps
  const CellScene& scene_;
  const AssemblyTree& tree_;
  const Plan& plan_;
  const bool keyframes_;  // a keyframe replay (no motion in the plan)
  const SimOptions& options_;
  RunContext& ctx_;
  SimReport report_;
  std::vector<Window> windows_;              // contact windows, from the segments
  std::optional<SimCollisions> collisions_;  // when collisions are judged
  bool collision_dirty_ = true;              // an action happened since the last check
  std::vector<JointVector> checked_q_;       // at the last collision check
  std::vector<double> checked_openings_;
  std::vector<Iso3> checked_X_WP_;

  std::unique_ptr<mjModel, ModelDeleter> model_;
  std::unique_ptr<mjData, DataDeleter> data_;
  std::vector<int> tcp_mocap_;             // mocap index per robot
  std::vector<std::vector<int>> grip_eq_;  // [robot][part] weld id
  std::vector<std::vector<int>> join_eq_;  // [p][q] weld id, p < q
  std::vector<int> part_body_, part_dof_;  // per part
  // The support spheres of one resting orientation (SupportSet) as geoms of the model.
  struct SupportGeoms {
    Vec3 up_P = Vec3::UnitZ();
    std::vector<int> geoms;
  };
  std::vector<std::vector<SupportGeoms>> supports_;    // per part, by orientation
  std::vector<std::vector<SupportSet>> support_sets_;  // per part, from the plan
  std::vector<WrenchLimits> limits_;                   // per robot
  std::vector<int> grip_part_;                         // per robot, -1 free
  std::vector<PlanGrasp> grasp_;                       // per robot, the grasp its weld holds
  std::vector<Vec3> hold_f_, hold_tau_;                // per robot, wrench when its insertion began
  std::vector<Vec3> prev_f_, prev_tau_;                // per robot, its last measured wrench
  std::vector<Fade> fades_;                            // grippers being let go of
  std::vector<std::deque<Vec6>> recent_;  // per robot, its last measured wrenches (averaged)
  std::vector<Vec6> mating_on_part_;      // per part, the mating wrench applied now (about its COM)
  std::vector<bool> was_inserting_;       // per robot
  std::map<int, Interface> interfaces_;   // per assemble action
  std::vector<Join> joins_;               // connections made so far
  // Who holds what (task/plan_state.h), replayed as the actions' moments pass. The pose of an
  // object nobody holds is where the plan has it: initially the plan's, after a release where
  // its last holder's TCP let go of it (Event).
  PlanState state_;
  std::map<int, int> last_action_;  // per object: the last action that changed its support
  std::unique_ptr<LpBackend> lp_ = MakeDenseSimplexBackend();  // BestSplit's
  LpProblem lp_problem_;
  LpSolution lp_solution_;
  double split_at_ = -1.0;                                     // when split_ was computed
  std::map<int, std::optional<std::map<int, double>>> split_;  // BestSplit by node at split_at_
  std::vector<int> order_;                                     // actions by end_s
  size_t next_event_ = 0;
  double makespan_ = 0.0;
};

}  // namespace wrap::detail
