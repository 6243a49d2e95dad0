// Internals of the segment builder (segments.h), shared by its files:
// - segments.cpp: the walk over the plan, each action's steps, the keyframes that follow a motion
//   onto another IK solution;
// - segments_scene.cpp: the builder's scene, the segments it records (with their swept boxes) and
//   its failure record;
// - cartesian_track.cpp: straight TCP moves tracked by IK, and their collision checks;
// - free_paths.cpp: free paths (RRT-Connect queries in the composite space of the robots that
//   move, through ompl_adapter.h), reused from the cache where the scene is the same;
// - skills.cpp: approach, retreat, lift and descent;
// - insertion_skill.cpp: the insertion, its slide start and hover, and its overlap check;
// - carries.cpp: two-handed carries (straight variants, then a search over the object's poses).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "mating/check.h"
#include "motion/ompl_adapter.h"
#include "motion/segments.h"

namespace wrap::detail {

// Largest joint jump between two IK samples of a straight move before it counts as a branch
// switch (no straight move there) [rad].
constexpr double kMaxTrackJump = 0.25;
// How close a tracked straight move's samples come to their targets [m]: within the validators'
// grasp tolerance (2 mm) for moves that carry, grasp or insert.
constexpr double kTrackTolerance = 5e-4;
// The same for a gripper backing away from what it let go of, or toward a grasp it has not
// closed (BackOff) [m]: only its clearance matters there, which the tracked samples are checked
// for. A 7-DoF arm at a joint limit tracks a line to about a millimetre, not half of one.
constexpr double kLooseTrackTolerance = 3e-3;
// An insertion's line is tracked and thinned to this fraction of the depth two touching parts
// may overlap (Geometry::touch_depth_m, 0.2 mm): the moved part slides along a face of the base
// with no clearance (the plumber's block: a block that left its line by 0.5 mm between two kept
// samples cut 0.3 mm into the base, and the trajectory check refused the plan).
constexpr double kInsertLineShare = 0.5;
// ... but no tighter than this [m] (a project that allows no overlap at all).
constexpr double kMinInsertLineTolerance = 5e-5;
// A tracked straight move must end this close to its keyframe's joints [rad]; farther, it has
// reached another IK solution of the same TCP pose, which replaces the keyframe's when valid.
constexpr double kMaxSnap = 0.05;
// Skills and the final free paths are checked this many times finer than the resolution, so
// that the dense check of the timed motion, sampling other points of the same straight pieces
// at the resolution, meets no grazing contact that the planner's samples stepped over.
constexpr int kRefine = 4;
// Joint perturbation and sample count of the tight-pocket test [rad].
constexpr double kTightRad = 0.03;
constexpr int kTightSamples = 16;

inline bool Same(const JointVector& a, const JointVector& b) {
  return a.size() == b.size() && (a - b).cwiseAbs().maxCoeff() <= 1e-9;
}

inline bool SamePose(const Iso3& a, const Iso3& b) {
  return (a.translation() - b.translation()).norm() <= 1e-7 &&
         (a.linear() - b.linear()).cwiseAbs().maxCoeff() <= 1e-7;
}

inline std::uint64_t Mix(std::uint64_t a, std::uint64_t b) {
  std::uint64_t x = a ^ (b + 0x9e3779b97f4a7c15ULL + (a << 6) + (a >> 2));
  x ^= x >> 31;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 29;
  return x;
}

inline const PlanObject* FindObject(const Keyframe& k, int node) {
  for (const PlanObject& o : k.objects) {
    if (o.node == node) return &o;
  }
  return nullptr;
}

// An object that an action moves to its pose at the action's target keyframe, and its holders.
struct MovingObject {
  int node;
  std::vector<int> holders;
  Iso3 X_goal;
};

// Another IK solution of a grasper's grasp that fits the keyframe, with its straight approach
// (waypoints toward the grasp) and that approach's length [m].
struct GraspAlternative {
  JointVector q;
  std::vector<JointVector> approach;
  double length = 0.0;
};

// What SegmentBuilder::Action works out for one action, handed from step to step.
struct ActionWork {
  std::vector<int> graspers;  // robots that take a new grasp (pick, add-grasp, handover)
  int grasped = -1;           // the action's first object
  PlanGrasp new_grasp;        // the graspers' grasp
  bool assemble = false;
  // Where the movers go before the final skill: the approach keyframe of an insertion (or the
  // start of its slide, or the hover pose above it), else the keyframe.
  Keyframe target_kf;
  // An insertion that starts on the table: the holders lower its input straight onto it.
  std::vector<int> hover_holders;
  std::vector<std::vector<JointVector>> hover_descent;
  double hover_length = 0.0;
  std::vector<MovingObject> moving;
  // Per grasper: its approach (waypoints toward the grasp), its length, and the alternatives.
  std::vector<std::vector<JointVector>> approaches;
  std::vector<double> approach_len;
  std::vector<std::vector<GraspAlternative>> alternatives;
  std::vector<JointVector> descend;  // a placement: its descent, top to bottom
  // The free moves: the graspers (first) and the single-handed carriers, with their goals and
  // the objects they approach or carry; two-handed carries apart (pointers into `moving`).
  std::vector<int> free_robots;
  std::vector<JointVector> free_goals;
  std::vector<int> free_objects;
  std::vector<const MovingObject*> carries;
};

// A free path request of SegmentBuilder::Free: the robots that move (their goals), the other
// goals that serve as well (one robot only), and the free segment's index.
struct FreeRequest {
  int action = -1;
  bool main = false;
  int index = -1;
  std::vector<int> movers;
  std::vector<JointVector> targets;
  const std::vector<JointVector>* others = nullptr;
};

// The builder's output and robots as they stood, to go back to before trying another order.
struct BuilderCheckpoint {
  size_t out = 0;
  std::vector<JointVector> cur;
  std::vector<double> opening;
  int free_index = 0;
};

// Builds the geometric motion of one plan (PlanGeometricMotion): walks the actions in order,
// keeping the robots' joints, finger openings and the objects' state, and records the segments.
class SegmentBuilder {
 public:
  SegmentBuilder(const TaskWorld& world, Plan& plan, const MotionOptions& options,
                 const MotionRequest& request, MotionCache& cache, RunContext& ctx,
                 MotionFailure* failure, std::optional<MotionScene>* scene)
      : w_(world),
        plan_(plan),
        opt_(options),
        effort_(request.effort),
        seed_(request.seed),
        cache_(cache),
        ctx_(ctx),
        failure_(failure),
        scene_holder_(scene) {}

