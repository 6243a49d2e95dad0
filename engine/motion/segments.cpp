#include "motion/segments.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <utility>

#include "mating/check.h"
#include "motion/ompl_adapter.h"
#include "robot/ik.h"
#include "robot/kinematics.h"

namespace wrap {

namespace {

constexpr std::array<std::string_view, 8> kKindNames = {"free",    "approach", "retreat", "lift",
                                                        "descend", "insert",   "carry",   "grip"};

// Largest joint jump between two IK samples of a straight move before it counts as a branch
// switch (no straight move there) [rad].
constexpr double kMaxTrackJump = 0.25;
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
// Least distance between two robots at a keyframe, as the task planner keeps it [m].
constexpr double kMinClearance = 0.005;

bool Same(const JointVector& a, const JointVector& b) {
  return a.size() == b.size() && (a - b).cwiseAbs().maxCoeff() <= 1e-9;
}

bool SamePose(const Iso3& a, const Iso3& b) {
  return (a.translation() - b.translation()).norm() <= 1e-7 &&
         (a.linear() - b.linear()).cwiseAbs().maxCoeff() <= 1e-7;
}

std::uint64_t Mix(std::uint64_t a, std::uint64_t b) {
  std::uint64_t x = a ^ (b + 0x9e3779b97f4a7c15ULL + (a << 6) + (a >> 2));
  x ^= x >> 31;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 29;
  return x;
}

const PlanObject* FindObject(const Keyframe& k, int node) {
  for (const PlanObject& o : k.objects) {
    if (o.node == node) return &o;
  }
  return nullptr;
}

class Builder {
 public:
  Builder(const TaskWorld& world, Plan& plan, const MotionOptions& options, int effort,
          std::uint64_t seed, MotionCache& cache, RunContext& ctx, MotionFailure* failure)
      : w_(world),
        plan_(plan),
        opt_(options),
        effort_(effort),
        seed_(seed),
        cache_(cache),
        ctx_(ctx),
        failure_(failure) {}

  Result<std::vector<GeoSegment>> Run();

 private:
  // Straight TCP moves of `robots` from `q0`: robot i's TCP follows targets[i](s), s in [0, 1],
  // in `steps` samples. Empty on failure (no IK, a branch jump).
  // With `goals`, a redundant arm is pulled toward its goal joints along the way.
  std::vector<std::vector<JointVector>> Track(
      const std::vector<int>& robots, const std::vector<JointVector>& q0,
      const std::vector<std::function<Iso3(double)>>& targets, int steps,
      const std::vector<JointVector>* goals = nullptr);
  // One arm's path: the fewest of its samples (the first and the last kept) between which straight
  // joint motion stays within a fraction of a millimetre of every dropped sample's TCP pose: a
  // skill is timed piece by piece, each piece from rest to rest, so a line tracked at millimetres
  // would be driven in jerks (MuJoCo saw the load on a lifting gripper swing by +-30%).
  std::vector<std::vector<JointVector>> Simplify(const std::vector<int>& robots,
                                                 std::vector<std::vector<JointVector>> path) const;
  // Collision-free straight joint motion between consecutive waypoints (scene already set).
  bool PathClear(const std::vector<int>& robots,
                 const std::vector<std::vector<JointVector>>& waypoints);
  Result<void> SetScene(const std::vector<double>& openings,
                        const std::vector<std::pair<int, int>>& mating = {},
                        const std::vector<int>& table_ok = {},
                        const std::vector<std::pair<int, int>>& gripper_ok = {});
  bool Fail(int action, SegmentKind kind, bool suspend, const std::string& message, int blame = -1);
  // The cell as it stands for the failure record: every robot where it is (cur_), the parts as
  // the scene has them.
  FailureScene CellNow();
  Iso3 Tcp(int robot, const JointVector& q) const {
    const TaskRobot& r = w_.robots[robot];
    return TcpPose(r.chain, r.X_WB, q, r.end_effector.X_FT);
  }
  std::string Name(int robot) const { return "'" + w_.robots[robot].name + "'"; }
  std::string NodeName(int node) const {
    return node >= 0 && node < static_cast<int>(plan_.nodes.size()) ? "'" + plan_.nodes[node] + "'"
                                                                    : "object";
  }
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
  // Fills seg.boxes (scene at the segment's start).
  void Sweep(GeoSegment& seg);
  // Backs robot r's TCP away from q along its approach axis (TCP z) by up to approach_m,
  // collision-free in the current scene; the waypoints from q outwards, or empty.
  std::vector<JointVector> BackOff(int robot, const JointVector& q, double* length);
  // Whether robot r at q is in a tight pocket: more than one in eight small perturbations of its
  // joints (kTightRad) collide in the current scene.
  bool Tight(int robot, const JointVector& q);
  // Everything a free path's validity depends on besides its own robots' start and goal: every
  // robot's joints, the objects' poses, the holds, grasps and finger openings.
  std::vector<double> SceneKey() const;
  bool Retreat(int action, int robot);
  // The weight of an object that robot `robot` holds alone, as its gripper takes it.
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
  // Free motion of `robots` to `goals`. With `others` (one robot only): other goals that serve
  // as well; *reached tells which was reached (0: goals[0], k: others[k - 1]).
  bool Free(int action, bool main, const std::vector<int>& robots,
            const std::vector<JointVector>& goals, const std::vector<int>& objects,
            const std::vector<JointVector>* others = nullptr, int* reached = nullptr);
  bool Lift(int action, int node, const std::vector<int>& holders);
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
  bool Action(int index);
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
  bool Return(int action, int robot, const JointVector& goal, bool main);
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

