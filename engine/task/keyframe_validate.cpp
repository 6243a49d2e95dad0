// Edge validation (paper Alg. 2, ValidateIK): draws the candidate object poses of an action's
// keyframe problem, solves every acting robot's IK at each, searches the combinations of IK
// solutions for one that passes the keyframe's checks, and turns the result into an outcome.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "robot/kinematics.h"
#include "task/keyframes.h"
#include "task/keyframes_internal.h"

namespace wrap {
namespace {

using detail::Clock;
using detail::Seconds;

constexpr int kMaxLeaves = 24;  // IK combinations tried per pose candidate

// How far a failure got: the higher, the more it says about the edge.
int GateRank(Gate x) {
  switch (x) {
    case Gate::kNone:
      return 0;
    case Gate::kTable:
      return 1;
    case Gate::kWrenchTransport:
    case Gate::kWrenchRelease:
    case Gate::kWrenchRest:
    case Gate::kWrenchAssembly:
      return 2;
    case Gate::kReach:
      return 3;
    case Gate::kIk:
      return 4;
    case Gate::kCollision:
    case Gate::kGripperTable:
      return 5;
    case Gate::kClearance:
      return 6;
    case Gate::kApproach:
    case Gate::kSkill:
      return 7;
  }
  return 0;
}

}  // namespace

void KeyframeSolver::Attempt::Note(Gate g, const std::string& what) {
  if (GateRank(g) >= GateRank(worst)) {
    worst = g;
    why = what;
  }
}

EdgeOutcome KeyframeSolver::Validate(const SymState& s, const ContState& c, const TaskAction& a,
                                     const SymState& next, int effort, std::uint64_t seed) {
  ++counters_.validations;
  const auto start = Clock::now();
  const double lp_before = counters_.t_lp_s;
  hit_ = FailureScene{};
  if (explain_) {
    q_now_ = c.q;  // robots not set below stay where the state has them
  }
  Edge e{s,
         c,
         a,
         next,
         std::clamp(effort, 0, 2),
         static_cast<int>(world_.robots.size()),
         std::mt19937_64(HashMix(seed, static_cast<std::uint64_t>(effort) + 11))};
  Problem p;
  BuildProblem(e, p);

  Attempt t;
  t.X = c.X_WA;
  for (int r = 0; r < e.n_robots; ++r) {
    EnableRobot(r, true);
    SetRobot(r, c.q[r]);
  }
  t.chosen.resize(p.movers.size());
  const std::vector<std::vector<Iso3>> candidates = Candidates(e, p, t);
  bool success = false;
  for (size_t k = 0; k < candidates.size() && !success; ++k) {
    t.X = candidates[k];
    success = TryCandidate(e, p, t);
  }
  for (int r = 0; r < e.n_robots; ++r) EnableRobot(r, true);
  counters_.t_ik_s += Seconds(start) - (counters_.t_lp_s - lp_before);
  return success ? Succeeded(e, p, t) : Failed(p, t);
}

std::vector<std::vector<Iso3>> KeyframeSolver::Candidates(Edge& e, Problem& p, Attempt& t) {
  // When poses are sampled, draw a larger pool and try first those where every acting gripper
  // approaches its grasp from its own robot's side (the approach axis pointing away from the
  // robot's shoulder): arms then reach without crossing each other.
  std::vector<std::vector<Iso3>> candidates;
  const int pool = p.reposed.empty() ? p.n_candidates : 4 * p.n_candidates;
  std::vector<std::pair<double, int>> scored;
  for (int k = 0; k < pool; ++k) {
    std::vector<Iso3> Xk = e.c.X_WA;
    if (!p.make(k, Xk)) {
      t.Note(Gate::kTable, "the object would be below the table top");
      continue;
    }
    double score = 1.0;
    for (const Mover& m : p.movers) {
      const Iso3 T = GraspTarget(Xk[m.node], m.grasp);
      const Vec3 from = (T.translation() - world_.robots[m.robot].shoulder_W).normalized();
      score = std::min(score, T.linear().col(2).dot(from));
    }
    // Keep the first candidate (the current pose) first: it needs no carrying.
    scored.push_back({k == 0 ? 2.0 : score, static_cast<int>(candidates.size())});
    candidates.push_back(std::move(Xk));
  }
  std::stable_sort(scored.begin(), scored.end(),
                   [](const auto& x, const auto& y) { return x.first > y.first; });
  std::vector<std::vector<Iso3>> ordered;
  for (int i = 0; i < static_cast<int>(scored.size()) && i < p.n_candidates; ++i) {
    ordered.push_back(std::move(candidates[scored[i].second]));
  }
  return ordered;
}

bool KeyframeSolver::TryCandidate(Edge& e, const Problem& p, Attempt& t) {
  Gate g = Gate::kNone;
  std::string message;
  if (!p.gates(t.X, g, message)) {
    t.Note(g, message);
    return false;
  }
  if (p.movers.empty() && p.freed.empty()) return true;
  std::vector<std::vector<JointVector>> sols(p.movers.size());
  if (!SolveMovers(e, p, t, sols)) return false;
  // Scene at the keyframe.
  t.objects.clear();
  for (int node : p.keyframe_nodes) {
    t.objects.push_back({node, t.X[node], p.keyframe_resting[node]});
  }
  SetScene(t.objects, p.holds_at_keyframe, p.allow_a, p.allow_b);
  for (const Mover& m : p.movers) EnableRobot(m.robot, false);
  int leaves = 0;
  t.gate = Gate::kNone;
  t.message.clear();
  auto leaf = [&](std::vector<JointVector>& q) { return KeyframeClear(e, p, t, q); };
  if (Search(p.movers, sols, 0, t.chosen, leaves, t.gate, leaf)) return true;
  for (const Mover& m : p.movers) EnableRobot(m.robot, true);
  std::string who;
  for (const Mover& m : p.movers)
    who += (who.empty() ? "'" : ", '") + world_.robots[m.robot].name + "'";
  t.Note(t.gate == Gate::kNone ? Gate::kCollision : t.gate,
         t.message.empty() ? "every IK solution of " + who + " collides" : t.message);
  return false;
}

bool KeyframeSolver::SolveMovers(Edge& e, const Problem& p, Attempt& t,
                                 std::vector<std::vector<JointVector>>& sols) {
  const SymState& s = e.s;
  const ContState& c = e.c;
  const std::vector<Mover>& movers = p.movers;
  bool all = true;
  for (size_t i = 0; i < movers.size() && all; ++i) {
    const Mover& m = movers[i];
    const Iso3 target = GraspTarget(t.X[m.node], m.grasp);
    if (!InReach(m.robot, target)) {
      t.Note(Gate::kReach, "'" + world_.robots[m.robot].name + "' cannot reach grasp " +
                               std::to_string(tables_.grasp(m.grasp).index) + " there");
      all = false;
      break;
    }
    if (!ClearOfTable(m.robot, target, GraspOpening(m.grasp))) {
      t.Note(Gate::kCollision, "the gripper of '" + world_.robots[m.robot].name +
                                   "' would be in the table at grasp " +
                                   std::to_string(tables_.grasp(m.grasp).index));
      all = false;
      break;
    }
    if (!SolveIk(m.robot, target, c.q[m.robot], e.effort, e.rng, sols[i])) {
      t.Note(Gate::kIk, "no IK solution for '" + world_.robots[m.robot].name + "' at grasp " +
                            std::to_string(tables_.grasp(m.grasp).index));
      all = false;
      continue;
    }
    // Two or more robots carrying one object move it as a rigid chain: a UR arm can only
    // follow on its current IK branch (another one is behind a singularity).
    if (s.held[m.robot] == m.node && world_.robots[m.robot].ur &&
        std::count_if(movers.begin(), movers.end(), [&](const Mover& x) {
          return x.node == m.node && s.held[x.robot] == x.node;
        }) >= 2) {
      const TaskRobot& rr = world_.robots[m.robot];
      const int branch = rr.ur->BranchOf(rr.chain, c.q[m.robot]);
      std::erase_if(sols[i],
                    [&](const JointVector& q) { return rr.ur->BranchOf(rr.chain, q) != branch; });
      if (sols[i].empty()) {
        t.Note(Gate::kIk, "'" + world_.robots[m.robot].name +
                              "' cannot carry its object there with the others on its IK branch");
        all = false;
      }
    }
  }
  return all;
}

bool KeyframeSolver::Search(const std::vector<Mover>& movers,
                            const std::vector<std::vector<JointVector>>& sols, size_t depth,
                            std::vector<JointVector>& chosen, int& leaves, Gate& gate,
                            const std::function<bool(std::vector<JointVector>&)>& leaf) {
  if (depth == movers.size()) {
    ++leaves;
    return leaf(chosen);
  }
  const int r = movers[depth].robot;
  EnableRobot(r, true);
  for (const JointVector& q : sols[depth]) {
    SetRobot(r, q);
    if (Collides()) {
      if (gate == Gate::kNone || gate == Gate::kIk) gate = Gate::kCollision;
      continue;
    }
    chosen[depth] = q;
    if (Search(movers, sols, depth + 1, chosen, leaves, gate, leaf)) return true;
    if (leaves >= kMaxLeaves) break;
  }
  EnableRobot(r, false);
  return false;
}

EdgeOutcome KeyframeSolver::Failed(const Problem& p, Attempt& t) {
  constexpr bool kFixedIkComplete = true;  // UR closed form: all solutions
  ++counters_.validation_failures;
  EdgeOutcome out;
  out.ok = false;
  out.gate = t.worst;
  out.message = t.why;
  const Gate worst = t.worst;
  if (worst == Gate::kCollision || worst == Gate::kSkill || worst == Gate::kApproach) {
    out.scene = std::move(hit_);
  }
  // Closed-form IK at a fixed pose (nothing sampled) or a wrench failure: effort cannot help.
  const bool wrench_only = worst == Gate::kWrenchAssembly || worst == Gate::kWrenchRest ||
                           worst == Gate::kWrenchRelease ||
                           (worst == Gate::kWrenchTransport && p.reposed.empty());
  out.permanent = wrench_only || (p.reposed.empty() && !p.numeric && kFixedIkComplete);
  return out;
}

EdgeOutcome KeyframeSolver::Succeeded(const Edge& e, const Problem& p, Attempt& t) {
  EdgeOutcome out;
  out.ok = true;
  ContState& nc = out.next;
  nc.q = e.c.q;
  for (size_t i = 0; i < p.movers.size(); ++i) nc.q[p.movers[i].robot] = t.chosen[i];
  nc.X_WA = t.X;
  Keyframe& kf = out.keyframe;
  kf.q = nc.q;
  for (int node : p.keyframe_nodes) {
    kf.objects.push_back({node, t.X[node], p.keyframe_resting[node]});
  }
  if (t.park_home) {
    for (int r : p.freed) nc.q[r] = world_.robots[r].home;
  }
  if (e.a.type == ActionType::kAssemble) {
    const StepInterface& st = world_.interface(e.a.obj);
    nc.X_WA[e.a.obj] = t.X[st.base];
    out.approach = std::move(t.approach);
  }
  return out;
}

}  // namespace wrap
