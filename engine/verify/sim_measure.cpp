// The measurements of the physics run (see detail/simulator.h): each gripper's wrench from its
// weld against its limits (averaged, judged by the best split of the load when MuJoCo's rigid
// welds overload one of several supports), the made connections against theirs, the table's
// friction under resting parts, every part's drift from where the plan has it, and the final
// assembly's pose errors.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <deque>

#include "core/frames.h"
#include "geometry/convex_hull.h"
#include "grasp/grasp.h"
#include "verify/detail/best_split.h"
#include "verify/detail/simulator.h"

namespace wrap::detail {

double BoxUtilisation(const Vec3& f, const Vec3& tau, const WrenchBox& box, double floor_N,
                      double floor_Nm) {
  double u = 0.0;
  for (int i = 0; i < 3; ++i) {
    u = std::max(u, std::abs(f[i]) / std::max(box.force_N[i], floor_N));
    u = std::max(u, std::abs(tau[i]) / std::max(box.torque_Nm[i], floor_Nm));
  }
  return u;
}

// The wrench weld `eq` exerts on part p: world force, and world torque about the part's origin.
void Simulator::WeldWrench(int eq, int p, Vec3& f_W, Vec3& tau_W) const {
  const mjModel* m = model_.get();
  const mjData* d = data_.get();
  const int dof = part_dof_[p];
  double gen[6] = {0, 0, 0, 0, 0, 0};
  int rows = 0;
  for (int row = 0; row < d->nefc && rows < kWeldRows; ++row) {
    if (d->efc_type[row] != mjCNSTR_EQUALITY || d->efc_id[row] != eq) continue;
    ++rows;
    for (int j = 0; j < 6; ++j) gen[j] += d->efc_J[row * m->nv + dof + j] * d->efc_force[row];
  }
  // A free joint's generalised force: world force, then torque in the body frame about its
  // origin (the part frame).
  f_W = Vec3(gen[0], gen[1], gen[2]);
  tau_W = PartPose(p).linear() * Vec3(gen[3], gen[4], gen[5]);
}

// The wrench robot r's weld exerts on its part, in the TCP (grasp) frame about its origin.
// While it fades, what is left of the wrench it hands over (Fade).
void Simulator::GripWrench(int r, Vec3& f_G, Vec3& tau_G, double t) const {
  const int p = grip_part_[r];
  Vec3 f_W, tau_W;
  if (const Fade* fade = FadeOf(r); fade && fade->started) {
    const double k = FadeLeft(*fade, t);
    f_W = k * fade->f_W;
    tau_W = k * fade->tau_W;
  } else {
    WeldWrench(grip_eq_[r][p], p, f_W, tau_W);
  }
  const Iso3 X_WG = TcpBodyPose(r);
  tau_W += (PartPose(p).translation() - X_WG.translation()).cross(f_W);
  f_G = X_WG.linear().transpose() * f_W;
  tau_G = X_WG.linear().transpose() * tau_W;
}

// Friction use of every resting part on the table (or floor): the resultant of its contacts'
// tangential forces over mu times their normal forces (MuJoCo spreads a part's load over its
// contacts as its solver likes, and with elliptic cones leaves some at their cone's edge while
// the part stands still: a single contact's use says little).
void Simulator::MeasureTable() {
  const mjModel* m = model_.get();
  const mjData* d = data_.get();
  constexpr double kMinNormal_N = 0.05;
  // Only parts that rest: a held part dragged over the table is the gripper's business.
  std::vector<char> held_body(m->nbody, 0);
  for (const auto& [node, o] : state_.objects) {
    if (state_.Holders(node).empty()) continue;
    for (int p : tree_.nodes[node].parts) held_body[part_body_[p]] = 1;
  }
  struct Sum {
    double normal = 0.0, mu = 0.0;
    Vec3 tangential = Vec3::Zero();
  };
  std::map<int, Sum> sums;  // by part body
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    const int b1 = m->geom_bodyid[c.geom1], b2 = m->geom_bodyid[c.geom2];
    if (held_body[b1] || held_body[b2]) continue;
    if (c.exclude != 0 || c.efc_address < 0 || c.friction[0] <= 0.0) continue;
    mjtNum f[6];
    mj_contactForce(m, d, i, f);
    // The force on geom2 in the contact frame (normal from geom1 to geom2): the part's.
    const int part = std::count(part_body_.begin(), part_body_.end(), b2) ? b2 : b1;
    const double sign = part == b2 ? 1.0 : -1.0;
    Sum& sum = sums[part];
    sum.normal += f[0];
    sum.mu = c.friction[0];
    for (int k = 0; k < 3; ++k) {
      sum.tangential[k] += sign * (f[1] * c.frame[3 + k] + f[2] * c.frame[6 + k]);
    }
  }
  for (const auto& [body, sum] : sums) {
    if (sum.normal < kMinNormal_N) continue;
    const double use = sum.tangential.norm() / (sum.mu * sum.normal);
    report_.peak.table_friction = std::max(report_.peak.table_friction, use);
  }
}