  MotionScene scene_;
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
  std::string last_hit_;  // the bodies of the last collision PathClear met
  FailureScene last_hit_scene_;  // and the cell at it
  bool hover_ = false;    // the carries' goal is a hover pose, not a keyframe: no rebranching
  bool jump_ = false;     // a segment did not start where its robots were (see Push)
  std::mt19937_64 rng_;
  std::optional<AssemblyGeometry> geometry_;  // the parts' meshes: longer insertion slides
};

Result<void> Builder::SetScene(const std::vector<double>& openings,
                               const std::vector<std::pair<int, int>>& mating,
                               const std::vector<int>& table_ok,
                               const std::vector<std::pair<int, int>>& gripper_ok) {
  // Objects still where they were picked from touch the table until they are lifted.
  std::vector<int> on_table = table_ok;
  on_table.insert(on_table.end(), grounded_.begin(), grounded_.end());
  return scene_.Set(state_, openings, cur_, mating, on_table, gripper_ok);
}

bool Builder::Fail(int action, SegmentKind kind, bool suspend, const std::string& message,
                   int blame) {
  if (failure_) {
    failure_->action = action;
    failure_->blame = blame >= 0 ? blame : action;
    failure_->segment = std::string(ToString(kind));
    failure_->suspend = suspend;
    failure_->message = message;
    // The collision the message names, where it happened; else the cell where the segment
    // starts.
    const bool named = !last_hit_.empty() && message.find(last_hit_) != std::string::npos &&
                       !last_hit_scene_.q.empty();
    failure_->scene = named ? last_hit_scene_ : CellNow();
  }
  return false;
}

FailureScene Builder::CellNow() {
  FailureScene scene;
  scene.q = cur_;
  scene.X_WP.resize(w_.num_parts);
  for (int p = 0; p < w_.num_parts; ++p) scene.X_WP[p] = scene_.cell().object_pose(p);
  return scene;
}

void Builder::Push(GeoSegment seg) {
  if (seg.openings.empty()) seg.openings = opening_;
  for (size_t i = 0; i < seg.robots.size() && !seg.waypoints.empty(); ++i) {
    const int r = seg.robots[i];
    if ((seg.waypoints.front()[i] - cur_[r]).cwiseAbs().maxCoeff() > 1e-6 && !jump_) {
      // A bug, not a plan that has no motion: the trajectory would jump.
      jump_ = true;
      Fail(seg.action, seg.kind, false,
           "internal: the " + std::string(ToString(seg.kind)) + " segment of " + Name(r) +
               " does not start where the robot is");
    }
  }
  Sweep(seg);
  for (size_t i = 0; i < seg.robots.size(); ++i) cur_[seg.robots[i]] = seg.waypoints.back()[i];
  out_.push_back(std::move(seg));
}

void Builder::PushSkill(SegmentKind kind, int action, bool main, std::vector<int> robots,
                        std::vector<int> objects, std::vector<std::vector<JointVector>> waypoints,
                        double length_m, double speed_mps) {
  GeoSegment seg;
  seg.kind = kind;
  seg.action = action;
  seg.main = main;
  seg.robots = std::move(robots);
  seg.objects = std::move(objects);
  seg.waypoints = std::move(waypoints);
  seg.skill_length_m = length_m;
  seg.skill_speed_mps = speed_mps;
  Push(std::move(seg));
}

void Builder::PushSkill(SegmentKind kind, int action, bool main, int robot, int object,
                        const std::vector<JointVector>& waypoints, double length_m,
                        double speed_mps) {
  std::vector<std::vector<JointVector>> composite;
  for (const JointVector& q : waypoints) composite.push_back({q});
  PushSkill(kind, action, main, {robot}, {object}, std::move(composite), length_m, speed_mps);
}

void Builder::Sweep(GeoSegment& seg) {
  // Samples no farther apart than kSweepStep in the sum of joint changes: with links at most
  // kLever from their joints, a body point between two samples lies within kSweepMargin of one.
  // Per body: its whole sweep, then the sweeps of runs of kChunk samples.
  constexpr double kSweepStep = 0.03;  // [rad]
  constexpr double kLever = 1.5;       // [m]
  constexpr double kSweepMargin = 0.5 * kSweepStep * kLever + 0.01;
  constexpr int kChunk = 6;
  if (!SetScene(seg.openings)) return;
  std::vector<std::vector<Aabb>> sweep;  // per body: [0] all, then chunks
  std::vector<Aabb> sample;
  int count = 0;
  auto merge = [](Aabb& into, const Aabb& b) {
    into.min = into.min.cwiseMin(b.min);
    into.max = into.max.cwiseMax(b.max);
  };
  auto add = [&] {
    sample.clear();
    for (int r : seg.robots) scene_.AppendBoxes(r, sample);
    for (int node : seg.objects) {
      if (state_.objects.count(node)) scene_.AppendObjectBoxes(node, sample);
    }
    if (sweep.size() != sample.size()) {  // first sample (or a body appeared: start over)
      sweep.assign(sample.size(), {});
      for (size_t b = 0; b < sample.size(); ++b) sweep[b] = {sample[b], sample[b]};
      count = 1;
      return;
    }
    const bool fresh = count % kChunk == 0;
    for (size_t b = 0; b < sample.size(); ++b) {
      merge(sweep[b][0], sample[b]);
      if (fresh) {
        sweep[b].push_back(sample[b]);
      } else {
        merge(sweep[b].back(), sample[b]);
      }
    }
    ++count;
  };
  const auto& wp = seg.waypoints;
  for (size_t i = 0; i < seg.robots.size(); ++i) scene_.SetRobot(seg.robots[i], wp[0][i]);
  add();
  for (size_t k = 1; k < wp.size(); ++k) {
    double l1 = 0.0;
    for (size_t i = 0; i < seg.robots.size(); ++i) l1 += (wp[k][i] - wp[k - 1][i]).cwiseAbs().sum();
    const int steps = std::max(1, static_cast<int>(std::ceil(l1 / kSweepStep)));
    for (int s = 1; s <= steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      for (size_t i = 0; i < seg.robots.size(); ++i) {
        scene_.SetRobot(seg.robots[i], wp[k - 1][i] + t * (wp[k][i] - wp[k - 1][i]));
      }
      add();
    }
  }
  for (auto& boxes : sweep) {
    for (Aabb& b : boxes) {
      b.min.array() -= kSweepMargin;
      b.max.array() += kSweepMargin;
    }
  }
  seg.sweep = std::move(sweep);
}

std::vector<std::vector<JointVector>> Builder::Track(
    const std::vector<int>& robots, const std::vector<JointVector>& q0,
    const std::vector<std::function<Iso3(double)>>& targets, int steps,
    const std::vector<JointVector>* goals) {
  std::vector<std::vector<JointVector>> out(steps + 1, std::vector<JointVector>(robots.size()));
  NumericIkOptions ik;
  ik.restarts = 0;
  ik.max_iterations = 100;
  ik.position_tolerance_m = 5e-4;  // within the validators' grasp tolerance (2 mm)
  ik.rotation_tolerance_rad = 5e-3;
  for (size_t i = 0; i < robots.size(); ++i) {
    const TaskRobot& r = w_.robots[robots[i]];
    JointVector q = q0[i];
    out[0][i] = q;
    // UR arms: the closed form on the start's branch (continuous away from singularities).
    const int branch = r.ur ? r.ur->BranchOf(r.chain, q) : -1;
    for (int k = 1; k <= steps; ++k) {
      const double s = static_cast<double>(k) / steps;
      const Iso3 X_BT = r.X_BW * targets[i](s);
      JointVector next;
      if (branch >= 0) {
        UrIkOptions options;
        options.q6_if_singular = q[5];
        const UrIkSolutions sols = r.ur->SolveTcp(X_BT, r.end_effector.X_FT, options);
        for (int c = 0; c < sols.count; ++c) {
          if (sols.branch[c] == branch) next = NearestEquivalent(r.chain, sols.q[c], q);
        }
        if (next.size() == 0) return {};
      } else {
        NumericIkRequest req;
        req.X_BT = X_BT;
        req.X_FT = r.end_effector.X_FT;
        // From the last sample, and from it nudged away from the joint limits (an arm stuck at a
        // limit finds the way round through its redundancy).
        JointVector centred = q;
        for (int j = 0; j < q.size(); ++j) {
          centred[j] += 0.15 * (0.5 * (r.chain.joints[j].lower + r.chain.joints[j].upper) - q[j]);
        }
        req.seeds = {q, centred};
        // A redundant arm drifts toward its goal joints where it has a choice.
        req.reference = goals ? JointVector(q0[i] + s * ((*goals)[i] - q0[i])) : q;
        auto sol = SolveNumericIk(r.chain, req, rng_, ik);
        if (!sol) {
          if (ctx_.Logs("motion")) {
            ctx_.Log("motion", StrFormat("track: %s step %d/%d: %s", r.name.c_str(), k, steps,
                         sol.error().message.c_str()));
          }
          return {};
        }
        next = sol->q;
      }
      if ((next - q).cwiseAbs().maxCoeff() > kMaxTrackJump) {
        if (ctx_.Logs("motion")) {
          ctx_.Log("motion", StrFormat("track: %s step %d/%d: jump %.3f", r.name.c_str(), k, steps,
                       (next - q).cwiseAbs().maxCoeff()));
        }
        return {};
      }
      q = next;
      out[k][i] = q;
    }
  }
  return Simplify(robots, std::move(out));
}

std::vector<std::vector<JointVector>> Builder::Simplify(
    const std::vector<int>& robots, std::vector<std::vector<JointVector>> path) const {
  // Arms that hold one object together keep every sample: where two grippers leave their
  // lines differently they pull on the object against each other (MuJoCo saw 50 N inside a
  // cross's base carried with 0.2 mm of tolerance, more than stop and go costs).
  if (path.size() <= 2 || robots.size() > 1) return path;
  // One arm may leave its Cartesian line by half a millimetre.
  const double tol_m = 5e-4;
  const double tol_rad = 5e-3;
  std::vector<std::vector<Iso3>> X(path.size(), std::vector<Iso3>(robots.size()));
  for (size_t k = 0; k < path.size(); ++k) {
    for (size_t i = 0; i < robots.size(); ++i) X[k][i] = Tcp(robots[i], path[k][i]);
  }
  // The straight joint motion from a to b passes within the tolerance of every sample between.
  auto covers = [&](size_t a, size_t b) {
    for (size_t m = a + 1; m < b; ++m) {
      const double f = static_cast<double>(m - a) / static_cast<double>(b - a);
      for (size_t i = 0; i < robots.size(); ++i) {
        const Iso3 Xl = Tcp(robots[i], path[a][i] + f * (path[b][i] - path[a][i]));
        if ((Xl.translation() - X[m][i].translation()).norm() > tol_m) return false;
        if (Eigen::AngleAxisd(Xl.linear().transpose() * X[m][i].linear()).angle() > tol_rad) {
          return false;
        }
      }
    }
    return true;
  };
  std::vector<std::vector<JointVector>> out = {path.front()};
  size_t a = 0;
  while (a + 1 < path.size()) {
    size_t b = a + 1;
    while (b + 1 < path.size() && covers(a, b + 1)) ++b;
    out.push_back(path[b]);
    a = b;
  }
  return out;
}

bool Builder::PathClear(const std::vector<int>& robots,
                        const std::vector<std::vector<JointVector>>& waypoints) {
  for (size_t k = 0; k < waypoints.size(); ++k) {
    const size_t prev = k == 0 ? 0 : k - 1;
    double span = 0.0;
    for (size_t i = 0; i < robots.size(); ++i) {
      span = std::max(span, (waypoints[k][i] - waypoints[prev][i]).cwiseAbs().maxCoeff());
    }
    const int steps =
        std::max(1, static_cast<int>(std::ceil(span * kRefine / opt_.resolution_rad)));
    for (int s = (k == 0 ? steps : 1); s <= steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      for (size_t i = 0; i < robots.size(); ++i) {
        scene_.SetRobot(robots[i], waypoints[prev][i] + t * (waypoints[k][i] - waypoints[prev][i]));
      }
      if (scene_.Collides(robots)) {
        CollisionResult hit;
        scene_.cell().InCollision(&hit);
        const CollisionWorld& cw = scene_.cell().world();
        last_hit_ = "'" + cw.body_name(hit.first.body_a) + "' hits '" +
                    cw.body_name(hit.first.body_b) + "'";
        // The failure record's picture: the robots where they hit, the parts as set.
        last_hit_scene_ = CellNow();
        for (size_t i = 0; i < robots.size(); ++i) {
          last_hit_scene_.q[robots[i]] =
              waypoints[prev][i] + t * (waypoints[k][i] - waypoints[prev][i]);
        }
        last_hit_scene_.bodies = {cw.body_name(hit.first.body_a), cw.body_name(hit.first.body_b)};
        return false;
      }
    }
  }
  return true;
}

std::vector<double> Builder::SceneKey() const {
  std::vector<double> key;
  for (const JointVector& q : cur_) key.insert(key.end(), q.data(), q.data() + q.size());
  key.insert(key.end(), opening_.begin(), opening_.end());
  for (int r : released_) key.push_back(r);
  for (const auto& [node, o] : state_.objects) {
    key.push_back(node);
    key.push_back(o.resting ? 1.0 : 0.0);
    const Eigen::Matrix4d m = o.X_WA.matrix();
    key.insert(key.end(), m.data(), m.data() + 12);
  }
  for (size_t r = 0; r < state_.held.size(); ++r) {
    key.push_back(state_.held[r]);
    if (state_.held[r] >= 0 && r < state_.grasp.size()) {
      key.push_back(state_.grasp[r].subassembly);
      key.push_back(state_.grasp[r].index);
    }
  }
  return key;
}

bool Builder::Tight(int robot, const JointVector& q) {
  // A few small joint perturbations, the same every time.
  std::mt19937_64 g(0x7469676874);
  std::uniform_real_distribution<double> u(-kTightRad, kTightRad);
  int bad = 0;
  for (int t = 0; t < kTightSamples; ++t) {
    JointVector x = q;
    for (int j = 0; j < x.size(); ++j) x[j] += u(g);
    scene_.SetRobot(robot, x);
    bad += scene_.Collides(std::span<const int>(&robot, 1));
  }
  scene_.SetRobot(robot, q);
  return bad > kTightSamples / 8;
}

std::vector<JointVector> Builder::BackOff(int robot, const JointVector& q, double* length) {
  const Iso3 X0 = Tcp(robot, q);
  const Vec3 axis = X0.linear().col(2);
  // The straight move back by d, collision-free, or empty (last_hit_ says why).
  auto straight = [&](double d) {
    const int steps = std::max(2, static_cast<int>(std::ceil(d / opt_.cartesian_step_m)));
    auto target = [X0, axis, d](double s) {
      Iso3 X = X0;
      X.translation() -= s * d * axis;
      return X;
    };
    auto path = Track({robot}, {q}, {target}, steps);
    std::vector<JointVector> out;
    if (path.empty()) {
      last_hit_ = "no IK solution along the line";
    } else if (PathClear({robot}, path)) {
      for (auto& wp : path) out.push_back(wp[0]);
    }
    return out;
  };
  // Longer first where the end of the usual length is in a tight pocket (free path searches
  // hardly leave one); then the usual length and shorter ones.
  std::vector<std::vector<JointVector>> longer;
  for (double d : {opt_.approach_m, 2 * opt_.approach_m, 3 * opt_.approach_m}) {
    std::vector<JointVector> out = straight(d);
    if (out.empty()) break;
    *length = d;
    if (!Tight(robot, out.back()) || d > 2.5 * opt_.approach_m) return out;
    longer.push_back(std::move(out));
  }
  if (!longer.empty()) {
    *length = opt_.approach_m * static_cast<double>(longer.size());
    return longer.back();
  }
  for (double d : {opt_.approach_m / 2, opt_.approach_m / 4, opt_.approach_m / 8}) {
    std::vector<JointVector> out = straight(d);
    if (out.empty()) continue;
    *length = d;
    return out;
  }
  return {};
}

std::vector<SoleLoad> Builder::SoleLoads(const std::vector<int>& robots) const {
  std::vector<SoleLoad> out;
  for (int r : robots) {
    if (std::optional<SoleLoad> l = SoleLoadOf(w_, state_, r)) out.push_back(*l);
  }
  return out;
}

bool Builder::MoveOpening(int robot, double wanted) {
  const double now = opening_[robot];
  opening_[robot] = wanted;
  if (wanted == now) return true;
  if (!SetScene(opening_)) return false;
  if (!scene_.Collides(std::vector<int>{robot})) return true;
  opening_[robot] = now;
  if (!SetScene(opening_)) return false;
  if (scene_.Collides(std::vector<int>{robot})) opening_[robot] = wanted;
  return true;
}

bool Builder::Retreat(int action, int robot) {
  const int node = released_[robot];
  if (node < 0) return true;
  if (!SetScene(opening_, {}, {}, {{robot, node}})) return false;
  double length = 0.0;
  std::vector<JointVector> back = BackOff(robot, cur_[robot], &length);
  if (back.empty()) {
    return Fail(action, SegmentKind::kRetreat, false,
                Name(robot) + " cannot back its gripper away from " + NodeName(node) +
                    " along the gripper axis: " + last_hit_,
                released_at_[robot]);
  }
  PushSkill(SegmentKind::kRetreat, action, false, robot, node, back, length, opt_.skill_speed_mps);
  released_[robot] = -1;
  return true;
}

bool Builder::Free(int action, bool main, const std::vector<int>& robots,
                   const std::vector<JointVector>& goals, const std::vector<int>& objects,
                   const std::vector<JointVector>* others, int* reached) {
  if (reached) *reached = 0;
  if (others && others->empty()) others = nullptr;
  std::vector<int> movers;
  std::vector<JointVector> targets;
  for (size_t i = 0; i < robots.size(); ++i) {
    if (!Same(cur_[robots[i]], goals[i])) {
      movers.push_back(robots[i]);
      targets.push_back(goals[i]);
    }
  }
  if (movers.empty()) return true;
  const int index = free_index_++;
  {
    std::string names;
    for (int r : movers) names += (names.empty() ? "" : ", ") + Name(r);
    ctx_.Progress("motion", static_cast<double>(action) / std::max<size_t>(1, plan_.actions.size()),
                  "action " + std::to_string(action + 1) + "/" +
                      std::to_string(plan_.actions.size()) + ": free path " +
                      std::to_string(index + 1) + " for " + names);
  }
  if (cache_.free_paths.size() <= static_cast<size_t>(index)) cache_.free_paths.resize(index + 1);
  GeoSegment seg;
  seg.kind = SegmentKind::kFree;
  seg.action = action;
  seg.main = main;
  seg.objects = objects;
  seg.openings = opening_;
  const std::vector<double> scene_key = SceneKey();
  if (const MotionCache::Path& c = cache_.free_paths[index];
      !c.waypoints.empty() && c.scene == scene_key) {
    // Reuse a path solved at a lower effort when it is the same query in the same scene.
    bool same = true;
    int end = 0;
    for (size_t i = 0; i < movers.size() && same; ++i) {
      const auto it = std::find(c.robots.begin(), c.robots.end(), movers[i]);
      same = it != c.robots.end();
      if (same) {
        const size_t j = static_cast<size_t>(it - c.robots.begin());
        same = Same(c.waypoints.front()[j], cur_[movers[i]]) &&
               Same(c.waypoints.back()[j], targets[i]);
        if (!same && others && movers.size() == 1 &&
            Same(c.waypoints.front()[j], cur_[movers[i]])) {
          for (size_t k = 0; k < others->size() && !same; ++k) {
            same = Same(c.waypoints.back()[j], (*others)[k]);
            end = static_cast<int>(k) + 1;
          }
        }
      }
    }
    if (same) {
      if (ctx_.Logs("motion")) {
        ctx_.Log("motion", StrFormat("free: action %d: reused path %d", action + 1, index));
      }
      if (reached) *reached = end;
      seg.robots = c.robots;
      seg.waypoints = c.waypoints;
      seg.free_index = index;
      Push(std::move(seg));
      return true;
    }
  }
  if (!SetScene(opening_)) return false;
  // One query in the composite space of `who` (goals `to`).
  auto plan = [&](const std::vector<int>& who, const std::vector<JointVector>& to,
                  std::vector<std::vector<JointVector>>* path) {
    PathQuery query;
    int dim = 0;
    for (int r : who) dim += static_cast<int>(w_.robots[r].chain.joints.size());
    query.lower.resize(dim);
    query.upper.resize(dim);
    query.start.resize(dim);
    query.goal.resize(dim);
    int k = 0;
    for (size_t i = 0; i < who.size(); ++i) {
      const Chain& chain = w_.robots[who[i]].chain;
      for (size_t j = 0; j < chain.joints.size(); ++j, ++k) {
        query.start[k] = cur_[who[i]][j];
        query.goal[k] = to[i][j];
        // Samples within half a turn beyond the ends (joints of +-2 pi would wrap in vain).
        const double lo = std::min(query.start[k], query.goal[k]) - M_PI;
        const double hi = std::max(query.start[k], query.goal[k]) + M_PI;
        query.lower[k] = std::max(chain.joints[j].lower, lo);
        query.upper[k] = std::min(chain.joints[j].upper, hi);
      }
    }
    if (others && who.size() == 1) {
      for (const JointVector& g : *others) {
        query.other_goals.push_back(g);
        query.lower = query.lower.cwiseMin(g);
        query.upper = query.upper.cwiseMax(g);
      }
    }
    auto split = [&](const Eigen::VectorXd& x) {
      std::vector<JointVector> qs(who.size());
      int o = 0;
      for (size_t i = 0; i < who.size(); ++i) {
        const int n = static_cast<int>(w_.robots[who[i]].chain.joints.size());
        qs[i] = x.segment(o, n);
        o += n;
      }
      return qs;
    };
    // Objects carried by one robot: their weight on the gripper stays within the limits' share
    // (or the worse of the two ends' loads).
    const std::vector<SoleLoad> loads = SoleLoads(who);
    std::vector<std::pair<size_t, double>> load_bound;  // (index in who, largest ratio)
    for (const SoleLoad& load : loads) {
      const size_t i =
          static_cast<size_t>(std::find(who.begin(), who.end(), load.robot) - who.begin());
      load_bound.push_back({i, std::max({opt_.transport_load_max, LoadRatio(load, cur_[who[i]]),
                                         LoadRatio(load, to[i])}) +
                                   1e-9});
    }
    for (size_t l = 0; l < loads.size() && ctx_.Logs("motion"); ++l) {
      ctx_.Log("motion", StrFormat("load: action %d %s: up to %.2f of its limits", action + 1,
                                   Name(loads[l].robot).c_str(), load_bound[l].second));
    }
    query.valid = [&](const Eigen::VectorXd& x) {
      const std::vector<JointVector> qs = split(x);
      for (size_t l = 0; l < loads.size(); ++l) {
        if (LoadRatio(loads[l], qs[load_bound[l].first]) > load_bound[l].second) return false;
      }
      for (size_t i = 0; i < who.size(); ++i) scene_.SetRobot(who[i], qs[i]);
      return !scene_.Collides(who);
    };
    query.resolution = opt_.resolution_rad;
    query.max_checks = opt_.segment_checks << effort_;
    query.seed = Mix(seed_, static_cast<std::uint64_t>(index) * 2 + (who.size() > movers.size()));
    if (auto it = cache_.reseed.find(index); it != cache_.reseed.end()) {
      query.seed = Mix(query.seed, 0x7265736565640000ULL + static_cast<std::uint64_t>(it->second));
    }
    query.stop = [this] { return ctx_.ShouldStop(); };
    query.shortcut_attempts = opt_.shortcut_attempts;
    const auto t_query = std::chrono::steady_clock::now();
    query.final_resolution = query.resolution / kRefine;
    const PathAnswer answer = PlanPath(query);
    std::string hit;
    if (ctx_.Logs("motion") && !answer.solved && !answer.timed_out) {
      const bool at_start = answer.why.find("start") != std::string::npos;
      for (size_t i = 0; i < who.size(); ++i)
        scene_.SetRobot(who[i], at_start ? cur_[who[i]] : to[i]);
      CollisionResult res;
      if (scene_.cell().InCollision(&res)) hit = " (" + scene_.cell().Describe(res.first) + ")";
      if (at_start) {
        for (int r : who) {
          std::string line = StrFormat("free: start of %s: opening %.4f, holds %d; keyframes:",
                                       Name(r).c_str(), opening_[r], state_.held[r]);
          for (int j = std::max(0, action - 3); j <= action; ++j) {
            line += StrFormat(" %d:%s", j + 1,
                              Same(plan_.actions[j].keyframe.q[r], cur_[r]) ? "same" : "differs");
          }
          ctx_.Log("motion", line);
        }
      }
    }
    for (size_t i = 0; i < who.size(); ++i) scene_.SetRobot(who[i], cur_[who[i]]);
    if (ctx_.Logs("motion")) {
      ctx_.Log("motion", StrFormat("free: action %d robots %zu: %s%s, %lld checks, %.2f s, %zu waypoints",
          action + 1, who.size(), answer.solved ? "solved" : answer.why.c_str(), hit.c_str(),
          answer.checks,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t_query).count(),
          answer.path.size()));
    }
    if (answer.solved) {
      for (const Eigen::VectorXd& x : answer.path) path->push_back(split(x));
    }
    return answer;
  };
  std::vector<std::vector<JointVector>> path;
  PathAnswer answer = plan(movers, targets, &path);
  if (answer.solved && reached) *reached = answer.goal_index;
  if (!answer.solved && answer.timed_out && ctx_.Logs("motion.diag") && movers.size() == 1) {
    // Diagnosis: is the start or the goal cut off from the robot's home?
    const JointVector saved = cur_[movers[0]];
    std::vector<std::vector<JointVector>> p1, p2;
    const PathAnswer a1 = plan(movers, {w_.robots[movers[0]].home}, &p1);
    cur_[movers[0]] = targets[0];
    scene_.SetRobot(movers[0], targets[0]);
    const PathAnswer a2 = plan(movers, {w_.robots[movers[0]].home}, &p2);
    cur_[movers[0]] = saved;
    scene_.SetRobot(movers[0], saved);
    // What the goal's neighbourhood hits.
    std::map<std::string, int> hits;
    {
      std::mt19937_64 g(7);
      std::uniform_real_distribution<double> u(-0.05, 0.05);
      for (int t = 0; t < 64; ++t) {
        JointVector x = targets[0];
        for (int j = 0; j < x.size(); ++j) x[j] += u(g);
        scene_.SetRobot(movers[0], x);
        CollisionResult res;
        if (scene_.cell().InCollision(&res)) {
          const CollisionWorld& cw = scene_.cell().world();
          ++hits[cw.body_name(res.first.body_a) + " ~ " + cw.body_name(res.first.body_b)];
        }
      }
      scene_.SetRobot(movers[0], saved);
    }
    std::string near;
    for (const auto& [k, v] : hits) near += " " + k + " x" + std::to_string(v);
    ctx_.Log("motion.diag",
             StrFormat("action %d %s (%s, holds %d): start->home %s, goal->home %s;%s",
                 action + 1, Name(movers[0]).c_str(), main ? "main" : "return",
                 state_.held[movers[0]], a1.solved ? "yes" : a1.why.c_str(),
                 a2.solved ? "yes" : a2.why.c_str(), near.c_str()));
  }
  std::vector<int> who = movers;
  if (!answer.solved && answer.timed_out && effort_ > 0 && !ctx_.ShouldStop()) {
    // The idle robots (free, not in this segment) may step aside and come back.
    std::vector<int> all = movers;
    std::vector<JointVector> to = targets;
    for (int r = 0; r < static_cast<int>(w_.robots.size()); ++r) {
      if (state_.held[r] < 0 && released_[r] < 0 &&
          std::find(movers.begin(), movers.end(), r) == movers.end()) {
        all.push_back(r);
        to.push_back(cur_[r]);
      }
    }
    if (all.size() > movers.size()) {
      std::vector<size_t> order(all.size());
      for (size_t k = 0; k < order.size(); ++k) order[k] = k;
      std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return all[x] < all[y]; });
      std::vector<int> sorted;
      std::vector<JointVector> sorted_to;
      for (size_t k : order) {
        sorted.push_back(all[k]);
        sorted_to.push_back(to[k]);
      }
      answer = plan(sorted, sorted_to, &path);
      who = sorted;
    }
  }
  if (!answer.solved) {
    if (ctx_.cancelled()) cancelled_ = true;
    std::string names;
    for (int r : movers) names += (names.empty() ? "" : ", ") + Name(r);
    return Fail(action, SegmentKind::kFree, answer.timed_out,
                "no collision-free path for " + names + " toward action " +
                    std::to_string(action + 1) + ": " + answer.why);
  }
  seg.robots = who;
  seg.waypoints = std::move(path);
  seg.free_index = index;
  cache_.free_paths[index] = {seg.robots, seg.waypoints, scene_key};
  Push(std::move(seg));
  return true;
}