  Result<std::vector<GeoSegment>> Run();

 private:
  // --- The builder's scene and record (segments_scene.cpp).
  Result<void> SetScene(const std::vector<double>& openings,
                        const std::vector<std::pair<int, int>>& mating = {},
                        const std::vector<int>& table_ok = {},
                        const std::vector<std::pair<int, int>>& gripper_ok = {});
  bool Fail(int action, SegmentKind kind, bool suspend, const std::string& message, int blame = -1);
  // The cell as it stands for the failure record: every robot where it is (cur_), the parts as
  // the scene has them.
  FailureScene CellNow();
  // Adds the segment with the robots' current openings, advancing cur_ to its last waypoint.
  void Push(GeoSegment seg);
  // Adds a straight skill of `robots` (waypoints[k][i] for robots[i]) of Cartesian `length_m`
  // done at `speed_mps`.
  void PushSkill(SegmentKind kind, int action, bool main, std::vector<int> robots,
                 std::vector<int> objects, std::vector<std::vector<JointVector>> waypoints,
                 double length_m, double speed_mps);
  // PushSkill of one robot's waypoints.
  void PushSkill(SegmentKind kind, int action, bool main, int robot, int object,
                 const std::vector<JointVector>& waypoints, double length_m, double speed_mps);
  // Fills seg.sweep (scene at the segment's start).
  void Sweep(GeoSegment& seg);
  // Everything a free path's validity depends on besides its own robots' start and goal: every
  // robot's joints, the objects' poses, the holds, grasps and finger openings.
  std::vector<double> SceneKey() const;
  BuilderCheckpoint Save() const;
  // Back to the checkpoint's output, joints and openings (free_index_ is the caller's).
  void Restore(const BuilderCheckpoint& saved);

