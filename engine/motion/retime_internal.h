// Internals of retiming (retime.h), shared by its files:
// - retime.cpp: each segment timed along its path (trapezoids), the per-robot trajectories;
// - schedule.cpp: the schedule in plan order, by the segments' real timed conflicts;
// - schedule_check.cpp: the timeline's cell at one moment and its collision test.
#pragma once

#include <deque>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "core/result.h"
#include "core/run_context.h"
#include "motion/scene.h"
#include "motion/segments.h"
#include "task/plan.h"
#include "task/plan_state.h"
#include "task/world.h"

namespace wrap::detail {

/// Times closer than this are the same moment [s].
inline constexpr double kEps = 1e-9;

/// Boxes a and b meet once each is grown by `grow` on every side [m].
inline bool Overlap(const Aabb& a, const Aabb& b, double grow) {
  return (a.min.array() <= b.max.array() + grow).all() &&
         (b.min.array() <= a.max.array() + grow).all();
}

// A time-optimal rest-to-rest trapezoid in the path parameter s in [0, 1] of one straight piece.
struct Profile {
  double t_acc = 0.0;    // acceleration phase [s]
  double t_total = 0.0;  // whole piece [s]
  double s_acc = 0.0;    // s reached at the end of the acceleration phase
  double v_peak = 0.0;   // peak ds/dt [1/s]
};

// A segment's motion as knots relative to its start: per knot the time, and per robot q, qd
// (constant acceleration between knots, as in a RobotTrajectory).
struct TimedSegment {
  double duration = 0.0;
  double stretch = 1.0;  // how much slower than its fastest timing
  std::vector<double> t;
  std::vector<std::vector<JointVector>> q;   // q[k][i]
  std::vector<std::vector<JointVector>> qd;  // qd[k][i]
  // Per straight piece (waypoint k to k + 1): its profile and start time.
  std::vector<Profile> pieces;
  std::vector<double> piece_t0;

  // Time at path parameter u = k + s (s along the piece from waypoint k to k + 1) [s].
  double TimeAt(double u) const;
  // Robot i's joints at time tau since the start (clamped to [0, duration]).
  JointVector At(size_t i, double tau) const;
  // Times since the start at which a check samples it: every knot, and in between so that no
  // joint moves more than `resolution_rad` from one to the next.
  std::vector<double> Samples(double resolution_rad) const;
};

// Times segment `seg` within its robots' joint limits (and a skill no faster than its speed).
TimedSegment TimeSegment(const TaskWorld& world, const GeoSegment& seg);

// What a segment's start waited for.
enum class WaitKind { kNone, kRobot, kObject, kCollision };

// A segment's place in the schedule.
struct Slot {
  double start_s = 0.0;
  double end_s = 0.0;
  WaitKind wait = WaitKind::kNone;
  int wait_on = -1;         // the segment waited for (index into the input segments), -1 none
  bool concurrent = false;  // it starts before everything placed before it has ended
};

// What scheduling cost.
struct ScheduleStats {
  int candidates = 0;        // start times tried
  int checked = 0;           // ... that needed the collision test of the timeline
  long long samples = 0;     // moments posed
  long long pair_tests = 0;  // body pairs tested exactly
};

// A time span [lo, hi] [s] in which two things may meet, with the segments whose motion it
// involves (-1: a rest).
struct Span {
  double lo = 0.0;
  double hi = 0.0;
  int moving_a = -1;
  int moving_b = -1;
};

// World boxes of some bodies over time: per body, [0] the whole span, then one box per chunk;
// chunk c spans [t[c], t[c + 1]] (a segment's sweep, or a robot or an object at rest).
struct TimedBoxes {
  const std::vector<std::vector<Aabb>>* boxes = nullptr;  // borrowed
  std::vector<double> t;
  int segment = -1;  // the segment whose motion it is; -1 at rest
};

// A collision the schedule found: when, the placed segment to blame, and until when what it hit
// stays where it is (t: it moves).
struct Conflict {
  double t = 0.0;
  int segment = -1;
  double until = 0.0;
};

// A body of the cell with its box and who it belongs to: robot `robot`'s link or gripper, or a
// part of object `node`.
struct Body {
  BodyId id;
  Aabb box;
  int robot = -1;
  bool gripper = false;
  int node = -1;
};

// The timeline's cell as the collision test walks its moments: the objects' state, the robots'
// joints and openings, the openings the scene was last set with for that state (empty: set it),
// and scratch lists of bodies.
struct MomentState {
  PlanState state;
  std::vector<JointVector> q;
  std::vector<double> openings, posed_openings;
  std::vector<Body> changed, other;
  std::vector<char> posed;  // per robot: posed at this moment
};

// What differs, for one candidate start t of a segment, from the cell it was planned in: the
// cell as the sequence left it is the timeline after everything placed so far has finished
// (`end`, the latest end). Before that, the placed segments that end after t still run
// (`segments`, their robots `robots` at the moments in between) and the objects they name may
// be elsewhere (`objects`).
struct Window {
  double t = 0.0;
  double end = 0.0;
  std::vector<int> segments;  // placed, ending after t
  std::vector<char> robots;   // per robot: in one of them
  // Named by one of them (node ids, ascending), with the end of the last that names it.
  std::vector<std::pair<int, double>> objects;
  std::vector<double> robot_end;  // per robot in `robots`: the end of its last segment
};

// The schedule in plan order (schedule.cpp, schedule_check.cpp): each segment starts at the
// earliest candidate time at which its timed motion, and its robots' rest at its end afterwards,
// collide with nothing placed before it.
class Scheduler {
 public:
  // `scene` (may be null: the scheduler builds its own) poses the timeline's cell.
  Scheduler(const TaskWorld& world, const Plan& plan, const std::vector<GeoSegment>& segments,
            const std::vector<TimedSegment>& timed, const RetimeOptions& options,
            const RunContext* log, MotionScene* scene)
      : w_(world),
        plan_(plan),
        segs_(segments),
        timed_(timed),
        opt_(options),
        log_(log),
        scene_(scene) {}

