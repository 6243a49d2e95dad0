// The events of the physics run (see detail/simulator.h): at each action's moment grips close
// (welds to the TCP) or open (after a fade that hands the load over), an insertion's mating
// wrench acts on both inputs while it runs, and a mated connection is welded.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "verify/detail/simulator.h"

namespace wrap::detail {

namespace {

// The box of a part's mesh in the assembly frame A.
Aabb PartBoxInA(const ScenePart& part) {
  Aabb box;
  box.min = Vec3::Constant(std::numeric_limits<double>::infinity());
  box.max = -box.min;
  for (const Vec3& v : part.mesh->vertices) {
    const Vec3 a = part.X_AP * v;
    box.min = box.min.cwiseMin(a);
    box.max = box.max.cwiseMax(a);
  }
  return box;
}

}  // namespace

Interface FindInterface(const CellScene& scene, const AssemblyTree& tree, const Mating& mating,
                        int moved, int base) {
  Interface out;
  out.axis_A = mating.axis.norm() > 0.0 ? mating.axis.normalized() : Vec3::UnitZ();
  out.force_N = mating.force_N;
  out.torque_Nm = mating.torque_Nm;
  double best = -1.0;
  double nearest = std::numeric_limits<double>::infinity();
  for (int pm : tree.nodes[moved].parts) {
    for (int pb : tree.nodes[base].parts) {
      const Aabb a = PartBoxInA(scene.parts[pm]);
      const Aabb b = PartBoxInA(scene.parts[pb]);
      const Vec3 lo = a.min.cwiseMax(b.min) - Vec3::Constant(1e-3);
      const Vec3 hi = a.max.cwiseMin(b.max) + Vec3::Constant(1e-3);
      if ((hi.array() > lo.array()).all()) {
        const double v = (hi - lo).prod();
        if (v > best) {
          best = v;
          out.part_moved = pm;
          out.part_base = pb;
          out.p_A = 0.5 * (lo + hi);
        }
      } else if (best < 0.0) {
        const Vec3 cm = 0.5 * (a.min + a.max);
        const Vec3 cb = 0.5 * (b.min + b.max);
        if ((cm - cb).norm() < nearest) {
          nearest = (cm - cb).norm();
          out.part_moved = pm;
          out.part_base = pb;
          out.p_A = 0.5 * (cm + cb);
        }
      }
    }
  }
  return out;
}

// Switches weld `eq` on with body2 held where it is now relative to body1.
void Simulator::Weld(int eq, const Iso3& X_W1, const Iso3& X_W2) {
  const Iso3 X_12 = X_W1.inverse() * X_W2;
  mjtNum* e = model_->eq_data + mjNEQDATA * eq;
  // eq_data of a weld in 2.2: anchor (3), relative position (3), relative quaternion (4),
  // torque scale (1); the relative pose is body2's in body1's frame.
  Eigen::Quaterniond q(X_12.linear());
  q.normalize();
  for (int k = 0; k < 3; ++k) e[3 + k] = X_12.translation()[k];
  e[6] = q.w();
  e[7] = q.x();
  e[8] = q.y();
  e[9] = q.z();
  model_->eq_active[eq] = 1;
}

// Robot r's fade (see Fade), or null.
const Simulator::Fade* Simulator::FadeOf(int r) const {
  for (const Fade& f : fades_) {
    if (f.robot == r) return &f;
  }
  return nullptr;
}

void Simulator::StopFade(int r) {
  fades_.erase(
      std::remove_if(fades_.begin(), fades_.end(), [&](const Fade& f) { return f.robot == r; }),
      fades_.end());
}

// What is left of a started fade at time t: 1 at its start, 0 from kReleaseRamp_s on.
double Simulator::FadeLeft(const Fade& f, double t) {
  return std::clamp(1.0 - (t - f.t0) / kReleaseRamp_s, 0.0, 1.0);
}

// Releases (a place, a release, a handover's giver) due within kReleaseRamp_s of t whose
// robot holds: its fade is scheduled.
void Simulator::FadeBeforeReleases(double t) {
  for (size_t e = next_event_; e < order_.size(); ++e) {
    const PlanAction& a = plan_.actions[order_[e]];
    if (a.end_s > t + kReleaseRamp_s) break;
    if (a.robots.empty() || (a.type != ActionType::kPlace && a.type != ActionType::kRelease &&
                             a.type != ActionType::kHandover)) {
      continue;
    }
    const int r = a.robots[0];
    if (r < 0 || r >= static_cast<int>(grip_part_.size()) || grip_part_[r] < 0) continue;
    // A handover's receiver closes first, so that it takes the load over from the giver.
    if (a.type == ActionType::kHandover && a.robots.size() > 1 && a.grasps.size() > 1) {
      const int r2 = a.robots[1];
      if (r2 >= 0 && r2 < static_cast<int>(grip_part_.size()) &&
          grip_part_[r2] != a.grasps[1].grasp.part) {
        Grip(r2, a.grasps[1].grasp);
      }
    }
    if (!FadeOf(r)) {
      Fade f;
      f.robot = r;
      f.part = grip_part_[r];
      f.t0 = a.end_s - kReleaseRamp_s;
      fades_.push_back(f);
    }
  }
}

// The fades at time t (after xfrc_applied was cleared): one due starts (its weld's last
// wrench taken over, the weld off), every started one applies what is left of its wrench.
void Simulator::ApplyFades(double t) {
  for (Fade& f : fades_) {
    if (!f.started) {
      if (t < f.t0) continue;
      const int eq = grip_eq_[f.robot][f.part];
      WeldWrench(eq, f.part, f.f_W, f.tau_W);
      model_->eq_active[eq] = 0;
      f.started = true;
    }
    const double k = FadeLeft(f, t);
    if (k <= 0.0) continue;
    const int body = part_body_[f.part];
    const Vec3 com(data_->xipos[3 * body], data_->xipos[3 * body + 1], data_->xipos[3 * body + 2]);
    // tau_W is about the part's origin; MuJoCo applies xfrc_applied at the COM.
    const Vec3 tau = f.tau_W + (PartPose(f.part).translation() - com).cross(f.f_W);
    mjtNum* x = data_->xfrc_applied + 6 * body;
    for (int i = 0; i < 3; ++i) {
      x[i] += k * f.f_W[i];
      x[3 + i] += k * tau[i];
    }
  }
}

void Simulator::Grip(int r, const PlanGrasp& g) {
  Release(r);
  if (g.part < 0 || g.part >= static_cast<int>(part_body_.size())) return;
  grip_part_[r] = g.part;
  grasp_[r] = g;
  recent_[r].clear();
  Weld(grip_eq_[r][g.part], TcpBodyPose(r), PartPose(g.part));
}

// Its weld off now (and its fade over, if it was fading).
void Simulator::Release(int r) {
  StopFade(r);
  if (grip_part_[r] >= 0) model_->eq_active[grip_eq_[r][grip_part_[r]]] = 0;
  grip_part_[r] = -1;
}

// The moment of action i: grips close or open, connections are made, and the plan state moves on
// (task/plan_state.h). An object its last holder lets go of is expected where that holder's TCP
// left it.
void Simulator::Event(int i, double t) {
  collision_dirty_ = true;
  const PlanAction& a = plan_.actions[i];
  const int node = a.objects.empty() ? -1 : a.objects[0];
  const PlanState at = StateAtKeyframe(state_, a);
  std::optional<Iso3> left;  // where the object was let go of by its last holder
  switch (a.type) {
    case ActionType::kPick:
    case ActionType::kAddGrasp:
      TakeHold(a.robots[0], a.grasps[0].grasp);
      break;
    case ActionType::kPlace:
    case ActionType::kRelease:
      left = LetGo(a.robots[0], node, at, t);
      break;
    case ActionType::kHandover:
      TakeHold(a.robots[1], a.grasps[1].grasp);
      left = LetGo(a.robots[0], node, at, t);
      break;
    case ActionType::kAssemble:
      if (!Mate(i, t)) return;
      break;
  }
  state_ = ApplyAction(state_, a);
  if (auto it = state_.objects.find(node); left && it != state_.objects.end()) {
    it->second.X_WA = *left;
  }
  if (a.type == ActionType::kAssemble) {
    last_action_.erase(a.objects[0]);
    last_action_.erase(a.objects[1]);
    last_action_[a.objects[2]] = i;
  } else if (node >= 0) {
    last_action_[node] = i;
  }
  report_.actions[i].status = "completed";
  ++report_.tasks_completed;
}

// Robot r closes on grasp g: its weld holds the part (a handover's receiver may have closed
// already, FadeBeforeReleases).
void Simulator::TakeHold(int r, const PlanGrasp& g) {
  if (grip_part_[r] != g.part) Grip(r, g);
}

// Robot r lets go of `node` (`at`: the plan state at the action's keyframe). The gripper may touch
// the object a little longer (it falls or is left). Returns where r's TCP leaves the object when r
// was its only holder.
std::optional<Iso3> Simulator::LetGo(int r, int node, const PlanState& at, double t) {
  windows_.push_back({t, t + kReleaseGrace_s, {r}, {node}, false});
  std::optional<Iso3> left;
  const std::vector<int> holders = at.Holders(node);
  if (holders.size() == 1 && holders.front() == r) left = CarriedX_WA(r);
  // Its wrench has faded away since kReleaseRamp_s before (FadeBeforeReleases).
  Release(r);
  return left;
}

// Assemble action i reaches its mating pose: the connection is welded, or, when the moved input
// sits too far off its pose on the base, the plan fails ("misalignment") and false is returned.
bool Simulator::Mate(int i, double t) {
  const Interface& in = interfaces_.at(i);
  // The mated pose: the moved part relative to the base part against the assembly.
  const Iso3 X_WPm = PartPose(in.part_moved);
  const Iso3 X_WPb = PartPose(in.part_base);
  const Iso3 actual = X_WPb.inverse() * X_WPm;
  const Iso3 nominal = scene_.parts[in.part_base].X_AP.inverse() * scene_.parts[in.part_moved].X_AP;
  const double dp = (actual.translation() - nominal.translation()).norm();
  const double da = AngleOf(actual.linear().transpose() * nominal.linear());
  if (dp > options_.misalign_tolerance_m || da > options_.misalign_tolerance_rad) {
    Failed(i, "misalignment",
           "'" + scene_.parts[in.part_moved].name + "' mated " + Num(1000 * dp) + " mm and " +
               Num(da * 180 / M_PI) + " deg off its pose on '" + scene_.parts[in.part_base].name +
               "'",
           t);
    return false;
  }
  const int p = std::min(in.part_moved, in.part_base);
  const int q = std::max(in.part_moved, in.part_base);
  Weld(join_eq_[p][q], PartPose(p), PartPose(q));
  joins_.push_back({join_eq_[p][q], q, i});
  return true;
}

// The assemble actions whose insertion runs at t.
std::vector<int> Simulator::Insertions(double t) const {
  std::vector<int> out;
  for (const MotionSegment& s : plan_.segments) {
    if (s.kind == "insert" && s.start_s <= t && t < s.end_s && interfaces_.count(s.action)) {
      out.push_back(s.action);
    }
  }
  return out;
}

// The mating wrench on both inputs of assemble action i, at their interface point.
void Simulator::ApplyMating(int i) {
  const Interface& in = interfaces_.at(i);
  const Iso3 X_WPb = PartPose(in.part_base);
  const Iso3 X_WA = X_WPb * scene_.parts[in.part_base].X_AP.inverse();
  const Vec3 axis_W = X_WA.linear() * in.axis_A;
  const Vec3 p_W = X_WA * in.p_A;
  const double s = options_.force_scale;
  // The base resists the moved input: on it -F along the axis, on the base +F.
  const Vec3 f_moved = -s * in.force_N * axis_W;
  const Vec3 tau_moved = -s * in.torque_Nm * axis_W;
  for (int side = 0; side < 2; ++side) {
    const int body = part_body_[side == 0 ? in.part_moved : in.part_base];
    const double sign = side == 0 ? 1.0 : -1.0;
    const Vec3 f = sign * f_moved;
    const Vec3 com(data_->xipos[3 * body], data_->xipos[3 * body + 1], data_->xipos[3 * body + 2]);
    const Vec3 tau = sign * tau_moved + (p_W - com).cross(f);
    Vec6& on = mating_on_part_[side == 0 ? in.part_moved : in.part_base];
    on.head<3>() += f;
    on.tail<3>() += tau;
    mjtNum* x = data_->xfrc_applied + 6 * body;
    for (int k = 0; k < 3; ++k) {
      x[k] += f[k];
      x[3 + k] += tau[k];
    }
  }
}

}  // namespace wrap::detail
