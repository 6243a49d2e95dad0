// Collision judging during the physics run (see detail/simulator.h): the contacts allowed at each
// moment (a robot with what it holds, the windows of approaches, grips, retreats and insertions
// from the plan's segments), the collision checks after enough motion, and an insertion's overlap
// with its base beyond what the geometry allows.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>

#include "mating/insertion.h"
#include "verify/detail/simulator.h"

namespace wrap::detail {

// Where a robot may touch an object besides holding it (plan segments): from the start of its
// approach through the grip to the grasp, while its gripper closes or opens, during its
// retreat, and the robots of an insertion with both inputs (which may touch each other then).
void Simulator::ContactWindows() {
  for (const MotionSegment& s : plan_.segments) {
    if (s.action < 0 || s.action >= static_cast<int>(plan_.actions.size())) continue;
    const double end_s = plan_.actions[s.action].end_s;
    if (s.kind == "approach") {
      windows_.push_back({s.start_s, std::max(s.end_s, end_s), s.robots, s.objects, false});
    } else if (s.kind == "grip" || s.kind == "retreat") {
      windows_.push_back({s.start_s, s.end_s, s.robots, s.objects, false});
    } else if (s.kind == "insert" && s.objects.size() >= 2) {
      const PlanAction& action = plan_.actions[s.action];
      windows_.push_back({s.start_s,
                          std::max(s.end_s, end_s),
                          action.robots,
                          {s.objects[0], s.objects[1]},
                          true,
                          action.objects.size() >= 3 ? action.objects[2] : -1});
    }
  }
}

// The contacts allowed at t: a robot with what it holds, parts of one object, parts nobody
// holds with each other (they do not collide in MuJoCo either), and the windows open at t.
ContactRules Simulator::Rules(double t) const {
  const int nr = static_cast<int>(scene_.robots.size());
  const int np = static_cast<int>(scene_.parts.size());
  ContactRules rules;
  std::vector<int> node_of(np, -1);
  rules.held.assign(np, 0);
  rules.robot_part_ok.assign(nr, std::vector<char>(np, 0));
  rules.part_pair_ok.assign(np, std::vector<char>(np, 0));
  for (const auto& [node, o] : state_.objects) {
    const std::vector<int> holders = state_.Holders(node);
    for (int p : tree_.nodes[node].parts) {
      node_of[p] = node;
      rules.held[p] = !holders.empty();
      for (int r : holders) rules.robot_part_ok[r][p] = 1;
    }
  }
  // A part nobody holds that is moving fast is falling or sliding: its fate is judged as
  // support ("no support"), not by what it hits on the way.
  std::vector<char> loose(np, 0);
  for (int p = 0; p < np; ++p) {
    const mjtNum* v = data_->qvel + part_dof_[p];
    loose[p] = !rules.held[p] && std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) > 0.05;
    if (loose[p]) {
      for (int r = 0; r < nr; ++r) rules.robot_part_ok[r][p] = 1;
    }
  }
  for (int p = 0; p < np; ++p) {
    for (int q = p + 1; q < np; ++q) {
      rules.part_pair_ok[p][q] =
          node_of[p] == node_of[q] || (!rules.held[p] && !rules.held[q]) || loose[p] || loose[q];
    }
  }
  const double slack = 2.0 * options_.sample_every * model_->opt.timestep;
  for (const Window& w : windows_) {
    if (t < w.t0 - slack || t > w.t1 + slack) continue;
    for (int node : w.nodes) {
      for (int p : tree_.nodes[node].parts) {
        for (int r : w.robots) rules.robot_part_ok[r][p] = 1;
      }
    }
    if (w.pair && w.nodes.size() >= 2) {
      for (int p : tree_.nodes[w.nodes[0]].parts) {
        for (int q : tree_.nodes[w.nodes[1]].parts) {
          rules.part_pair_ok[std::min(p, q)][std::max(p, q)] = 1;
        }
      }
    }
  }
  return rules;
}

// The action a robot was working on at t: that of its motion segment under way (or just
// ended: checks come every few steps); -1 when it was idle.
int Simulator::ActionOfRobot(int r, double t) const {
  const double slack = 2.0 * options_.sample_every * model_->opt.timestep;
  for (const MotionSegment& s : plan_.segments) {
    if (s.action >= 0 && s.start_s <= t && t <= s.end_s + slack &&
        std::find(s.robots.begin(), s.robots.end(), r) != s.robots.end()) {
      return s.action;
    }
  }
  return -1;
}

// Collisions at t, when something moved enough since the last check (or an action happened).
Result<void> Simulator::CheckCollisions(double t) {
  if (!collisions_) return {};
  const int nr = static_cast<int>(scene_.robots.size());
  const int np = static_cast<int>(scene_.parts.size());
  std::vector<JointVector> q(nr);
  std::vector<double> openings(nr);
  for (int r = 0; r < nr; ++r) {
    q[r] = SampleTrajectory(plan_.trajectories[r], t);
    openings[r] = OpeningAt(plan_.trajectories[r], t);
  }
  std::vector<Iso3> X_WP(np);
  for (int p = 0; p < np; ++p) X_WP[p] = PartPose(p);
  bool moved = collision_dirty_ || checked_q_.empty();
  for (int r = 0; r < nr && !moved; ++r) {
    moved = (q[r] - checked_q_[r]).cwiseAbs().maxCoeff() > options_.collision_resolution_rad ||
            openings[r] != checked_openings_[r];
  }
  for (int p = 0; p < np && !moved; ++p) {
    moved = (X_WP[p].translation() - checked_X_WP_[p].translation()).norm() >
                options_.collision_resolution_m ||
            AngleOf(X_WP[p].linear().transpose() * checked_X_WP_[p].linear()) >
                options_.collision_resolution_rad;
  }
  if (!moved) return {};
  checked_q_ = q;
  checked_openings_ = openings;
  checked_X_WP_ = X_WP;
  collision_dirty_ = false;
  ++report_.collision_checks;
  auto hit = collisions_->Check(q, openings, X_WP, Rules(t));
  if (!hit) return std::unexpected(hit.error());
  if (!hit->has_value()) {
    CheckInsertionOverlaps(t, X_WP);
    return {};
  }
  BlameCollision(**hit, t);
  return {};
}

