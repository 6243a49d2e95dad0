// The keyframe problem of each action type: which robots move to which grasps, which object poses
// are tried (fixed, or sampled in the air), which robots are freed, and the action's wrench gates
// at a candidate pose.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <utility>

#include "task/keyframes.h"
#include "task/keyframes_internal.h"

namespace wrap {
namespace {

// Candidates tried per effort level for poses in the air.
constexpr int kAirSamples[] = {6, 16, 40};
constexpr int kAssemblySamples[] = {10, 25, 60};

Mat3 RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

// The robots holding `node` in `st`, with their grasps.
std::vector<std::pair<int, int>> HoldersOf(const SymState& st, int node, int n_robots) {
  std::vector<std::pair<int, int>> h;
  for (int r = 0; r < n_robots; ++r) {
    if (st.held[r] == node) h.push_back({r, st.grasp[r]});
  }
  return h;
}

// Workspace centre of some robots: their shoulders' mean, pulled toward the table centre.
Vec3 WorkspaceCentre(const TaskWorld& world, const std::vector<int>& robots) {
  Vec3 m = Vec3::Zero();
  for (int r : robots) m += world.robots[r].shoulder_W;
  m /= std::max<size_t>(1, robots.size());
  Vec3 p = m + 0.4 * (world.table_center - m);
  p.z() = world.table_top + 0.28;
  return p;
}

// Random pose of `node` around `centre`, orientation R.
Iso3 AirPose(const TaskWorld& world, std::mt19937_64& rng, int node, const Mat3& R,
             const Vec3& centre, bool jitter) {
  Vec3 p = centre;
  if (jitter) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    p += Vec3(0.08 * u(rng), 0.08 * u(rng), 0.06 + 0.08 * u(rng));
  }
  Iso3 X = Iso3::Identity();
  X.linear() = R;
  X.translation() = p - R * world.pre->subassemblies[node].com_A;
  return X;
}

bool AboveTable(const TaskWorld& world, int node, const Iso3& X) {
  return LowestPoint(world, node, X) >= world.table_top + 0.01;
}

}  // namespace

void KeyframeSolver::BuildProblem(Edge& e, Problem& p) {
  const SymState& s = e.s;
  p.keyframe_resting.assign(world_.num_nodes, false);
  for (int r = 0; r < e.n_robots; ++r) {
    if (s.held[r] >= 0) p.holds_at_keyframe.push_back({r, s.grasp[r]});
  }
  for (int node = 0; node < world_.num_nodes; ++node) {
    if (s.loc[node] != kInactive) {
      p.keyframe_nodes.push_back(node);
      p.keyframe_resting[node] = s.loc[node] >= 0;
    }
  }
  switch (e.a.type) {
    case ActionType::kPick:
      BuildPick(e, p);
      break;
    case ActionType::kPlace:
      BuildPlace(e, p);
      break;
    case ActionType::kHandover:
      BuildHandover(e, p);
      break;
    case ActionType::kAddGrasp:
      BuildAddGrasp(e, p);
      break;
    case ActionType::kRelease:
      BuildRelease(e, p);
      break;
    case ActionType::kAssemble:
      BuildAssemble(e, p);
      break;
  }
}

void KeyframeSolver::BuildPick(Edge& e, Problem& p) {
  const TaskAction& a = e.a;
  const int o = a.obj;
  p.AddMover(world_, a.r1, o, a.grasp);
  p.holds_at_keyframe.push_back({a.r1, a.grasp});
  p.make = [](int, std::vector<Iso3>&) { return true; };
  p.gates = [this, &a, &s = e.s, o](const std::vector<Iso3>& X, Gate& g, std::string& why) {
    const WrenchObject obj{o, X[o], false, {{a.r1, a.grasp}}};
    const std::uint64_t key =
        HashMix(HashMix(HashMix(1, static_cast<std::uint64_t>(s.loc[o]) + 100), WrenchClass(a.r1)),
                static_cast<std::uint64_t>(a.grasp));
    if (!Wrench(WrenchGate::kTransport, {&obj, 1}, -1, key, &why)) {
      g = Gate::kWrenchTransport;
      return false;
    }
    return true;
  };
}

