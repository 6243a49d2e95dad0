#include "verify/simulate.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <limits>
#include <map>
#include <memory>

#include "core/frames.h"
#include "geometry/convex_hull.h"
#include "mating/assembly_geometry.h"
#include "mating/insertion.h"
#include "robot/kinematics.h"
#include "sim/mjcf.h"
#include "sim/mujoco_model.h"
#include "sim/scene.h"
#include "verify/detail/collisions.h"
#include "verify/detail/best_split.h"
#include "verify/detail/keyframe_replay.h"
#include "wrench/lp.h"
#include "wrench/wrench.h"

namespace wrap {

namespace {

constexpr int kWeldRows = 6;             // a weld constrains 3 positions and 3 rotations
constexpr double kReleaseGrace_s = 0.5;  // a released object may touch its gripper this long
// A gripper lets go over this long before its release's moment (Simulator::Fade).
constexpr double kReleaseRamp_s = 0.1;
// BestSplit: an object's vertices this close to the table top may bear on it [m]; at most this
// many corners of their hull are used.
constexpr double kSupportReach_m = 0.001;
constexpr size_t kMaxSupportPoints = 16;

double AngleOf(const Mat3& R) { return std::abs(Eigen::AngleAxisd(R).angle()); }

std::string Num(double v, int digits = 3) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

// Where the two inputs of a step meet, chosen as the planner does (task/world.cpp): the pair
// of parts whose boxes in A overlap most, the centre of that overlap as the contact point.
struct Interface {
  int part_moved = -1;
  int part_base = -1;
  Vec3 p_A = Vec3::Zero();
  Vec3 axis_A = Vec3::UnitZ();
  double force_N = 0.0;
  double torque_Nm = 0.0;
  WrenchBox limits;  // T_pq of the connection, in its frame C
};

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

// Utilisation of a wrench (force, torque) against a symmetric box: the largest |component| /
// bound, a zero bound taken as the floor.
double BoxUtilisation(const Vec3& f, const Vec3& tau, const WrenchBox& box, double floor_N,
                      double floor_Nm) {
  double u = 0.0;
  for (int i = 0; i < 3; ++i) {
    u = std::max(u, std::abs(f[i]) / std::max(box.force_N[i], floor_N));
    u = std::max(u, std::abs(tau[i]) / std::max(box.torque_Nm[i], floor_Nm));
  }
  return u;
}

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

class Simulator {
 public:
  Simulator(const Project& project, const ProjectCheck& check, const CellScene& scene,
            const AssemblyTree& tree, const Plan& plan, bool keyframes, const SimOptions& options,
            RunContext& ctx)
      : project_(project),
        geometry_(AssemblyGeometry::FromProject(project, check)),
        scene_(scene),
        tree_(tree),
        plan_(plan),
        keyframes_(keyframes),
        options_(options),
        ctx_(ctx) {}

  Result<SimReport> Run() {
    if (auto ok = Setup(); !ok) return std::unexpected(ok.error());
    Result<void> cancelled;
    auto guarded = RunGuarded("simulating the plan", [&] { cancelled = Loop(); });
    if (!guarded) return std::unexpected(guarded.error());
    if (!cancelled) return std::unexpected(cancelled.error());
    for (std::string& w : TakeMujocoWarnings()) report_.warnings.push_back("MuJoCo: " + w);
    report_.success = !report_.failure.has_value();
    return std::move(report_);
  }

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
    double t0 = 0.0;      // starts [s]
    bool started = false;
    Vec3 f_W = Vec3::Zero();    // the weld's last force on the part, world
    Vec3 tau_W = Vec3::Zero();  // and torque, about the part's origin
  };

  struct Object {
    Iso3 X_WA = Iso3::Identity();  // where it should be while nobody holds it
    std::vector<int> holders;      // robots, ascending
    int last_action = -1;          // the last action that changed its support
  };

