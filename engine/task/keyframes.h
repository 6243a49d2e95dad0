// Edge validation of the task search (paper Alg. 2, ValidateIK): turns one symbolic action from a
// continuous state into a keyframe where every acting robot reaches its grasp (IK), nothing
// collides, the robots keep their minimum clearance and the wrench gates hold; or says which gate
// failed. Also the cheap checks the search makes while expanding (reach, gripper vs table, LPs
// whose poses are fixed).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "robot/cell.h"
#include "task/failure.h"
#include "task/planner.h"
#include "task/state.h"
#include "task/world.h"
#include "task/wrench_model.h"
#include "wrench/wrench.h"

namespace wrap {

/// Which check rejected an edge.
enum class Gate {
  kNone,
  kReach,
  kIk,
  kCollision,
  kClearance,
  kApproach,
  kTable,
  kWrenchAssembly,
  kWrenchTransport,
  kWrenchRelease,
  kWrenchRest,
  kSkill,         ///< No room for a straight approach, retreat or descent at the keyframe.
  kGripperTable,  ///< A grasp that puts the gripper into the table where the object rests.
};
/// Words for a gate, e.g. "IK", "collision", "wrench (assembly)".
std::string_view GateName(Gate gate);
inline constexpr int kNumGates = 13;

/// Counters and times of the checks.
struct TaskCounters {
  long long validations = 0;
  long long validation_failures = 0;
  long long lp_checks = 0;      ///< Wrench checks asked (cache hits included).
  long long lp_cache_hits = 0;  ///< ... answered from the checker's cache.
  long long lp_solves = 0;      ///< LPs solved for the others (a vertex of U each, at least).
  long long lp_pivots = 0;      ///< Their simplex pivots.
  long long ik_calls = 0;
  long long collision_checks = 0;
  double t_ik_s = 0.0;
  double t_lp_s = 0.0;
};

/// What validating an edge gave.
struct EdgeOutcome {
  bool ok = false;
  bool permanent = false;   ///< Failed for a reason more effort cannot change.
  Gate gate = Gate::kNone;  ///< The gate that failed (most informative candidate).
  std::string message;      ///< Why, in words.
  Keyframe keyframe;        ///< The keyframe (ok only).
  std::optional<Keyframe> approach;
  ContState next;  ///< Continuous state after the action (ok only).
  /// Failed by a collision while explaining (KeyframeSolver::set_explain): the cell at the last
  /// collision found, with the two bodies.
  FailureScene scene;
};

/// Validates edges and answers the cheap checks. Holds a copy of the cell: one per thread.
class KeyframeSolver {
 public:
  KeyframeSolver(const TaskWorld& world, TaskTables& tables, const TaskPlannerOptions& options,
                 Cell cell, TaskCounters& counters);

  /// Validates `a` from (s, c) at effort level `effort` (0-based); `next` is the symbolic state
  /// after it. `seed` makes the pose sampling deterministic.
  EdgeOutcome Validate(const SymState& s, const ContState& c, const TaskAction& a,
                       const SymState& next, int effort, std::uint64_t seed);

  /// While on, Validate records the cell at each collision it finds (EdgeOutcome::scene), for
  /// the failure record; off (the default) it only counts them.
  void set_explain(bool on) { explain_ = on; }
  /// Where the collisions of its checks are logged ("task", trace level); null: nowhere.
  void set_log(const RunContext* log) {
    log_ = log;
    trace_collisions_ = log != nullptr && log->Logs("task", LogLevel::kTrace);
  }