bool Builder::Lift(int action, int node, const std::vector<int>& holders) {
  if (!SetScene(opening_, {}, {node})) return false;
  // Straight up; else back along the first holder's approach axis when that leaves the table
  // upward; else up and sideways; else a shorter lift.
  const Vec3 back = -Tcp(holders[0], cur_[holders[0]]).linear().col(2);
  std::vector<std::pair<Vec3, double>> moves = {{Vec3::UnitZ(), opt_.lift_m}};
  if (back.z() > 0.3) moves.push_back({back, opt_.lift_m / back.z()});
  for (const Vec3& side :
       std::array<Vec3, 4>{Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0)}) {
    moves.push_back({(side + Vec3::UnitZ()).normalized(), opt_.lift_m * std::sqrt(2.0)});
  }
  moves.push_back({Vec3::UnitZ(), opt_.lift_m / 2});
  std::string why;
  for (const auto& [dir, d] : moves) {
    std::vector<JointVector> q0;
    std::vector<std::function<Iso3(double)>> targets;
    for (int r : holders) {
      q0.push_back(cur_[r]);
      const Iso3 X0 = Tcp(r, cur_[r]);
      targets.push_back([X0, d = d, dir = dir](double s) {
        Iso3 X = X0;
        X.translation() += s * d * dir;
        return X;
      });
    }
    const int steps = std::max(2, static_cast<int>(std::ceil(d / opt_.cartesian_step_m)));
    auto path = Track(holders, q0, targets, steps);
    if (path.empty()) {
      why = "no IK solution along the line";
      continue;
    }
    if (!PathClear(holders, path)) {
      why = last_hit_;
      continue;
    }
    PushSkill(SegmentKind::kLift, action, true, holders, {node}, std::move(path), d,
              opt_.skill_speed_mps);
    grounded_.erase(node);
    return true;
  }
  return Fail(action, SegmentKind::kLift, false,
              "the holders of " + NodeName(node) + " cannot lift it off the table: " + why);
}

