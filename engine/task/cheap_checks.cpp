// The cheap checks of the task search (search.h): before an action becomes a candidate, the
// checks that need no sampled pose (reach, the gripper clear of the table and of the other input,
// IK of the object where it rests, the deterministic wrench gates), cached per question and
// tallied once per milestone; and the abstract check that some grasps and supports balance a
// step's mating wrench at all.
#include <algorithm>
#include <cmath>

#include "grasp/table_slots.h"
#include "task/search.h"

namespace wrap {
bool TaskSearch::Recall(CheapAnswer& answer) {
  // Counted once per milestone: the tally counts distinct questions, not how often the search
  // met them.
  if (!answer.ok && answer.tallied_round != tally_round_) {
    answer.tallied_round = tally_round_;
    tally_.Add(answer.gate, answer.why, answer.about);
  }
  return answer.ok;
}

void TaskSearch::Remember(std::uint64_t key, bool ok) {
  CheapAnswer answer;
  if (!ok) {
    answer = CheapAnswer{false, tally_.last_gate, tally_.last_message, tally_.last_subject};
  }
  answer.tallied_round = tally_round_;
  if (int* index = cheap_.find(key)) {
    cheap_answers_[*index] = std::move(answer);
  } else {
    cheap_.try_emplace(key, static_cast<int>(cheap_answers_.size()));
    cheap_answers_.push_back(std::move(answer));
  }
}

bool TaskSearch::GripperFitsAtRest(int robot, int node, int loc, int grasp, bool placing,
                                   const CheckSubject& about) {
  const Iso3 target = solver_.GraspTarget(tables_.location(loc).X_WA, grasp);
  const std::string& name = world_.tree->nodes[node].name;
  const std::string grasp_index = std::to_string(tables_.grasp(grasp).index);
  if (!solver_.InReach(robot, target)) {
    tally_.Add(Gate::kReach,
               "'" + world_.robots[robot].name + "' cannot reach " +
                   (placing ? "to set '" + name + "' down there"
                            : "grasp " + grasp_index + " of '" + name + "' where it rests"),
               about);
    return false;
  }
  if (!solver_.ClearOfTable(robot, target, solver_.GraspOpening(grasp))) {
    CheckSubject hit = about;
    hit.hit_table = true;
    tally_.Add(Gate::kGripperTable,
               placing ? "setting '" + name + "' down with grasp " + grasp_index +
                             " puts the gripper into the table"
                       : "grasp " + grasp_index + " of '" + name +
                             "' puts the gripper into the table where it rests",
               hit);
    return false;
  }
  return true;
}

bool TaskSearch::CheapPick(int robot, int node, int loc, int grasp) {
  std::uint64_t key = HashMix(HashMix(HashMix(HashMix(101, robot), node), loc), grasp);
  if (int* index = cheap_.find(key)) return Recall(cheap_answers_[*index]);
  const Iso3 X_WA = tables_.location(loc).X_WA;
  const CheckSubject about{.object = node, .robot = robot, .grasp = grasp, .loc = loc};
  bool ok = GripperFitsAtRest(robot, node, loc, grasp, /*placing=*/false, about);
  if (ok) {
    std::string why;
    ok = solver_.SoloReach(robot, {{node, X_WA, true}}, grasp, &why);
    if (!ok)
      tally_.Add(Gate::kIk, why + " where '" + world_.tree->nodes[node].name + "' rests", about);
  }
  if (ok) {
    // Transport right after the lift: deterministic, so checked here.
    const WrenchObject obj{node, X_WA, false, {{robot, grasp}}};
    std::string why;
    const std::uint64_t lp_key = HashMix(
        HashMix(HashMix(1, static_cast<std::uint64_t>(loc) + 100), solver_.WrenchClass(robot)),
        grasp);
    ok = solver_.Wrench(WrenchGate::kTransport, {&obj, 1}, -1, lp_key, &why);
    if (!ok) tally_.Add(Gate::kWrenchTransport, why, about);
  }
  Remember(key, ok);
  return ok;
}

std::uint64_t TaskSearch::RestingNeighbours(const SymState& s, int node) const {
  std::uint64_t h = 105;
  for (int n = 0; n < world_.num_nodes; ++n) {
    if (n != node && s.loc[n] >= 0)
      h = HashMix(HashMix(h, n), static_cast<std::uint64_t>(s.loc[n]));
  }
  return h;
}

bool TaskSearch::ApproachClear(const SymState& s, std::uint64_t neighbours, int robot, int node,
                               int loc, int grasp) {
  const std::uint64_t key = HashMix(HashMix(HashMix(HashMix(neighbours, robot), node), loc), grasp);
  if (int* index = cheap_.find(key)) return Recall(cheap_answers_[*index]);
  std::vector<std::pair<int, Iso3>>& others = approach_others_;
  others.clear();
  for (int n = 0; n < world_.num_nodes; ++n) {
    if (n != node && s.loc[n] >= 0) others.push_back({n, tables_.location(s.loc[n]).X_WA});
  }
  int hit = -1;
  const bool ok = others.empty() ||
                  solver_.ApproachClear(robot, grasp, tables_.location(loc).X_WA, others, &hit);
  if (!ok) {
    CheckSubject about{.object = node, .robot = robot, .grasp = grasp, .loc = loc};
    about.hit_node = hit;
    tally_.Add(Gate::kSkill,
               "'" + world_.robots[robot].name + "' cannot approach grasp " +
                   std::to_string(tables_.grasp(grasp).index) + " of '" +
                   world_.tree->nodes[node].name + "' straight: its gripper hits '" +
                   world_.tree->nodes[hit].name + "' resting beside it",
               about);
  }
  Remember(key, ok);
  return ok;
}

bool TaskSearch::CanBePicked(int node, int loc, int max_grasps) {
  for (int r = 0; r < n_robots_; ++r) {
    const std::vector<int>& ids = GraspIds(node, r);
    const int n = std::min<int>(static_cast<int>(ids.size()), max_grasps);
    for (int k = 0; k < n; ++k) {
      if (CheapPick(r, node, loc, ids[k])) return true;
    }
  }
  return false;
}

std::string TaskSearch::PickCensus(int node, int loc, int max_grasps) {
  // The first check each grasp fails, in CheapPick's order, over every robot.
  long long tried = 0, reach = 0, table = 0, ik = 0, wrench = 0;
  const Iso3 X_WA = tables_.location(loc).X_WA;
  for (int r = 0; r < n_robots_; ++r) {
    const std::vector<int>& ids = GraspIds(node, r);
    const int n = std::min<int>(static_cast<int>(ids.size()), max_grasps);
    for (int k = 0; k < n; ++k) {
      const int g = ids[k];
      ++tried;
      const Iso3 target = solver_.GraspTarget(X_WA, g);
      if (!solver_.InReach(r, target)) {
        ++reach;
      } else if (!solver_.ClearOfTable(r, target, solver_.GraspOpening(g))) {
        ++table;
      } else if (std::string why; !solver_.SoloReach(r, {{node, X_WA, true}}, g, &why)) {
        ++ik;
      } else if (!CheapPick(r, node, loc, g)) {
        ++wrench;  // the last of CheapPick's checks: carrying it right after the lift
      }
    }
  }
  const std::string name = "'" + world_.tree->nodes[node].name + "'";
  if (tried == 0) return "no robot has a grasp of " + name;
  std::vector<std::pair<long long, std::string>> reasons = {{table, "gripper into the table"},
                                                            {reach, "out of reach"},
                                                            {ik, "no collision-free IK"},
                                                            {wrench, "too weak to carry it"}};
  std::stable_sort(reasons.begin(), reasons.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::string out = "no grasp of " + name + " can be taken where it rests (";
  if (reasons[0].first == tried) {
    out += "every one of the " + std::to_string(tried) + " robot grasps: " + reasons[0].second;
  } else {
    out += "of " + std::to_string(tried) + " robot grasps:";
    for (const auto& [count, words] : reasons) {
      if (count > 0) out += " " + std::to_string(count) + " " + words + ",";
    }
    out.pop_back();
  }
  return out + ")";
}

bool TaskSearch::HomesClear(int node, int loc) {
  auto [it, inserted] = homes_clear_.try_emplace(HashMix(node, loc), true);
  if (inserted) it->second = solver_.ClearOfHomes(node, tables_.location(loc).X_WA);
  return it->second;
}

bool TaskSearch::CheapPlace(int robot, int node, int loc, int grasp) {
  std::uint64_t key = HashMix(HashMix(HashMix(HashMix(102, robot), node), loc), grasp);
  if (int* index = cheap_.find(key)) return Recall(cheap_answers_[*index]);
  const Iso3 X_WA = tables_.location(loc).X_WA;
  const CheckSubject about{.object = node, .robot = robot, .grasp = grasp, .loc = loc};
  bool ok = GripperFitsAtRest(robot, node, loc, grasp, /*placing=*/true, about);
  if (ok && !HomesClear(node, loc)) {
    ok = false;
    CheckSubject in_way = about;
    in_way.robot = -1;
    in_way.grasp = -1;
    tally_.Add(Gate::kCollision,
               "'" + world_.tree->nodes[node].name +
                   "' set down there would be in the way of a robot at home",
               in_way);
  }
  if (ok) {
    std::string why;
    ok = solver_.SoloReach(robot, {{node, X_WA, true}}, grasp, &why);
    if (!ok)
      tally_.Add(Gate::kIk, why + " to set '" + world_.tree->nodes[node].name + "' down", about);
  }
  if (ok) {
    const WrenchObject obj{node, X_WA, true, {}};
    std::string why;
    ok = solver_.Wrench(WrenchGate::kRest, {&obj, 1}, -1, HashMix(2, loc + 1), &why);
    if (!ok) tally_.Add(Gate::kWrenchRest, why, about);
  }
  Remember(key, ok);
  return ok;
}

bool TaskSearch::CheapAssemble(const SymState& s, const Milestone& m) {
  std::vector<std::pair<int, int>> mh, bh;
  for (int r = 0; r < n_robots_; ++r) {
    if (s.held[r] == m.moved) mh.push_back({r, s.grasp[r]});
    if (s.held[r] == m.base) bh.push_back({r, s.grasp[r]});
  }
  const bool b_rests = s.loc[m.base] >= 0;
  const std::uint64_t key = CheapAssembleKey(m.step, b_rests ? s.loc[m.base] : -1, mh, bh);
  if (int* index = cheap_.find(key)) return Recall(cheap_answers_[*index]);
  bool ok = true;
  std::string why;
  // What the checks are about: the moved input where it is mated (on the resting base, or at
  // the base's frame when both are in the air), held by its first holder.
  auto about = [&](int robot, int grasp, int node, int hit_node) {
    CheckSubject a;
    a.object = node;
    a.robot = robot;
    a.grasp = grasp;
    if (b_rests) a.X_WA = tables_.location(s.loc[m.base]).X_WA;
    a.hit_node = hit_node;
    return a;
  };
  const int r0 = mh.empty() ? -1 : mh.front().first, g0 = mh.empty() ? -1 : mh.front().second;
  // Context-free: no gripper may touch the other input at the mating pose. Each holder of
  // `held`, in order, against `other`; the first that touches fails the check.
  {
    const Iso3 X = b_rests ? tables_.location(s.loc[m.base]).X_WA : Iso3::Identity();
    auto grippers_clear = [&](const std::vector<std::pair<int, int>>& holders, int held,
                              int other) {
      for (const auto& [r, g] : holders) {
        if (ok && !solver_.GripperClear(r, g, X, other, X)) {
          ok = false;
          tally_.Add(Gate::kCollision,
                     "the gripper of '" + world_.robots[r].name + "' at grasp " +
                         std::to_string(tables_.grasp(g).index) + " of '" +
                         world_.tree->nodes[held].name + "' hits '" +
                         world_.tree->nodes[other].name + "' when mated",
                     about(r, g, held, other));
        }
      }
    };
    grippers_clear(mh, m.moved, m.base);
    grippers_clear(bh, m.base, m.moved);
  }
  if (!ok) {
  } else if (b_rests) {
    const Iso3 X_WB = tables_.location(s.loc[m.base]).X_WA;
    for (const auto& [r, g] : mh) {
      const Iso3 target = solver_.GraspTarget(X_WB, g);
      if (!solver_.InReach(r, target) ||
          !solver_.ClearOfTable(r, target, solver_.GraspOpening(g))) {
        ok = false;
        tally_.Add(Gate::kReach,
                   "'" + world_.robots[r].name + "' cannot bring '" +
                       world_.tree->nodes[m.moved].name + "' to '" +
                       world_.tree->nodes[m.base].name + "' where it rests",
                   about(r, g, m.moved, -1));
      }
    }
    const bool m_touches = std::abs(LowestPoint(world_, m.moved, X_WB) - world_.table_top) <= 2e-3;
    for (const auto& [r, g] : mh) {
      if (!ok) break;
      std::string solo;
      ok = solver_.SoloReach(r, {{m.moved, X_WB, m_touches}, {m.base, X_WB, true}}, g, &solo);
      if (!ok)
        tally_.Add(Gate::kIk, solo + " to insert '" + world_.tree->nodes[m.moved].name + "'",
                   about(r, g, m.moved, -1));
    }
    if (ok && !solver_.ClearOfHomes(m.step, X_WB)) {
      ok = false;
      tally_.Add(Gate::kCollision,
                 "'" + world_.tree->nodes[m.step].name + "' built where '" +
                     world_.tree->nodes[m.base].name +
                     "' rests would be in the way of a robot at home",
                 about(-1, -1, m.moved, -1));
    }
    if (ok && LowestPoint(world_, m.moved, X_WB) < world_.table_top - 1e-3) {
      ok = false;
      CheckSubject through = about(r0, g0, m.moved, -1);
      through.hit_table = true;
      tally_.Add(Gate::kTable,
                 "'" + world_.tree->nodes[m.moved].name +
                     "' would go through the table to reach '" + world_.tree->nodes[m.base].name +
                     "' resting as it is",
                 through);
    }
    if (ok) {
      const bool m_rests = std::abs(LowestPoint(world_, m.moved, X_WB) - world_.table_top) <= 2e-3;
      const WrenchObject objs[2] = {{m.moved, X_WB, m_rests, mh}, {m.base, X_WB, true, bh}};
      ok = solver_.Wrench(
          WrenchGate::kAssembly, objs, m.step,
          AssemblyLpKey(m.step, s.loc[m.base], solver_.ClassHolders(mh), solver_.ClassHolders(bh)),
          &why);
      if (!ok) tally_.Add(Gate::kWrenchAssembly, why, about(r0, g0, m.moved, -1));
    }
  } else {
    ok = solver_.AirAssemblyPossible(
        m.step, mh, bh,
        CheapAssembleKey(m.step, -1, solver_.ClassHolders(mh), solver_.ClassHolders(bh)), &why);
    if (!ok) tally_.Add(Gate::kWrenchAssembly, why, about(r0, g0, m.moved, -1));
  }
  Remember(key, ok);
  return ok;
}

bool TaskSearch::AssemblyPossible(const Milestone& m, std::string* why) {
  auto cached = possible_.find(m.step);
  if (cached != possible_.end()) {
    if (why) *why = cached->second.second;
    return cached->second.first;
  }
  if (options_.wrench_mode == MatingWrenchMode::kNone) return true;
  // One robot per end effector: the grasps a robot of that kind can take.
  std::vector<int> kinds;
  for (int r = 0; r < n_robots_; ++r) {
    bool seen = false;
    for (int k : kinds) seen = seen || world_.robots[k].grasp_set == world_.robots[r].grasp_set;
    if (!seen) kinds.push_back(r);
  }
  constexpr int kMaxGrasps = 10;
  auto grasps_of = [&](int node, int robot) {
    std::vector<int> ids = GraspIds(node, robot);
    if (static_cast<int>(ids.size()) > kMaxGrasps) ids.resize(kMaxGrasps);
    return ids;
  };
  // The moved input held by one gripper, or by two.
  std::vector<std::vector<std::pair<int, int>>> movers;
  for (int r : kinds) {
    for (int g : grasps_of(m.moved, r)) movers.push_back({{r, g}});
  }
  const size_t singles = movers.size();
  for (size_t i = 0; i < singles; ++i) {
    for (size_t j = i + 1; j < singles; ++j) {
      if (GraspsApart(movers[i][0].second, movers[j][0].second)) {
        movers.push_back({movers[i][0], movers[j][0]});
      }
    }
  }
  const auto& placements = world_.pre->subassemblies[m.base].placements;
  const TableSlots& slots = world_.pre->table_slots;
  std::string reason;
  long long budget = 4000;  // LP questions before giving the search the benefit of the doubt
  auto answer = [&](bool ok) {
    possible_[m.step] = {ok, reason};
    if (why) *why = reason;
    return ok;
  };
  for (const auto& mh : movers) {
    // The base in the air held by one gripper.
    for (int r : kinds) {
      for (int g : grasps_of(m.base, r)) {
        if (--budget < 0) return answer(true);
        std::string w;
        const std::uint64_t key = HashMix(HashMix(HashMix(0xa551, m.step), mh[0].second),
                                          HashMix(mh.size() > 1 ? mh[1].second : -1, g));
        if (solver_.AirAssemblyPossible(m.step, mh, {{r, g}}, key, &w)) return answer(true);
        if (reason.empty()) reason = w;
      }
    }
    // The base resting on the table in each placement, alone or braced by one gripper.
    if (slots.slots.empty()) continue;
    for (size_t p = 0; p < placements.size(); ++p) {
      const Iso3 X = PlacementPose(slots.slots[0], 0.0, placements[p]);
      if (LowestPoint(world_, m.moved, X) < world_.table_top - 1e-3) continue;
      const bool m_rests = std::abs(LowestPoint(world_, m.moved, X) - world_.table_top) <= 2e-3;
      std::vector<std::vector<std::pair<int, int>>> braces{{}};
      for (int r : kinds) {
        for (int g : grasps_of(m.base, r)) braces.push_back({{r, g}});
      }
      for (const auto& bh : braces) {
        if (--budget < 0) return answer(true);
        const WrenchObject objs[2] = {{m.moved, X, m_rests, mh}, {m.base, X, true, bh}};
        std::string w;
        if (solver_.Wrench(WrenchGate::kAssembly, objs, m.step, 0, &w)) return answer(true);
        if (reason.empty()) reason = w;
      }
    }
  }
  if (reason.empty()) reason = "no grasp of '" + world_.tree->nodes[m.moved].name + "'";
  return answer(false);
}

}  // namespace wrap