// Every made connection against its limits, in its connection frame.
void Simulator::MeasureConnections() {
  for (const Join& j : joins_) {
    const Interface& in = interfaces_.at(j.action);
    Vec3 f_W, tau_W;
    WeldWrench(j.eq, j.part, f_W, tau_W);
    const Iso3 X_WA = PartPose(in.part_base) * scene_.parts[in.part_base].X_AP.inverse();
    Iso3 X_AC = Iso3::Identity();  // the connection frame C in A (core/pose.h)
    X_AC.linear() = RotationWithZ(in.axis_A);
    X_AC.translation() = in.p_A;
    const Iso3 X_WC = X_WA * X_AC;
    tau_W += (PartPose(j.part).translation() - X_WC.translation()).cross(f_W);
    const double u =
        BoxUtilisation(X_WC.linear().transpose() * f_W, X_WC.linear().transpose() * tau_W,
                       in.limits, options_.zero_limit_force_N, options_.zero_limit_torque_Nm);
    report_.peak.connection = std::max(report_.peak.connection, u);
  }
}

// The best split of the load on object `node` among its supports (detail/best_split.h): the
// robots whose welds hold its parts (not one fading out: its wrench is applied, a load the
// others take over) and the table under it. The measured whole is every constraint force on
// the object's free joints, about its first part's origin. Per robot its utilisation in that
// split, or nothing when the object has a single support (its weld's measurement is then the
// answer) or the LP failed.
std::optional<std::map<int, double>> Simulator::BestSplit(int node) {
  const mjModel* m = model_.get();
  const mjData* d = data_.get();
  const std::vector<int>& parts = tree_.nodes[node].parts;
  std::vector<char> in_object(m->nbody, 0);
  for (int p : parts) in_object[part_body_[p]] = 1;
  const Vec3 p0 = PartPose(parts.front()).translation();
  SplitQuery q;
  // Measured: the supports' whole (constraint forces), and the applied mating wrench.
  Vec6 W_mate = Vec6::Zero();
  for (int p : parts) {
    const int dof = part_dof_[p];
    const Iso3 X = PartPose(p);
    const Vec3 f(d->qfrc_constraint[dof], d->qfrc_constraint[dof + 1], d->qfrc_constraint[dof + 2]);
    const Vec3 tau = X.linear() * Vec3(d->qfrc_constraint[dof + 3], d->qfrc_constraint[dof + 4],
                                       d->qfrc_constraint[dof + 5]);
    q.whole.head<3>() += f;
    q.whole.tail<3>() += tau + (X.translation() - p0).cross(f);
    const int b = part_body_[p];
    const Vec3 com(d->xipos[3 * b], d->xipos[3 * b + 1], d->xipos[3 * b + 2]);
    const Vec6& on = mating_on_part_[p];
    W_mate.head<3>() += on.head<3>();
    W_mate.tail<3>() += on.tail<3>() + (com - p0).cross(on.head<3>());
  }
  q.mating = -W_mate;
  std::vector<int> robots;
  for (size_t r = 0; r < grip_part_.size(); ++r) {
    const int p = grip_part_[r];
    if (p < 0 || !in_object[part_body_[p]]) continue;
    if (const Fade* fade = FadeOf(static_cast<int>(r)); fade && fade->started) continue;
    const Iso3 G = TcpBodyPose(static_cast<int>(r));
    SplitHolder h;
    h.A = GraspWrenchToWorld(G.linear(), G.translation() - p0);
    h.vacuum = scene_.robots[r].end_effector.kind == EndEffectorKind::kVacuum;
    h.limits = HeldLimits(static_cast<int>(r));
    q.holders.push_back(h);
    robots.push_back(static_cast<int>(r));
  }
  // Where the object could bear on the table: its vertices within kSupportReach_m of the top
  // (a part held exactly at the table's height, e.g. slid along it into its base, touches it
  // or not by a rounding), the corners of their convex hull in the plane.
  const SceneTable& table = scene_.table;
  const double top = table.top_center.z();
  std::vector<Eigen::Vector2d> low;
  for (int p : parts) {
    const Iso3 X = PartPose(p);
    for (const Vec3& v : scene_.parts[p].mesh->vertices) {
      const Vec3 w = X * v;
      if (w.z() - top > kSupportReach_m) continue;
      if (std::abs(w.x() - table.top_center.x()) > 0.5 * table.size.x() ||
          std::abs(w.y() - table.top_center.y()) > 0.5 * table.size.y()) {
        continue;
      }
      low.emplace_back(w.x(), w.y());
    }
  }
  const std::vector<int> hull = ConvexHull2d(low);
  const size_t n = hull.size(), used = std::min(n, kMaxSupportPoints);  // evenly picked
  for (size_t i = 0; i < used; ++i) {
    const Eigen::Vector2d& c = low[hull[i * n / used]];
    q.support_points.push_back(Vec3(c.x(), c.y(), top) - p0);
  }
  q.friction = table.friction;
  q.floor_N = options_.zero_limit_force_N;
  q.floor_Nm = options_.zero_limit_torque_Nm;
  auto split = wrap::detail::BestSplit(q, *lp_, lp_problem_, lp_solution_);
  if (!split) return std::nullopt;
  ++report_.split_measurements;
  std::map<int, double> u;
  for (size_t h = 0; h < robots.size(); ++h) u[robots[h]] = (*split)[h];
  return u;
}

