#include "motion/trajectory_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "geometry/convex_hull.h"
#include "mating/assembly_geometry.h"
#include "mating/insertion.h"
#include "robot/kinematics.h"

namespace wrap {

namespace {

std::string Num(double v, const char* fmt = "%.3f") {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

// An object as the check replays it.
struct Thing {
  bool resting = true;
  Iso3 X_WA = Iso3::Identity();
  std::vector<int> holders;  // ascending
};

// Who holds what, replayed from the actions whose moments have passed.
struct Replay {
  std::map<int, Thing> things;
  std::vector<int> held;
  std::vector<PlanGrasp> grasp;
};

const PlanObject* KeyframeObject(const Keyframe& k, int node) {
  for (const PlanObject& o : k.objects) {
    if (o.node == node) return &o;
  }
  return nullptr;
}

// Who holds what after action `a`, replayed independently of task/plan_state.h's ApplyAction on
// purpose: this check verifies motion built from ApplyAction's states and must not share its
// code. Like the simulation and the renderer's motion view it applies actions in time order
// (end_s). Keep it in step with plan.h's semantics.
void Apply(Replay& s, const PlanAction& a) {
  auto drop = [&](int node, int r) {
    auto& h = s.things[node].holders;
    h.erase(std::remove(h.begin(), h.end(), r), h.end());
    s.held[r] = -1;
  };
  auto take = [&](int node, int r, const PlanGrasp& g) {
    auto& h = s.things[node].holders;
    if (std::find(h.begin(), h.end(), r) == h.end()) h.push_back(r);
    std::sort(h.begin(), h.end());
    s.held[r] = node;
    s.grasp[r] = g;
  };
  const int o = a.objects.empty() ? -1 : a.objects[0];
  switch (a.type) {
    case ActionType::kPick:
      take(o, a.robots[0], a.grasps[0].grasp);
      s.things[o].resting = false;
      break;
    case ActionType::kAddGrasp:
      take(o, a.robots[0], a.grasps[0].grasp);
      break;
    case ActionType::kPlace:
    case ActionType::kRelease: {
      drop(o, a.robots[0]);
      Thing& t = s.things[o];
      if (const PlanObject* k = KeyframeObject(a.keyframe, o)) t.X_WA = k->X_WA;
      if (a.type == ActionType::kPlace || t.holders.empty()) t.resting = true;
      break;
    }
    case ActionType::kHandover:
      drop(o, a.robots[0]);
      take(o, a.robots[1], a.grasps[1].grasp);
      break;
    case ActionType::kAssemble: {
      const int m = a.objects[0], b = a.objects[1], result = a.objects[2];
      Thing t;
      t.resting = s.things[b].resting;
      if (const PlanObject* k = KeyframeObject(a.keyframe, b)) t.X_WA = k->X_WA;
      for (int node : {m, b}) {
        for (int r : s.things[node].holders) t.holders.push_back(r);
      }
      std::sort(t.holders.begin(), t.holders.end());
      for (int r : t.holders) s.held[r] = result;
      s.things.erase(m);
      s.things.erase(b);
      s.things[result] = t;
      break;
    }
  }
}

// A contact that a skill of the plan declares, from t0 to t1: a gripper (robot) and object a (an
// approach or retreat), or, robot -1, an insertion's inputs a (moving into) b.
struct Window {
  double t0, t1;
  int robot;  // -1: object pair (an insertion: a moves into b)
  int a, b;
  int step = -1;  // an insertion's step node
};

// Whether a window allows the contact at time t: robot >= 0, its gripper and object a; robot
// -1, the objects a and b.
bool InWindow(const std::vector<Window>& windows, double t, int robot, int a, int b) {
  for (const Window& wdw : windows) {
    if (t < wdw.t0 - 1e-9 || t > wdw.t1 + 1e-9 || wdw.robot != robot) continue;
    if (robot >= 0 && wdw.a == a) return true;
    if (robot < 0 && ((wdw.a == a && wdw.b == b) || (wdw.a == b && wdw.b == a))) return true;
  }
  return false;
}

// The dense check's replay as it walks its sample times.
struct DenseState {
  Replay s;                 // who holds what, the objects' poses
  std::vector<int> events;  // actions in the order of their moments
  size_t next_event = 0;    // the first not yet applied
  std::vector<Window> windows;
  std::set<std::pair<int, int>> reported;  // pairs already reported (bodies, robot and object)
  std::vector<std::vector<Iso3>> frames;   // per robot: its links' frames
  std::vector<JointVector> q;              // per robot: its joints
  std::vector<Iso3> X_WT;                  // per robot: its TCP
};

class Checker {
 public:
  Checker(const TaskWorld& w, const Plan& p, const TrajectoryCheckOptions& o)
      : w_(w), plan_(p), opt_(o) {}
  TrajectoryCheck Run();

 private:
  void Issue(double t, int robot, std::string check, std::string message) {
    out_.issues.push_back({t, robot, std::move(check), std::move(message)});
  }
  std::string Robot(int r) const { return "'" + w_.robots[r].name + "'"; }
  std::string Node(int n) const { return "'" + plan_.nodes[n] + "'"; }
  void CheckKnots(int r);
  void CheckEvents();
  // The dense check (CheckTrajectories): every sample time, the cell replayed there, nothing
  // colliding beyond the contacts the plan allows.
  void CheckDense();
  // The parts' convex hulls (hull_): their lowest points against the table top.
  void ComputeHulls();
  // Every knot, and between knots so that no joint moves more than the resolution; the actions'
  // moments.
  std::vector<double> SampleTimes() const;
  // The actions in the order of their moments.
  std::vector<int> EventOrder() const;
  // The contact windows the plan's skills declare.
  std::vector<Window> ContactWindows() const;
  // One sample at time t: events up to t applied, robots and objects posed, contacts allowed,
  // the cell checked. False when the cell cannot be built (the check stops).
  bool CheckSample(double t, DenseState& d);
  // Every robot at its trajectory's joints at t, in the cell of its finger openings then (null
  // when that cell cannot be built).
  Cell* PoseRobots(double t, DenseState& d);
  // The objects where they are at t (carried: from their first holder's TCP), each holder
  // checked against its grasp; node_of (per part) and node_X (per object) filled.
  void PlaceObjects(double t, DenseState& d, Cell& cell, std::vector<int>& node_of,
                    std::map<int, Iso3>& node_X);
  // The contacts allowed at t: the parts of one object, the insertion windows' pairs, an
  // object touching the table from above, a gripper and what it holds or its window's object.
  void AllowContacts(double t, const DenseState& d, Cell& cell, const std::vector<int>& node_of);
  // The cell's collision query; the first collision of each pair of bodies is an issue.
  void CheckCollision(double t, DenseState& d, Cell& cell);
  Cell* CellFor(const std::vector<double>& openings);
  // The moved input M of an insertion against its base B, both at their poses at this sample,
  // with the meshes: more overlap than the geometry allows where M is along its path is a
  // collision (the cell lets the two touch).
  void CheckInsertionOverlap(double t, int step_node, int M, int B, const std::map<int, Iso3>& X_WA,
                             std::set<std::pair<int, int>>& reported);

  const TaskWorld& w_;
  const Plan& plan_;
  const TrajectoryCheckOptions& opt_;
  TrajectoryCheck out_;
  std::map<std::vector<long long>, Cell> cells_;
  std::vector<std::vector<Vec3>> hull_;       // per part, in the part frame
  std::optional<AssemblyGeometry> geometry_;  // the parts' meshes, for insertion overlaps
};

void Checker::CheckInsertionOverlap(double t, int step_node, int M, int B,
                                    const std::map<int, Iso3>& X_WA,
                                    std::set<std::pair<int, int>>& reported) {
  const auto m = X_WA.find(M), b = X_WA.find(B);
  if (m == X_WA.end() || b == X_WA.end() || step_node < w_.num_parts) return;
  if (!geometry_) geometry_.emplace(AssemblyGeometry::FromProject(*w_.project, *w_.check));
  const StepInterface& st = w_.interface(step_node);
  const Mating& mating = *st.mating;
  // How far M is back along its path: X_WM = X_WB translated by -s along the axis.
  const double s = -(b->second.inverse() * m->second).translation().dot(st.axis_A);
  const double touch = w_.project->geometry.touch_depth_m;
  const double allowed =
      AllowedOverlap(mating.interference_travel_m, mating.interference_depth_m, touch, s);
  std::vector<Iso3> X(w_.num_parts, Iso3::Identity());
  for (int node : {M, B}) {
    for (int p : w_.tree->nodes[node].parts) X[p] = X_WA.at(node) * w_.X_AP[p];
  }
  const auto o =
      OverlapBeyond(*geometry_, w_.tree->nodes[M].parts, w_.tree->nodes[B].parts, X, allowed);
  if (!o || !reported.insert({-100 - o->part_a, -100 - o->part_b}).second) return;
  Issue(t, -1, "collision",
        "'" + geometry_->name(o->part_a) + "' cuts into '" + geometry_->name(o->part_b) +
            "' deeper than the " + Num(allowed * 1000, "%.1f") + " mm allowed, " +
            Num(std::max(0.0, s) * 1000, "%.1f") + " mm before its mating pose (inserting " +
            Node(M) + " into " + Node(B) + ")");
}

void Checker::CheckKnots(int r) {
  const RobotTrajectory& tr = plan_.trajectories[r];
  const Chain& chain = w_.robots[r].chain;
  const int dof = static_cast<int>(chain.joints.size());
  const auto& k = tr.knots;
  for (size_t i = 0; i < k.size(); ++i) {
    if (k[i].q.size() != dof || k[i].qd.size() != dof) {
      Issue(k[i].t, r, "format", "knot " + std::to_string(i) + " has the wrong number of joints");
      return;
    }
    if (i > 0 && !(k[i].t >= k[i - 1].t)) {
      Issue(k[i].t, r, "format", "knot times decrease at knot " + std::to_string(i));
      return;
    }
  }
  if (k.front().t != 0.0) Issue(k.front().t, r, "format", "the first knot is not at 0 s");
  for (size_t i = 0; i < k.size(); ++i) {
    for (int j = 0; j < dof; ++j) {
      const Joint& J = chain.joints[j];
      const double v = std::abs(k[i].qd[j]) / J.max_velocity;
      out_.max_velocity_ratio = std::max(out_.max_velocity_ratio, v);
      if (v > 1.0 + opt_.limit_slack) {
        Issue(k[i].t, r, "limits",
              "joint " + std::to_string(j + 1) + " moves at " + Num(std::abs(k[i].qd[j])) +
                  " rad/s, above its limit " + Num(J.max_velocity));
      }
      if (k[i].q[j] < J.lower - 1e-9 || k[i].q[j] > J.upper + 1e-9) {
        Issue(k[i].t, r, "limits",
              "joint " + std::to_string(j + 1) + " at " + Num(k[i].q[j]) + " is outside [" +
                  Num(J.lower) + ", " + Num(J.upper) + "]");
      }
    }
    if (i == 0) continue;
    const double dt = k[i].t - k[i - 1].t;
    if (dt <= 0.0) {
      if ((k[i].q - k[i - 1].q).cwiseAbs().maxCoeff() > 1e-9) {
        Issue(k[i].t, r, "continuity", "the position jumps at knot " + std::to_string(i));
      }
      continue;
    }
    for (int j = 0; j < dof; ++j) {
      const Joint& J = chain.joints[j];
      const double acc = (k[i].qd[j] - k[i - 1].qd[j]) / dt;
      const double ratio = std::abs(acc) / J.max_acceleration;
      out_.max_acceleration_ratio = std::max(out_.max_acceleration_ratio, ratio);
      if (ratio > 1.0 + opt_.limit_slack) {
        Issue(k[i - 1].t, r, "limits",
              "joint " + std::to_string(j + 1) + " accelerates at " + Num(std::abs(acc)) +
                  " rad/s^2, above its limit " + Num(J.max_acceleration));
      }
      const double expected = k[i - 1].q[j] + 0.5 * (k[i - 1].qd[j] + k[i].qd[j]) * dt;
      if (std::abs(expected - k[i].q[j]) > 1e-6 * (1.0 + std::abs(k[i].q[j] - k[i - 1].q[j]))) {
        Issue(k[i].t, r, "continuity",
              "joint " + std::to_string(j + 1) + " reaches " + Num(k[i].q[j], "%.6f") +
                  " at knot " + std::to_string(i) + " but its velocities lead to " +
                  Num(expected, "%.6f"));
      }
      // A turning point inside the stretch must stay within the limits too.
      if (acc != 0.0) {
        const double tau = -k[i - 1].qd[j] / acc;
        if (tau > 0.0 && tau < dt) {
          const double q = k[i - 1].q[j] + k[i - 1].qd[j] * tau + 0.5 * acc * tau * tau;
          if (q < J.lower - 1e-9 || q > J.upper + 1e-9) {
            Issue(
                k[i - 1].t + tau, r, "limits",
                "joint " + std::to_string(j + 1) + " turns at " + Num(q) + ", outside its limits");
          }
        }
      }
    }
  }
  if ((k.front().q - plan_.initial.q[r]).cwiseAbs().maxCoeff() > opt_.joint_tolerance ||
      k.front().qd.cwiseAbs().maxCoeff() > 0.0) {
    Issue(0.0, r, "start", "does not start at rest at its initial joints");
  }
  if ((k.back().q - plan_.initial.q[r]).cwiseAbs().maxCoeff() > opt_.joint_tolerance ||
      k.back().qd.cwiseAbs().maxCoeff() > 0.0) {
    Issue(k.back().t, r, "end", "does not end at rest at its initial (home) joints");
  }
}

void Checker::CheckEvents() {
  std::map<int, std::pair<double, int>> last_robot, last_object;  // -> (time, action)
  for (size_t i = 0; i < plan_.actions.size(); ++i) {
    const PlanAction& a = plan_.actions[i];
    const std::string label =
        "action " + std::to_string(i + 1) + " (" + DescribeAction(plan_, a) + ")";
    if (!(a.start_s >= 0.0) || !(a.end_s >= a.start_s)) {
      Issue(a.end_s, -1, "event", label + " has no times (start_s, end_s)");
      continue;
    }
    if (a.end_s > out_.makespan_s + 1e-9) {
      Issue(a.end_s, -1, "event", label + " ends after the trajectories do");
    }
    for (size_t k = 0; k < a.robots.size(); ++k) {
      const int r = a.robots[k];
      const JointVector q = SampleTrajectory(plan_.trajectories[r], a.end_s);
      const double off = (q - a.keyframe.q[r]).cwiseAbs().maxCoeff();
      if (off > opt_.joint_tolerance) {
        Issue(a.end_s, r, "event",
              "is " + Num(off, "%.2e") + " rad away from its keyframe joints at the moment of " +
                  label);
      }
      if (auto it = last_robot.find(r); it != last_robot.end() && it->second.first > a.end_s) {
        Issue(a.end_s, r, "event",
              label + " happens before action " + std::to_string(it->second.second + 1) +
                  ", which comes earlier in the plan");
      }
      last_robot[r] = {a.end_s, static_cast<int>(i)};
    }
    for (int o : a.objects) {
      if (auto it = last_object.find(o); it != last_object.end() && it->second.first > a.end_s) {
        Issue(a.end_s, -1, "event",
              label + " happens before action " + std::to_string(it->second.second + 1) +
                  ", which comes earlier in the plan and involves " + Node(o));
      }
      last_object[o] = {a.end_s, static_cast<int>(i)};
    }
  }
}

Cell* Checker::CellFor(const std::vector<double>& openings) {
  std::vector<long long> key;
  for (double o : openings) key.push_back(o < 0.0 ? -1 : std::llround(o * 1e5));
  if (auto it = cells_.find(key); it != cells_.end()) return &it->second;
  CellDef def = w_.cell_def;
  // With the fingers (the task world's cell leaves them out): fully open, or at the opening.
  for (size_t r = 0; r < w_.robots.size(); ++r) {
    const EndEffector& ee = w_.robots[r].end_effector;
    def.robots[r].end_effector.collision =
        openings[r] >= 0.0 ? EndEffectorShapesAt(ee, openings[r]) : ee.collision;
  }
  CellOptions options;
  options.objects_touch_table = false;
  auto cell = Cell::Build(def, options);
  if (!cell) {
    Issue(-1, -1, "collision", "the check's cell does not build: " + cell.error().message);
    return nullptr;
  }
  return &cells_.emplace(key, std::move(*cell)).first->second;
}

void Checker::CheckDense() {
  const int n_robots = static_cast<int>(w_.robots.size());
  ComputeHulls();
  const std::vector<double> times = SampleTimes();
  DenseState d;
  d.events = EventOrder();
  d.windows = ContactWindows();
  d.s.held.assign(n_robots, -1);
  d.s.grasp.resize(n_robots);
  for (const PlanObject& o : plan_.initial.objects) d.s.things[o.node] = {o.resting, o.X_WA, {}};
  d.frames.resize(n_robots);
  d.q.resize(n_robots);
  d.X_WT.resize(n_robots);
  for (double t : times) {
    if (!CheckSample(t, d)) return;
  }
}

void Checker::ComputeHulls() {
  for (int p = 0; p < w_.num_parts; ++p) {
    auto hull = ComputeConvexHull(w_.cell_def.objects[p].mesh);
    hull_.push_back(hull ? hull->mesh.vertices : w_.cell_def.objects[p].mesh.vertices);
  }
}

std::vector<double> Checker::SampleTimes() const {
  // Sample times: every knot, and in between so that no joint moves more than the resolution.
  std::vector<double> times;
  for (const RobotTrajectory& tr : plan_.trajectories) {
    for (size_t i = 0; i < tr.knots.size(); ++i) {
      times.push_back(tr.knots[i].t);
      if (i == 0) continue;
      const double dt = tr.knots[i].t - tr.knots[i - 1].t;
      const double v =
          std::max(tr.knots[i].qd.cwiseAbs().maxCoeff(), tr.knots[i - 1].qd.cwiseAbs().maxCoeff());
      const int n = static_cast<int>(std::ceil(v * dt / opt_.resolution_rad));
      for (int s = 1; s < n; ++s) times.push_back(tr.knots[i - 1].t + dt * s / n);
    }
  }
  for (const PlanAction& a : plan_.actions) times.push_back(a.end_s);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end(),
                          [](double x, double y) { return std::abs(x - y) < 1e-9; }),
              times.end());
  return times;
}

std::vector<int> Checker::EventOrder() const {
  std::vector<int> events(plan_.actions.size());
  for (size_t i = 0; i < events.size(); ++i) events[i] = static_cast<int>(i);
  std::stable_sort(events.begin(), events.end(),
                   [&](int x, int y) { return plan_.actions[x].end_s < plan_.actions[y].end_s; });
  return events;
}

std::vector<Window> Checker::ContactWindows() const {
  std::vector<Window> windows;
  for (const MotionSegment& m : plan_.segments) {
    if (m.kind == "insert" && m.objects.size() >= 2 && m.action >= 0) {
      const PlanAction& action = plan_.actions[m.action];
      windows.push_back({m.start_s, action.end_s, -1, m.objects[0], m.objects[1],
                         action.objects.size() >= 3 ? action.objects[2] : -1});
    } else if (m.kind == "approach" && !m.robots.empty() && m.action >= 0) {
      // The gripper touches its object (a suction cup does) from the end of the approach
      // through the grip to the grasp event.
      const double t1 = std::max(m.end_s, plan_.actions[m.action].end_s);
      for (int o : m.objects) windows.push_back({m.start_s, t1, m.robots[0], o, -1});
    } else if (m.kind == "retreat" && !m.robots.empty()) {
      for (int o : m.objects) windows.push_back({m.start_s, m.end_s, m.robots[0], o, -1});
    }
  }
  return windows;
}

bool Checker::CheckSample(double t, DenseState& d) {
  while (d.next_event < d.events.size() &&
         plan_.actions[d.events[d.next_event]].end_s <= t + 1e-12) {
    Apply(d.s, plan_.actions[d.events[d.next_event]]);
    ++d.next_event;
  }
  Cell* cell = PoseRobots(t, d);
  if (cell == nullptr) return false;
  std::vector<int> node_of(w_.num_parts, -1);
  std::map<int, Iso3> node_X;
  PlaceObjects(t, d, *cell, node_of, node_X);
  for (const Window& wdw : d.windows) {
    if (wdw.robot < 0 && t >= wdw.t0 - 1e-9 && t <= wdw.t1 + 1e-9) {
      CheckInsertionOverlap(t, wdw.step, wdw.a, wdw.b, node_X, d.reported);
    }
  }
  AllowContacts(t, d, *cell, node_of);
  CheckCollision(t, d, *cell);
  return true;
}

Cell* Checker::PoseRobots(double t, DenseState& d) {
  const int n_robots = static_cast<int>(w_.robots.size());
  std::vector<double> openings(n_robots);
  for (int r = 0; r < n_robots; ++r) {
    d.q[r] = SampleTrajectory(plan_.trajectories[r], t);
    openings[r] = OpeningAt(plan_.trajectories[r], t);
    const TaskRobot& R = w_.robots[r];
    d.X_WT[r] = TcpPose(R.chain, R.X_WB, d.q[r], R.end_effector.X_FT);
  }
  Cell* cell = CellFor(openings);
  if (cell == nullptr) return nullptr;
  ++out_.samples;
  for (int r = 0; r < n_robots; ++r) {
    d.frames[r].resize(w_.robots[r].chain.links.size());
    ForwardKinematics(w_.robots[r].chain, w_.robots[r].X_WB, d.q[r], d.frames[r]);
    cell->SetConfiguration(r, std::span<const double>(d.q[r].data(), d.q[r].size()), d.frames[r]);
  }
  return cell;
}

void Checker::PlaceObjects(double t, DenseState& d, Cell& cell, std::vector<int>& node_of,
                           std::map<int, Iso3>& node_X) {
  for (auto& [node, thing] : d.s.things) {
    Iso3 X_WA = thing.X_WA;
    if (!thing.resting && !thing.holders.empty()) {
      const int c = thing.holders.front();
      const PlanGrasp& g = d.s.grasp[c];
      X_WA = d.X_WT[c] * (w_.X_AP[g.part] * g.X_PG).inverse();
    }
    for (int r : thing.holders) {
      const PlanGrasp& g = d.s.grasp[r];
      const Iso3 want = X_WA * w_.X_AP[g.part] * g.X_PG;
      const double dp = (want.translation() - d.X_WT[r].translation()).norm();
      const double dr = Eigen::AngleAxisd(want.linear().transpose() * d.X_WT[r].linear()).angle();
      if (dp > opt_.grasp_tolerance_m || dr > opt_.grasp_tolerance_rad) {
        if (d.reported.insert({-10 - r, node}).second) {
          Issue(t, r, "grasp",
                "its TCP is " + Num(dp * 1000, "%.1f") + " mm / " + Num(dr, "%.3f") +
                    " rad away from its grasp on " + Node(node) + ", which " +
                    (thing.resting ? "rests" : "another robot carries"));
        }
      }
    }
    node_X[node] = X_WA;
    for (int p : w_.tree->nodes[node].parts) {
      node_of[p] = node;
      cell.SetObjectPose(p, X_WA * w_.X_AP[p]);
    }
  }
}

void Checker::AllowContacts(double t, const DenseState& d, Cell& cell,
                            const std::vector<int>& node_of) {
  const int n_robots = static_cast<int>(w_.robots.size());
  const int n_parts = w_.num_parts;
  CollisionWorld& cw = cell.world();
  for (int p = 0; p < n_parts; ++p) {
    const int node = node_of[p];
    cell.SetObjectEnabled(p, node >= 0);
    for (int o = p + 1; o < n_parts; ++o) {
      const bool ok = node >= 0 && node_of[o] >= 0 &&
                      (node == node_of[o] || InWindow(d.windows, t, -1, node, node_of[o]));
      cell.SetObjectPairAllowed(p, o, ok);
    }
    bool table = false;
    if (node >= 0) {
      const Iso3& X = cw.pose(cell.object_body(p));
      double lowest = std::numeric_limits<double>::infinity();
      for (const Vec3& v : hull_[p]) lowest = std::min(lowest, (X * v).z());
      table = lowest >= w_.table_top - opt_.table_tolerance_m;
    }
    cw.SetAllowed(cell.object_body(p), cell.table_body(), table);
    for (int r = 0; r < n_robots; ++r) {
      const bool holds = node >= 0 && d.s.held[r] == node;
      cw.SetAllowed(cell.object_body(p), cell.end_effector_body(r),
                    holds || (node >= 0 && InWindow(d.windows, t, r, node, -1)));
    }
  }
}

void Checker::CheckCollision(double t, DenseState& d, Cell& cell) {
  CollisionWorld& cw = cell.world();
  ++out_.collision_checks;
  CollisionResult hit;
  CollisionRequest request;
  if (!cell.InCollision(&hit, request)) return;
  const auto key = std::minmax(hit.first.body_a.value, hit.first.body_b.value);
  if (opt_.log != nullptr && opt_.log->Logs("motion")) {
    for (const auto& [node, thing] : d.s.things) {
      opt_.log->Log("motion",
                    StrFormat("check: t=%.2f %s resting %d holders %zu X_WA %.3f %.3f %.3f", t,
                              plan_.nodes[node].c_str(), thing.resting, thing.holders.size(),
                              thing.X_WA.translation().x(), thing.X_WA.translation().y(),
                              thing.X_WA.translation().z()));
    }
  }
  if (d.reported.insert(key).second) {
    Issue(t, cell.robot_of(hit.first.body_a), "collision",
          "'" + cw.body_name(hit.first.body_a) + "' collides with '" +
              cw.body_name(hit.first.body_b) + "' (" + cell.Describe(hit.first) + ")");
  }
}

TrajectoryCheck Checker::Run() {
  const int n_robots = static_cast<int>(w_.robots.size());
  for (int r = 0; r < n_robots; ++r) {
    if (plan_.trajectories[r].knots.empty()) {
      Issue(-1, r, "format", "has no knots");
      return out_;
    }
    out_.makespan_s = std::max(out_.makespan_s, plan_.trajectories[r].knots.back().t);
  }
  for (int r = 0; r < n_robots; ++r) {
    CheckKnots(r);
    if (std::abs(plan_.trajectories[r].knots.back().t - out_.makespan_s) > 1e-9) {
      Issue(plan_.trajectories[r].knots.back().t, r, "end",
            "its trajectory ends before the others' (" + Num(out_.makespan_s) + " s)");
    }
  }
  CheckEvents();
  const bool readable = std::none_of(out_.issues.begin(), out_.issues.end(),
                                     [](const TrajectoryIssue& i) { return i.check == "format"; });
  if (opt_.check_collisions && readable) CheckDense();
  out_.valid = out_.issues.empty();
  return out_;
}

}  // namespace