bool Builder::Carry(int action, int node, const std::vector<int>& holders, const Iso3& X_goal,
                    std::vector<JointVector> goal_q, const Keyframe& target, bool approach) {
  // The object's pose now, from its first holder's TCP.
  const PlanGrasp& g0 = state_.grasp[holders[0]];
  const Iso3 X_AT0 = w_.X_AP[g0.part] * g0.X_PG;
  const Iso3 X_start = Tcp(holders[0], cur_[holders[0]]) * X_AT0.inverse();
  const double dist = (X_goal.translation() - X_start.translation()).norm();
  const Eigen::Quaterniond qa(X_start.linear());
  const Eigen::Quaterniond qb(X_goal.linear());
  const double angle = qa.angularDistance(qb);
  const Vec3 pa = X_start.translation();
  const Vec3 pb = X_goal.translation();
  // Object paths tried in turn: straight; rotate, then translate; translate, then rotate; up
  // 10 cm, across, down.
  auto pose = [&](int variant, double s) {
    double sr = s, st = s;
    Vec3 lift = Vec3::Zero();
    if (variant == 1) {
      sr = std::min(1.0, 2 * s);
      st = std::max(0.0, 2 * s - 1);
    } else if (variant == 2) {
      st = std::min(1.0, 2 * s);
      sr = std::max(0.0, 2 * s - 1);
    } else if (variant == 3) {
      lift.z() = 0.10 * std::min(1.0, std::min(4 * s, 4 * (1 - s)));
      st = std::clamp(2 * s - 0.5, 0.0, 1.0);
    }
    Iso3 X = Iso3::Identity();
    X.linear() = qa.slerp(sr, qb).toRotationMatrix();
    X.translation() = (1 - st) * pa + st * pb + lift;
    return X;
  };
  const double length = dist + 0.2 + angle * 0.1;
  const int steps = std::max(
      2, static_cast<int>(std::ceil(std::max(length / opt_.cartesian_step_m, 2 * angle / 0.02))));
  std::string why;
  for (int variant = 0; variant < 4; ++variant) {
    std::vector<JointVector> q0;
    std::vector<std::function<Iso3(double)>> targets;
    for (int r : holders) {
      q0.push_back(cur_[r]);
      const PlanGrasp& g = state_.grasp[r];
      const Iso3 X_AT = w_.X_AP[g.part] * g.X_PG;
      targets.push_back([&pose, variant, X_AT](double s) { return pose(variant, s) * X_AT; });
    }
    auto path = Track(holders, q0, targets, steps, &goal_q);
    std::vector<std::pair<size_t, JointVector>> rebranch;
    why.clear();
    if (path.empty()) {
      why = "an arm cannot follow the object (no IK solution near the last one)";
      continue;
    }
    if (!CarryEnd(holders, goal_q, target, path.back(), rebranch, why)) continue;
    if (!SetScene(opening_)) return false;
    if (!PathClear(holders, path)) {
      why = "on the way " + last_hit_;
      continue;
    }
    for (const auto& [i, q] : rebranch) Rebranch(holders[i], action, approach, goal_q[i], q);
    PushSkill(SegmentKind::kCarry, action, true, holders, {node}, std::move(path),
              variant == 3 ? dist + 0.2 : std::max(dist, angle * 0.1), opt_.carry_speed_mps);
    return true;
  }
  // Neither of the straight variants: search the object's poses (at effort 1 and more; at
  // effort 0 the plan is suspended so that other task plans get their turn first).
  if (effort_ >= 1 && !ctx_.ShouldStop()) {
    std::vector<std::pair<size_t, JointVector>> rebranch;
    double carry_length = 0.0;
    std::string search_why;
    if (!SetScene(opening_)) return false;
    auto path =
        CarrySearch(holders, X_start, X_goal, goal_q, target, rebranch, &carry_length, search_why);
    if (!path.empty()) {
      for (const auto& [i, q] : rebranch) Rebranch(holders[i], action, approach, goal_q[i], q);
      PushSkill(SegmentKind::kCarry, action, true, holders, {node}, std::move(path), carry_length,
                opt_.carry_speed_mps);
      return true;
    }
    why += "; searched over the object's poses: " + search_why;
  }
  return Fail(action, SegmentKind::kCarry, !ctx_.ShouldStop(),
              "the robots holding " + NodeName(node) +
                  " cannot carry it together to its keyframe pose (straight, rotating first or "
                  "last, or over the top" +
                  (effort_ >= 1 ? ", or by a search over its poses" : "") + "): " + why);
}