  Iso3 Tcp(int robot, const JointVector& q) const {
    const TaskRobot& r = w_.robots[robot];
    return TcpPose(r.chain, r.X_WB, q, r.end_effector.X_FT);
  }
  std::string Name(int robot) const { return "'" + w_.robots[robot].name + "'"; }
  std::string NodeName(int node) const {
    return node >= 0 && node < static_cast<int>(plan_.nodes.size()) ? "'" + plan_.nodes[node] + "'"
                                                                    : "object";
  }

  // --- Straight TCP moves (cartesian_track.cpp).
  // Straight TCP moves of `robots` from `q0`: robot i's TCP follows targets[i](s), s in [0, 1],
  // in `steps` samples. Empty on failure (no IK, a branch jump).
  // With `goals`, a redundant arm is pulled toward its goal joints along the way. Each sample is
  // within `tolerance_m` of its target (and a tenth of it in radians): a grasp, a lift or an
  // insertion holds the validators' grasp tolerance; a gripper backing away from what it let go
  // only needs to stay clear (BackOff).
  std::vector<std::vector<JointVector>> Track(
      const std::vector<int>& robots, const std::vector<JointVector>& q0,
      const std::vector<std::function<Iso3(double)>>& targets, int steps,
      const std::vector<JointVector>* goals = nullptr, double tolerance_m = kTrackTolerance);
  // Targets for Track: robot robots[i]'s TCP at joints q[i], translated by s * offset.
  std::vector<std::function<Iso3(double)>> ShiftedTcps(const std::vector<int>& robots,
                                                       const std::vector<JointVector>& q,
                                                       const Vec3& offset) const;
  // One arm's path: the fewest of its samples (the first and the last kept) between which straight
  // joint motion stays within `tolerance_m` (at most kTrackTolerance; a tenth of it in radians
  // times 10) of every dropped sample's TCP pose: a skill is timed piece by piece, each piece
  // from rest to rest, so a line tracked at millimetres would be driven in jerks (MuJoCo saw
  // the load on a lifting gripper swing by +-30%).
  std::vector<std::vector<JointVector>> Simplify(const std::vector<int>& robots,
                                                 std::vector<std::vector<JointVector>> path,
                                                 double tolerance_m) const;
  // Collision-free straight joint motion between consecutive waypoints (scene already set).
  bool PathClear(const std::vector<int>& robots,
                 const std::vector<std::vector<JointVector>>& waypoints);
  // Whether robot r at q is in a tight pocket: more than one in eight small perturbations of its
  // joints (kTightRad) collide in the current scene.
  bool Tight(int robot, const JointVector& q);