std::string FormatTrajectoryIssue(const Plan& plan, const TrajectoryIssue& issue) {
  std::string out;
  if (issue.t >= 0.0) out += "t=" + Num(issue.t, "%.2f") + " s: ";
  if (issue.robot >= 0 && issue.robot < static_cast<int>(plan.robots.size())) {
    out += plan.robots[issue.robot] + ": ";
  }
  return out + issue.check + ": " + issue.message;
}

Result<TrajectoryCheck> CheckTrajectories(const TaskWorld& world, const Plan& plan,
                                          const TrajectoryCheckOptions& options) {
  const int n_robots = static_cast<int>(world.robots.size());
  if (plan.trajectories.empty()) {
    return Fail(ErrorCode::kInvalidInput, "the plan has no trajectories (run motion planning)");
  }
  if (static_cast<int>(plan.trajectories.size()) != n_robots ||
      static_cast<int>(plan.initial.q.size()) != n_robots) {
    return Fail(ErrorCode::kInvalidInput, "the plan's trajectories do not match the robots");
  }
  for (int r = 0; r < n_robots; ++r) {
    if (plan.trajectories[r].robot != r) {
      return Fail(ErrorCode::kInvalidInput, "trajectory " + std::to_string(r) + " is for robot " +
                                                std::to_string(plan.trajectories[r].robot));
    }
  }
  for (const PlanAction& a : plan.actions) {
    for (int r : a.robots) {
      if (r < 0 || r >= n_robots) return Fail(ErrorCode::kInvalidInput, "a robot is out of range");
    }
    for (int o : a.objects) {
      if (o < 0 || o >= world.num_nodes) {
        return Fail(ErrorCode::kInvalidInput, "an object is out of range");
      }
    }
  }
  if (!(options.resolution_rad > 0.0)) {
    return Fail(ErrorCode::kInvalidInput, "the resolution must be positive");
  }
  Checker checker(world, plan, options);
  return checker.Run();
}

}  // namespace wrap