bool Builder::CarryEnd(const std::vector<int>& holders, const std::vector<JointVector>& goal_q,
                       const Keyframe& target, std::vector<JointVector>& last,
                       std::vector<std::pair<size_t, JointVector>>& rebranch, std::string& why) {
  for (size_t i = 0; i < holders.size(); ++i) {
    const double off = (last[i] - goal_q[i]).cwiseAbs().maxCoeff();
    const JointVector same_pose =
        NearestEquivalent(w_.robots[holders[i]].chain, goal_q[i], last[i]);
    if (off > kMaxSnap && hover_) {
      why = Name(holders[i]) + " ends " + std::to_string(off).substr(0, 4) +
            " rad away from its joints above the insertion's start";
      return false;
    } else if (off > kMaxSnap && (same_pose - last[i]).cwiseAbs().maxCoeff() <= kMaxSnap) {
      // The keyframe's joints up to turns of 2 pi: the same configuration.
      rebranch.push_back({i, same_pose});
      last[i] = same_pose;
    } else if (off > kMaxSnap) {
      if (KeyframeAccepts(holders[i], last[i], target, {})) {
        rebranch.push_back({i, last[i]});
      } else {
        why = Name(holders[i]) + " ends " + std::to_string(off).substr(0, 4) +
              " rad away from its keyframe joints, on another IK solution that does not fit "
              "the keyframe";
        return false;
      }
    } else {
      last[i] = goal_q[i];
    }
  }
  return true;
}

std::vector<std::vector<JointVector>> Builder::CarryEdge(const std::vector<int>& holders,
                                                         const std::vector<JointVector>& q0,
                                                         const Iso3& X_a, const Iso3& X_b) {
  const Eigen::Quaterniond qa(X_a.linear());
  const Eigen::Quaterniond qb(X_b.linear());
  const double angle = qa.angularDistance(qb);
  const double dist = (X_b.translation() - X_a.translation()).norm();
  const int steps = std::max(
      2, static_cast<int>(std::ceil(std::max(dist / opt_.cartesian_step_m, 2 * angle / 0.02))));
  std::vector<std::function<Iso3(double)>> targets;
  for (int r : holders) {
    const PlanGrasp& g = state_.grasp[r];
    const Iso3 X_AT = w_.X_AP[g.part] * g.X_PG;
    targets.push_back([&, X_AT](double s) {
      Iso3 X = Iso3::Identity();
      X.linear() = qa.slerp(s, qb).toRotationMatrix();
      X.translation() = (1 - s) * X_a.translation() + s * X_b.translation();
      return X * X_AT;
    });
  }
  auto path = Track(holders, q0, targets, steps, nullptr);
  if (path.empty() || !PathClear(holders, path)) return {};
  return path;
}

std::vector<std::vector<JointVector>> Builder::CarrySearch(
    const std::vector<int>& holders, const Iso3& X_start, const Iso3& X_goal,
    const std::vector<JointVector>& goal_q, const Keyframe& target,
    std::vector<std::pair<size_t, JointVector>>& rebranch, double* length, std::string& why) {
  struct Node {
    Iso3 X;
    std::vector<JointVector> q;
    int parent = -1;
  };
  auto metric = [](const Iso3& a, const Iso3& b) {
    return (a.translation() - b.translation()).norm() +
           0.15 * Eigen::Quaterniond(a.linear()).angularDistance(Eigen::Quaterniond(b.linear()));
  };
  std::vector<JointVector> q0;
  for (int r : holders) q0.push_back(cur_[r]);
  std::vector<Node> tree = {{X_start, q0, -1}};
  const Vec3 lo = X_start.translation().cwiseMin(X_goal.translation()) - Vec3(0.25, 0.25, 0.05);
  const Vec3 hi = X_start.translation().cwiseMax(X_goal.translation()) + Vec3(0.25, 0.25, 0.30);
  const Eigen::Quaterniond qs(X_start.linear());
  const Eigen::Quaterniond qg(X_goal.linear());
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n01(0.0, 1.0);
  const int budget = opt_.carry_edges << std::max(0, effort_ - 1);  // edges tried
  const auto t0 = std::chrono::steady_clock::now();
  constexpr double kStepM = 0.08;  // longest edge in the metric [m]
  constexpr int kMaxNodes = 4000;
  int goal_node = -1;
  std::vector<JointVector> goal_last;
  int edges = 0;
  std::string end_why;
  while (goal_node < 0 && static_cast<int>(tree.size()) < kMaxNodes && !ctx_.ShouldStop() &&
         edges < budget) {
    const bool to_goal = u(rng_) < 0.2;
    Iso3 X_rand = X_goal;
    if (!to_goal) {
      X_rand.translation() = lo + (hi - lo).cwiseProduct(Vec3(u(rng_), u(rng_), u(rng_)));
      // Orientations between the start's and the goal's, turned by up to ~0.6 rad.
      const Vec3 axis = Vec3(n01(rng_), n01(rng_), n01(rng_)).normalized();
      const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.6 * u(rng_), axis));
      X_rand.linear() = (turn * qs.slerp(u(rng_), qg)).toRotationMatrix();
    }
    int nearest = 0;
    double best = metric(tree[0].X, X_rand);
    for (size_t k = 1; k < tree.size(); ++k) {
      const double d = metric(tree[k].X, X_rand);
      if (d < best) {
        best = d;
        nearest = static_cast<int>(k);
      }
    }
    const bool reaches = best <= kStepM;
    Iso3 X_new = X_rand;
    if (!reaches) {
      const double f = kStepM / best;
      const Iso3& X_n = tree[nearest].X;
      X_new.translation() = X_n.translation() + f * (X_rand.translation() - X_n.translation());
      X_new.linear() = Eigen::Quaterniond(X_n.linear())
                           .slerp(f, Eigen::Quaterniond(X_rand.linear()))
                           .toRotationMatrix();
    }
    ++edges;
    auto edge = CarryEdge(holders, tree[nearest].q, tree[nearest].X, X_new);
    if (edge.empty()) continue;
    tree.push_back({X_new, edge.back(), nearest});
    if (to_goal && reaches) {
      std::vector<JointVector> last = edge.back();
      std::vector<std::pair<size_t, JointVector>> rb;
      if (CarryEnd(holders, goal_q, target, last, rb, end_why)) {
        goal_node = static_cast<int>(tree.size()) - 1;
      }
    }
  }
  if (ctx_.Logs("motion")) {
    ctx_.Log("motion", StrFormat("carry: search: %zu poses, %d edges tried, %.2f s, %s", tree.size(),
                 edges,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                 goal_node >= 0 ? "reached" : "not reached"));
  }
  if (goal_node < 0) {
    why = "the goal pose was not reached from " + std::to_string(tree.size()) + " poses" +
          (end_why.empty() ? "" : " (" + end_why + ")");
    return {};
  }
  std::vector<int> chain;
  for (int k = goal_node; k >= 0; k = tree[k].parent) chain.push_back(k);
  std::reverse(chain.begin(), chain.end());
  // Shortcut greedily: from each pose, the farthest one along the chain it reaches directly.
  std::vector<std::vector<JointVector>> path = {q0};
  double total = 0.0;
  size_t at = 0;
  std::vector<JointVector> q = q0;
  while (at + 1 < chain.size()) {
    bool moved = false;
    for (size_t j = chain.size() - 1; j > at && !moved; --j) {
      auto edge = CarryEdge(holders, q, tree[chain[at]].X, tree[chain[j]].X);
      if (edge.empty()) continue;
      if (j + 1 == chain.size()) {
        std::vector<std::pair<size_t, JointVector>> rb;
        std::string w;
        if (!CarryEnd(holders, goal_q, target, edge.back(), rb, w)) continue;
        rebranch = std::move(rb);
      }
      total += metric(tree[chain[at]].X, tree[chain[j]].X);
      path.insert(path.end(), edge.begin() + 1, edge.end());
      q = path.back();
      at = j;
      moved = true;
    }
    if (!moved) {
      why = "the found path could not be retraced";
      return {};
    }
  }
  *length = total;
  return path;
}

bool Builder::KeyframeAccepts(int robot, const JointVector& q, const Keyframe& kf,
                              const std::vector<std::pair<int, int>>& mating) {
  PlanState at = state_;
  for (const PlanObject& o : kf.objects) {
    if (auto it = at.objects.find(o.node); it != at.objects.end()) it->second.X_WA = o.X_WA;
  }
  std::vector<JointVector> qs = kf.q;
  qs[robot] = q;
  if (!scene_.Set(at, opening_, qs, mating)) return false;
  CollisionResult hit;
  if (scene_.cell().InCollision(&hit)) {
    if (ctx_.Logs("motion")) {
      ctx_.Log("motion", StrFormat("keyframe: %s", scene_.cell().Describe(hit.first).c_str()));
    }
    return false;
  }
  DistanceRequest request;
  request.upper_bound_m = 0.02;
  return scene_.cell().MinRobotClearance(request).distance >= kMinClearance;
}

bool Builder::LongerSlideFree(int step, double extra) {
  if (step < w_.num_parts || !w_.check || !w_.check->tree) return true;
  if (!geometry_) geometry_.emplace(AssemblyGeometry::FromProject(*w_.project, *w_.check));
  InsertionPath path =
      StepInsertionPath(*w_.project, *w_.check->tree, w_.tree->nodes[step].step, -1);
  path.length_m += extra;
  return IsPathFree(*geometry_, path);
}