  Result<void> Setup() {
    const int nr = static_cast<int>(scene_.robots.size());
    const int np = static_cast<int>(scene_.parts.size());
    report_.tasks_total = static_cast<int>(plan_.actions.size());
    for (const PlanAction& a : plan_.actions) {
      report_.actions.push_back({std::string(ToString(a.type)), "not reached", -1.0});
    }
    // Initial state: robots at the start of their trajectories, parts as the plan begins.
    SceneState state;
    for (int r = 0; r < nr; ++r) {
      state.q.push_back(SampleTrajectory(plan_.trajectories[r], 0.0));
      state.opening_m.push_back(scene_.robots[r].end_effector.stroke_m);
    }
    state.X_WP.assign(np, Iso3::Identity());
    for (const PlanObject& o : plan_.initial.objects) {
      objects_[o.node] = {o.X_WA, {}, -1};
      for (int p : tree_.nodes[o.node].parts) state.X_WP[p] = o.X_WA * scene_.parts[p].X_AP;
    }
    MjcfOptions mo;
    mo.physics = true;
    mo.timestep_s = options_.timestep_s;
    mo.shadows = false;
    auto doc = BuildCellMjcf(scene_, state, mo);
    if (!doc) return std::unexpected(doc.error());
    for (const std::string& w : doc->warnings) report_.warnings.push_back(w);
    if (!options_.mjcf_dir.empty()) {
      if (auto ok = WriteMjcf(*doc, options_.mjcf_dir); !ok) return ok;
    }
    auto cell = CellModel::Compile(*doc);
    if (!cell) return std::unexpected(cell.error());
    // Our own copy: welds are switched on and retargeted in the model (eq_active, eq_data).
    auto guarded = RunGuarded("preparing the physics model", [&] {
      model_.reset(mj_copyModel(nullptr, cell->model()));
      data_.reset(mj_makeData(model_.get()));
    });
    if (!guarded) return std::unexpected(guarded.error());
    if (auto ok = cell->Apply(state, data_.get()); !ok) return ok;
    const mjModel* m = model_.get();
    for (int r = 0; r < nr; ++r) {
      const int body = mj_name2id(m, mjOBJ_BODY, doc->tcp_bodies[r].c_str());
      if (body < 0 || m->body_mocapid[body] < 0) {
        return Fail(ErrorCode::kInternal, "sim: no TCP mocap body for robot " + std::to_string(r));
      }
      tcp_mocap_.push_back(m->body_mocapid[body]);
      std::vector<int> ids;
      for (int p = 0; p < np; ++p) {
        ids.push_back(mj_name2id(m, mjOBJ_EQUALITY, doc->grip_welds[r][p].c_str()));
      }
      grip_eq_.push_back(std::move(ids));
    }
    join_eq_.assign(np, std::vector<int>(np, -1));
    for (int p = 0; p < np; ++p) {
      part_body_.push_back(mj_name2id(m, mjOBJ_BODY, doc->part_bodies[p].c_str()));
      part_dof_.push_back(m->jnt_dofadr[m->body_jntadr[part_body_.back()]]);
      for (int q = p + 1; q < np; ++q) {
        join_eq_[p][q] = mj_name2id(m, mjOBJ_EQUALITY, doc->join_welds[p][q].c_str());
      }
    }
    // Limits, grips and the steps' interfaces.
    for (const Robot& r : project_.robots) {
      limits_.push_back(r.wrench_limits.value_or(project_.wrench_limits));
    }
    grip_part_.assign(nr, -1);
    mating_on_part_.assign(np, Vec6::Zero());
    recent_.assign(nr, {});
    grasp_.assign(nr, PlanGrasp{});
    hold_f_.assign(nr, Vec3::Zero());
    hold_tau_.assign(nr, Vec3::Zero());
    prev_f_.assign(nr, Vec3::Zero());
    prev_tau_.assign(nr, Vec3::Zero());
    was_inserting_.assign(nr, false);
    for (size_t i = 0; i < plan_.actions.size(); ++i) {
      const PlanAction& a = plan_.actions[i];
      if (a.type != ActionType::kAssemble) continue;
      const int step = tree_.nodes[a.objects[2]].step;
      const Mating& mating = project_.steps[step].mating;
      Interface in = FindInterface(scene_, tree_, mating, a.objects[0], a.objects[1]);
      in.limits = mating.connection_limits.value_or(project_.connection_limits);
      interfaces_[static_cast<int>(i)] = in;
    }
    order_.resize(plan_.actions.size());
    for (size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<int>(i);
    std::stable_sort(order_.begin(), order_.end(),
                     [&](int a, int b) { return plan_.actions[a].end_s < plan_.actions[b].end_s; });
    for (const RobotTrajectory& tr : plan_.trajectories) {
      makespan_ = std::max(makespan_, tr.knots.back().t);
    }
    for (const PlanAction& a : plan_.actions) makespan_ = std::max(makespan_, a.end_s);
    report_.motion = keyframes_ ? "keyframes" : "trajectories";
    report_.collisions_judged = options_.check_collisions && !keyframes_;
    if (report_.collisions_judged) {
      auto judge = detail::SimCollisions::Build(scene_, options_.collision_tolerance_m);
      if (!judge) return std::unexpected(judge.error());
      collisions_.emplace(std::move(*judge));
      ContactWindows();
    }
    SetTcps(0.0);
    mj_forward(model_.get(), data_.get());
    return {};
  }

  // The action running at `t`: the first (in time order) whose moment has not passed.
  int CurrentAction() const {
    if (next_event_ < order_.size()) return order_[next_event_];
    return order_.empty() ? -1 : order_.back();
  }

  Iso3 Tcp(int r, double t) const {
    const SceneRobot& robot = scene_.robots[r];
    return TcpPose(robot.chain, robot.X_WB, SampleTrajectory(plan_.trajectories[r], t),
                   robot.end_effector.X_FT);
  }

  void SetTcps(double t) {
    std::vector<Iso3> X_WT(tcp_mocap_.size());
    for (size_t r = 0; r < tcp_mocap_.size(); ++r) X_WT[r] = Tcp(static_cast<int>(r), t);
    if (keyframes_) {
      // Keyframes are joined straight in joint space, which would pull apart the grippers of a
      // shared object: its other holders follow the first one's TCP at their grasps.
      for (const auto& [node, o] : objects_) {
        if (o.holders.size() < 2) continue;
        const int c = o.holders.front();
        const Iso3 X_WA = X_WT[c] * (scene_.parts[grasp_[c].part].X_AP * grasp_[c].X_PG).inverse();
        for (size_t k = 1; k < o.holders.size(); ++k) {
          const PlanGrasp& g = grasp_[o.holders[k]];
          X_WT[o.holders[k]] = X_WA * scene_.parts[g.part].X_AP * g.X_PG;
        }
      }
    }
    for (size_t r = 0; r < tcp_mocap_.size(); ++r) {
      const Iso3& X = X_WT[r];
      const int i = tcp_mocap_[r];
      Eigen::Quaterniond q(X.linear());
      q.normalize();
      for (int k = 0; k < 3; ++k) data_->mocap_pos[3 * i + k] = X.translation()[k];
      data_->mocap_quat[4 * i + 0] = q.w();
      data_->mocap_quat[4 * i + 1] = q.x();
      data_->mocap_quat[4 * i + 2] = q.y();
      data_->mocap_quat[4 * i + 3] = q.z();
    }
  }

  Iso3 BodyPose(int body) const {
    Iso3 X = Iso3::Identity();
    const mjtNum* p = data_->xpos + 3 * body;
    const mjtNum* q = data_->xquat + 4 * body;
    X.translation() = Vec3(p[0], p[1], p[2]);
    X.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
    return X;
  }
  Iso3 PartPose(int p) const { return BodyPose(part_body_[p]); }
  Iso3 TcpBodyPose(int r) const {
    Iso3 X = Iso3::Identity();
    const int i = tcp_mocap_[r];
    X.translation() =
        Vec3(data_->mocap_pos[3 * i], data_->mocap_pos[3 * i + 1], data_->mocap_pos[3 * i + 2]);
    X.linear() = Eigen::Quaterniond(data_->mocap_quat[4 * i], data_->mocap_quat[4 * i + 1],
                                    data_->mocap_quat[4 * i + 2], data_->mocap_quat[4 * i + 3])
                     .normalized()
                     .toRotationMatrix();
    return X;
  }

  // Switches weld `eq` on with body2 held where it is now relative to body1.
  void Weld(int eq, const Iso3& X_W1, const Iso3& X_W2) {
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
  const Fade* FadeOf(int r) const {
    for (const Fade& f : fades_) {
      if (f.robot == r) return &f;
    }
    return nullptr;
  }
  void StopFade(int r) {
    fades_.erase(std::remove_if(fades_.begin(), fades_.end(),
                                [&](const Fade& f) { return f.robot == r; }),
                 fades_.end());
  }
  // What is left of a started fade at time t: 1 at its start, 0 from kReleaseRamp_s on.
  static double FadeLeft(const Fade& f, double t) {
    return std::clamp(1.0 - (t - f.t0) / kReleaseRamp_s, 0.0, 1.0);
  }

  // Releases (a place, a release, a handover's giver) due within kReleaseRamp_s of t whose
  // robot holds: its fade is scheduled.
  void FadeBeforeReleases(double t) {
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
  void ApplyFades(double t) {
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
      const Vec3 com(data_->xipos[3 * body], data_->xipos[3 * body + 1],
                     data_->xipos[3 * body + 2]);
      // tau_W is about the part's origin; MuJoCo applies xfrc_applied at the COM.
      const Vec3 tau = f.tau_W + (PartPose(f.part).translation() - com).cross(f.f_W);
      mjtNum* x = data_->xfrc_applied + 6 * body;
      for (int i = 0; i < 3; ++i) {
        x[i] += k * f.f_W[i];
        x[3 + i] += k * tau[i];
      }
    }
  }

  void Grip(int r, const PlanGrasp& g) {
    Release(r);
    if (g.part < 0 || g.part >= static_cast<int>(part_body_.size())) return;
    grip_part_[r] = g.part;
    grasp_[r] = g;
    recent_[r].clear();
    Weld(grip_eq_[r][g.part], TcpBodyPose(r), PartPose(g.part));
  }

  // Its weld off now (and its fade over, if it was fading).
  void Release(int r) {
    StopFade(r);
    if (grip_part_[r] >= 0) model_->eq_active[grip_eq_[r][grip_part_[r]]] = 0;
    grip_part_[r] = -1;
  }

  // The object (node) part p belongs to now, or -1.
  int NodeOfPart(int p) const {
    for (const auto& [node, o] : objects_) {
      const std::vector<int>& ps = tree_.nodes[node].parts;
      if (std::find(ps.begin(), ps.end(), p) != ps.end()) return node;
    }
    return -1;
  }

  // Where the plan has an object now: carried by its first holder, else where it was left.
  Iso3 ExpectedX_WA(const Object& o) const {
    if (o.holders.empty()) return o.X_WA;
    const int r = o.holders.front();
    const PlanGrasp& g = grasp_[r];
    return TcpBodyPose(r) * (scene_.parts[g.part].X_AP * g.X_PG).inverse();
  }

  void Failed(int action, const std::string& reason, const std::string& detail, double t) {
    if (report_.failure) return;
    for (int c = 0; c < data_->ncon && ctx_.Logs("sim"); ++c) {
      const mjContact& con = data_->contact[c];
      const char* n1 = mj_id2name(model_.get(), mjOBJ_BODY, model_->geom_bodyid[con.geom1]);
      const char* n2 = mj_id2name(model_.get(), mjOBJ_BODY, model_->geom_bodyid[con.geom2]);
      ctx_.Log("sim", StrFormat("contact at the failure: %s - %s dist %.4f", n1 ? n1 : "world",
                                n2 ? n2 : "world", con.dist));
    }
    report_.failure = SimFailure{action, reason, detail, t};
    if (action >= 0) report_.actions[action].status = "failed";
  }

  // Where a robot may touch an object besides holding it (plan segments): from the start of its
  // approach through the grip to the grasp, while its gripper closes or opens, during its
  // retreat, and the robots of an insertion with both inputs (which may touch each other then).
  void ContactWindows() {
    for (const MotionSegment& s : plan_.segments) {
      if (s.action < 0 || s.action >= static_cast<int>(plan_.actions.size())) continue;
      const double end_s = plan_.actions[s.action].end_s;
      if (s.kind == "approach") {
        windows_.push_back({s.start_s, std::max(s.end_s, end_s), s.robots, s.objects, false});
      } else if (s.kind == "grip" || s.kind == "retreat") {
        windows_.push_back({s.start_s, s.end_s, s.robots, s.objects, false});
      } else if (s.kind == "insert" && s.objects.size() >= 2) {
        const PlanAction& action = plan_.actions[s.action];
        windows_.push_back({s.start_s, std::max(s.end_s, end_s), action.robots,
                            {s.objects[0], s.objects[1]}, true,
                            action.objects.size() >= 3 ? action.objects[2] : -1});
      }
    }
  }

  // The contacts allowed at t: a robot with what it holds, parts of one object, parts nobody
  // holds with each other (they do not collide in MuJoCo either), and the windows open at t.
  detail::ContactRules Rules(double t) const {
    const int nr = static_cast<int>(scene_.robots.size());
    const int np = static_cast<int>(scene_.parts.size());
    detail::ContactRules rules;
    std::vector<int> node_of(np, -1);
    rules.held.assign(np, 0);
    rules.robot_part_ok.assign(nr, std::vector<char>(np, 0));
    rules.part_pair_ok.assign(np, std::vector<char>(np, 0));
    for (const auto& [node, o] : objects_) {
      for (int p : tree_.nodes[node].parts) {
        node_of[p] = node;
        rules.held[p] = !o.holders.empty();
        for (int r : o.holders) rules.robot_part_ok[r][p] = 1;
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
  // ended: checks come every few steps), else the action under way.
  int ActionOfRobot(int r, double t) const {
    const double slack = 2.0 * options_.sample_every * model_->opt.timestep;
    for (const MotionSegment& s : plan_.segments) {
      if (s.action >= 0 && s.start_s <= t && t <= s.end_s + slack &&
          std::find(s.robots.begin(), s.robots.end(), r) != s.robots.end()) {
        return s.action;
      }
    }
    return CurrentAction();
  }

  // The robots where they are driven and the parts where MuJoCo has them.
  SceneState CurrentState(double t) const {
    SceneState state;
    for (size_t r = 0; r < scene_.robots.size(); ++r) {
      const RobotTrajectory& tr = plan_.trajectories[r];
      state.q.push_back(SampleTrajectory(tr, t));
      const double o = OpeningAt(tr, t);
      const double stroke = scene_.robots[r].end_effector.stroke_m;
      state.opening_m.push_back(o < 0.0 ? stroke : std::clamp(o, 0.0, stroke));
    }
    for (size_t p = 0; p < scene_.parts.size(); ++p) {
      state.X_WP.push_back(PartPose(static_cast<int>(p)));
    }
    return state;
  }

  // Collisions at t, when something moved enough since the last check (or an action happened).
  Result<void> CheckCollisions(double t) {
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
    const detail::CollisionHit& h = **hit;
    auto holder = [&](int p) {
      for (const auto& [node, o] : objects_) {
        const auto& parts = tree_.nodes[node].parts;
        if (!o.holders.empty() && std::find(parts.begin(), parts.end(), p) != parts.end()) {
          return o.holders.front();
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
    Failed(robot >= 0 ? ActionOfRobot(robot, t) : CurrentAction(), "collision", detail, t);
    return {};
  }

  // The two inputs of an insertion under way where MuJoCo has them (the collision rules let them
  // touch): more overlap than the geometry allows where the moved input is along its path is a
  // collision naming both parts.
  void CheckInsertionOverlaps(double t, const std::vector<Iso3>& X_WP) {
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
          std::max(options_.collision_tolerance_m,
                   along <= mating.interference_travel_m + 1e-9
                       ? std::max(mating.interference_depth_m, touch)
                       : touch);
      const auto o = OverlapBeyond(geometry_, moved, base, X_WP, allowed);
      if (!o) continue;
      Failed(ActionOfInsertion(w.step), "collision",
             "'" + scene_.parts[o->part_a].name + "' cuts into '" +
                 scene_.parts[o->part_b].name + "' deeper than the " + Num(1000 * allowed) +
                 " mm allowed, " + Num(1000 * std::max(0.0, along)) +
                 " mm before its mating pose (inserting '" + node.name + "')",
             t);
      return;
    }
  }

  // The assemble action that builds step node `step`.
  int ActionOfInsertion(int step) const {
    for (size_t i = 0; i < plan_.actions.size(); ++i) {
      const PlanAction& a = plan_.actions[i];
      if (a.type == ActionType::kAssemble && a.objects.size() >= 3 && a.objects[2] == step) {
        return static_cast<int>(i);
      }
    }
    return CurrentAction();
  }

  // The moment of action i: grips close or open, connections are made.
  void Event(int i, double t) {
    collision_dirty_ = true;
    const PlanAction& a = plan_.actions[i];
    const int node = a.objects.empty() ? -1 : a.objects[0];
    auto take = [&](int r, const PlanGrasp& g) {
      Object& o = objects_[node];
      o.holders.push_back(r);
      std::sort(o.holders.begin(), o.holders.end());
      if (grip_part_[r] != g.part) Grip(r, g);  // (a handover's receiver may have closed)
    };
    auto drop = [&](int r) {
      // The gripper that lets go may touch the object a little longer (it falls or is left).
      windows_.push_back({t, t + kReleaseGrace_s, {r}, {node}, false});
      Object& o = objects_[node];
      if (o.holders.size() == 1 && o.holders.front() == r) o.X_WA = ExpectedX_WA(o);
      o.holders.erase(std::remove(o.holders.begin(), o.holders.end(), r), o.holders.end());
      // Its wrench has faded away since kReleaseRamp_s before (FadeBeforeReleases).
      Release(r);
    };
    switch (a.type) {
      case ActionType::kPick:
      case ActionType::kAddGrasp:
        take(a.robots[0], a.grasps[0].grasp);
        break;
      case ActionType::kPlace:
      case ActionType::kRelease:
        drop(a.robots[0]);
        break;
      case ActionType::kHandover:
        take(a.robots[1], a.grasps[1].grasp);
        drop(a.robots[0]);
        break;
      case ActionType::kAssemble: {
        const Interface& in = interfaces_.at(i);
        // The mated pose: the moved part relative to the base part against the assembly.
        const Iso3 X_WPm = PartPose(in.part_moved);
        const Iso3 X_WPb = PartPose(in.part_base);
        const Iso3 actual = X_WPb.inverse() * X_WPm;
        const Iso3 nominal =
            scene_.parts[in.part_base].X_AP.inverse() * scene_.parts[in.part_moved].X_AP;
        const double dp = (actual.translation() - nominal.translation()).norm();
        const double da = AngleOf(actual.linear().transpose() * nominal.linear());
        if (dp > options_.misalign_tolerance_m || da > options_.misalign_tolerance_rad) {
          Failed(i, "misalignment",
                 "'" + scene_.parts[in.part_moved].name + "' mated " + Num(1000 * dp) + " mm and " +
                     Num(da * 180 / M_PI) + " deg off its pose on '" +
                     scene_.parts[in.part_base].name + "'",
                 t);
          return;
        }
        const int p = std::min(in.part_moved, in.part_base);
        const int q = std::max(in.part_moved, in.part_base);
        Weld(join_eq_[p][q], PartPose(p), PartPose(q));
        joins_.push_back({join_eq_[p][q], q, i});
        Object merged = objects_[a.objects[1]];
        for (int r : objects_[a.objects[0]].holders) merged.holders.push_back(r);
        std::sort(merged.holders.begin(), merged.holders.end());
        objects_.erase(a.objects[0]);
        objects_.erase(a.objects[1]);
        objects_[a.objects[2]] = merged;
        objects_[a.objects[2]].last_action = i;
        break;
      }
    }
    if (a.type != ActionType::kAssemble && node >= 0) objects_[node].last_action = i;
    report_.actions[i].status = "completed";
    ++report_.tasks_completed;
  }

  // The assemble actions whose insertion runs at t.
  std::vector<int> Insertions(double t) const {
    std::vector<int> out;
    for (const MotionSegment& s : plan_.segments) {
      if (s.kind == "insert" && s.start_s <= t && t < s.end_s && interfaces_.count(s.action)) {
        out.push_back(s.action);
      }
    }
    return out;
  }

  // The mating wrench on both inputs of assemble action i, at their interface point.
  void ApplyMating(int i) {
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
      const Vec3 com(data_->xipos[3 * body], data_->xipos[3 * body + 1],
                     data_->xipos[3 * body + 2]);
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

  // The wrench weld `eq` exerts on part p: world force, and world torque about the part's origin.
  void WeldWrench(int eq, int p, Vec3& f_W, Vec3& tau_W) const {
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
  void GripWrench(int r, Vec3& f_G, Vec3& tau_G, double t) const {
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
  void MeasureTable() {
    const mjModel* m = model_.get();
    const mjData* d = data_.get();
    constexpr double kMinNormal_N = 0.05;
    // Only parts that rest: a held part dragged over the table is the gripper's business.
    std::vector<char> held_body(m->nbody, 0);
    for (const auto& [node, o] : objects_) {
      if (o.holders.empty()) continue;
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
  void MeasureConnections() {
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
  std::optional<std::map<int, double>> BestSplit(int node) {
    const mjModel* m = model_.get();
    const mjData* d = data_.get();
    const std::vector<int>& parts = tree_.nodes[node].parts;
    std::vector<char> in_object(m->nbody, 0);
    for (int p : parts) in_object[part_body_[p]] = 1;
    const Vec3 p0 = PartPose(parts.front()).translation();
    detail::SplitQuery q;
    // Measured: the supports' whole (constraint forces), and the applied mating wrench.
    Vec6 W_mate = Vec6::Zero();
    for (int p : parts) {
      const int dof = part_dof_[p];
      const Iso3 X = PartPose(p);
      const Vec3 f(d->qfrc_constraint[dof], d->qfrc_constraint[dof + 1],
                   d->qfrc_constraint[dof + 2]);
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
      detail::SplitHolder h;
      h.A = detail::GraspWrenchToWorld(G.linear(), G.translation() - p0);
      h.vacuum = scene_.robots[r].end_effector.kind == EndEffectorKind::kVacuum;
      h.limits = limits_[r];
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
    auto split = detail::BestSplit(q, *lp_, lp_problem_, lp_solution_);
    if (!split) return std::nullopt;
    ++report_.split_measurements;
    std::map<int, double> u;
    for (size_t h = 0; h < robots.size(); ++h) u[robots[h]] = (*split)[h];
    return u;
  }

  void Measure(double t, const std::vector<int>& inserting) {
    const int current = CurrentAction();
    // Grippers against their limits.
    for (size_t ri = 0; ri < grip_part_.size(); ++ri) {
      const int r = static_cast<int>(ri);
      if (grip_part_[r] < 0) {
        was_inserting_[r] = false;
        prev_f_[r] = prev_tau_[r] = Vec3::Zero();
        recent_[r].clear();
        continue;
      }
      Vec3 f, tau;
      GripWrench(r, f, tau, t);
      // Averaged over the last options_.average_s (see SimOptions).
      {
        std::deque<Vec6>& recent = recent_[r];
        Vec6 w;
        w << f, tau;
        recent.push_back(w);
        const double sample_s = options_.sample_every * model_->opt.timestep;
        const size_t keep = static_cast<size_t>(
            std::max(1.0, std::round(std::max(0.0, options_.average_s) / sample_s)));
        while (recent.size() > keep) recent.pop_front();
        Vec6 mean = Vec6::Zero();
        for (const Vec6& x : recent) mean += x;
        mean /= static_cast<double>(recent.size());
        f = mean.head<3>();
        tau = mean.tail<3>();
      }
      int insert_action = -1;
      for (int i : inserting) {
        const auto& rs = plan_.actions[i].robots;
        if (std::find(rs.begin(), rs.end(), r) != rs.end()) insert_action = i;
      }
      const bool vacuum = scene_.robots[r].end_effector.kind == EndEffectorKind::kVacuum;
      const WrenchLimits& lim = limits_[r];
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
          const std::vector<int>& moved =
              tree_.nodes[plan_.actions[insert_action].objects[0]].parts;
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
        ctx_.Log("sim",
                 StrFormat("t %.4f %s u %.3f f %.2f %.2f %.2f tau %.3f %.3f %.3f", t,
                           scene_.robots[r].name.c_str(), u, f.x(), f.y(), f.z(), tau.x(), tau.y(),
                           tau.z()),
                 LogLevel::kTrace);
      }
      double& peak = vacuum ? (insert_action >= 0 ? report_.peak.vacuum_insertion
                                                  : report_.peak.vacuum_transport)
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
                   " limits (" + (split ? "in the best split of the load among its object's "
                                          "supports; its weld measured " : "") +
                   "force " + Num(f.x()) + ", " + Num(f.y()) + ", " + Num(f.z()) +
                   " N, torque " + Num(tau.x()) + ", " + Num(tau.y()) + ", " + Num(tau.z()) +
                   " N m in the grasp frame)",
               t);
        return;
      }
    }
    MeasureConnections();
    MeasureTable();
    // Every part where the plan has it.
    for (const auto& [node, o] : objects_) {
      const Iso3 X_WA = ExpectedX_WA(o);
      for (int p : tree_.nodes[node].parts) {
        const Iso3 expected = X_WA * scene_.parts[p].X_AP;
        const Iso3 actual = PartPose(p);
        const double dp = (actual.translation() - expected.translation()).norm();
        const double da = AngleOf(actual.linear().transpose() * expected.linear());
        if (dp > options_.drift_tolerance_m || da > options_.drift_tolerance_rad) {
          const int blamed = o.holders.empty() && o.last_action >= 0 ? o.last_action : current;
          Failed(blamed, "no support",
                 "'" + scene_.parts[p].name + "' is " + Num(1000 * dp) + " mm and " +
                     Num(da * 180 / M_PI) + " deg from where the plan has it" +
                     (o.holders.empty() ? " (nobody holds it)" : ""),
                 t);
          return;
        }
      }
    }
  }

  // The final assembly: every part against the assembly's relative poses.
  void CheckFinal(double t) {
    for (const auto& [node, o] : objects_) {
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

  Result<void> Loop() {
    const double dt = model_->opt.timestep;
    const double t_end = makespan_ + std::max(0.0, options_.settle_s);
    const long long n_steps = static_cast<long long>(std::ceil(t_end / dt));
    const int every = std::max(1, options_.sample_every);
    const double frame_dt = options_.frame_interval_s > 0.0 ? options_.frame_interval_s : 0.1;
    double next_frame_s = 0.0;
    for (long long k = 0; k < n_steps; ++k) {
      const double t = k * dt;
      if (options_.on_frame && t >= next_frame_s - 1e-9) {
        options_.on_frame(t, CurrentState(t));
        next_frame_s += frame_dt;
      }
      while (next_event_ < order_.size() && plan_.actions[order_[next_event_]].end_s <= t) {
        Event(order_[next_event_++], t);
        if (report_.failure) break;
      }
      if (report_.failure) break;
      SetTcps(t);
      FadeBeforeReleases(t);
      mju_zero(data_->xfrc_applied, 6 * model_->nbody);
      for (Vec6& w : mating_on_part_) w.setZero();
      ApplyFades(t);
      const std::vector<int> inserting = Insertions(t);
      for (int i : inserting) ApplyMating(i);
      mj_step(model_.get(), data_.get());
      report_.steps = k + 1;
      report_.simulated_s = t + dt;
      if (k % every == 0) {
        Measure(t, inserting);
        if (report_.failure) break;
        if (auto ok = CheckCollisions(t); !ok) return ok;
        if (report_.failure) break;
      }
      if (k % 1000 == 0 && ctx_.ShouldStop()) {
        return wrap::Fail(ErrorCode::kCancelled, "sim: stopped at t = " + Num(t) + " s");
      }
    }
    if (!report_.failure) CheckFinal(report_.simulated_s);
    if (options_.on_frame)
      options_.on_frame(report_.simulated_s, CurrentState(report_.simulated_s));
    return {};
  }

  const Project& project_;
  AssemblyGeometry geometry_;  // the parts' meshes: insertion overlaps
  const CellScene& scene_;
  const AssemblyTree& tree_;
  const Plan& plan_;
  const bool keyframes_;  // a keyframe replay (no motion in the plan)
  const SimOptions& options_;
  RunContext& ctx_;
  SimReport report_;
  struct Window {
    double t0 = 0.0, t1 = 0.0;
    std::vector<int> robots;
    std::vector<int> nodes;
    bool pair = false;  // the two nodes may touch each other too (an insertion)
    int step = -1;      // an insertion's step node: nodes[0] moves into nodes[1]
  };
  std::vector<Window> windows_;                      // contact windows, from the segments
  std::optional<detail::SimCollisions> collisions_;  // when collisions are judged
  bool collision_dirty_ = true;                      // an action happened since the last check
  std::vector<JointVector> checked_q_;               // at the last collision check
  std::vector<double> checked_openings_;
  std::vector<Iso3> checked_X_WP_;

  std::unique_ptr<mjModel, ModelDeleter> model_;
  std::unique_ptr<mjData, DataDeleter> data_;
  std::vector<int> tcp_mocap_;             // mocap index per robot
  std::vector<std::vector<int>> grip_eq_;  // [robot][part] weld id
  std::vector<std::vector<int>> join_eq_;  // [p][q] weld id, p < q
  std::vector<int> part_body_, part_dof_;  // per part
  std::vector<WrenchLimits> limits_;       // per robot
  std::vector<int> grip_part_;             // per robot, -1 free
  std::vector<PlanGrasp> grasp_;           // per robot, its current grasp
  std::vector<Vec3> hold_f_, hold_tau_;    // per robot, wrench when its insertion began
  std::vector<Vec3> prev_f_, prev_tau_;    // per robot, its last measured wrench
  std::vector<Fade> fades_;              // grippers being let go of
  std::vector<std::deque<Vec6>> recent_;  // per robot, its last measured wrenches (averaged)
  std::vector<Vec6> mating_on_part_;     // per part, the mating wrench applied now (about its COM)
  std::vector<bool> was_inserting_;      // per robot
  std::map<int, Interface> interfaces_;  // per assemble action
  struct Join {
    int eq = -1;      // weld id
    int part = -1;    // its body2
    int action = -1;  // the assemble that made it
  };
  std::vector<Join> joins_;        // connections made so far
  std::map<int, Object> objects_;  // by node id
  std::unique_ptr<LpBackend> lp_ = MakeDenseSimplexBackend();  // BestSplit's
  LpProblem lp_problem_;
  LpSolution lp_solution_;
  double split_at_ = -1.0;                                 // when split_ was computed
  std::map<int, std::optional<std::map<int, double>>> split_;  // BestSplit by node at split_at_
  std::vector<int> order_;         // actions by end_s
  size_t next_event_ = 0;
  double makespan_ = 0.0;
};

}  // namespace

Result<SimReport> SimulatePlan(const Project& project, const ProjectCheck& check,
                               const std::filesystem::path& project_file, const Plan& plan,
                               const SimOptions& options, RunContext& ctx) {
  InstallMujocoHandlers();
  auto bad = [](const std::string& m) { return Fail(ErrorCode::kInvalidInput, m); };
  if (!check.tree) return bad("sim: the project's assembly DAG is not well formed");
  if (!(options.timestep_s > 0.0 && options.timestep_s <= 0.01)) {
    return bad("sim: timestep must be in (0, 0.01] s");
  }
  if (!(options.force_scale >= 0.0) || !std::isfinite(options.force_scale)) {
    return bad("sim: force scale must be a finite number >= 0");
  }
  auto scene = BuildCellScene(project, check, project_file);
  if (!scene) return std::unexpected(scene.error());
  const AssemblyTree& tree = *check.tree;
  if (!(options.frame_interval_s > 0.0) || !std::isfinite(options.frame_interval_s)) {
    return bad("sim: the frame interval must be a positive number of seconds");
  }
  if (!(options.average_s >= 0.0) || !std::isfinite(options.average_s)) {
    return bad("sim: the averaging window must be a number of seconds >= 0");
  }
  // A plan without motion: its keyframes replayed one action at a time.
  std::optional<Plan> timed;
  std::vector<std::string> notes;
  if (plan.trajectories.empty()) {
    timed = plan;
    if (auto ok = detail::TimeKeyframes(*scene, tree, *timed, {}, notes); !ok) {
      return std::unexpected(ok.error());
    }
  }
  const Plan& run = timed ? *timed : plan;
  for (size_t k = 0; timed && k < run.segments.size() && ctx.Logs("sim"); ++k) {
    const MotionSegment& m = run.segments[k];
    ctx.Log("sim", StrFormat("segment: %s action %d robots %zu: %.3f - %.3f s", m.kind.c_str(),
                             m.action, m.robots.size(), m.start_s, m.end_s));
  }
  if (run.trajectories.size() != scene->robots.size()) {
    return bad("trajectories: " + std::to_string(run.trajectories.size()) +
               " trajectories for the cell's " + std::to_string(scene->robots.size()) +
               " robots (one per robot, or none for a keyframe replay)");
  }
  for (size_t r = 0; r < scene->robots.size(); ++r) {
    const RobotTrajectory& tr = run.trajectories[r];
    if (tr.knots.empty() || tr.knots.front().q.size() != scene->robots[r].chain.dof()) {
      return bad("trajectories[" + std::to_string(r) + "]: the trajectory of robot '" +
                 scene->robots[r].name + "' does not fit its " +
                 std::to_string(scene->robots[r].chain.dof()) + " joints");
    }
  }
  const int n_nodes = static_cast<int>(tree.nodes.size());
  for (size_t i = 0; i < run.actions.size(); ++i) {
    const PlanAction& a = run.actions[i];
    const std::string where = "actions[" + std::to_string(i) + "]: ";
    if (!(a.end_s >= 0.0)) return bad(where + "no timing (end_s); the plan has no motion");
    const size_t n_robots = a.type == ActionType::kHandover ? 2 : 1;
    if (a.robots.size() < n_robots || a.grasps.size() < n_robots) {
      return bad(where + "expected " + std::to_string(n_robots) + " robots with grasps");
    }
    for (int r : a.robots) {
      if (r < 0 || r >= static_cast<int>(scene->robots.size())) return bad(where + "bad robot");
    }
    const size_t n_objects = a.type == ActionType::kAssemble ? 3 : 1;
    if (a.objects.size() < n_objects) return bad(where + "too few objects");
    for (int o : a.objects) {
      if (o < 0 || o >= n_nodes) return bad(where + "object is not a node of the assembly");
    }
    if (a.type == ActionType::kAssemble && tree.nodes[a.objects[2]].step < 0) {
      return bad(where + "the assembled object is not a step");
    }
  }
  std::vector<int> seen(scene->parts.size(), 0);
  for (const PlanObject& o : run.initial.objects) {
    if (o.node < 0 || o.node >= n_nodes) return bad("initial: object is not a node");
    for (int p : tree.nodes[o.node].parts) ++seen[p];
  }
  for (size_t p = 0; p < seen.size(); ++p) {
    if (seen[p] != 1) return bad("initial: part '" + scene->parts[p].name + "' is not placed once");
  }
  Simulator sim(project, check, *scene, tree, run, timed.has_value(), options, ctx);
  auto report = sim.Run();
  if (report) {
    for (std::string& n : notes) report->notes.push_back(std::move(n));
    if (timed) {
      report->notes.insert(report->notes.begin(),
                           "the plan has no motion: its keyframes were replayed one action at a "
                           "time, straight in joint space (collisions not judged)");
    }
  }
  return report;
}

}  // namespace wrap
