// The driver of the physics run (see simulate.h and detail/simulator.h): SimulatePlan checks the
// plan against the cell, the Simulator builds the MuJoCo model and steps it through the plan,
// driving the robots' TCPs along their trajectories and letting each action happen at its moment.
#include "verify/simulate.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "robot/kinematics.h"
#include "sim/mjcf.h"
#include "sim/mujoco_model.h"
#include "sim/scene.h"
#include "verify/detail/keyframe_replay.h"
#include "verify/detail/simulator.h"

namespace wrap {

namespace detail {

double AngleOf(const Mat3& R) { return std::abs(Eigen::AngleAxisd(R).angle()); }

std::string Num(double v, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

Simulator::Simulator(const Project& project, const ProjectCheck& check, const CellScene& scene,
                     const AssemblyTree& tree, const Plan& plan, bool keyframes,
                     const SimOptions& options, RunContext& ctx)
    : project_(project),
      geometry_(AssemblyGeometry::FromProject(project, check)),
      scene_(scene),
      tree_(tree),
      plan_(plan),
      keyframes_(keyframes),
      options_(options),
      ctx_(ctx) {}

Result<SimReport> Simulator::Run() {
  if (auto ok = Setup(); !ok) return std::unexpected(ok.error());
  Result<void> cancelled;
  auto guarded = RunGuarded("simulating the plan", [&] { cancelled = Loop(); });
  if (!guarded) return std::unexpected(guarded.error());
  if (!cancelled) return std::unexpected(cancelled.error());
  for (std::string& w : TakeMujocoWarnings()) report_.warnings.push_back("MuJoCo: " + w);
  report_.success = !report_.failure.has_value();
  return std::move(report_);
}

Result<void> Simulator::Setup() {
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
  state_ = InitialPlanState(plan_.initial, nr);
  for (const PlanObject& o : plan_.initial.objects) {
    for (int p : tree_.nodes[o.node].parts) state.X_WP[p] = o.X_WA * scene_.parts[p].X_AP;
  }
  if (auto ok = BuildModel(state); !ok) return ok;
  PrepareActions();
  report_.motion = keyframes_ ? "keyframes" : "trajectories";
  report_.collisions_judged = options_.check_collisions && !keyframes_;
  if (report_.collisions_judged) {
    auto judge = SimCollisions::Build(scene_, options_.collision_tolerance_m);
    if (!judge) return std::unexpected(judge.error());
    collisions_.emplace(std::move(*judge));
    ContactWindows();
  }
  SetTcps(0.0);
  mj_forward(model_.get(), data_.get());
  SwitchSupports();
  return {};
}

// The physics model of the cell with the parts at `state`: our own copy, since welds are switched
// on and retargeted in the model (eq_active, eq_data).
Result<void> Simulator::BuildModel(const SceneState& state) {
  MjcfOptions mo;
  mo.physics = true;
  mo.timestep_s = options_.timestep_s;
  mo.shadows = false;
  support_sets_ = RestingSupportSets(scene_, tree_, plan_);
  for (const std::vector<SupportSet>& sets : support_sets_) {
    mo.support_points_P.emplace_back();
    for (const SupportSet& s : sets) {
      mo.support_points_P.back().insert(mo.support_points_P.back().end(), s.centres_P.begin(),
                                        s.centres_P.end());
    }
  }
  auto doc = BuildCellMjcf(scene_, state, mo);
  if (!doc) return std::unexpected(doc.error());
  for (const std::string& w : doc->warnings) report_.warnings.push_back(w);
  if (!options_.mjcf_dir.empty()) {
    if (auto ok = WriteMjcf(*doc, options_.mjcf_dir); !ok) return ok;
  }
  auto cell = CellModel::Compile(*doc);
  if (!cell) return std::unexpected(cell.error());
  auto guarded = RunGuarded("preparing the physics model", [&] {
    model_.reset(mj_copyModel(nullptr, cell->model()));
    data_.reset(mj_makeData(model_.get()));
  });
  if (!guarded) return std::unexpected(guarded.error());
  if (auto ok = cell->Apply(state, data_.get()); !ok) return ok;
  return FindBodies(*doc);
}

// The model's ids of the robots' TCP mocap bodies, the parts' bodies and the welds.
Result<void> Simulator::FindBodies(const MjcfDocument& doc) {
  const int nr = static_cast<int>(scene_.robots.size());
  const int np = static_cast<int>(scene_.parts.size());
  const mjModel* m = model_.get();
  for (int r = 0; r < nr; ++r) {
    const int body = mj_name2id(m, mjOBJ_BODY, doc.tcp_bodies[r].c_str());
    if (body < 0 || m->body_mocapid[body] < 0) {
      return Fail(ErrorCode::kInternal, "sim: no TCP mocap body for robot " + std::to_string(r));
    }
    tcp_mocap_.push_back(m->body_mocapid[body]);
    std::vector<int> ids;
    for (int p = 0; p < np; ++p) {
      ids.push_back(mj_name2id(m, mjOBJ_EQUALITY, doc.grip_welds[r][p].c_str()));
    }
    grip_eq_.push_back(std::move(ids));
  }
  join_eq_.assign(np, std::vector<int>(np, -1));
  for (int p = 0; p < np; ++p) {
    part_body_.push_back(mj_name2id(m, mjOBJ_BODY, doc.part_bodies[p].c_str()));
    part_dof_.push_back(m->jnt_dofadr[m->body_jntadr[part_body_.back()]]);
    for (int q = p + 1; q < np; ++q) {
      join_eq_[p][q] = mj_name2id(m, mjOBJ_EQUALITY, doc.join_welds[p][q].c_str());
    }
  }
  // The support spheres, in the order of support_sets_ (BuildModel wrote them so).
  supports_.assign(np, {});
  for (int p = 0; p < np && p < static_cast<int>(support_sets_.size()); ++p) {
    size_t k = 0;
    for (const SupportSet& s : support_sets_[p]) {
      SupportGeoms geoms{s.up_P, {}};
      for (size_t i = 0; i < s.centres_P.size(); ++i, ++k) {
        const int g = k < doc.support_geoms[p].size()
                          ? mj_name2id(m, mjOBJ_GEOM, doc.support_geoms[p][k].c_str())
                          : -1;
        if (g < 0) {
          return Fail(ErrorCode::kInternal, "sim: no support sphere " + std::to_string(k) +
                                                " for part '" + scene_.parts[p].name + "'");
        }
        geoms.geoms.push_back(g);
      }
      supports_[p].push_back(std::move(geoms));
    }
  }
  return {};
}

// Limits, per-robot measurement state, the steps' interfaces, the actions in time order and the
// makespan.
void Simulator::PrepareActions() {
  const int nr = static_cast<int>(scene_.robots.size());
  const int np = static_cast<int>(scene_.parts.size());
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
}

// The action running at `t`: the first (in time order) whose moment has not passed.
int Simulator::CurrentAction() const {
  if (next_event_ < order_.size()) return order_[next_event_];
  return order_.empty() ? -1 : order_.back();
}

Iso3 Simulator::Tcp(int r, double t) const {
  const SceneRobot& robot = scene_.robots[r];
  return TcpPose(robot.chain, robot.X_WB, SampleTrajectory(plan_.trajectories[r], t),
                 robot.end_effector.X_FT);
}

void Simulator::SetTcps(double t) {
  std::vector<Iso3> X_WT(tcp_mocap_.size());
  for (size_t r = 0; r < tcp_mocap_.size(); ++r) X_WT[r] = Tcp(static_cast<int>(r), t);
  if (keyframes_) {
    // Keyframes are joined straight in joint space, which would pull apart the grippers of a
    // shared object: its other holders follow the first one's TCP at their grasps.
    for (const auto& [node, o] : state_.objects) {
      const std::vector<int> holders = state_.Holders(node);
      if (holders.size() < 2) continue;
      const int c = holders.front();
      const Iso3 X_WA = X_WT[c] * (scene_.parts[grasp_[c].part].X_AP * grasp_[c].X_PG).inverse();
      for (size_t k = 1; k < holders.size(); ++k) {
        const PlanGrasp& g = grasp_[holders[k]];
        X_WT[holders[k]] = X_WA * scene_.parts[g.part].X_AP * g.X_PG;
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

Iso3 Simulator::BodyPose(int body) const {
  Iso3 X = Iso3::Identity();
  const mjtNum* p = data_->xpos + 3 * body;
  const mjtNum* q = data_->xquat + 4 * body;
  X.translation() = Vec3(p[0], p[1], p[2]);
  X.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  return X;
}

Iso3 Simulator::TcpBodyPose(int r) const {
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

// The object (node) part p belongs to now, or -1.
int Simulator::NodeOfPart(int p) const {
  for (const auto& [node, o] : state_.objects) {
    const std::vector<int>& ps = tree_.nodes[node].parts;
    if (std::find(ps.begin(), ps.end(), p) != ps.end()) return node;
  }
  return -1;
}

Iso3 Simulator::CarriedX_WA(int r) const {
  const PlanGrasp& g = grasp_[r];
  return TcpBodyPose(r) * (scene_.parts[g.part].X_AP * g.X_PG).inverse();
}

Iso3 Simulator::ExpectedX_WA(int node, const PlanObject& o) const {
  const std::vector<int> holders = state_.Holders(node);
  if (holders.empty()) return o.X_WA;
  return CarriedX_WA(holders.front());
}

void Simulator::Failed(int action, const std::string& reason, const std::string& detail, double t) {
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

// The robots where they are driven and the parts where MuJoCo has them.
SceneState Simulator::CurrentState(double t) const {
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

Result<void> Simulator::Loop() {
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
    SwitchSupports();
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
  if (options_.on_frame) options_.on_frame(report_.simulated_s, CurrentState(report_.simulated_s));
  return {};
}

}  // namespace detail

namespace {

// The timed plan `run` fits the cell: one trajectory per robot with its joints, actions with
// their times, robots, grasps and objects, every part placed once at the start. Fails with
// kInvalidInput naming the plan's JSON path.
Result<void> CheckRunFitsCell(const CellScene& scene, const AssemblyTree& tree, const Plan& run) {
  auto bad = [](const std::string& m) { return Fail(ErrorCode::kInvalidInput, m); };
  if (run.trajectories.size() != scene.robots.size()) {
    return bad("trajectories: " + std::to_string(run.trajectories.size()) +
               " trajectories for the cell's " + std::to_string(scene.robots.size()) +
               " robots (one per robot, or none for a keyframe replay)");
  }
  for (size_t r = 0; r < scene.robots.size(); ++r) {
    const RobotTrajectory& tr = run.trajectories[r];
    if (tr.knots.empty() || tr.knots.front().q.size() != scene.robots[r].chain.dof()) {
      return bad("trajectories[" + std::to_string(r) + "]: the trajectory of robot '" +
                 scene.robots[r].name + "' does not fit its " +
                 std::to_string(scene.robots[r].chain.dof()) + " joints");
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
      if (r < 0 || r >= static_cast<int>(scene.robots.size())) return bad(where + "bad robot");
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
  std::vector<int> seen(scene.parts.size(), 0);
  for (const PlanObject& o : run.initial.objects) {
    if (o.node < 0 || o.node >= n_nodes) return bad("initial: object is not a node");
    for (int p : tree.nodes[o.node].parts) ++seen[p];
  }
  for (size_t p = 0; p < seen.size(); ++p) {
    if (seen[p] != 1) return bad("initial: part '" + scene.parts[p].name + "' is not placed once");
  }
  return {};
}

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
  if (auto ok = CheckRunFitsCell(*scene, tree, run); !ok) return std::unexpected(ok.error());
  detail::Simulator sim(project, check, *scene, tree, run, timed.has_value(), options, ctx);
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
