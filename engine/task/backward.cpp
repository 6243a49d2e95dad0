// WRAP's backward abstract heuristic (paper §IV-D, Alg. 2 "BackwardSearch"): per milestone, a
// breadth-first search backwards from the assembly over the projected state of the two inputs.
//
// Projection. Each input is either resting (where it rests at the milestone's start, or in one of
// its stable placements anywhere on the table: slot and yaw are projected away) or held by one
// robot with a grasp of one of two classes: "assembly grasps" leave the gripper clear of the other
// input at the mating pose, the others do not. Everything else of the forward state (the exact
// grasp, slot and yaw, the other robots' objects) is projected away. The "fine" variant keeps
// more of the grasp: its class is also the gripper's approach direction in the object's frame
// (one of six), so the abstraction sees, for instance, that two grippers coming from the same
// side cannot hand over and that a grasp from below cannot set an object down.
//
// Abstract actions. pick and place (some grasp of the class clears the table in that placement;
// from the start location the search's own cheap pick check), handover (some pair of grasps of
// the two classes lies apart), assemble (the moved input held with an assembly grasp and the base
// resting where the moved input stays above the table, or held by another robot with an assembly
// grasp; the wrench LP answers that with some grasp of the class, budgeted). Each abstract action
// is feasible when some concrete action it stands for passes those checks, so the distances are
// a relaxation: they count the handovers, regrasps and set-downs the counting heuristic misses.
#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "grasp/table_slots.h"
#include "task/search.h"

namespace wrap {
namespace {

constexpr int kFar = TaskSearch::kFarDistance;

}  // namespace

bool TaskSearch::AssemblyGrasp(int input, int robot, int grasp) {
  auto& classes = backward_.assembly_grasp[input];
  if (auto it = classes.find(grasp); it != classes.end()) return it->second;
  const int other = input == 0 ? backward_.base : backward_.moved;
  const bool ok = solver_.GripperClear(robot, grasp, Iso3::Identity(), other, Iso3::Identity());
  classes.emplace(grasp, ok);
  return ok;
}

int TaskSearch::GraspClass(int input, int robot, int grasp) {
  const int assembly = AssemblyGrasp(input, robot, grasp) ? 1 : 0;
  if (!fine_) return assembly;
  // Fine: the approach axis of the gripper in the object's frame, one of six directions.
  const GraspRef& g = tables_.grasp(grasp);
  const Vec3 z = (world_.X_AP[g.part] * g.X_PG).linear().col(2);
  int axis = 0;
  z.cwiseAbs().maxCoeff(&axis);
  return assembly + 2 * (2 * axis + (z[axis] < 0.0 ? 1 : 0));
}

// The robot-free answers of one milestone's abstraction, by input k (0 moved, 1 base): rest
// statuses are 0 (the start location) and 1 + p (placement p); grasp classes c < nc.
struct TaskSearch::BackwardTables {
  int nodes[2] = {-1, -1};  ///< Node ids of the moved input and the base.
  int R = 0;                ///< Robots.
  int nc = 2;               ///< Grasp classes (assembly or not; fine: times 6 directions).
  Resolution res;           ///< The resolution the abstraction is built at.
  /// Per input and rest status: its pose.
  std::vector<std::vector<Iso3>> rest_pose = std::vector<std::vector<Iso3>>(2);
  /// Robots with the same end effector and the project's wrench limits answer the robot-free
  /// questions (table clearance, the wrench LP) alike: `same_as[r]` is the first such robot.
  std::vector<int> same_as;
  /// pick[k][idx_pick(i, r, c)] (also place for i > 0): some grasp of class c of robot r takes
  /// input k from rest status i.
  std::vector<char> pick[2];
  /// hand[k][idx_hand(r1, c1, r2, c2)]: some grasps of the two classes lie apart.
  std::vector<char> hand[2];
  /// rest_asm[i * R + r]: robot r inserts the moved input into the base resting in status i: 0
  /// no, 1 yes, 2 braced (the assembly LP failed alone: cost 2).
  std::vector<int> rest_asm;
  /// air_asm[rm * R + rb]: the moved input held by rm and the base by rb, both with assembly
  /// grasps, balance the mating wrench.
  std::vector<char> air_asm;