void Builder::SlideStart(int action, Keyframe& goal) {
  const PlanAction& a = plan_.actions[action];
  if (a.type != ActionType::kAssemble || !a.approach || a.objects.size() < 2) return;
  const int m_node = a.objects[0], b_node = a.objects[1];
  const std::vector<int> holders = state_.Holders(m_node);
  if (holders.empty()) return;
  const int h0 = holders[0];
  const bool clear = KeyframeAccepts(h0, goal.q[h0], goal, {});
  if (clear && !Tight(h0, goal.q[h0])) return;  // clear, with room around it
  if (!clear && !KeyframeAccepts(h0, goal.q[h0], goal, {{m_node, b_node}})) return;  // not that
  Vec3 u = Tcp(h0, goal.q[h0]).translation() - Tcp(h0, a.keyframe.q[h0]).translation();
  if (u.norm() < 1e-6) return;
  u.normalize();
  std::vector<JointVector> q0;
  for (int r : holders) q0.push_back(goal.q[r]);
  // Further back along the insertion line: the first start that is clear with room around it
  // (a free path hardly reaches a start in a pocket, e.g. a long bolt still near its hole);
  // else the first clear one when the approach keyframe touches the base.
  std::optional<Keyframe> first_clear;
  double first_extra = 0.0;
  for (double extra : {0.01, 0.02, 0.04, 0.06, 0.09, 0.12}) {
    if (a.objects.size() >= 3 && !LongerSlideFree(a.objects[2], extra)) break;
    std::vector<std::function<Iso3(double)>> targets;
    for (int r : holders) {
      const Iso3 Xa = Tcp(r, goal.q[r]);
      targets.push_back([Xa, u, extra](double s) {
        Iso3 X = Xa;
        X.translation() += s * extra * u;
        return X;
      });
    }
    const int steps = std::max(2, static_cast<int>(std::ceil(extra / opt_.cartesian_step_m)));
    const auto path = Track(holders, q0, targets, steps);
    if (path.empty()) continue;
    Keyframe pre = goal;
    for (size_t k = 0; k < holders.size(); ++k) pre.q[holders[k]] = path.back()[k];
    for (PlanObject& o : pre.objects) {
      if (o.node == m_node) o.X_WA.translation() += extra * u;
    }
    if (!KeyframeAccepts(h0, pre.q[h0], pre, {})) continue;
    if (!Tight(h0, pre.q[h0])) {
      if (ctx_.Logs("motion")) {
        ctx_.Log("motion",
                 StrFormat("slide: action %d: %s %s %s at the approach; the slide starts %.0f mm "
                           "further back",
                           action + 1, NodeName(m_node).c_str(), clear ? "is close to" : "touches",
                           NodeName(b_node).c_str(), 1000.0 * extra));
      }
      goal = std::move(pre);
      return;
    }
    if (!clear && !first_clear) {
      first_clear = std::move(pre);
      first_extra = extra;
    }
  }
  if (first_clear) {
    if (ctx_.Logs("motion")) {
      ctx_.Log("motion",
               StrFormat("slide: action %d: %s touches %s at the approach; the slide starts "
                         "%.0f mm further back (still tight)",
                         action + 1, NodeName(m_node).c_str(), NodeName(b_node).c_str(),
                         1000.0 * first_extra));
    }
    goal = std::move(*first_clear);
  }
}

bool Builder::HoverAbove(int action, Keyframe& goal, std::vector<int>& holders,
                         std::vector<std::vector<JointVector>>& descent, double* length) {
  // An input this close above the table top touches it [m].
  constexpr double kTouch = 2e-3;
  const PlanAction& a = plan_.actions[action];
  if (a.objects.size() < 2) return true;
  const int m_node = a.objects[0], b_node = a.objects[1];
  const PlanObject* mo = FindObject(goal, m_node);
  if (mo == nullptr || LowestPoint(w_, m_node, mo->X_WA) > w_.table_top + kTouch) return true;
  holders = state_.Holders(m_node);
  if (holders.empty()) return true;
  // The scene at the goal: the objects where the keyframe has them, every robot at its joints.
  PlanState at = state_;
  for (const PlanObject& o : goal.objects) {
    if (auto it = at.objects.find(o.node); it != at.objects.end()) it->second.X_WA = o.X_WA;
  }
  std::vector<JointVector> q0;
  for (int r : holders) q0.push_back(goal.q[r]);
  // Straight down onto the table; else down and forward along the slide (from above and behind
  // its start), where the space above the start is taken.
  std::vector<Vec3> dirs = {Vec3::UnitZ()};
  Vec3 back = Tcp(holders[0], goal.q[holders[0]]).translation() -
              Tcp(holders[0], a.keyframe.q[holders[0]]).translation();
  back.z() = 0.0;
  if (back.norm() > 1e-6) dirs.push_back((Vec3::UnitZ() + back.normalized()).normalized());
  std::string why = "no IK solution along the line";
  for (const Vec3& dir : dirs) {
    for (double d : {opt_.lift_m, 2 * opt_.lift_m, opt_.lift_m / 2}) {
      const double len = d / dir.z();
      std::vector<std::function<Iso3(double)>> targets;
      for (int r : holders) {
        const Iso3 X0 = Tcp(r, goal.q[r]);
        targets.push_back([X0, dir, len](double s) {
          Iso3 X = X0;
          X.translation() += s * len * dir;
          return X;
        });
      }
      auto path = Track(holders, q0, targets,
                        std::max(2, static_cast<int>(std::ceil(len / opt_.cartesian_step_m))));
      if (path.empty()) continue;
      Keyframe top = goal;
      for (size_t k = 0; k < holders.size(); ++k) top.q[holders[k]] = path.back()[k];
      for (PlanObject& o : top.objects) {
        if (o.node == m_node) o.X_WA.translation() += len * dir;
      }
      if (!KeyframeAccepts(holders[0], top.q[holders[0]], top, {})) {
        why = "the pose " + std::to_string(static_cast<int>(std::lround(d * 1000))) +
              " mm above it collides";
        continue;
      }
      // The way down may touch the table and the base (the slide's contacts).
      if (!scene_.Set(at, opening_, goal.q, {{m_node, b_node}}, {m_node})) return false;
      if (!PathClear(holders, path)) {
        why = last_hit_;
        continue;
      }
      if (ctx_.Logs("motion")) {
        ctx_.Log("motion",
                 StrFormat("hover: action %d: %s touches the table at the insertion's start; it "
                           "is lowered %.0f mm onto it",
                           action + 1, NodeName(m_node).c_str(), 1000.0 * d));
      }
      descent.assign(path.rbegin(), path.rend());
      *length = len;
      goal = std::move(top);
      return true;
    }
  }
  return Fail(action, SegmentKind::kDescend, false,
              "the holders of " + NodeName(m_node) +
                  " cannot lower it straight onto the table where its insertion starts: " + why);
}

bool Builder::StageAccepts(int robot, int action, bool from_approach, const JointVector& old_q,
                           const JointVector& new_q) {
  const PlanState saved = state_;
  bool ok = true;
  for (size_t j = static_cast<size_t>(action); ok && j < plan_.actions.size(); ++j) {
    const PlanAction& b = plan_.actions[j];
    state_ = states_[j];
    if (b.approach && (from_approach || j > static_cast<size_t>(action))) {
      if (!Same(b.approach->q[robot], old_q)) break;
      ok = KeyframeAccepts(robot, new_q, *b.approach, {});
    }
    if (!ok || !Same(b.keyframe.q[robot], old_q)) break;
    std::vector<std::pair<int, int>> mating;
    if (b.type == ActionType::kAssemble) mating.push_back({b.objects[0], b.objects[1]});
    ok = KeyframeAccepts(robot, new_q, b.keyframe, mating);
  }
  state_ = saved;
  return ok;
}

void Builder::Rebranch(int robot, int action, bool from_approach, JointVector old_q,
                       JointVector new_q) {
  // By value: old_q may be a keyframe's own joints, which this overwrites.
  for (size_t j = static_cast<size_t>(action); j < plan_.actions.size(); ++j) {
    PlanAction& b = plan_.actions[j];
    if (b.approach && (from_approach || j > static_cast<size_t>(action))) {
      if (!Same(b.approach->q[robot], old_q)) return;
      b.approach->q[robot] = new_q;
    }
    if (!Same(b.keyframe.q[robot], old_q)) return;
    b.keyframe.q[robot] = new_q;
  }
}

bool Builder::Return(int action, int robot, const JointVector& goal, bool main) {
  if (Same(cur_[robot], goal)) return true;
  if (!Retreat(action, robot)) return false;
  // Fingers open fully on the way, unless that hits something where the robot is.
  const double saved = opening_[robot];
  opening_[robot] = -1.0;
  if (!SetScene(opening_)) return false;
  if (scene_.Collides(std::vector<int>{robot})) opening_[robot] = saved;
  return Free(action, main, {robot}, {goal}, {});
}