  // Every segment's slot, in the input order. Fails with kInvalidInput when the motion scene
  // does not build.
  Result<std::vector<Slot>> Run(ScheduleStats* stats);

 private:
  // --- Placing (schedule.cpp).
  // Per segment: its chunks' times, its boxes at its start and end, its sample times.
  void Prepare();
  // Places segment j (the earlier ones are placed).
  void Place(int j);
  // The first conflict of segment j started at t with what is placed, if any.
  std::optional<Conflict> TryStart(int j, double t);
  // The window of a start at t (the placed segments so far).
  Window WindowAt(double t) const;
  // The spans of time in which segment j started at `window.t` may come near what the window's
  // segments, robots and objects do or leave (the swept boxes of both meet).
  std::vector<Span> Suspect(int j, const Window& window) const;
  // Segment j's boxes from `t0`: its motion's chunks.
  TimedBoxes MotionBoxes(int j, double t0) const;
  // The rests of robot r within [lo, hi] as boxes, appended.
  void RestBoxes(int r, double lo, double hi, std::vector<TimedBoxes>& out) const;
  // The objects of the window at rest within [lo, hi] as boxes (kept in `store`), appended.
  void ObjectRestBoxes(const Window& window, std::deque<std::vector<std::vector<Aabb>>>& store,
                       std::vector<TimedBoxes>& out) const;
  // The segment of robot r under way at tau, or the last one it ended before tau, or its first
  // (it still waits for it); -1 when it has none placed.
  int SegmentOf(int robot, double tau) const;
  // The placed actions' moments (their grips' ends) with segment j at t, by time.
  std::vector<std::pair<double, int>> Events(int j, double t) const;

  // --- The timeline's cell (schedule_check.cpp).
  // The first conflict of segment j started at `window.t` within `spans` (sampled at the
  // resolution), if any.
  std::optional<Conflict> Check(int j, const Window& window, const std::vector<Span>& spans);
  // One moment tau of that test, in the objects' state m.state.
  std::optional<Conflict> CheckMoment(int j, const Window& window, double tau, MomentState& m);
  // Robot r's joints and finger opening at tau, with segment j started at t.
  void RobotAt(int r, double tau, int j, double t, JointVector& q, double& opening) const;
  // The sample times of `spans`: their ends and, within each, the samples of the segments whose
  // motion it involves.
  std::vector<double> SampleTimes(int j, const Window& window,
                                  const std::vector<Span>& spans) const;
  // The conflict with a body at tau: robot `robot`'s (a link or its gripper), or object
  // `node`'s (a part of it; robot -1).
  Conflict Blame(int robot, int node, double tau, const Window& window,
                 const PlanState& state) const;

  const TaskWorld& w_;
  const Plan& plan_;
  const std::vector<GeoSegment>& segs_;
  const std::vector<TimedSegment>& timed_;
  const RetimeOptions& opt_;
  const RunContext* log_;
  MotionScene* scene_ = nullptr;
  std::optional<MotionScene> own_scene_;
  ScheduleStats stats_;
  std::vector<Slot> slots_;
  std::vector<char> placed_;
  double latest_ = 0.0;                           // the latest end placed
  std::vector<int> last_of_robot_;                // per robot: its last placed segment, -1
  std::map<int, int> last_of_object_;             // per node: the last placed segment naming it
  std::vector<std::vector<int>> robot_segments_;  // per robot: placed segments, by time
  std::vector<int> grip_of_action_;               // per action: its grip segment, -1
  // Per segment: the objects it acts on (moves, touches, or changes at its event); it waits for
  // the earlier segments acting on them, and they count as changed by it.
  std::vector<std::vector<int>> acts_;
  // Per segment: chunk times since its start (size chunks + 1), boxes at its start and end (per
  // body: the box twice), sample times since its start.
  std::vector<std::vector<double>> chunk_t_;
  std::vector<const std::vector<std::vector<Aabb>>*> boxes_;  // its sweep, or own_
  std::vector<std::vector<std::vector<Aabb>>> own_;  // a segment without chunks: its whole boxes
  std::vector<std::vector<std::vector<Aabb>>> first_boxes_, last_boxes_;
  std::vector<std::vector<double>> samples_;
  std::vector<Aabb> part_box_;  // per part: its mesh's box in its frame
};

}  // namespace wrap::detail