  int idx_pick(int i, int r, int c) const { return ((i * R) + r) * nc + c; }
  int idx_hand(int r1, int c1, int r2, int c2) const { return ((r1 * nc + c1) * R + r2) * nc + c2; }
  int& asm_at(int i, int r) { return rest_asm[static_cast<size_t>(i) * R + r]; }
  int asm_at(int i, int r) const { return rest_asm[static_cast<size_t>(i) * R + r]; }
};

std::span<const int> TaskSearch::AbstractGrasps(const BackwardTables& t, int k, int r) {
  const std::vector<int>& ids = GraspIds(t.nodes[k], r);
  return std::span<const int>(ids.data(),
                              std::min<size_t>(ids.size(), static_cast<size_t>(t.res.grasps)));
}

void TaskSearch::BackwardStatuses(const SymState& s0, BackwardTables& t) {
  Backward& b = backward_;
  const TableSlots& slots = world_.pre->table_slots;
  // Rest statuses: 0 = the start location, 1 + p = placement p.
  for (int k = 0; k < 2; ++k) {
    b.loc0[k] = s0.loc[t.nodes[k]];
    const auto& placements = world_.pre->subassemblies[t.nodes[k]].placements;
    b.n_place[k] = slots.slots.empty()
                       ? 0
                       : std::min<int>(t.res.placements, static_cast<int>(placements.size()));
    b.n_rest[k] = 1 + b.n_place[k];
    b.n_status[k] = b.n_rest[k] + t.nc * t.R;
    t.rest_pose[k].push_back(b.loc0[k] >= 0 ? tables_.location(b.loc0[k]).X_WA : Iso3::Identity());
    for (int p = 0; p < b.n_place[k]; ++p) {
      t.rest_pose[k].push_back(PlacementPose(slots.slots[0], 0.0, placements[p]));
    }
  }
  t.same_as.resize(t.R);
  for (int r = 0; r < t.R; ++r) {
    t.same_as[r] = r;
    for (int q = 0; q < r; ++q) {
      if (world_.robots[q].grasp_set == world_.robots[r].grasp_set &&
          !world_.project->robots[q].wrench_limits && !world_.project->robots[r].wrench_limits) {
        t.same_as[r] = q;
        break;
      }
    }
  }
}

void TaskSearch::BackwardPicks(BackwardTables& t) {
  const Backward& b = backward_;
  for (int k = 0; k < 2; ++k) {
    t.pick[k].assign(static_cast<size_t>(b.n_rest[k]) * t.R * t.nc, 0);
    for (int r = 0; r < t.R; ++r) {
      for (int g : AbstractGrasps(t, k, r)) {
        const int c = GraspClass(k, r, g);
        if (b.loc0[k] >= 0 && !t.pick[k][t.idx_pick(0, r, c)] &&
            CheapPick(r, t.nodes[k], b.loc0[k], g)) {
          t.pick[k][t.idx_pick(0, r, c)] = 1;
        }
        for (int p = 0; p < b.n_place[k]; ++p) {
          char& slot = t.pick[k][t.idx_pick(1 + p, r, c)];
          if (t.same_as[r] != r) {
            slot = t.pick[k][t.idx_pick(1 + p, t.same_as[r], c)];
            continue;
          }
          if (slot) continue;
          const Iso3 target = solver_.GraspTarget(t.rest_pose[k][1 + p], g);
          if (solver_.ClearOfTable(r, target, solver_.GraspOpening(g))) slot = 1;
        }
      }
    }
  }
}

void TaskSearch::BackwardHandovers(BackwardTables& t) {
  // The answer depends on the two robots' grasp sets only: computed once per pair of sets.
  const int R = t.R, nc = t.nc;
  for (int k = 0; k < 2; ++k) {
    t.hand[k].assign(static_cast<size_t>(nc * nc * R * R), 0);
    std::map<std::pair<int, int>, std::vector<char>> by_sets;
    for (int r1 = 0; r1 < R; ++r1) {
      for (int r2 = 0; r2 < R; ++r2) {
        if (r1 == r2) continue;
        auto [it, fresh] =
            by_sets.try_emplace({world_.robots[r1].grasp_set, world_.robots[r2].grasp_set},
                                std::vector<char>(static_cast<size_t>(nc * nc), 0));
        std::vector<char>& apart = it->second;
        for (int g1 : AbstractGrasps(t, k, r1)) {
          if (!fresh) break;
          const int c1 = GraspClass(k, r1, g1);
          for (int g2 : AbstractGrasps(t, k, r2)) {
            const int c2 = GraspClass(k, r2, g2);
            if (!apart[c1 * nc + c2] && HandsApart(r1, g1, r2, g2)) apart[c1 * nc + c2] = 1;
          }
        }
        for (int c = 0; c < nc * nc; ++c) t.hand[k][t.idx_hand(r1, c / nc, r2, c % nc)] = apart[c];
      }
    }
  }
}

void TaskSearch::BackwardRestAssembly(const Milestone& m, BackwardTables& t) {
  // The moved input stays above the table, the gripper clears it, and (budgeted) the assembly
  // LP holds for some grasp, alone or with a brace (cost 2 then).
  const Backward& b = backward_;
  const int R = t.R;
  const bool wrench = options_.wrench_mode != MatingWrenchMode::kNone;
  long long lp_budget = 150;
  t.rest_asm.assign(static_cast<size_t>(b.n_rest[1]) * R, 0);
  for (int i = 0; i < b.n_rest[1]; ++i) {
    if (i == 0 && b.loc0[1] < 0) continue;
    const Iso3& X = t.rest_pose[1][i];
    const double low = LowestPoint(world_, m.moved, X);
    if (low < world_.table_top - 1e-3) continue;
    const bool m_rests = std::abs(low - world_.table_top) <= 2e-3;
    const int loc = i == 0 ? b.loc0[1] : tables_.PlacedLocation(m.base, i - 1, 0, 0, X);
    for (int r = 0; r < R; ++r) {
      int best = 0;
      if (i > 0 && t.same_as[r] != r) {  // a placement: wherever on the table, the same answers
        t.asm_at(i, r) = t.asm_at(i, t.same_as[r]);
        continue;
      }
      for (int g : AbstractGrasps(t, 0, r)) {
        if (best == 1) break;
        if (!AssemblyGrasp(0, r, g)) continue;
        const Iso3 target = solver_.GraspTarget(X, g);
        if (i == 0 && !solver_.InReach(r, target)) continue;
        if (!solver_.ClearOfTable(r, target, solver_.GraspOpening(g))) continue;
        if (!wrench || --lp_budget < 0) {
          best = 1;
          break;
        }
        const std::vector<std::pair<int, int>> mh = {{r, g}};
        const WrenchObject objs[2] = {{m.moved, X, m_rests, mh}, {m.base, X, true, {}}};
        std::string why;
        best = solver_.Wrench(WrenchGate::kAssembly, objs, m.step,
                              AssemblyLpKey(m.step, loc, solver_.ClassHolders(mh), {}), &why)
                   ? 1
                   : 2;
      }
      t.asm_at(i, r) = best;
    }
  }
}

void TaskSearch::BackwardAirAssembly(const Milestone& m, BackwardTables& t) {
  // Budgeted: some orientation balances the mating wrench.
  const int R = t.R;
  const bool wrench = options_.wrench_mode != MatingWrenchMode::kNone;
  t.air_asm.assign(static_cast<size_t>(R * R), 0);
  long long air_budget = 12;
  for (int rm = 0; rm < R; ++rm) {
    for (int rb = 0; rb < R; ++rb) {
      if (rm == rb) continue;
      char& out = t.air_asm[rm * R + rb];
      for (int gm : AbstractGrasps(t, 0, rm)) {
        if (out || !AssemblyGrasp(0, rm, gm)) continue;
        for (int gb : AbstractGrasps(t, 1, rb)) {
          if (!AssemblyGrasp(1, rb, gb)) continue;
          if (!wrench || --air_budget < 0) {
            out = 1;
            break;
          }
          const std::vector<std::pair<int, int>> mh = {{rm, gm}}, bh = {{rb, gb}};
          std::string why;
          if (solver_.AirAssemblyPossible(
                  m.step, mh, bh,
                  CheapAssembleKey(m.step, -1, solver_.ClassHolders(mh), solver_.ClassHolders(bh)),
                  &why)) {
            out = 1;
          }
          break;  // one LP family per moved grasp: the base grasps differ little
        }
      }
    }
  }
}

void TaskSearch::BackwardDistances(const BackwardTables& t) {
  Backward& b = backward_;
  const int R = t.R, nc = t.nc;
  // The abstract graph: states (status of the moved input, status of the base); edges reversed.
  const int NM = b.n_status[0], NB = b.n_status[1];
  const int N = NM * NB;
  auto held_by = [&](int k, int status) {
    return status >= b.n_rest[k] ? (status - b.n_rest[k]) / nc : -1;
  };
  std::vector<std::vector<int>> reverse(N);
  std::vector<int> goal_cost(N, kFar);
  for (int sm = 0; sm < NM; ++sm) {
    for (int sb = 0; sb < NB; ++sb) {
      const int rm = held_by(0, sm), rb = held_by(1, sb);
      if (rm >= 0 && rm == rb) continue;
      const int from = sm * NB + sb;
      const int status[2] = {sm, sb};
      for (int k = 0; k < 2; ++k) {
        const int s = status[k];
        const int other_holder = k == 0 ? rb : rm;
        auto add = [&](int s2) {
          const int to = k == 0 ? s2 * NB + sb : sm * NB + s2;
          reverse[to].push_back(from);
        };
        if (s < b.n_rest[k]) {
          if (s == 0 && b.loc0[k] < 0) continue;
          for (int r = 0; r < R; ++r) {
            if (r == other_holder) continue;
            for (int c = 0; c < nc; ++c) {
              if (t.pick[k][t.idx_pick(s, r, c)]) add(b.n_rest[k] + nc * r + c);
            }
          }
        } else {
          const int r = (s - b.n_rest[k]) / nc, c = (s - b.n_rest[k]) % nc;
          for (int p = 0; p < b.n_place[k]; ++p) {
            if (t.pick[k][t.idx_pick(1 + p, r, c)]) add(1 + p);
          }
          for (int r2 = 0; r2 < R; ++r2) {
            if (r2 == r || r2 == other_holder) continue;
            for (int c2 = 0; c2 < nc; ++c2) {
              if (t.hand[k][t.idx_hand(r, c, r2, c2)]) add(b.n_rest[k] + nc * r2 + c2);
            }
          }
        }
      }
      // Assemble: the moved input held with an assembly grasp.
      if (rm >= 0 && (sm - b.n_rest[0]) % nc % 2 == 1) {
        if (rb >= 0) {
          if ((sb - b.n_rest[1]) % nc % 2 == 1 && t.air_asm[rm * R + rb]) goal_cost[from] = 1;
        } else if (sb > 0 || b.loc0[1] >= 0) {
          const int ra = t.asm_at(sb, rm);
          if (ra > 0) goal_cost[from] = ra;
        }
      }
    }
  }
  // Unit-cost edges, assembly costs 1 or 2: a breadth-first search with a two-bucket start.
  b.dist = goal_cost;
  std::deque<int> queue;
  for (int d = 1; d <= 2; ++d) {
    for (int v = 0; v < N; ++v) {
      if (goal_cost[v] == d) queue.push_back(v);
    }
  }
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop_front();
    for (int u : reverse[v]) {
      if (b.dist[u] > b.dist[v] + 1) {
        b.dist[u] = b.dist[v] + 1;
        queue.push_back(u);
      }
    }
  }
}