void KeyframeSolver::BuildPlace(Edge& e, Problem& p) {
  const TaskAction& a = e.a;
  const int o = a.obj;
  p.AddMover(world_, a.r1, o, e.s.grasp[a.r1]);
  p.keyframe_resting[o] = true;
  p.freed.push_back(a.r1);
  p.make = [this, &a, o](int, std::vector<Iso3>& X) {
    X[o] = tables_.location(a.loc).X_WA;
    return true;
  };
  p.gates = [this, &a, &s = e.s, o](const std::vector<Iso3>& X, Gate& g, std::string& why) {
    const WrenchObject obj{o, X[o], true, {}};
    if (!Wrench(WrenchGate::kRest, {&obj, 1}, -1, HashMix(2, a.loc + 1), &why)) {
      g = Gate::kWrenchRest;
      return false;
    }
    // Brought down to that pose by its holder alone (the same problem as a pick from it).
    const WrenchObject carried{o, X[o], false, {{a.r1, s.grasp[a.r1]}}};
    const std::uint64_t key =
        HashMix(HashMix(HashMix(1, static_cast<std::uint64_t>(a.loc) + 100), WrenchClass(a.r1)),
                static_cast<std::uint64_t>(s.grasp[a.r1]));
    if (!Wrench(WrenchGate::kTransport, {&carried, 1}, -1, key, &why)) {
      g = Gate::kWrenchTransport;
      return false;
    }
    return true;
  };
}

void KeyframeSolver::BuildHandover(Edge& e, Problem& p) {
  const TaskAction& a = e.a;
  const int o = a.obj;
  p.AddMover(world_, a.r1, o, e.s.grasp[a.r1]);
  p.AddMover(world_, a.r2, o, a.grasp);
  p.holds_at_keyframe.push_back({a.r2, a.grasp});
  p.freed.push_back(a.r1);
  p.reposed.push_back(o);
  p.n_candidates = kAirSamples[e.effort];
  const Vec3 centre = WorkspaceCentre(world_, {a.r1, a.r2});
  // Draw 0 is the workspace centre in the object's orientation; draws below n_candidates / 3
  // keep that orientation, later ones turn it at random; all but draw 0 are jittered.
  p.make = [this, &e, &p, o, centre](int k, std::vector<Iso3>& X) {
    const Mat3 R = k < p.n_candidates / 3 ? Mat3(e.c.X_WA[o].linear()) : RandomRotation(e.rng);
    X[o] = AirPose(world_, e.rng, o, R, centre, k > 0);
    return AboveTable(world_, o, X[o]);
  };
  p.gates = [this, &a, &s = e.s, o](const std::vector<Iso3>& X, Gate& g, std::string& why) {
    // The giver brings it there alone; the receiver holds it alone afterwards.
    const WrenchObject giver{o, X[o], false, {{a.r1, s.grasp[a.r1]}}};
    const WrenchObject obj{o, X[o], false, {{a.r2, a.grasp}}};
    if (!Wrench(WrenchGate::kTransport, {&giver, 1}, -1, 0, &why) ||
        !Wrench(WrenchGate::kTransport, {&obj, 1}, -1, 0, &why)) {
      g = Gate::kWrenchTransport;
      return false;
    }
    return true;
  };
}

void KeyframeSolver::BuildAddGrasp(Edge& e, Problem& p) {
  const TaskAction& a = e.a;
  const int o = a.obj;
  const auto holders = HoldersOf(e.s, o, e.n_robots);
  const bool resting = e.s.loc[o] >= 0;
  // An object in the air may be moved by its holders to where the new hand reaches it.
  if (!resting) {
    for (const auto& [r, g] : holders) p.AddMover(world_, r, o, g);
    p.reposed.push_back(o);
  }
  p.AddMover(world_, a.r1, o, a.grasp);
  p.holds_at_keyframe.push_back({a.r1, a.grasp});
  std::vector<int> robots;
  for (const Mover& m : p.movers) robots.push_back(m.robot);
  const Vec3 centre = WorkspaceCentre(world_, robots);
  p.n_candidates = resting ? 1 : kAirSamples[e.effort];
  p.make = [this, &e, &p, o, centre, resting](int k, std::vector<Iso3>& X) {
    if (resting || k == 0) return true;
    const Mat3 R = k < p.n_candidates / 2 ? Mat3(e.c.X_WA[o].linear()) : RandomRotation(e.rng);
    X[o] = AirPose(world_, e.rng, o, R, centre, true);
    return AboveTable(world_, o, X[o]);
  };
  p.gates = [this, &a, o, holders, resting](const std::vector<Iso3>& X, Gate& g, std::string& why) {
    // In the air its holders bring it there before the new hand takes it.
    if (!resting) {
      const WrenchObject before{o, X[o], false, holders};
      if (!Wrench(WrenchGate::kTransport, {&before, 1}, -1, 0, &why)) {
        g = Gate::kWrenchTransport;
        return false;
      }
    }
    WrenchObject obj{o, X[o], resting, holders};
    obj.holders.push_back({a.r1, a.grasp});
    if (!Wrench(WrenchGate::kRelease, {&obj, 1}, -1, 0, &why)) {
      g = Gate::kWrenchRelease;
      return false;
    }
    return true;
  };
}