  // --- Free paths (free_paths.cpp).
  // Free motion of `robots` to `goals`. With `others` (one robot only): other goals that serve
  // as well; *reached tells which was reached (0: goals[0], k: others[k - 1]).
  bool Free(int action, bool main, const std::vector<int>& robots,
            const std::vector<JointVector>& goals, const std::vector<int>& objects,
            const std::vector<JointVector>* others = nullptr, int* reached = nullptr);
  // The progress line of a free path search.
  void ReportFree(const FreeRequest& req);
  // The cached path of the request's index, pushed as `seg`, when it is the same query in the
  // same scene (`scene_key`); false otherwise.
  bool ReuseFree(const FreeRequest& req, const std::vector<double>& scene_key, GeoSegment& seg,
                 int* reached);
  // One path query in the composite space of `who` (goals `to`); the path, on success, is
  // appended to *path.
  PathAnswer FreeQuery(const FreeRequest& req, const std::vector<int>& who,
                       const std::vector<JointVector>& to,
                       std::vector<std::vector<JointVector>>* path);
  // The query's joint bounds, start and goals (the request's other goals for one robot).
  PathQuery FreeQueryBounds(const FreeRequest& req, const std::vector<int>& who,
                            const std::vector<JointVector>& to) const;
  // A composite state of `who` split into each robot's joints.
  std::vector<JointVector> SplitComposite(const std::vector<int>& who,
                                          const Eigen::VectorXd& x) const;
  // What the failed query's start or goal hits, for the log (empty when not logging).
  std::string DescribeFreeFailure(int action, const std::vector<int>& who,
                                  const std::vector<JointVector>& to, const PathAnswer& answer);
  // Logging ("motion.diag") after a timed-out search of one robot: are its start and goal cut
  // off from its home, and what does the goal's neighbourhood hit.
  void DiagnoseFree(const FreeRequest& req);
  // After a timed-out search: the idle robots (free, not in the request) may step aside and
  // come back; searched in the composite space of all of them (`who` becomes it).
  void StepAside(const FreeRequest& req, PathAnswer& answer,
                 std::vector<std::vector<JointVector>>& path, std::vector<int>& who);
  // The loads of the robots of `robots` that carry an object alone (state_).
  std::vector<SoleLoad> SoleLoads(const std::vector<int>& robots) const;
  // LoadRatio of the load's weight at joints q.
  double LoadRatio(const SoleLoad& load, const JointVector& q) const {
    return wrap::LoadRatio(load, Tcp(load.robot, q).linear());
  }
  // Sets robot's finger opening for a free move toward a grasp: `wanted`, unless the fingers at
  // `wanted` hit something where the robot stands and at their present opening do not (then
  // they stay). False when the scene cannot be set.
  bool MoveOpening(int robot, double wanted);

  // --- Skills (skills.cpp).
  // Backs robot r's TCP away from q along its approach axis (TCP z) by up to approach_m,
  // collision-free in the current scene, to an end that `end_clear` (when given) accepts; the
  // waypoints from q outwards, or empty.
  std::vector<JointVector> BackOff(int robot, const JointVector& q, double* length,
                                   const std::function<bool(const JointVector&)>& end_clear = {});
  // Robot r at q_end touches nothing in the scene of `openings` with no gripper contact
  // allowed; the scene is then set again with `gripper_ok` (the straight move's), robots at cur_.
  bool EndClear(int robot, const JointVector& q_end, const std::vector<double>& openings,
                const std::vector<std::pair<int, int>>& gripper_ok);
  // A robot that let go of an object (released_) backs its gripper away from it.
  bool Retreat(int action, int robot);
  bool Lift(int action, int node, const std::vector<int>& holders);
  // The approach of each grasper of action i, planned backwards from its grasp, and the other
  // IK solutions of the grasp it may approach instead (w.approaches, approach_len,
  // alternatives).
  bool PlanApproaches(int i, ActionWork& w);
  // The joints robot r may grasp with at action i: its keyframe joints, then (UR arms, at
  // effort 1 and more) the other IK solutions of the same TCP pose that every keyframe it would
  // rewrite accepts.
  std::vector<JointVector> GraspSolutions(int i, int r);
  // BackOff of grasper r from its grasp at joints q, in the scene of action i's keyframe (the
  // grasped object and the carriers where the keyframe has them); false when that scene cannot
  // be set.
  bool BackOffGrasp(int i, const ActionWork& w, int r, const JointVector& q,
                    std::vector<JointVector>& back, double& length);
  // A placement: the straight descent onto the table, top to bottom (w.descend).
  bool PlanPlaceDescent(int i, ActionWork& w);