std::string TaskSearch::BackwardWhy(const Milestone& m, const BackwardTables& t) {
  const Backward& b = backward_;
  const std::string& mn = world_.tree->nodes[m.moved].name;
  const std::string& bn = world_.tree->nodes[m.base].name;
  int n_asm = 0, n_all = 0;
  bool base_support = false, m_pick = b.loc0[0] < 0;
  for (int r = 0; r < t.R; ++r) {
    for (int g : AbstractGrasps(t, 0, r)) {
      ++n_all;
      n_asm += AssemblyGrasp(0, r, g) ? 1 : 0;
    }
    for (int i = 0; i < b.n_rest[1]; ++i) base_support |= t.asm_at(i, r) > 0;
    for (int q = 0; q < t.R; ++q) base_support |= t.air_asm[r * t.R + q] != 0;
    for (int c = 0; c < t.nc; ++c) m_pick |= t.pick[0][t.idx_pick(0, r, c)] != 0;
  }
  if (n_all == 0) return "no robot has a grasp of '" + mn + "'";
  if (n_asm == 0) {
    return "none of the " + std::to_string(n_all) + " grasps of '" + mn +
           "' leaves the gripper clear of '" + bn + "' at the mating pose";
  }
  if (!base_support) {
    return "'" + bn + "' offers no support for the insertion: resting in none of its " +
           std::to_string(b.n_place[1]) + " placements considered does an assembly grasp of '" +
           mn + "' stay clear of the table (or balance the mating wrench), and held by one " +
           "robot no pair of assembly grasps balances it";
  }
  if (!m_pick) return PickCensus(m.moved, b.loc0[0], t.res.grasps);
  return "no sequence of picks, handovers and set-downs gives a robot one of the " +
         std::to_string(n_asm) + " assembly grasps of '" + mn + "' (of " + std::to_string(n_all) +
         ") while '" + bn + "' is supported";
}

