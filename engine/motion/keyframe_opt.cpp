// Joint keyframe optimisation: stages, IK candidates, a collision cell per finger opening, a
// Viterbi pass per robot and coordinate descent over the robots (see keyframe_opt.h).
#include "motion/keyframe_opt.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "robot/catalog.h"
#include "robot/cell.h"
#include "robot/ik.h"
#include "robot/kinematics.h"
#include "task/plan_state.h"

namespace wrap {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;
// Joints equal within this are one stage (the plan validator's joint tolerance).
constexpr double kSameJoints = 1e-6;
// A candidate's TCP lies this close to the stage's TCP pose.
constexpr double kTcpPositionTolerance = 1e-4;  // [m]
constexpr double kTcpRotationTolerance = 1e-3;  // [rad]
// Candidates closer than this in every joint are one.
constexpr double kDuplicateJoints = 1e-6;
// Fingers of a two-finger gripper stand this far off each side of the held grasp's width (as
// the planner and the validator open them).
constexpr double kFingerClearanceM = 1e-3;
// An objective must drop by more than this for a robot's new chain to be kept.
constexpr double kImprovement = 1e-9;

// One keyframe of the sequence and what holds what at it.
struct KeyframeInfo {
  Keyframe* kf = nullptr;
  int action = -1;                          // -1: the initial keyframe
  bool approach = false;                    // an assemble's approach
  std::vector<int> held_part;               // per robot: the part it holds here, -1 none
  std::vector<double> opening;              // per robot: finger opening [m], -1 the default shapes
  std::vector<std::pair<int, Iso3>> parts;  // every part present and its pose X_WP
  int cell = -1;                            // index of the cell with these openings
};

// A candidate configuration of a stage.
struct Candidate {
  JointVector q;
  int branch = -1;
};

// A run of keyframes over which a robot keeps its joints.
struct Stage {
  std::vector<int> keyframes;         // indices into the sequence, consecutive
  bool fixed = false;                 // initial or home: only the current configuration
  std::vector<Candidate> candidates;  // [0] the current configuration
};

// Per robot: what the plan holds and what the optimiser chose.
struct RobotStages {
  std::vector<Stage> stages;
  std::vector<int> choice;  // per stage: index into its candidates
};

double RotationAngle(const Iso3& a, const Iso3& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

std::uint64_t Mix(std::uint64_t x) {  // splitmix64's finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

class Optimizer {
 public:
  Optimizer(const TaskWorld& world, Plan& plan, const KeyframeOptOptions& options, RunContext& ctx)
      : world_(world),
        plan_(plan),
        options_(options),
        ctx_(ctx),
        n_robots_(static_cast<int>(world.robots.size())) {}

  Result<KeyframeOptReport> Run();

 private:
  Result<void> CheckPlan() const;
  Result<void> BuildSequence();
  Result<int> CellFor(const std::vector<double>& opening);
  void BuildStages();
  void GenerateCandidates(int robot, int stage_index, std::uint64_t seed);
  int BranchOf(int robot, const JointVector& q) const;

  const JointVector& Chosen(int robot, int keyframe) const {
    const RobotStages& rs = robots_[robot];
    const int s = stage_of_[robot][keyframe];
    return rs.stages[s].candidates[rs.choice[s]].q;
  }
  // Puts the cell of keyframe k into its state with every robot at its chosen configuration.
  Cell& Setup(int k);
  void SetRobot(Cell& cell, int robot, const JointVector& q);
  bool RobotCollides(Cell& cell, int robot);
  double RobotClearance(Cell& cell, int robot, double upper_bound);

  double Transition(int robot, int stage_a, const Candidate& a, const Candidate& b) const;
  // The objective with the current choices; fills the smallest robot-robot clearance when given.
  double Objective();
  double SmallestClearance();
  void Metrics(int* branch_changes, double* joint_motion) const;
  // The Viterbi-optimal chain of one robot against the others' current choices.
  std::vector<int> BestChain(int robot);

  const TaskWorld& world_;
  Plan& plan_;
  const KeyframeOptOptions& options_;
  RunContext& ctx_;
  const int n_robots_;

  std::vector<KeyframeInfo> sequence_;
  std::vector<std::vector<int>> stage_of_;  // per robot, per keyframe: its stage
  std::vector<RobotStages> robots_;
  std::map<std::vector<long long>, int> cell_index_;
  std::vector<Cell> cells_;
  std::vector<Iso3> frames_;
  CollisionResult collision_result_;
  int candidates_ = 0;
};

Result<void> Optimizer::CheckPlan() const {
  const int n_parts = world_.num_parts;
  const int n_nodes = world_.num_nodes;
  auto bad = [](const std::string& what) -> Result<void> {
    return Fail(ErrorCode::kInvalidInput, "keyframe optimisation: " + what);
  };
  auto check_kf = [&](const Keyframe& kf, const std::string& where) -> Result<void> {
    if (static_cast<int>(kf.q.size()) != n_robots_) {
      return bad(where + " has " + std::to_string(kf.q.size()) + " joint vectors for " +
                 std::to_string(n_robots_) + " robots");
    }
    for (int r = 0; r < n_robots_; ++r) {
      if (kf.q[r].size() != world_.robots[r].chain.dof()) {
        return bad(where + ": robot '" + world_.robots[r].name + "' has " +
                   std::to_string(kf.q[r].size()) + " joints, its chain " +
                   std::to_string(world_.robots[r].chain.dof()));
      }
    }
    for (const PlanObject& o : kf.objects) {
      if (o.node < 0 || o.node >= n_nodes) {
        return bad(where + ": object node " + std::to_string(o.node) + " out of range");
      }
    }
    return {};
  };
  if (world_.tree == nullptr) return bad("the world has no assembly tree");
  if (auto ok = check_kf(plan_.initial, "the initial keyframe"); !ok) return ok;
  for (size_t i = 0; i < plan_.actions.size(); ++i) {
    const PlanAction& a = plan_.actions[i];
    const std::string where = "action " + std::to_string(i);
    if (auto ok = check_kf(a.keyframe, where); !ok) return ok;
    if (a.approach) {
      if (auto ok = check_kf(*a.approach, where + " (approach)"); !ok) return ok;
    }
    for (int r : a.robots) {
      if (r < 0 || r >= n_robots_) return bad(where + ": robot " + std::to_string(r));
    }
    for (int o : a.objects) {
      if (o < 0 || o >= n_nodes) return bad(where + ": node " + std::to_string(o));
    }
    for (const PlanHold& h : a.grasps) {
      if (h.robot < 0 || h.robot >= n_robots_ || h.grasp.part < 0 || h.grasp.part >= n_parts) {
        return bad(where + ": a grasp names robot " + std::to_string(h.robot) + ", part " +
                   std::to_string(h.grasp.part));
      }
    }
    if (a.objects.empty() || (a.type == ActionType::kAssemble && a.objects.size() != 3) ||
        a.robots.empty()) {
      return bad(where + " (" + std::string(ToString(a.type)) + ") is malformed");
    }
  }
  return {};
}

Result<int> Optimizer::CellFor(const std::vector<double>& opening) {
  std::vector<long long> key;
  for (double o : opening) key.push_back(o < 0.0 ? -1 : std::llround(o * 1e5));
  if (auto it = cell_index_.find(key); it != cell_index_.end()) return it->second;
  CellDef def = world_.cell_def;
  for (int r = 0; r < n_robots_; ++r) {
    const EndEffector& ee = world_.robots[r].end_effector;
    def.robots[r].end_effector.collision =
        opening[r] < 0.0 ? ee.collision : EndEffectorShapesAt(ee, opening[r]);
  }
  auto cell = Cell::Build(def);
  if (!cell) {
    return Fail(
        ErrorCode::kInternal,
        "keyframe optimisation: the collision cell could not be built: " + cell.error().message);
  }
  // Objects and the table keep their poses whatever the joints: their pairs are left out.
  cell->world().SetGroupPairAllowed(kCellObjectGroup, kCellObjectGroup, true);
  cell->world().SetGroupPairAllowed(kCellObjectGroup, kCellTableGroup, true);
  cells_.push_back(std::move(*cell));
  const int index = static_cast<int>(cells_.size()) - 1;
  cell_index_.emplace(std::move(key), index);
  return index;
}

Result<void> Optimizer::BuildSequence() {
  auto add = [&](Keyframe* kf, int action, bool approach, const PlanState& at) -> Result<void> {
    KeyframeInfo info;
    info.kf = kf;
    info.action = action;
    info.approach = approach;
    info.held_part.assign(n_robots_, -1);
    info.opening.assign(n_robots_, -1.0);
    for (int r = 0; r < n_robots_; ++r) {
      if (at.held[r] < 0) continue;
      info.held_part[r] = at.grasp[r].part;
      if (world_.robots[r].end_effector.kind == EndEffectorKind::kTwoFinger) {
        info.opening[r] = at.grasp[r].width_m + 2.0 * kFingerClearanceM;
      }
    }
    for (const PlanObject& o : kf->objects) {
      for (int p : world_.tree->nodes[o.node].parts) {
        info.parts.emplace_back(p, o.X_WA * world_.X_AP[p]);
      }
    }
    auto cell = CellFor(info.opening);
    if (!cell) return std::unexpected(cell.error());
    info.cell = *cell;
    sequence_.push_back(std::move(info));
    return {};
  };
  PlanState state = InitialPlanState(plan_.initial, n_robots_);
  if (auto ok = add(&plan_.initial, -1, false, state); !ok) return ok;
  for (size_t i = 0; i < plan_.actions.size(); ++i) {
    PlanAction& a = plan_.actions[i];
    // Who holds what at the approach and the keyframe: the grasps the action closes are closed.
    const PlanState at = StateAtKeyframe(state, a);
    if (a.approach) {
      if (auto ok = add(&*a.approach, static_cast<int>(i), true, at); !ok) return ok;
    }
    if (auto ok = add(&a.keyframe, static_cast<int>(i), false, at); !ok) return ok;
    state = ApplyAction(state, a);
  }
  return {};
}

int Optimizer::BranchOf(int robot, const JointVector& q) const {
  const TaskRobot& tr = world_.robots[robot];
  if (tr.ur) {
    return tr.ur->BranchOf(tr.chain, q);
  }
  int branch = 0;
  const int dof = tr.chain.dof();
  int bit = 0;
  for (int j = 1; j <= 5; j += 2, ++bit) {
    if (j < dof && q[j] < 0.0) branch |= 1 << bit;
  }
  return branch;
}

void Optimizer::BuildStages() {
  const int n_kf = static_cast<int>(sequence_.size());
  robots_.resize(n_robots_);
  stage_of_.assign(n_robots_, std::vector<int>(n_kf, -1));
  for (int r = 0; r < n_robots_; ++r) {
    const TaskRobot& tr = world_.robots[r];
    RobotStages& rs = robots_[r];
    for (int k = 0; k < n_kf; ++k) {
      const JointVector& q = sequence_[k].kf->q[r];
      const bool same =
          k > 0 && JointDistanceMax(tr.chain, q, sequence_[k - 1].kf->q[r], false) <= kSameJoints;
      if (!same) {
        Stage stage;
        stage.candidates.push_back({q, BranchOf(r, q)});
        stage.fixed = k == 0 || (tr.home.size() == q.size() &&
                                 JointDistanceMax(tr.chain, q, tr.home, false) <= kSameJoints);
        rs.stages.push_back(std::move(stage));
      }
      rs.stages.back().keyframes.push_back(k);
      stage_of_[r][k] = static_cast<int>(rs.stages.size()) - 1;
    }
    rs.choice.assign(rs.stages.size(), 0);
  }
}

void Optimizer::GenerateCandidates(int robot, int stage_index, std::uint64_t seed) {
  const TaskRobot& tr = world_.robots[robot];
  Stage& stage = robots_[robot].stages[stage_index];
  const JointVector q0 = stage.candidates[0].q;
  const Iso3 X_WT0 = TcpPose(tr.chain, tr.X_WB, q0, tr.end_effector.X_FT);
  const Iso3 X_BT0 = tr.X_BW * X_WT0;

  std::vector<JointVector> solutions = {q0};
  if (tr.ur) {
    UrIkOptions ik_options;
    ik_options.q6_if_singular = q0[5];
    const UrIkSolutions s = tr.ur->SolveTcp(X_BT0, tr.end_effector.X_FT, ik_options);
    for (int i = 0; i < s.count; ++i) solutions.push_back(NearestEquivalent(tr.chain, s.q[i], q0));
  } else {
    NumericIkRequest request;
    request.X_BT = X_BT0;
    request.X_FT = tr.end_effector.X_FT;
    request.seeds = {q0};
    request.reference = q0;
    NumericIkOptions ik_options;
    ik_options.all_branches = true;
    ik_options.restarts = std::max(0, options_.numeric_candidates);
    std::mt19937_64 rng(seed);
    if (auto result = SolveNumericIk(tr.chain, request, rng, ik_options)) {
      solutions.insert(solutions.end(), result->branches.begin(), result->branches.end());
    }
  }
  // Each solution also as the 2 pi equivalents nearest the neighbouring stages and home: the
  // wrist joints of a UR arm turn +-2 pi, and the nearest way to the next stage may be around.
  std::vector<JointVector> references = {q0};
  const std::vector<Stage>& stages = robots_[robot].stages;
  if (stage_index > 0) references.push_back(stages[stage_index - 1].candidates[0].q);
  if (stage_index + 1 < static_cast<int>(stages.size())) {
    references.push_back(stages[stage_index + 1].candidates[0].q);
  }
  if (tr.home.size() == q0.size()) references.push_back(tr.home);
  std::vector<JointVector> variants;
  for (const JointVector& q : solutions) {
    for (const JointVector& reference : references) {
      variants.push_back(NearestEquivalent(tr.chain, q, reference));
    }
  }
  for (const JointVector& q : variants) {
    if (q.size() != q0.size() || !WithinLimits(tr.chain, q)) continue;
    const Iso3 X_WT = TcpPose(tr.chain, tr.X_WB, q, tr.end_effector.X_FT);
    if ((X_WT.translation() - X_WT0.translation()).norm() > kTcpPositionTolerance ||
        RotationAngle(X_WT, X_WT0) > kTcpRotationTolerance) {
      continue;
    }
    const bool duplicate =
        std::any_of(stage.candidates.begin(), stage.candidates.end(), [&](const Candidate& c) {
          return JointDistanceMax(tr.chain, c.q, q, false) <= kDuplicateJoints;
        });
    if (!duplicate) stage.candidates.push_back({q, BranchOf(robot, q)});
  }
  candidates_ += static_cast<int>(stage.candidates.size());
}

void Optimizer::SetRobot(Cell& cell, int robot, const JointVector& q) {
  const Chain& chain = world_.robots[robot].chain;
  frames_.resize(chain.links.size());
  ForwardKinematics(chain, world_.robots[robot].X_WB, q, frames_);
  cell.SetConfiguration(robot, std::span<const double>(q.data(), q.size()), frames_);
}

Cell& Optimizer::Setup(int k) {
  const KeyframeInfo& info = sequence_[k];
  Cell& cell = cells_[info.cell];
  for (int r = 0; r < n_robots_; ++r) SetRobot(cell, r, Chosen(r, k));
  std::vector<char> present(cell.num_objects(), 0);
  for (const auto& [p, X_WP] : info.parts) {
    present[p] = 1;
    cell.SetObjectPose(p, X_WP);
  }
  CollisionWorld& w = cell.world();
  for (int p = 0; p < cell.num_objects(); ++p) {
    cell.SetObjectEnabled(p, present[p] != 0);
    for (int r = 0; r < n_robots_; ++r) {
      w.SetAllowed(cell.object_body(p), cell.end_effector_body(r), info.held_part[r] == p);
    }
  }
  return cell;
}

bool Optimizer::RobotCollides(Cell& cell, int robot) {
  CollisionRequest request;
  request.group_mask = (std::uint64_t{1} << CellLinkGroup(robot)) |
                       (std::uint64_t{1} << CellEndEffectorGroup(robot));
  collision_result_.Clear();
  return cell.InCollision(&collision_result_, request);
}

double Optimizer::RobotClearance(Cell& cell, int robot, double upper_bound) {
  if (n_robots_ < 2) return kInf;
  GroupPairSet pairs;
  for (int s = 0; s < n_robots_; ++s) {
    if (s == robot) continue;
    for (int g : {CellLinkGroup(robot), CellEndEffectorGroup(robot)}) {
      pairs.Add(g, CellLinkGroup(s));
      pairs.Add(g, CellEndEffectorGroup(s));
    }
  }
  DistanceRequest request;
  request.nearest_points = false;
  request.upper_bound_m = upper_bound;
  return cell.world().MinDistance(pairs, request).distance;
}

double Optimizer::Transition(int robot, int stage_a, const Candidate& a, const Candidate& b) const {
  const RobotStages& rs = robots_[robot];
  const int k_a = rs.stages[stage_a].keyframes.back();
  const int k_b = rs.stages[stage_a + 1].keyframes.front();
  // The insertion from an assemble's approach to its keyframe is a short straight move: it keeps
  // the branch and turns no joint by more than pi (unless the plan already does so there).
  const bool insertion = sequence_[k_a].approach && sequence_[k_b].action == sequence_[k_a].action;
  if (insertion) {
    auto continuous = [](const Candidate& x, const Candidate& y) {
      return x.branch == y.branch && (x.q - y.q).cwiseAbs().maxCoeff() <= kPi;
    };
    if (!continuous(a, b) &&
        continuous(rs.stages[stage_a].candidates[0], rs.stages[stage_a + 1].candidates[0])) {
      return kInf;
    }
  }
  double cost = a.branch != b.branch ? options_.branch_change_cost : 0.0;
  cost += options_.joint_motion_weight * (a.q - b.q).cwiseAbs().sum();
  return cost;
}

double Optimizer::Objective() {
  const int n_kf = static_cast<int>(sequence_.size());
  const double cap = options_.clearance_cap_m;
  // Per robot, per keyframe: its clearance to the others, capped.
  std::vector<std::vector<double>> clearance(n_robots_, std::vector<double>(n_kf, cap));
  if (n_robots_ >= 2 && cap > 0.0) {
    for (int k = 0; k < n_kf; ++k) {
      Cell& cell = Setup(k);
      for (int r = 0; r < n_robots_; ++r) {
        clearance[r][k] = std::min(cap, RobotClearance(cell, r, cap));
      }
    }
  }
  double cost = 0.0;
  for (int r = 0; r < n_robots_; ++r) {
    const RobotStages& rs = robots_[r];
    for (size_t s = 0; s < rs.stages.size(); ++s) {
      double c = cap;
      for (int k : rs.stages[s].keyframes) c = std::min(c, clearance[r][k]);
      cost -= options_.clearance_weight * std::max(0.0, c);
      if (s + 1 < rs.stages.size()) {
        cost += Transition(r, static_cast<int>(s), rs.stages[s].candidates[rs.choice[s]],
                           rs.stages[s + 1].candidates[rs.choice[s + 1]]);
      }
    }
  }
  return cost;
}

double Optimizer::SmallestClearance() {
  if (n_robots_ < 2) return kInf;
  double smallest = kInf;
  DistanceRequest request;
  request.nearest_points = false;
  for (int k = 0; k < static_cast<int>(sequence_.size()); ++k) {
    smallest = std::min(smallest, Setup(k).MinRobotClearance(request).distance);
  }
  return smallest;
}

void Optimizer::Metrics(int* branch_changes, double* joint_motion) const {
  *branch_changes = 0;
  *joint_motion = 0.0;
  for (int r = 0; r < n_robots_; ++r) {
    const RobotStages& rs = robots_[r];
    for (size_t s = 0; s + 1 < rs.stages.size(); ++s) {
      const Candidate& a = rs.stages[s].candidates[rs.choice[s]];
      const Candidate& b = rs.stages[s + 1].candidates[rs.choice[s + 1]];
      if (a.branch != b.branch) ++*branch_changes;
      *joint_motion += (a.q - b.q).cwiseAbs().sum();
    }
  }
}

std::vector<int> Optimizer::BestChain(int robot) {
  RobotStages& rs = robots_[robot];
  const int n = static_cast<int>(rs.stages.size());
  const double cap = options_.clearance_cap_m;
  const double bound = std::max(cap, options_.min_clearance_m) + 1e-3;
  // Node costs: -weight * min(clearance, cap); +inf for an invalid candidate.
  std::vector<std::vector<double>> node(n);
  for (int s = 0; s < n; ++s) {
    const Stage& stage = rs.stages[s];
    const int m = static_cast<int>(stage.candidates.size());
    std::vector<double> clearance(m, kInf);
    std::vector<char> valid(m, 1);
    for (int k : stage.keyframes) {
      Cell& cell = Setup(k);
      for (int c = 0; c < m; ++c) {
        if (!valid[c]) continue;
        SetRobot(cell, robot, stage.candidates[c].q);
        if (c > 0 && RobotCollides(cell, robot)) {
          valid[c] = 0;
          continue;
        }
        const double d = RobotClearance(cell, robot, bound);
        if (c > 0 && d < options_.min_clearance_m) {
          valid[c] = 0;
          continue;
        }
        clearance[c] = std::min(clearance[c], d);
      }
    }
    node[s].resize(m);
    for (int c = 0; c < m; ++c) {
      node[s][c] =
          valid[c] ? -options_.clearance_weight * std::max(0.0, std::min(clearance[c], cap)) : kInf;
    }
  }
  // Viterbi: best[s][c] the cheapest chain ending with candidate c at stage s.
  std::vector<std::vector<double>> best(n);
  std::vector<std::vector<int>> from(n);
  best[0] = node[0];
  from[0].assign(node[0].size(), -1);
  for (int s = 1; s < n; ++s) {
    const int m = static_cast<int>(node[s].size());
    best[s].assign(m, kInf);
    from[s].assign(m, -1);
    for (int c = 0; c < m; ++c) {
      if (node[s][c] == kInf) continue;
      for (size_t p = 0; p < best[s - 1].size(); ++p) {
        if (best[s - 1][p] == kInf) continue;
        const double t =
            Transition(robot, s - 1, rs.stages[s - 1].candidates[p], rs.stages[s].candidates[c]);
        const double v = best[s - 1][p] + t + node[s][c];
        if (v < best[s][c] - 1e-12) {
          best[s][c] = v;
          from[s][c] = static_cast<int>(p);
        }
      }
    }
  }
  std::vector<int> chain = rs.choice;
  int c = -1;
  double v = kInf;
  for (size_t i = 0; i < best[n - 1].size(); ++i) {
    if (best[n - 1][i] < v - 1e-12) {
      v = best[n - 1][i];
      c = static_cast<int>(i);
    }
  }
  if (c < 0) return chain;  // no feasible chain (cannot happen: the current one is)
  for (int s = n - 1; s >= 0; --s) {
    chain[s] = c;
    c = from[s][c];
    if (c < 0 && s > 0) return rs.choice;
  }
  return chain;
}

Result<KeyframeOptReport> Optimizer::Run() {
  if (auto ok = CheckPlan(); !ok) return std::unexpected(ok.error());
  if (ctx_.cancelled()) return Fail(ErrorCode::kCancelled, "keyframe optimisation: cancelled");
  if (auto ok = BuildSequence(); !ok) return std::unexpected(ok.error());
  BuildStages();

  KeyframeOptReport report;
  const std::uint64_t base_seed = ctx_.rng()();
  for (int r = 0; r < n_robots_; ++r) {
    if (ctx_.cancelled()) return Fail(ErrorCode::kCancelled, "keyframe optimisation: cancelled");
    RobotStages& rs = robots_[r];
    for (int s = 0; s < static_cast<int>(rs.stages.size()); ++s) {
      if (rs.stages[s].fixed) continue;
      ++report.stages;
      if (ctx_.timed_out()) continue;  // past the deadline: the current configuration only
      const std::uint64_t seed =
          Mix(base_seed ^ Mix((static_cast<std::uint64_t>(r) << 32) |
                              static_cast<std::uint64_t>(rs.stages[s].keyframes.front())));
      GenerateCandidates(r, s, seed);
    }
  }
  report.candidates = candidates_;

  Metrics(&report.branch_changes_before, &report.joint_motion_before);
  report.min_clearance_before_m = SmallestClearance();
  double cost = Objective();
  report.cost_before = cost;

  bool stop = false;
  for (int sweep = 0; sweep < options_.sweeps && !stop; ++sweep) {
    bool improved = false;
    for (int r = 0; r < n_robots_; ++r) {
      if (ctx_.cancelled()) return Fail(ErrorCode::kCancelled, "keyframe optimisation: cancelled");
      if (ctx_.timed_out()) {
        stop = true;
        break;
      }
      const bool free = std::any_of(robots_[r].stages.begin(), robots_[r].stages.end(),
                                    [](const Stage& s) { return s.candidates.size() > 1; });
      if (!free) continue;
      const std::vector<int> previous = robots_[r].choice;
      std::vector<int> chain = BestChain(r);
      if (chain == previous) continue;
      robots_[r].choice = std::move(chain);
      const double candidate_cost = Objective();
      if (candidate_cost < cost - kImprovement) {
        cost = candidate_cost;
        improved = true;
      } else {
        robots_[r].choice = previous;
      }
    }
    if (!improved) break;
  }

  report.cost_after = cost;
  Metrics(&report.branch_changes_after, &report.joint_motion_after);
  report.min_clearance_after_m = SmallestClearance();

  // Write the choices back.
  for (int r = 0; r < n_robots_; ++r) {
    const RobotStages& rs = robots_[r];
    for (size_t s = 0; s < rs.stages.size(); ++s) {
      if (rs.choice[s] == 0) continue;
      ++report.changed;
      for (int k : rs.stages[s].keyframes) {
        sequence_[k].kf->q[r] = rs.stages[s].candidates[rs.choice[s]].q;
      }
    }
  }
  return report;
}

}  // namespace

Result<KeyframeOptReport> OptimizeKeyframes(const TaskWorld& world, Plan& plan,
                                            const KeyframeOptOptions& options, RunContext& ctx) {
  if (!(options.branch_change_cost >= 0.0) || !(options.joint_motion_weight >= 0.0) ||
      !(options.clearance_weight >= 0.0) || !(options.clearance_cap_m >= 0.0) ||
      !(options.min_clearance_m >= 0.0) || options.numeric_candidates < 0 || options.sweeps < 0) {
    return Fail(ErrorCode::kInvalidInput,
                "keyframe optimisation: weights, clearances, candidates and sweeps must be >= 0");
  }
  Optimizer optimizer(world, plan, options, ctx);
  return optimizer.Run();
}

}  // namespace wrap