  // --- The insertion (insertion_skill.cpp).
  // The start of an insertion's slide. The task planner lets the moved input touch the base at
  // the approach keyframe (faces that slide along each other, as in a stack of cubes), but a
  // free path or a carry cannot end in that contact. When the moved input touches the base
  // there (and nothing else is hit), the start moves back along the insertion line, 1 to 6 cm,
  // until the input is clear: `goal` (the approach keyframe) gets the holders' joints and the
  // input's pose there, and the insertion skill slides from it. Otherwise `goal` stays.
  void SlideStart(int action, Keyframe& goal);
  // Whether the insertion of step node `step` stays free of its base over `extra` more travel
  // back along its axis than its approach (the geometry's sweep on the meshes).
  bool LongerSlideFree(int step, double extra);
  // An insertion whose moved input touches the table top at `goal` (its approach keyframe or
  // slide start: the input slides along the table into a resting base): the holders come to a
  // pose lift_m above it instead, and `descent` (their waypoints, top to bottom) lowers it
  // straight onto the table. `goal` becomes the top; nothing changes when the input is clear of
  // the table there. False (with the failure set) when no straight descent is clear.
  bool HoverAbove(int action, Keyframe& goal, std::vector<int>& holders,
                  std::vector<std::vector<JointVector>>& descent, double* length);
  // The insertion of action i: the holders of its moved input slide it straight from where they
  // are to the keyframe (its joints may move to another IK solution of the same TCP pose).
  bool Insert(int i);
  // Whether the moved input of action i's insertion stays within the overlap the geometry allows
  // of its base along `path` (the first inserter's waypoints, straight joint motion between
  // them), sampled every millimetre of the TCP's travel.
  bool InsertionWithinOverlap(int i, const std::vector<int>& inserters,
                              const std::vector<std::vector<JointVector>>& path);

  // --- Carries (carries.cpp).
  bool Carry(int action, int node, const std::vector<int>& holders, const Iso3& X_goal,
             std::vector<JointVector> goal_q, const Keyframe& target, bool approach);
  // The end of a carry: the holders' last joints `last` snapped to their keyframe joints
  // `goal_q` (or to an equivalent turn), or accepted as another IK solution that fits `target`
  // (added to `rebranch`); false with `why` otherwise.
  bool CarryEnd(const std::vector<int>& holders, const std::vector<JointVector>& goal_q,
                const Keyframe& target, std::vector<JointVector>& last,
                std::vector<std::pair<size_t, JointVector>>& rebranch, std::string& why);
  // The holders' joints along the object moving from X_a to X_b (translation straight, rotation
  // by slerp), tracked from q0 and collision-free in the current scene; empty when an arm
  // cannot follow or something is hit.
  std::vector<std::vector<JointVector>> CarryEdge(const std::vector<int>& holders,
                                                  const std::vector<JointVector>& q0,
                                                  const Iso3& X_a, const Iso3& X_b);
  // A carry the straight variants could not make: a tree of object poses grown from the start
  // (RRT with goal bias, each edge tracked by the holders' IK and checked for collisions), then
  // shortcut. Budget: carry_edges * 2^(effort - 1) edges tried. The path on success (empty
  // otherwise).
  std::vector<std::vector<JointVector>> CarrySearch(
      const std::vector<int>& holders, const Iso3& X_start, const Iso3& X_goal,
      const std::vector<JointVector>& goal_q, const Keyframe& target,
      std::vector<std::pair<size_t, JointVector>>& rebranch, double* length, std::string& why);