// Reports collision `h` found at t: what touched what, blamed on the action of the robot involved
// (or of the part's holder).
void Simulator::BlameCollision(const CollisionHit& h, double t) {
  auto holder = [&](int p) {
    for (const auto& [node, o] : state_.objects) {
      const auto& parts = tree_.nodes[node].parts;
      const std::vector<int> holders = state_.Holders(node);
      if (!holders.empty() && std::find(parts.begin(), parts.end(), p) != parts.end()) {
        return holders.front();
      }
    }
    return -1;
  };
  auto part_words = [&](int p, const std::string& name) {
    const int r = holder(p);
    return "'" + name + "'" + (r >= 0 ? " (held by '" + scene_.robots[r].name + "')" : "");
  };
  int robot = h.robot_a >= 0 ? h.robot_a : h.robot_b;
  if (robot < 0 && h.part_a >= 0) robot = holder(h.part_a);
  if (robot < 0 && h.part_b >= 0) robot = holder(h.part_b);
  const std::string tol = Num(1000 * options_.collision_tolerance_m) + " mm";
  std::string detail;
  if (h.body_b == "table" && h.part_a >= 0) {
    detail = part_words(h.part_a, h.body_a) + " is " + Num(1000 * h.depth_m) +
             " mm into the table (tolerance " + tol + ")";
  } else {
    const std::string a = h.part_a >= 0 ? part_words(h.part_a, h.body_a) : "'" + h.body_a + "'";
    const std::string b = h.part_b >= 0 ? part_words(h.part_b, h.body_b) : "'" + h.body_b + "'";
    detail = a + " touches " + b + " deeper than the " + tol + " tolerance";
    if (h.robot_a >= 0 && h.robot_b >= 0) {
      detail += " (robot against robot)";
    } else if ((h.robot_a >= 0) != (h.robot_b >= 0) && (h.part_a >= 0 || h.part_b >= 0)) {
      detail += " (a part the robot neither holds nor is grasping or releasing)";
    }
  }
  // The action of a robot of the collision (or of a holder of a part of it) that was moving
  // then: robots work at the same time, so the next action to happen may be another's.
  int action = -1;
  for (int r : {h.robot_a, h.robot_b, h.part_a >= 0 ? holder(h.part_a) : -1,
                h.part_b >= 0 ? holder(h.part_b) : -1}) {
    if (r >= 0 && action < 0) action = ActionOfRobot(r, t);
  }
  Failed(action >= 0 ? action : CurrentAction(), "collision", detail, t);
}

// The two inputs of an insertion under way where MuJoCo has them (the collision rules let them
// touch): more overlap than the geometry allows where the moved input is along its path is a
// collision naming both parts.
void Simulator::CheckInsertionOverlaps(double t, const std::vector<Iso3>& X_WP) {
  const double slack = 2.0 * options_.sample_every * model_->opt.timestep;
  for (const Window& w : windows_) {
    if (!w.pair || w.step < 0 || w.nodes.size() < 2 || t < w.t0 - slack || t > w.t1 + slack) {
      continue;
    }
    const AssemblyNode& node = tree_.nodes[w.step];
    const Mating& mating = project_.steps[node.step].mating;
    const std::vector<int>& moved = tree_.nodes[w.nodes[0]].parts;
    const std::vector<int>& base = tree_.nodes[w.nodes[1]].parts;
    const Iso3 X_WM = X_WP[moved.front()] * scene_.parts[moved.front()].X_AP.inverse();
    const Iso3 X_WB = X_WP[base.front()] * scene_.parts[base.front()].X_AP.inverse();
    const double along = -(X_WB.inverse() * X_WM).translation().dot(mating.axis.normalized());
    // What the geometry allows there, and at least the simulation's own tolerance (a resting
    // base settles and a weld gives by a fraction of a millimetre).
    const double touch = project_.geometry.touch_depth_m;
    const double allowed =
        std::max(options_.collision_tolerance_m, along <= mating.interference_travel_m + 1e-9
                                                     ? std::max(mating.interference_depth_m, touch)
                                                     : touch);
    const auto o = OverlapBeyond(geometry_, moved, base, X_WP, allowed);
    if (!o) continue;
    Failed(ActionOfInsertion(w.step), "collision",
           "'" + scene_.parts[o->part_a].name + "' cuts into '" + scene_.parts[o->part_b].name +
               "' deeper than the " + Num(1000 * allowed) + " mm allowed, " +
               Num(1000 * std::max(0.0, along)) + " mm before its mating pose (inserting '" +
               node.name + "')",
           t);
    return;
  }
}

// The assemble action that builds step node `step`.
int Simulator::ActionOfInsertion(int step) const {
  for (size_t i = 0; i < plan_.actions.size(); ++i) {
    const PlanAction& a = plan_.actions[i];
    if (a.type == ActionType::kAssemble && a.objects.size() >= 3 && a.objects[2] == step) {
      return static_cast<int>(i);
    }
  }
  return CurrentAction();
}

}  // namespace wrap::detail
