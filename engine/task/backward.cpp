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

void TaskSearch::BuildBackward(const Milestone& m, const Resolution& res, const SymState& s0) {
  Backward& b = backward_;
  b = Backward{};
  b.step = m.step;
  b.moved = m.moved;
  b.base = m.base;
  const int nodes[2] = {m.moved, m.base};
  const TableSlots& slots = world_.pre->table_slots;
  const int R = n_robots_;
  const int nc = fine_ ? 12 : 2;  // grasp classes (assembly or not; fine: times 6 directions)
  b.classes = nc;

  // Rest statuses: 0 = the start location, 1 + p = placement p.
  std::vector<std::vector<Iso3>> rest_pose(2);
  for (int k = 0; k < 2; ++k) {
    b.loc0[k] = s0.loc[nodes[k]];
    const auto& placements = world_.pre->subassemblies[nodes[k]].placements;
    b.n_place[k] = slots.slots.empty()
                       ? 0
                       : std::min<int>(res.placements, static_cast<int>(placements.size()));
    b.n_rest[k] = 1 + b.n_place[k];
    b.n_status[k] = b.n_rest[k] + nc * R;
    rest_pose[k].push_back(b.loc0[k] >= 0 ? tables_.location(b.loc0[k]).X_WA : Iso3::Identity());
    for (int p = 0; p < b.n_place[k]; ++p) {
      rest_pose[k].push_back(PlacementPose(slots.slots[0], 0.0, placements[p]));
    }
  }
  // Robots with the same end effector and the project's wrench limits answer the robot-free
  // questions (table clearance, the wrench LP) alike: `same_as[r]` is the first such robot.
  std::vector<int> same_as(R);
  for (int r = 0; r < R; ++r) {
    same_as[r] = r;
    for (int q = 0; q < r; ++q) {
      if (world_.robots[q].grasp_set == world_.robots[r].grasp_set &&
          !world_.project->robots[q].wrench_limits && !world_.project->robots[r].wrench_limits) {
        same_as[r] = q;
        break;
      }
    }
  }
  auto grasps = [&](int k, int r) {
    const std::vector<int>& ids = GraspIds(nodes[k], r);
    return std::span<const int>(ids.data(),
                                std::min<size_t>(ids.size(), static_cast<size_t>(res.grasps)));
  };

  // pick[k][i][r][c] (also place for i > 0): some grasp of class c of robot r takes input k
  // from rest status i.
  auto idx_pick = [&](int i, int r, int c) { return ((i * R) + r) * nc + c; };
  std::vector<char> pick[2];
  for (int k = 0; k < 2; ++k) {
    pick[k].assign(static_cast<size_t>(b.n_rest[k]) * R * nc, 0);
    for (int r = 0; r < R; ++r) {
      for (int g : grasps(k, r)) {
        const int c = GraspClass(k, r, g);
        if (b.loc0[k] >= 0 && !pick[k][idx_pick(0, r, c)] && CheapPick(r, nodes[k], b.loc0[k], g)) {
          pick[k][idx_pick(0, r, c)] = 1;
        }
        for (int p = 0; p < b.n_place[k]; ++p) {
          char& slot = pick[k][idx_pick(1 + p, r, c)];
          if (same_as[r] != r) {
            slot = pick[k][idx_pick(1 + p, same_as[r], c)];
            continue;
          }
          if (slot) continue;
          const Iso3 target = solver_.GraspTarget(rest_pose[k][1 + p], g);
          if (solver_.ClearOfTable(r, target, solver_.GraspOpening(g))) slot = 1;
        }
      }
    }
  }
  // hand[k][(r1, c1), (r2, c2)]: some grasps of the two classes lie apart. The answer depends on
  // the two robots' grasp sets only: computed once per pair of sets.
  auto idx_hand = [&](int r1, int c1, int r2, int c2) {
    return ((r1 * nc + c1) * R + r2) * nc + c2;
  };
  std::vector<char> hand[2];
  for (int k = 0; k < 2; ++k) {
    hand[k].assign(static_cast<size_t>(nc * nc * R * R), 0);
    std::map<std::pair<int, int>, std::vector<char>> by_sets;
    for (int r1 = 0; r1 < R; ++r1) {
      for (int r2 = 0; r2 < R; ++r2) {
        if (r1 == r2) continue;
        auto [it, fresh] =
            by_sets.try_emplace({world_.robots[r1].grasp_set, world_.robots[r2].grasp_set},
                                std::vector<char>(static_cast<size_t>(nc * nc), 0));
        std::vector<char>& apart = it->second;
        for (int g1 : grasps(k, r1)) {
          if (!fresh) break;
          const int c1 = GraspClass(k, r1, g1);
          for (int g2 : grasps(k, r2)) {
            const int c2 = GraspClass(k, r2, g2);
            if (!apart[c1 * nc + c2] && HandsApart(r1, g1, r2, g2)) apart[c1 * nc + c2] = 1;
          }
        }
        for (int c = 0; c < nc * nc; ++c) hand[k][idx_hand(r1, c / nc, r2, c % nc)] = apart[c];
      }
    }
  }
  // rest_asm[i][r]: robot r can insert the moved input (assembly grasp) into the base resting in
  // status i: the moved input stays above the table, the gripper clears it, and (budgeted) the
  // assembly LP holds for some grasp, alone or with a brace (cost 2 then).
  const bool wrench = options_.wrench_mode != MatingWrenchMode::kNone;
  long long lp_budget = 150;
  std::vector<int> rest_asm(static_cast<size_t>(b.n_rest[1]) * R, 0);  // 0 no, 1 ok, 2 braced
  auto asm_at = [&](int i, int r) -> int& { return rest_asm[static_cast<size_t>(i) * R + r]; };
  for (int i = 0; i < b.n_rest[1]; ++i) {
    if (i == 0 && b.loc0[1] < 0) continue;
    const Iso3& X = rest_pose[1][i];
    const double low = LowestPoint(world_, m.moved, X);
    if (low < world_.table_top - 1e-3) continue;
    const bool m_rests = std::abs(low - world_.table_top) <= 2e-3;
    const int loc = i == 0 ? b.loc0[1] : tables_.PlacedLocation(m.base, i - 1, 0, 0, X);
    for (int r = 0; r < R; ++r) {
      int best = 0;
      if (i > 0 && same_as[r] != r) {  // a placement: wherever on the table, the same answers
        asm_at(i, r) = asm_at(i, same_as[r]);
        continue;
      }
      for (int g : grasps(0, r)) {
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
                              AssemblyLpKey(m.step, loc, mh, {}), &why)
                   ? 1
                   : 2;
      }
      asm_at(i, r) = best;
    }
  }
  // air_asm[r_m][r_b]: the moved input held by r_m and the base by r_b, both with assembly
  // grasps, balance the mating wrench in some orientation (budgeted).
  std::vector<char> air_asm(static_cast<size_t>(R * R), 0);
  long long air_budget = 12;
  for (int rm = 0; rm < R; ++rm) {
    for (int rb = 0; rb < R; ++rb) {
      if (rm == rb) continue;
      char& out = air_asm[rm * R + rb];
      for (int gm : grasps(0, rm)) {
        if (out || !AssemblyGrasp(0, rm, gm)) continue;
        for (int gb : grasps(1, rb)) {
          if (!AssemblyGrasp(1, rb, gb)) continue;
          if (!wrench || --air_budget < 0) {
            out = 1;
            break;
          }
          const std::vector<std::pair<int, int>> mh = {{rm, gm}}, bh = {{rb, gb}};
          std::string why;
          if (solver_.AirAssemblyPossible(m.step, mh, bh, CheapAssembleKey(m.step, -1, mh, bh),
                                          &why)) {
            out = 1;
          }
          break;  // one LP family per moved grasp: the base grasps differ little
        }
      }
    }
  }

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
              if (pick[k][idx_pick(s, r, c)]) add(b.n_rest[k] + nc * r + c);
            }
          }
        } else {
          const int r = (s - b.n_rest[k]) / nc, c = (s - b.n_rest[k]) % nc;
          for (int p = 0; p < b.n_place[k]; ++p) {
            if (pick[k][idx_pick(1 + p, r, c)]) add(1 + p);
          }
          for (int r2 = 0; r2 < R; ++r2) {
            if (r2 == r || r2 == other_holder) continue;
            for (int c2 = 0; c2 < nc; ++c2) {
              if (hand[k][idx_hand(r, c, r2, c2)]) add(b.n_rest[k] + nc * r2 + c2);
            }
          }
        }
      }
      // Assemble: the moved input held with an assembly grasp.
      if (rm >= 0 && (sm - b.n_rest[0]) % nc % 2 == 1) {
        if (rb >= 0) {
          if ((sb - b.n_rest[1]) % nc % 2 == 1 && air_asm[rm * R + rb]) goal_cost[from] = 1;
        } else if (sb > 0 || b.loc0[1] >= 0) {
          const int ra = asm_at(sb, rm);
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

  // Why the assembly is out of reach from the start, in words.
  const int start = BackwardDistance(s0);
  if (start >= kFar) {
    const std::string& mn = world_.tree->nodes[m.moved].name;
    const std::string& bn = world_.tree->nodes[m.base].name;
    int n_asm = 0, n_all = 0;
    bool base_support = false, m_pick = b.loc0[0] < 0;
    for (int r = 0; r < R; ++r) {
      for (int g : grasps(0, r)) {
        ++n_all;
        n_asm += AssemblyGrasp(0, r, g) ? 1 : 0;
      }
      for (int i = 0; i < b.n_rest[1]; ++i) base_support |= asm_at(i, r) > 0;
      for (int q = 0; q < R; ++q) base_support |= air_asm[r * R + q] != 0;
      for (int c = 0; c < nc; ++c) m_pick |= pick[0][idx_pick(0, r, c)] != 0;
    }
    if (n_all == 0) {
      b.why = "no robot has a grasp of '" + mn + "'";
    } else if (n_asm == 0) {
      b.why = "none of the " + std::to_string(n_all) + " grasps of '" + mn +
              "' leaves the gripper clear of '" + bn + "' at the mating pose";
    } else if (!base_support) {
      b.why = "'" + bn + "' offers no support for the insertion: resting in none of its " +
              std::to_string(b.n_place[1]) + " placements considered does an assembly grasp of '" +
              mn + "' stay clear of the table (or balance the mating wrench), and held by one " +
              "robot no pair of assembly grasps balances it";
    } else if (!m_pick) {
      b.why = PickCensus(m.moved, b.loc0[0], res.grasps);
    } else {
      b.why = "no sequence of picks, handovers and set-downs gives a robot one of the " +
              std::to_string(n_asm) + " assembly grasps of '" + mn + "' (of " +
              std::to_string(n_all) + ") while '" + bn + "' is supported";
    }
  }
  if (ctx_.Logs("task")) {
    for (int k = 0; k < 2; ++k) {
      std::string line = StrFormat("backward: input %d '%s' loc0 %d, %d placements; per robot: ",
                                   k, world_.tree->nodes[nodes[k]].name.c_str(), b.loc0[k],
                                   b.n_place[k]);
      for (int r = 0; r < R; ++r) {
        int n_asm = 0, n = 0;
        for (int g : grasps(k, r)) {
          ++n;
          n_asm += AssemblyGrasp(k, r, g) ? 1 : 0;
        }
        int n_pick = 0;
        for (int c = 0; c < nc; ++c) n_pick += pick[k][idx_pick(0, r, c)];
        line += StrFormat("r%d %d/%d asm, pick0 %d classes; ", r, n_asm, n, n_pick);
      }
      ctx_.Log("task", line);
    }
    std::string line = "backward: rest_asm:";
    for (int i = 0; i < b.n_rest[1]; ++i) {
      line += " [";
      for (int r = 0; r < R; ++r) line += std::to_string(asm_at(i, r));
      line += "]";
    }
    line += " air_asm:";
    for (int v : air_asm) line += std::to_string(v);
    ctx_.Log("task", line);
  }
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