  // --- The walk over the plan (segments.cpp).
  bool Action(int index);
  // Robots freed earlier (not in action i, holding nothing) go where its keyframe has them.
  bool ReturnFreed(int i);
  // Robot `robot` backs off what it let go, then moves freely to `goal`, fingers open.
  bool Return(int action, int robot, const JointVector& goal, bool main);
  // Who grasps at action i, with which grasp, and which object.
  void FindGraspers(int i, ActionWork& w);
  // The target keyframe of action i (w.target_kf), with an insertion's slide start and hover.
  bool PrepareTarget(int i, ActionWork& w);
  // The objects that move to their target poses (w.moving).
  void FindMoving(int i, ActionWork& w);
  // Robots that let go and stayed back off; what moves is lifted off the table.
  bool RetreatAndLift(int i, ActionWork& w);
  // Sorts the movers into free moves (graspers, single-handed carriers) and two-handed carries.
  void SortMovers(int i, ActionWork& w);
  // The free moves of the graspers and single-handed carriers: one robot after another, in two
  // orders, else all at once in their composite space.
  bool FreeMoves(int i, ActionWork& w);
  // The free move of w.free_robots[k]; `ok` says whether it was found. False when the scene
  // cannot be set.
  bool FreeMoveOne(int i, ActionWork& w, size_t k, bool& ok);
  // All free movers at once in their composite space, from the checkpoint; `ok` as above.
  bool FreeTogether(int i, ActionWork& w, const BuilderCheckpoint& saved, int n_orders, bool& ok);
  // The final skills of action i: the hover's descent, a placement's descent, the insertion,
  // the graspers' approaches.
  bool FinalSkills(int i, ActionWork& w);
  // Every robot at action i's keyframe (keyframes off by whole turns follow the robot).
  bool ArriveAtKeyframe(int i);
  // The grip segment of action i (grippers closing or opening).
  void PushGrip(int i);
  // What action i changes for the builder: released objects to back off from, grounded objects.
  void ApplyEffects(int i, int grasped);
  // Robot r at `q` instead of its joints at the keyframe `kf` (same TCP): collision-free and
  // clear of the other robots there (objects at the keyframe's poses, `mating` allowed).
  bool KeyframeAccepts(int robot, const JointVector& q, const Keyframe& kf,
                       const std::vector<std::pair<int, int>>& mating);
  // Moves robot r from `old_q` to `new_q` at action `action`'s approach keyframe (when
  // `from_approach`) or keyframe and at every following keyframe where it kept `old_q`.
  void Rebranch(int robot, int action, bool from_approach, JointVector old_q, JointVector new_q);
  // Whether every keyframe that Rebranch(robot, action, from_approach, old_q, new_q) would
  // rewrite accepts new_q (KeyframeAccepts in the state before its action).
  bool StageAccepts(int robot, int action, bool from_approach, const JointVector& old_q,
                    const JointVector& new_q);

  const TaskWorld& w_;
  Plan& plan_;
  const MotionOptions& opt_;
  int effort_;
  std::uint64_t seed_;
  MotionCache& cache_;
  RunContext& ctx_;
  MotionFailure* failure_;

  std::optional<MotionScene>* scene_holder_ = nullptr;  // the caller's scene, if it keeps one
  std::optional<MotionScene> own_scene_;
  MotionScene* scene_ = nullptr;  // one of them (Run)
  std::vector<PlanState> states_;
  PlanState state_;
  std::vector<JointVector> cur_;
  std::vector<double> opening_;
  std::vector<int> released_;     // per robot: object let go at its last event, not yet backed off
  std::vector<int> released_at_;  // per robot: the action of that event
  std::set<int> grounded_;        // objects touching the table top
  std::vector<GeoSegment> out_;
  int free_index_ = 0;
  bool cancelled_ = false;
  std::string last_hit_;         // the bodies of the last collision PathClear met
  FailureScene last_hit_scene_;  // and the cell at it
  bool hover_ = false;  // the carries' goal is a hover pose, not a keyframe: no rebranching
  bool jump_ = false;   // a segment did not start where its robots were (see Push)
  std::mt19937_64 rng_;
  std::optional<AssemblyGeometry> geometry_;  // the parts' meshes: longer insertion slides
};

}  // namespace wrap::detail