bool Builder::Action(int i) {
  const PlanAction& a = plan_.actions[i];
  const Keyframe& K = a.keyframe;
  const int n_robots = static_cast<int>(w_.robots.size());
  state_ = states_[i];
  auto in_action = [&](int r) {
    return std::find(a.robots.begin(), a.robots.end(), r) != a.robots.end();
  };
  // Robots freed earlier go where the keyframe has them (home).
  for (int r = 0; r < n_robots; ++r) {
    if (in_action(r) || state_.held[r] >= 0) continue;
    if (!Return(i, r, K.q[r], false)) return false;
  }
  // Who grasps, which objects move and where to.
  std::vector<int> graspers;
  int grasped = a.objects.empty() ? -1 : a.objects[0];
  PlanGrasp new_grasp;
  if (a.type == ActionType::kPick || a.type == ActionType::kAddGrasp) {
    graspers.push_back(a.robots[0]);
    new_grasp = a.grasps[0].grasp;
  } else if (a.type == ActionType::kHandover) {
    graspers.push_back(a.robots[1]);
    new_grasp = a.grasps[1].grasp;
  }
  const bool assemble = a.type == ActionType::kAssemble;
  // Where the movers go before the final skill: the approach keyframe of an insertion (or the
  // start of its slide), else the keyframe.
  Keyframe target_kf = assemble && a.approach ? *a.approach : K;
  if (assemble && a.approach) SlideStart(i, target_kf);
  std::vector<int> hover_holders;
  std::vector<std::vector<JointVector>> hover_descent;
  double hover_length = 0.0;
  if (assemble && a.approach &&
      !HoverAbove(i, target_kf, hover_holders, hover_descent, &hover_length)) {
    return false;
  }
  hover_ = !hover_descent.empty();
  struct Moving {
    int node;
    std::vector<int> holders;
    Iso3 X_goal;
  };
  std::vector<Moving> moving;
  for (const auto& [node, o] : state_.objects) {
    const std::vector<int> holders = state_.Holders(node);
    if (holders.empty()) continue;
    const PlanObject* goal = FindObject(target_kf, node);
    if (goal == nullptr) continue;
    // A placement moves its object even to where it was (its carrier comes to the descent).
    if (!SamePose(goal->X_WA, o.X_WA) || (a.type == ActionType::kPlace && node == grasped)) {
      moving.push_back({node, holders, goal->X_WA});
    }
  }
  // Robots that let go and stayed back off first.
  for (int r : a.robots) {
    if (released_[r] >= 0 && !Retreat(i, r)) return false;
  }
  for (const Moving& m : moving) {
    for (int r : m.holders) {
      if (released_[r] >= 0 && !Retreat(i, r)) return false;
    }
  }
  // Lift what moves off the table.
  for (const Moving& m : moving) {
    if (grounded_.count(m.node) && !Lift(i, m.node, m.holders)) return false;
  }
  // The approach of each grasper, planned backwards from its grasp.
  std::vector<std::vector<JointVector>> approaches(graspers.size());
  std::vector<double> approach_len(graspers.size(), 0.0);
  // Other IK solutions of each grasper's grasp (UR arms, at higher effort): where they fit the
  // keyframe and can approach straight, the free path may end at any of them.
  struct Alternative {
    JointVector q;
    std::vector<JointVector> approach;
    double length = 0.0;
  };
  std::vector<std::vector<Alternative>> alternatives(graspers.size());
  for (size_t k = 0; k < graspers.size(); ++k) {
    const int r = graspers[k];
    std::vector<JointVector> options = {K.q[r]};
    const TaskRobot& tr = w_.robots[r];
    if (effort_ >= 1 && tr.ur) {
      const UrIkSolutions sols = tr.ur->SolveTcp(tr.X_BW * Tcp(r, K.q[r]), tr.end_effector.X_FT);
      for (int c = 0; c < sols.count; ++c) {
        const JointVector q = NearestEquivalent(tr.chain, sols.q[c], cur_[r]);
        if ((NearestEquivalent(tr.chain, q, K.q[r]) - K.q[r]).cwiseAbs().maxCoeff() < 1e-6) {
          continue;
        }
        if (StageAccepts(r, i, false, K.q[r], q)) options.push_back(q);
      }
      if (ctx_.Logs("motion")) {
        ctx_.Log("motion", StrFormat("alternatives: action %d %s: %d IK solutions, %zu fit", i + 1,
                     Name(r).c_str(), sols.count, options.size() - 1));
      }
    }
    for (size_t o = 0; o < options.size(); ++o) {
      std::vector<double> openings = opening_;
      openings[r] = GraspOpening(w_.robots[r], new_grasp);
      const JointVector saved = cur_[r];
      cur_[r] = K.q[r];
      // The scene at the keyframe's object poses: the object to grasp where it will be.
      PlanState at = state_;
      for (const PlanObject& ob : K.objects) {
        if (auto it = at.objects.find(ob.node); it != at.objects.end()) it->second.X_WA = ob.X_WA;
      }
      std::swap(state_, at);
      std::vector<int> carriers_now;
      for (const Moving& m : moving) {
        for (int h : m.holders) {
          carriers_now.push_back(h);
        }
      }
      std::vector<JointVector> saved_carriers;
      for (int h : carriers_now) {
        saved_carriers.push_back(cur_[h]);
        cur_[h] = K.q[h];
      }
      auto set = SetScene(openings, {}, {}, {{r, grasped}});
      if (!set) return false;
      double len = 0.0;
      std::vector<JointVector> back = BackOff(r, options[o], &len);
      for (size_t c = 0; c < carriers_now.size(); ++c) cur_[carriers_now[c]] = saved_carriers[c];
      std::swap(state_, at);
      cur_[r] = saved;
      if (o > 0) {
        if (!back.empty()) {
          std::reverse(back.begin(), back.end());
          alternatives[k].push_back({options[o], std::move(back), len});
        }
        continue;
      }
      if (back.empty()) {
        return Fail(i, SegmentKind::kApproach, false,
                    Name(r) + " cannot approach its grasp on " + NodeName(grasped) +
                        " straight along the gripper axis: " + last_hit_);
      }
      std::reverse(back.begin(), back.end());
      approaches[k] = std::move(back);
      approach_len[k] = len;
    }
  }
  // Where the carriers go before their final skill: the descent's top for a place.
  std::vector<JointVector> descend;
  if (a.type == ActionType::kPlace) {
    const int r = a.robots[0];
    const JointVector saved = cur_[r];
    cur_[r] = K.q[r];
    if (!SetScene(opening_, {}, {grasped})) return false;
    const Iso3 X0 = Tcp(r, K.q[r]);
    const double d = opt_.lift_m;
    auto path = Track({r}, {K.q[r]}, {[X0, d](double s) {
                        Iso3 X = X0;
                        X.translation().z() += s * d;
                        return X;
                      }},
                      std::max(2, static_cast<int>(std::ceil(d / opt_.cartesian_step_m))));
    const bool ok = !path.empty() && PathClear({r}, path);
    cur_[r] = saved;
    if (!ok) {
      return Fail(i, SegmentKind::kDescend, false,
                  Name(r) + " cannot set " + NodeName(grasped) +
                      " down straight onto the table at its placement: " + last_hit_);
    }
    for (auto it = path.rbegin(); it != path.rend(); ++it) descend.push_back((*it)[0]);
  }
  // Free motion of the graspers and of single-handed carriers; two-handed carries after.
  std::vector<int> free_robots;
  std::vector<JointVector> free_goals;
  std::vector<int> free_objects;
  std::vector<const Moving*> carries;
  for (size_t k = 0; k < graspers.size(); ++k) {
    free_robots.push_back(graspers[k]);
    free_goals.push_back(approaches[k].front());
  }
  for (const Moving& m : moving) {
    if (m.holders.size() > 1) {
      carries.push_back(&m);
      continue;
    }
    const int r = m.holders[0];
    free_robots.push_back(r);
    free_goals.push_back(a.type == ActionType::kPlace ? descend.front() : target_kf.q[r]);
    free_objects.push_back(m.node);
  }
  if (grasped >= 0 && !graspers.empty()) free_objects.push_back(grasped);
  // Two-handed carries first: the object reaches its pose, then the others come to it.
  for (const Moving* m : carries) {
    std::vector<JointVector> goal_q;
    for (int r : m->holders) goal_q.push_back(target_kf.q[r]);
    if (!Carry(i, m->node, m->holders, m->X_goal, goal_q, target_kf, assemble && a.approach))
      return false;
  }
  {
    // One robot after another (prioritised): the carriers bring their objects, then the
    // graspers come to them. Each search is in one arm's space; the schedule lets the moves
    // overlap in time where their sweeps allow. When that fails, all of them at once in their
    // composite space.
    const size_t n_graspers = graspers.size();
    const size_t saved_out = out_.size();
    const std::vector<JointVector> saved_cur = cur_;
    const std::vector<double> saved_opening = opening_;
    const int saved_index = free_index_;
    // Carriers first; when that fails, the graspers first (a carrier's goal may be where a
    // grasper stands now).
    const int n_orders = n_graspers > 0 && free_robots.size() > n_graspers ? 2 : 1;
    bool ok = false;
    for (int order = 0; order < n_orders && !ok; ++order) {
      if (order > 0) {
        if (cancelled_ || ctx_.cancelled()) return false;
        out_.resize(saved_out);
        cur_ = saved_cur;
        opening_ = saved_opening;
        free_index_ = saved_index + static_cast<int>(free_robots.size());
      }
      ok = true;
      for (size_t pass = 0; pass < 2 && ok; ++pass) {
        for (size_t k = 0; k < free_robots.size() && ok; ++k) {
          const bool is_grasper = k < n_graspers;
          if (is_grasper != ((pass == 1) != (order == 1))) continue;
          std::vector<int> objects;
          if (is_grasper && grasped >= 0) objects.push_back(grasped);
          if (!is_grasper) {
            for (const Moving& m : moving) {
              if (m.holders.size() == 1 && m.holders[0] == free_robots[k])
                objects.push_back(m.node);
            }
          }
          std::vector<JointVector> others;
          if (is_grasper) {
            for (const Alternative& alt : alternatives[k]) others.push_back(alt.approach.front());
          }
          // A grasper opens to its grasp as it moves in (not before: robots moving earlier
          // pass its fingers as they are); where its fingers at that width would hit something
          // where it stands (open fingers straddling a part), it moves as it is and sets them at
          // the start of its approach.
          double grasp_opening = 0.0;
          if (is_grasper) {
            grasp_opening = GraspOpening(w_.robots[free_robots[k]], new_grasp);
            if (!MoveOpening(free_robots[k], grasp_opening)) return false;
          }
          int reached = 0;
          ok = Free(i, true, {free_robots[k]}, {free_goals[k]}, objects, &others, &reached);
          if (is_grasper) opening_[free_robots[k]] = grasp_opening;
          if (ok && reached > 0) {
            // It reached another IK solution of the grasp: the keyframe follows.
            Alternative& alt = alternatives[k][reached - 1];
            const int r = free_robots[k];
            // The old solution stays an alternative (Rebranch overwrites K.q[r]).
            const JointVector old_q = K.q[r];
            Rebranch(r, i, false, old_q, alt.q);
            std::swap(approaches[k], alt.approach);
            std::swap(approach_len[k], alt.length);
            alt.q = old_q;
            free_goals[k] = approaches[k].front();
          }
        }
      }
    }
    if (!ok && free_robots.size() > 1) {
      if (cancelled_ || ctx_.cancelled()) return false;
      out_.resize(saved_out);
      cur_ = saved_cur;
      opening_ = saved_opening;
      for (int r : graspers) {
        if (!MoveOpening(r, GraspOpening(w_.robots[r], new_grasp))) return false;
      }
      free_index_ = saved_index + n_orders * static_cast<int>(free_robots.size());
      std::vector<size_t> order(free_robots.size());
      for (size_t k = 0; k < order.size(); ++k) order[k] = k;
      std::sort(order.begin(), order.end(),
                [&](size_t x, size_t y) { return free_robots[x] < free_robots[y]; });
      std::vector<int> robots;
      std::vector<JointVector> goals;
      for (size_t k : order) {
        robots.push_back(free_robots[k]);
        goals.push_back(free_goals[k]);
      }
      ok = Free(i, true, robots, goals, free_objects);
      for (int r : graspers) opening_[r] = GraspOpening(w_.robots[r], new_grasp);
    }
    if (!ok) return false;
  }
  hover_ = false;
  // The final skills.
  if (!hover_descent.empty()) {
    PushSkill(SegmentKind::kDescend, i, true, hover_holders, {a.objects[0]},
              std::move(hover_descent), hover_length, opt_.skill_speed_mps);
  }
  if (a.type == ActionType::kPlace) {
    PushSkill(SegmentKind::kDescend, i, true, a.robots[0], grasped, descend, opt_.lift_m,
              opt_.skill_speed_mps);
  }
  if (assemble && a.approach) {
    const int m_node = a.objects[0];
    const int b_node = a.objects[1];
    std::vector<int> inserters = state_.Holders(m_node);
    std::vector<JointVector> q0;
    std::vector<std::function<Iso3(double)>> targets;
    double len = 0.0;
    for (int r : inserters) {
      q0.push_back(cur_[r]);
      const Iso3 Xa = Tcp(r, cur_[r]);
      const Iso3 Xb = Tcp(r, K.q[r]);
      len = std::max(len, (Xb.translation() - Xa.translation()).norm());
      targets.push_back([Xa, Xb](double s) {
        Iso3 X = Xa;
        X.translation() = (1 - s) * Xa.translation() + s * Xb.translation();
        return X;
      });
    }
    const int steps = std::max(2, static_cast<int>(std::ceil(len / opt_.cartesian_step_m)));
    std::vector<JointVector> goals;
    for (int r : inserters) goals.push_back(K.q[r]);
    auto path = Track(inserters, q0, targets, steps, &goals);
    bool ok = !path.empty();
    for (size_t k = 0; ok && k < inserters.size(); ++k) {
      const int r = inserters[k];
      if ((path.back()[k] - K.q[r]).cwiseAbs().maxCoeff() > kMaxSnap) {
        ok = KeyframeAccepts(r, path.back()[k], K, {{m_node, b_node}});
        if (ok) Rebranch(r, i, false, K.q[r], path.back()[k]);
      }
      if (ok) path.back()[k] = K.q[r];
    }
    if (ok) {
      if (!SetScene(opening_, {{m_node, b_node}}, {m_node})) return false;
      ok = PathClear(inserters, path);
    }
    if (!ok) {
      return Fail(i, SegmentKind::kInsert, false,
                  "the insertion of " + NodeName(m_node) + " into " + NodeName(b_node) +
                      " is not a collision-free straight move: " + last_hit_);
    }
    PushSkill(SegmentKind::kInsert, i, true, inserters, {m_node, b_node}, std::move(path), len,
              opt_.insert_speed_mps);
  }
  for (size_t k = 0; k < graspers.size(); ++k) {
    PushSkill(SegmentKind::kApproach, i, true, graspers[k], grasped, approaches[k], approach_len[k],
              opt_.skill_speed_mps);
  }
  // Every robot is now at the keyframe (a robot whose keyframe joints differ from where it is by
  // whole turns only is where the keyframe wants it: the keyframes follow it).
  for (int r = 0; r < n_robots; ++r) {
    if ((cur_[r] - K.q[r]).cwiseAbs().maxCoeff() > 1e-6 &&
        (NearestEquivalent(w_.robots[r].chain, K.q[r], cur_[r]) - cur_[r]).cwiseAbs().maxCoeff() <=
            1e-6) {
      Rebranch(r, i, a.approach.has_value(), K.q[r], cur_[r]);
    }
    if ((cur_[r] - K.q[r]).cwiseAbs().maxCoeff() > 1e-6) {
      return Fail(i, SegmentKind::kFree, false,
                  Name(r) + " would have to change its joints at the keyframe of action " +
                      std::to_string(i + 1) + " while it holds an object that stays put");
    }
    cur_[r] = K.q[r];
  }
  GeoSegment grip;
  grip.kind = SegmentKind::kGrip;
  grip.action = i;
  grip.main = true;
  grip.robots = a.robots;
  std::sort(grip.robots.begin(), grip.robots.end());
  grip.objects = a.objects;
  grip.waypoints.push_back({});
  for (int r : grip.robots) grip.waypoints[0].push_back(K.q[r]);
  grip.hold_s = assemble || a.type == ActionType::kRelease ? opt_.grip_s / 2 : opt_.grip_s;
  Push(std::move(grip));
  // Effects.
  switch (a.type) {
    case ActionType::kPick:
    case ActionType::kAddGrasp:
      break;
    case ActionType::kPlace:
      grounded_.insert(grasped);
      released_[a.robots[0]] = grasped;
      released_at_[a.robots[0]] = i;
      break;
    case ActionType::kRelease:
      released_[a.robots[0]] = grasped;
      released_at_[a.robots[0]] = i;
      break;
    case ActionType::kHandover:
      released_[a.robots[0]] = grasped;
      released_at_[a.robots[0]] = i;
      break;
    case ActionType::kAssemble: {
      const bool base_grounded = grounded_.count(a.objects[1]) > 0;
      grounded_.erase(a.objects[0]);
      grounded_.erase(a.objects[1]);
      if (base_grounded) grounded_.insert(a.objects[2]);
      break;
    }
  }
  return true;
}