void TaskSearch::LogBackward(const BackwardTables& t) {
  const Backward& b = backward_;
  for (int k = 0; k < 2; ++k) {
    std::string line =
        StrFormat("backward: input %d '%s' loc0 %d, %d placements; per robot: ", k,
                  world_.tree->nodes[t.nodes[k]].name.c_str(), b.loc0[k], b.n_place[k]);
    for (int r = 0; r < t.R; ++r) {
      int n_asm = 0, n = 0;
      for (int g : AbstractGrasps(t, k, r)) {
        ++n;
        n_asm += AssemblyGrasp(k, r, g) ? 1 : 0;
      }
      int n_pick = 0;
      for (int c = 0; c < t.nc; ++c) n_pick += t.pick[k][t.idx_pick(0, r, c)];
      line += StrFormat("r%d %d/%d asm, pick0 %d classes; ", r, n_asm, n, n_pick);
    }
    ctx_.Log("task", line);
  }
  std::string line = "backward: rest_asm:";
  for (int i = 0; i < b.n_rest[1]; ++i) {
    line += " [";
    for (int r = 0; r < t.R; ++r) line += std::to_string(t.asm_at(i, r));
    line += "]";
  }
  line += " air_asm:";
  for (int v : t.air_asm) line += std::to_string(v);
  ctx_.Log("task", line);
}