// One measurement of every gripper's load (stopping at the first beyond its limits: the plan
// fails), the made connections, the table's friction and every object's drift from the plan.
void Simulator::Measure(double t, const std::vector<int>& inserting) {
  const int current = CurrentAction();
  for (size_t r = 0; r < grip_part_.size(); ++r) {
    if (!MeasureGripper(static_cast<int>(r), t, inserting, current)) return;
  }
  MeasureConnections();
  MeasureTable();
  MeasureDrift(t, current);
}

// Robot r's gripper against its limits; false when beyond them (the plan failed).
bool Simulator::MeasureGripper(int r, double t, const std::vector<int>& inserting, int current) {
  if (grip_part_[r] < 0) {
    was_inserting_[r] = false;
    prev_f_[r] = prev_tau_[r] = Vec3::Zero();
    recent_[r].clear();
    return true;
  }
  Vec3 f, tau;
  GripWrench(r, f, tau, t);
  AverageWrench(r, f, tau);
  int insert_action = -1;
  for (int i : inserting) {
    const auto& rs = plan_.actions[i].robots;
    if (std::find(rs.begin(), rs.end(), r) != rs.end()) insert_action = i;
  }
  const bool vacuum = scene_.robots[r].end_effector.kind == EndEffectorKind::kVacuum;
  double u = GripperUtilisation(r, f, tau, insert_action);
  bool split = false;
  if (u > 1.0) {
    // Beyond its limits as MuJoCo split the load: judged by the best split when the
    // object has other supports (BestSplit).
    const int node = NodeOfPart(grip_part_[r]);
    if (node >= 0) {
      if (split_at_ != t) {
        split_at_ = t;
        split_.clear();
      }
      auto it = split_.find(node);
      if (it == split_.end()) it = split_.emplace(node, BestSplit(node)).first;
      if (it->second && it->second->count(r)) {
        u = it->second->at(r);
        split = true;
      }
    }
  }
  prev_f_[r] = f;
  prev_tau_[r] = tau;
  if (ctx_.Logs("sim", LogLevel::kTrace)) {
    ctx_.Log(
        "sim",
        StrFormat("t %.4f %s u %.3f f %.2f %.2f %.2f tau %.3f %.3f %.3f", t,
                  scene_.robots[r].name.c_str(), u, f.x(), f.y(), f.z(), tau.x(), tau.y(), tau.z()),
        LogLevel::kTrace);
  }
  double& peak =
      vacuum ? (insert_action >= 0 ? report_.peak.vacuum_insertion : report_.peak.vacuum_transport)
             : (insert_action >= 0 ? report_.peak.two_finger_insertion
                                   : report_.peak.two_finger_transport);
  peak = std::max(peak, u);
  const int blamed = insert_action >= 0 ? insert_action : current;
  if (blamed >= 0) {
    report_.actions[blamed].peak_utilisation =
        std::max(report_.actions[blamed].peak_utilisation, u);
  }
  if (u > 1.0) {
    Failed(blamed, vacuum ? "vacuum limit" : "slip",
           "robot '" + scene_.robots[r].name + "' at " + Num(100 * u) + "% of its " +
               (vacuum ? (insert_action >= 0 ? "vacuum assembly/transport" : "vacuum transport")
                       : "two-finger") +
               " limits (" +
               (split ? "in the best split of the load among its object's "
                        "supports; its weld measured "
                      : "") +
               "force " + Num(f.x()) + ", " + Num(f.y()) + ", " + Num(f.z()) + " N, torque " +
               Num(tau.x()) + ", " + Num(tau.y()) + ", " + Num(tau.z()) +
               " N m in the grasp frame)",
           t);
    return false;
  }
  return true;
}