Result<std::vector<GeoSegment>> Builder::Run() {
  auto scene = MotionScene::Build(w_);
  if (!scene) return std::unexpected(scene.error());
  scene_ = std::move(*scene);
  rng_.seed(Mix(seed_, 0x6d6f74));
  const int n_robots = static_cast<int>(w_.robots.size());
  if (static_cast<int>(plan_.initial.q.size()) != n_robots) {
    return wrap::Fail(ErrorCode::kInvalidInput, "the plan's robots do not match the project's");
  }
  states_ = ReplayPlanStates(plan_);
  cur_ = plan_.initial.q;
  opening_.assign(n_robots, -1.0);
  released_.assign(n_robots, -1);
  released_at_.assign(n_robots, -1);
  for (const PlanObject& o : plan_.initial.objects) {
    if (o.resting) grounded_.insert(o.node);
  }
  for (size_t i = 0; i < plan_.actions.size(); ++i) {
    if (ctx_.cancelled()) return wrap::Fail(ErrorCode::kCancelled, "motion planning cancelled");
    ctx_.Progress("motion", static_cast<double>(i) / plan_.actions.size(),
                  "action " + std::to_string(i + 1) + "/" + std::to_string(plan_.actions.size()) +
                      ": " + DescribeAction(plan_, plan_.actions[i]));
    if (!Action(static_cast<int>(i)) || jump_) {
      if (cancelled_ || ctx_.cancelled()) {
        return wrap::Fail(ErrorCode::kCancelled, "motion planning cancelled");
      }
      return std::vector<GeoSegment>{};
    }
  }
  // Everyone home at the end.
  const int last = static_cast<int>(plan_.actions.size()) - 1;
  state_ = states_.back();
  for (int r = 0; r < n_robots; ++r) {
    if (!Return(std::max(last, 0), r, plan_.initial.q[r], false) || jump_) {
      if (cancelled_ || ctx_.cancelled()) {
        return wrap::Fail(ErrorCode::kCancelled, "motion planning cancelled");
      }
      return std::vector<GeoSegment>{};
    }
  }
  return std::move(out_);
}

}  // namespace

std::string_view ToString(SegmentKind kind) { return kKindNames[static_cast<int>(kind)]; }

Result<std::vector<GeoSegment>> PlanGeometricMotion(const TaskWorld& world, Plan& plan,
                                                    const MotionOptions& options, int effort,
                                                    std::uint64_t seed, MotionCache& cache,
                                                    RunContext& ctx, MotionFailure* failure) {
  Builder builder(world, plan, options, effort, seed, cache, ctx, failure);
  return builder.Run();
}

std::optional<SoleLoad> SoleLoadOf(const TaskWorld& world, const PlanState& state, int robot) {
  const int node = state.held[robot];
  if (node < 0 || state.Holders(node).size() != 1) return std::nullopt;
  SoleLoad l;
  l.robot = robot;
  Vec3 com_A = Vec3::Zero();
  for (int p : world.tree->nodes[node].parts) {
    l.mass += world.part_mass[p];
    com_A += world.part_mass[p] * world.part_com_A[p];
  }
  if (!(l.mass > 0.0)) return std::nullopt;
  com_A /= l.mass;
  const PlanGrasp& g = state.grasp[robot];
  l.com_G = (world.X_AP[g.part] * g.X_PG).inverse() * com_A;
  const TaskRobot& tr = world.robots[robot];
  l.box = tr.end_effector.kind == EndEffectorKind::kVacuum ? tr.limits.vacuum_transport
                                                           : tr.limits.two_finger;
  return l;
}

double LoadRatio(const SoleLoad& load, const Mat3& R_WG, const Vec3& accel_W) {
  constexpr double kG = 9.81;
  // What the gripper applies on the object, and its moment about the grasp point, in the grasp
  // frame.
  const Vec3 f_G = R_WG.transpose() * (load.mass * (accel_W + Vec3(0.0, 0.0, kG)));
  const Vec3 tau_G = load.com_G.cross(f_G);
  double u = 0.0;
  for (int i = 0; i < 3; ++i) {
    u = std::max(u, std::abs(f_G[i]) / std::max(load.box.force_N[i], 1e-9));
    u = std::max(u, std::abs(tau_G[i]) / std::max(load.box.torque_Nm[i], 1e-9));
  }
  return u;
}

}  // namespace wrap