void TaskSearch::BuildBackward(const Milestone& m, const Resolution& res, const SymState& s0) {
  Backward& b = backward_;
  b = Backward{};
  b.step = m.step;
  b.moved = m.moved;
  b.base = m.base;
  BackwardTables t;
  t.nodes[0] = m.moved;
  t.nodes[1] = m.base;
  t.R = n_robots_;
  t.nc = fine_ ? 12 : 2;  // grasp classes (assembly or not; fine: times 6 directions)
  t.res = res;
  b.classes = t.nc;
  BackwardStatuses(s0, t);
  BackwardPicks(t);
  BackwardHandovers(t);
  BackwardRestAssembly(m, t);
  BackwardAirAssembly(m, t);
  BackwardDistances(t);
  // Why the assembly is out of reach from the start, in words.
  if (BackwardDistance(s0) >= kFar) b.why = BackwardWhy(m, t);
  if (ctx_.Logs("task")) LogBackward(t);
}

int TaskSearch::BackwardDistance(const SymState& s) {
  const Backward& b = backward_;
  const int nodes[2] = {b.moved, b.base};
  // Each input's statuses: resting (one), or held (one per holder: the nearest counts).
  int status[2][2] = {{-1, -1}, {-1, -1}};
  for (int k = 0; k < 2; ++k) {
    const int node = nodes[k];
    const int16_t loc = s.loc[node];
    if (loc >= 0) {
      const int p = loc == b.loc0[k] ? -1 : tables_.location(loc).placement.placement;
      status[k][0] = p >= 0 && p < b.n_place[k] ? 1 + p : 0;
      continue;
    }
    int n = 0;
    for (int r = 0; r < n_robots_ && n < 2; ++r) {
      if (s.held[r] == node)
        status[k][n++] = b.n_rest[k] + b.classes * r + GraspClass(k, r, s.grasp[r]);
    }
    if (n == 0) return kFar;
  }
  int best = kFar;
  for (int sm : status[0]) {
    for (int sb : status[1]) {
      if (sm >= 0 && sb >= 0) best = std::min(best, b.dist[sm * b.n_status[1] + sb]);
    }
  }
  return best;
}

}  // namespace wrap