// Robot r's wrench (f, tau) averaged with its measurements over the last options_.average_s (see
// SimOptions).
void Simulator::AverageWrench(int r, Vec3& f, Vec3& tau) {
  std::deque<Vec6>& recent = recent_[r];
  Vec6 w;
  w << f, tau;
  recent.push_back(w);
  const double sample_s = options_.sample_every * model_->opt.timestep;
  const size_t keep =
      static_cast<size_t>(std::max(1.0, std::round(std::max(0.0, options_.average_s) / sample_s)));
  while (recent.size() > keep) recent.pop_front();
  Vec6 mean = Vec6::Zero();
  for (const Vec6& x : recent) mean += x;
  mean /= static_cast<double>(recent.size());
  f = mean.head<3>();
  tau = mean.tail<3>();
}

WrenchLimits Simulator::HeldLimits(int r) const {
  return GraspLimits(limits_[r], grasp_[r].torque_scale);
}

// Robot r's utilisation of its limits with wrench (f, tau) in its grasp frame, during insertion
// `insert_action` (-1: none).
double Simulator::GripperUtilisation(int r, const Vec3& f, const Vec3& tau, int insert_action) {
  const bool vacuum = scene_.robots[r].end_effector.kind == EndEffectorKind::kVacuum;
  const WrenchLimits lim = HeldLimits(r);
  const double fN = options_.zero_limit_force_N, fNm = options_.zero_limit_torque_Nm;
  double u = 0.0;
  if (!vacuum) {
    u = BoxUtilisation(f, tau, lim.two_finger, fN, fNm);
  } else if (insert_action < 0) {
    u = BoxUtilisation(f, tau, lim.vacuum_transport, fN, fNm);
  } else {
    // Held, then mated (wrench.h): the whole within the transport box, and what the
    // insertion adds to the load of holding within the assembly box, component by
    // component: a component that shrinks (the weight passed on to the table or the base
    // the part lands on) adds nothing, one that grows or turns round adds what it exceeds.
    // A cup on the moved input is judged from its load just before the insertion (the
    // mating wrench goes through it, onset included). A cup on the base is judged from the
    // insertion's first measurement, which already holds most of the onset: judging that
    // too would judge how MuJoCo's rigid welds split a wrench among an object's several
    // holders and the table (statically indeterminate), not the split the plan's LP chose
    // (the chair's seat cup took 15 times its assembly limits where the plan has two-finger
    // grippers take the leg's mating force).
    if (!was_inserting_[r]) {
      const std::vector<int>& moved = tree_.nodes[plan_.actions[insert_action].objects[0]].parts;
      const bool on_moved = std::find(moved.begin(), moved.end(), grip_part_[r]) != moved.end();
      hold_f_[r] = on_moved ? prev_f_[r] : f;
      hold_tau_[r] = on_moved ? prev_tau_[r] : tau;
    }
    Vec3 add_f, add_tau;
    for (int i = 0; i < 3; ++i) {
      add_f[i] = std::max(0.0, std::abs(f[i]) - std::abs(hold_f_[r][i]));
      add_tau[i] = std::max(0.0, std::abs(tau[i]) - std::abs(hold_tau_[r][i]));
    }
    u = std::max(BoxUtilisation(f, tau, lim.vacuum_transport, fN, fNm),
                 BoxUtilisation(add_f, add_tau, lim.vacuum_assembly, fN, fNm));
  }
  was_inserting_[r] = insert_action >= 0;
  return u;
}