void KeyframeSolver::BuildRelease(Edge& e, Problem& p) {
  const int o = e.a.obj;
  p.freed.push_back(e.a.r1);
  p.make = [](int, std::vector<Iso3>&) { return true; };
  p.gates = [this, &e, o](const std::vector<Iso3>& X, Gate& g, std::string& why) {
    // The remaining holders hold it (with the table where it rests), or the table alone.
    auto remaining = HoldersOf(e.next, o, e.n_robots);
    const bool resting = e.s.loc[o] >= 0;
    const WrenchObject obj{o, X[o], resting, remaining};
    const WrenchGate gate = remaining.empty() ? WrenchGate::kRest : WrenchGate::kRelease;
    if (!Wrench(gate, {&obj, 1}, -1, 0, &why)) {
      g = remaining.empty() ? Gate::kWrenchRest : Gate::kWrenchRelease;
      return false;
    }
    return true;
  };
}

void KeyframeSolver::BuildAssemble(Edge& e, Problem& p) {
  const int o = e.a.obj;
  const StepInterface& st = world_.interface(o);
  const int M = st.moved, B = st.base;
  const auto m_holders = HoldersOf(e.s, M, e.n_robots);
  const auto b_holders = HoldersOf(e.s, B, e.n_robots);
  const bool b_rests = e.s.loc[B] >= 0;
  for (const auto& [r, g] : m_holders) p.AddMover(world_, r, M, g);
  std::vector<int> robots;
  for (const auto& [r, g] : m_holders) robots.push_back(r);
  // A base in the air is moved by its holders too, to a sampled mating pose.
  if (!b_rests) {
    for (const auto& [r, g] : b_holders) {
      p.AddMover(world_, r, B, g);
      robots.push_back(r);
    }
    p.reposed.push_back(B);
    p.n_candidates = kAssemblySamples[e.effort];
  }
  p.allow_a = M;
  p.allow_b = B;
  const Vec3 centre = WorkspaceCentre(world_, robots);
  // Draw 0 keeps the base's orientation, the next ones take each axis orientation in turn, later
  // ones a random axis orientation, jittered.
  p.make = [this, &e, &p, centre, orientations = AxisOrientations(st.axis_A), b_rests, M, B](
               int k, std::vector<Iso3>& X) {
    if (!b_rests) {
      Mat3 R;
      if (k == 0) {
        R = e.c.X_WA[B].linear();
      } else if (k <= static_cast<int>(orientations.size())) {
        R = orientations[k - 1];
      } else {
        R = orientations[e.rng() % orientations.size()];
      }
      X[B] = AirPose(world_, e.rng, B, R, centre, k > static_cast<int>(orientations.size()));
    }
    X[M] = X[B];
    // A moved input that reaches down to the table top slides along it into a resting base.
    p.keyframe_resting[M] = b_rests && std::abs(LowestPoint(world_, M, X[M]) - world_.table_top) <=
                                           detail::kTouchTolerance;
    if (!b_rests && !AboveTable(world_, B, X[B])) return false;
    // The moved input must not reach under the table top.
    return LowestPoint(world_, M, X[M]) >= world_.table_top - 1e-3;
  };
  p.gates = [this, &e, &p, o, m_holders, b_holders, b_rests, M, B](const std::vector<Iso3>& X,
                                                                   Gate& g, std::string& why) {
    // Each input is brought to the mating pose by its own holders, alone: the base in the
    // air, the moved input (oriented as at its approach).
    const WrenchObject m_alone{M, X[M], false, m_holders};
    const WrenchObject b_alone{B, X[B], false, b_holders};
    if ((!m_holders.empty() && !Wrench(WrenchGate::kTransport, {&m_alone, 1}, -1, 0, &why)) ||
        (!b_rests && !Wrench(WrenchGate::kTransport, {&b_alone, 1}, -1, 0, &why))) {
      g = Gate::kWrenchTransport;
      return false;
    }
    const WrenchObject objs[2] = {{M, X[M], p.keyframe_resting[M], m_holders},
                                  {B, X[B], b_rests, b_holders}};
    std::uint64_t key = 0;
    if (b_rests) {
      key = AssemblyLpKey(o, e.s.loc[B], ClassHolders(m_holders), ClassHolders(b_holders));
    }
    if (!Wrench(WrenchGate::kAssembly, objs, o, key, &why)) {
      g = Gate::kWrenchAssembly;
      return false;
    }
    return true;
  };
}

}  // namespace wrap