  /// Cheap: the TCP pose is inside the robot's reach sphere.
  bool InReach(int robot, const Iso3& X_WT) const;
  /// The robot alone (the other robots taken out) reaches grasp `grasp` on objects[0] with some
  /// IK solution that collides with nothing among `objects` and the table. Context-free, so the
  /// search caches it: an action that fails here fails in every state.
  bool SoloReach(int robot, const std::vector<PlanObject>& objects, int grasp, std::string* why);
  /// Cheap: robot's end effector with its TCP at X_WT (fingers at `opening_m`, or fully open
  /// when negative) does not hit the table.
  bool ClearOfTable(int robot, const Iso3& X_WT, double opening_m = -1.0);
  /// Cheap and context-free: the gripper of `robot` at `grasp` on an object at X_WA (fingers
  /// closed to the grasp) does not touch the parts of `other_node` at X_other.
  bool GripperClear(int robot, int grasp, const Iso3& X_WA, int other_node, const Iso3& X_other);
  /// Cheap: the end effector of `robot` at `grasp` on an object at X_WA (fingers at the grasp's
  /// opening), and backed off along its axis by the grasp approach's least length, does not
  /// touch the parts of the nodes of `others` at their poses. On a hit, `hit_node` is the node.
  bool ApproachClear(int robot, int grasp, const Iso3& X_WA,
                     std::span<const std::pair<int, Iso3>> others, int* hit_node);
  /// Robot-free and context-free: the end effectors of `robot_a` at grasp `grasp_a` and of
  /// `robot_b` at grasp `grasp_b` of one object keep the robots' minimum clearance (the two
  /// hands of a handover or of a two-handed hold).
  bool GrippersApart(int robot_a, int grasp_a, int robot_b, int grasp_b);
  /// Cheap and context-free: `node` resting at X_WA leaves every robot room to stand at home
  /// (no link, end effector or finger of a robot at its home configuration touches it).
  bool ClearOfHomes(int node, const Iso3& X_WA);
  /// Robot `robot` from `q` moves its TCP straight by `length_m` along `dir_W` without hitting
  /// anything in the cell as the last validation left it (its keyframe), checked at a few points
  /// on the arm's IK branch: the straight approach to a grasp, the retreat from a release, the
  /// descent of a placement, which the motion stage makes as skills. Restores `q`. False with
  /// the reason in `why`.
  bool StraightClear(int robot, const JointVector& q, const Vec3& dir_W, double length_m,
                     std::string* why);
  /// Object `node`, held by `holders` (grasp ids `grasps`, joints `q0`), is carried from X_a to
  /// X_b with every holder's TCP following it on the arm's IK branch, straight (translation
  /// and slerp) or else up 10 cm, across and down, as the motion stage first tries a
  /// two-handed carry; nothing hits anything in the cell as set (the caller poses the rest).
  /// Leaves the holders and the object where the last sample put them. False with `why`.
  bool CarryClear(int node, const std::vector<int>& holders, const std::vector<int>& grasps,
                  const std::vector<JointVector>& q0, const Iso3& X_a, const Iso3& X_b,
                  std::string* why);
  /// Finger opening of a robot holding with `grasp` (width plus clearance).
  double GraspOpening(int grasp) const;
  /// Robots alike in the wrench LP (the same end effector, grasp set and wrench limits) share a
  /// class: the first such robot's index. The LP cache keys of the search name holders by it.
  int WrenchClass(int robot) const { return wrench_class_[robot]; }
  /// `holders` ((robot, grasp id) pairs) with each robot replaced by its wrench class, sorted.
  std::vector<std::pair<int, int>> ClassHolders(std::vector<std::pair<int, int>> holders) const;
  /// The wrench gate for `objects` (cached by `key`, which must identify the question with its
  /// holders named by WrenchClass, or 0: then by the question's content), with the reason when
  /// infeasible. An answer serves every robot of the class; a reason is renamed to the robots
  /// that hold. Mode none: always true.
  bool Wrench(WrenchGate gate, std::span<const WrenchObject> objects, int mating_step,
              std::uint64_t key, std::string* reason);
  /// Whether some orientation of the candidate set lets the assembly LP of `step` hold with the
  /// base in the air (cached by `key`).
  bool AirAssemblyPossible(int step, const std::vector<std::pair<int, int>>& moved_holders,
                           const std::vector<std::pair<int, int>>& base_holders, std::uint64_t key,
                           std::string* reason);

  /// False when the mating load of `step` cannot be added to any holding wrenches of these
  /// holders in any orientation of the pair (MatingIncrementRelaxation of the "held, then mated"
  /// check; true when the check is not of that kind). Cached by `key`.
  bool MatingIncrementFits(int step, const std::vector<std::pair<int, int>>& moved_holders,
                           const std::vector<std::pair<int, int>>& base_holders, std::uint64_t key);

  /// TCP target of a robot holding node (at X_WA) with grasp id.
  Iso3 GraspTarget(const Iso3& X_WA, int grasp_id) const;
  /// Orientation candidates for an object whose insertion axis (in A) is `axis_A`: the axis
  /// pointing down, sideways, up, each with 4 turns about it.
  static std::vector<Mat3> AxisOrientations(const Vec3& axis_A);

 private:
  struct Mover {
    int robot = -1;
    int node = -1;
    int grasp = -1;
  };
  struct Edge;     // The edge under validation (keyframes_internal.h).
  struct Problem;  // Its keyframe problem, built per action type.
  struct Attempt;  // The search for its keyframe.

  // The keyframe problem of each action type (keyframe_actions.cpp).
  void BuildProblem(Edge& e, Problem& p);
  void BuildPick(Edge& e, Problem& p);
  void BuildPlace(Edge& e, Problem& p);
  void BuildHandover(Edge& e, Problem& p);
  void BuildAddGrasp(Edge& e, Problem& p);
  void BuildRelease(Edge& e, Problem& p);
  void BuildAssemble(Edge& e, Problem& p);