// Every part where the plan has it (held: with its first holder's TCP; else where it was left).
void Simulator::MeasureDrift(double t, int current) {
  for (const auto& [node, o] : state_.objects) {
    const Iso3 X_WA = ExpectedX_WA(node, o);
    for (int p : tree_.nodes[node].parts) {
      const Iso3 expected = X_WA * scene_.parts[p].X_AP;
      const Iso3 actual = PartPose(p);
      const double dp = (actual.translation() - expected.translation()).norm();
      const double da = AngleOf(actual.linear().transpose() * expected.linear());
      if (dp > options_.drift_tolerance_m || da > options_.drift_tolerance_rad) {
        const bool unheld = state_.Holders(node).empty();
        const auto last = last_action_.find(node);
        const int blamed =
            unheld && last != last_action_.end() && last->second >= 0 ? last->second : current;
        Failed(blamed, "no support",
               "'" + scene_.parts[p].name + "' is " + Num(1000 * dp) + " mm and " +
                   Num(da * 180 / M_PI) + " deg from where the plan has it" +
                   (unheld ? " (nobody holds it)" : ""),
               t);
        return;
      }
    }
  }
}

// The final assembly: every part against the assembly's relative poses.
void Simulator::CheckFinal(double t) {
  for (const auto& [node, o] : state_.objects) {
    const std::vector<int>& parts = tree_.nodes[node].parts;
    if (parts.size() < 2) continue;
    const int ref = parts.front();
    const Iso3 X_WA = PartPose(ref) * scene_.parts[ref].X_AP.inverse();
    for (int p : parts) {
      const Iso3 expected = X_WA * scene_.parts[p].X_AP;
      const Iso3 actual = PartPose(p);
      const double dp = (actual.translation() - expected.translation()).norm();
      const double da = AngleOf(actual.linear().transpose() * expected.linear());
      report_.final_position_error_m = std::max(report_.final_position_error_m, dp);
      report_.final_angle_error_rad = std::max(report_.final_angle_error_rad, da);
    }
  }
  if (report_.final_position_error_m > options_.misalign_tolerance_m ||
      report_.final_angle_error_rad > options_.misalign_tolerance_rad) {
    Failed(order_.empty() ? -1 : order_.back(), "misalignment",
           "final assembly " + Num(1000 * report_.final_position_error_m) + " mm and " +
               Num(report_.final_angle_error_rad * 180 / M_PI) + " deg off",
           t);
  }
}

}  // namespace wrap::detail