  // The search for the keyframe (keyframe_validate.cpp).
  /// The candidate object poses (node-indexed), best first; those below the table are noted.
  std::vector<std::vector<Iso3>> Candidates(Edge& e, Problem& p, Attempt& t);
  /// Tests the candidate t.X: wrench gates, every mover's IK, then the combinations of IK
  /// solutions until one passes the keyframe's checks (true, t.chosen) or none does (noted).
  bool TryCandidate(Edge& e, const Problem& p, Attempt& t);
  /// Every mover's IK solutions at t.X in `sols`; false (noted) when one has none.
  bool SolveMovers(Edge& e, const Problem& p, Attempt& t,
                   std::vector<std::vector<JointVector>>& sols);
  EdgeOutcome Failed(const Problem& p, Attempt& t);
  EdgeOutcome Succeeded(const Edge& e, const Problem& p, Attempt& t);

  // The checks of a keyframe candidate, its movers at `q` (keyframe_checks.cpp); false with
  // t.gate and t.message.
  /// The cell as set puts two robots closer than the minimum clearance.
  bool RobotsTooClose();
  /// All of the checks below, in order, with the robots' clearance first.
  bool KeyframeClear(Edge& e, const Problem& p, Attempt& t, const std::vector<JointVector>& q);
  /// Each new grasp's straight approach, each freed gripper's retreat, a placement's descent.
  bool SkillsClear(const Edge& e, const Problem& p, Attempt& t, const std::vector<JointVector>& q);
  /// Each object held by two robots or more and reposed can be carried to its new pose.
  bool CarriesClear(const Edge& e, const Problem& p, Attempt& t, const std::vector<JointVector>& q);
  /// The freed robots can go home, or else stay with the gripper open (t.park_home).
  bool FreedRobotsClear(const Edge& e, const Problem& p, Attempt& t,
                        const std::vector<JointVector>& q);
  /// Assemble: the insertion from the approach pose is reachable and clear (t.approach).
  bool InsertionClear(Edge& e, const Problem& p, Attempt& t, const std::vector<JointVector>& q);

  /// The checker's answer for `config` at `gate` (cached by `key`, 0: by content; not through
  /// the checker's cache when `uncached`, for a caller that keeps the answer itself), counted in
  /// the counters (checks, hits, LPs, pivots, t_lp).
  Result<WrenchCheck> CountedCheck(WrenchGate gate, std::uint64_t key,
                                   const StepConfiguration& config, bool uncached = false);
  bool SolveIk(int robot, const Iso3& X_WT, const JointVector& reference, int effort,
               std::mt19937_64& rng, std::vector<JointVector>& out);
  void SetScene(const std::vector<PlanObject>& objects,
                const std::vector<std::pair<int, int>>& holds, int allow_a, int allow_b);
  void SetRobot(int robot, const JointVector& q);
  void EnableRobot(int robot, bool on);
  bool Collides();
  /// Depth first over the movers' IK solutions from `depth` on, skipping those that collide
  /// (gate: collision), until `leaf` accepts a combination (in `chosen`) or kMaxLeaves are tried.
  bool Search(const std::vector<Mover>& movers, const std::vector<std::vector<JointVector>>& sols,
              size_t depth, std::vector<JointVector>& chosen, int& leaves, Gate& gate,
              const std::function<bool(std::vector<JointVector>&)>& leaf);

  const TaskWorld& world_;
  TaskTables& tables_;
  const TaskPlannerOptions& options_;
  Cell cell_;
  TaskCounters& counters_;
  std::vector<int> wrench_class_;  // WrenchClass per robot
  // Wrench answers by class key: feasible, or the reason with the robots it names (the holders
  // in class order), renamed for the robots of a later question.
  struct ClassAnswer {
    bool feasible = true;
    std::string reason;
    std::vector<int> robots;
  };
  std::unordered_map<std::uint64_t, ClassAnswer> class_answers_;
  WrenchChecker checker_;
  std::vector<std::vector<Iso3>> frames_;  // per robot scratch FK frames
  std::vector<int> part_object_;           // scratch: object index of each part in SetScene
  struct Fingers {
    BodyId body[2];
    Iso3 X_FS0[2];      // finger box in the flange frame, closed
    Vec3 per_metre[2];  // its translation per metre of opening
    double stroke = 0.0;
  };
  std::vector<std::optional<Fingers>> fingers_;  // per robot (two-finger grippers)
  std::vector<double> opening_;                  // per robot: current finger opening
  bool explain_ = false;                         // record the cell at collisions
  const RunContext* log_ = nullptr;              // the run's log
  bool trace_collisions_ = false;                // log_ takes "task" at trace level
  std::vector<JointVector> q_now_;               // per robot: the joints last set
  FailureScene hit_;                             // the cell at the last collision recorded
  void PlaceFingers(int robot, const Iso3& X_WF);
};

}  // namespace wrap
