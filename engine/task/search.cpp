#include "task/search.h"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <queue>
#include <tuple>
#include <unordered_set>

#include "grasp/table_slots.h"

namespace wrap {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kPermanent = INT_MAX;
// Node budget of a search from a committed state past the milestone's start: beyond it the
// state counts as a dead end and the search backs up.
constexpr long long kLocalNodes = 20000;
// Validation failures after which the fill stops searching from the milestone's start and
// commits to the validated prefix of its candidates.
constexpr int kRootFailures = 15;
// Most actions in one milestone's plan: longer candidates count as dead ends.
constexpr int kMaxMilestoneActions = 16;
// Optimistic: failures of the target's assembly before the next target.
constexpr int kTargetFailures = 3;
// Optimistic: nodes of a search towards one target (an unreachable target exhausts it).
constexpr long long kTargetNodes = 200000;
// Validation failures in one round (resolution and effort level) before moving to the next.
constexpr int kRoundFailures = 400;

std::uint64_t EdgeKey(const SymState& s, const TaskAction& a) {
  return HashMix(s.Hash(), a.Hash());
}

}  // namespace

void GateTally::Add(Gate gate, const std::string& message, const CheckSubject& about) {
  const int i = static_cast<int>(gate);
  ++count[i];
  if (example[i].empty()) {
    example[i] = message;
    subject[i] = about;
  }
  last_gate = gate;
  last_message = message;
  last_subject = about;
}

bool TaskSearch::Recall(std::uint64_t key, const CheapAnswer& answer) {
  // Counted once per milestone: the tally counts distinct questions, not how often the search
  // met them.
  if (!answer.ok && tallied_.insert(key).second) tally_.Add(answer.gate, answer.why, answer.about);
  return answer.ok;
}

void TaskSearch::Remember(std::uint64_t key, bool ok) {
  tallied_.insert(key);
  cheap_[key] = ok ? CheapAnswer{}
                   : CheapAnswer{false, tally_.last_gate, tally_.last_message, tally_.last_subject};
}

std::string GateTally::Summary(int max_gates) const {
  const std::vector<Gate> order = Order();
  std::string out;
  for (int k = 0; k < static_cast<int>(order.size()) && k < max_gates; ++k) {
    if (!out.empty()) out += "; ";
    out += Words(order[k]);
  }
  return out.empty() ? "no candidate action passed the cheap checks" : out;
}

TaskSearch::TaskSearch(const TaskWorld& world, TaskTables& tables, KeyframeSolver& solver,
                       const TaskPlannerOptions& options, RunContext& ctx, std::uint64_t seed,
                       bool widen)
    : world_(world),
      tables_(tables),
      solver_(solver),
      options_(options),
      ctx_(ctx),
      seed_(seed),
      widen_(widen),
      n_robots_(static_cast<int>(world.robots.size())),
      use_backward_(options.planner == "wrap" || options.planner == "exact" ||
                    options.planner == "fine"),
      default_weight_(options.planner == "exact" ? 1 : 2),
      weight_(default_weight_),
      fine_(options.planner == "fine"),
      flat_(options.planner == "flat"),
      optimistic_(options.planner == "optimistic"),
      flat_order_(world.tree->step_order),
      rss0_(ResidentMemoryBytes()) {
  // Edges on which the motion of an earlier task plan failed: never taken (motion feedback).
  for (std::uint64_t edge : options.banned_edges) failed_level_[edge] = kPermanent;
}

TaskSearch::Milestone TaskSearch::StepMilestone(int step, int next_step) const {
  Milestone m;
  m.step = step;
  m.moved = world_.interface(step).moved;
  m.base = world_.interface(step).base;
  m.final = next_step < 0;
  // Objects robots may still hold at the end: the inputs of the next step (none at the end).
  if (next_step >= 0) {
    m.keep[0] = world_.interface(next_step).moved;
    m.keep[1] = world_.interface(next_step).base;
  }
  return m;
}

void TaskSearch::SetClasses(const Milestone& m) {
  if (backward_.step == m.step) return;
  backward_ = Backward{};
  backward_.step = m.step;
  backward_.moved = m.moved;
  backward_.base = m.base;
}

std::size_t TaskSearch::MemoryBytes(std::size_t open, std::size_t closed) const {
  // A node: the struct, its state's three vectors (heap blocks with their headers).
  const std::size_t state = static_cast<std::size_t>(world_.num_nodes) * 2 +
                            static_cast<std::size_t>(n_robots_) * 6 + 3 * 32;
  std::size_t bytes = nodes_.capacity() * (sizeof(Node) + state);
  bytes += open * 48 + closed * 48;  // the queue's entries, the hash map's
  // Caches that live across searches: witnesses hold keyframes (joint vectors, poses).
  bytes += witnesses_.size() * 2048 + cheap_.size() * 96 + failed_level_.size() * 48;
  return bytes;
}

TaskSearch::Resolution TaskSearch::ResolutionAt(int level) const {
  constexpr int kGrasps[] = {6, 12, 1 << 20};
  constexpr int kPlacements[] = {2, 4, 1 << 20};
  constexpr int kSlots[] = {3, 6, 1 << 20};
  constexpr int kYaws[] = {2, 2, 1 << 20};
  Resolution r;
  r.grasps = widen_ ? kGrasps[level] : 1 << 20;
  r.placements = kPlacements[level];
  r.slots = kSlots[level];
  r.yaws = kYaws[level];
  return r;
}

const std::vector<int>& TaskSearch::GraspIds(int node, int robot) {
  auto [it, inserted] = grasp_ids_.try_emplace({node, world_.robots[robot].grasp_set});
  if (inserted) {
    if (const GraspSet* set = world_.grasp_set(node, robot)) {
      for (size_t i = 0; i < set->grasps.size(); ++i) {
        const Grasp& g = set->grasps[i];
        GraspRef ref{node, static_cast<int>(i), g.part, g.X_PG, g.width_m, g.quality};
        // Grasp sets of different end effectors of one node are told apart by the index offset.
        const int key_index = world_.robots[robot].grasp_set * 100000 + static_cast<int>(i);
        it->second.push_back(tables_.Grasp(node, key_index, ref));
      }
    }
  }
  return it->second;
}

bool TaskSearch::GraspsApart(int grasp_a, int grasp_b) const {
  const GraspRef& a = tables_.grasp(grasp_a);
  const GraspRef& b = tables_.grasp(grasp_b);
  const Iso3 X_AGa = world_.X_AP[a.part] * a.X_PG;
  const Iso3 X_AGb = world_.X_AP[b.part] * b.X_PG;
  if ((X_AGa.translation() - X_AGb.translation()).norm() < 0.04) return false;
  // Two grippers coming from nearly the same side of an object collide; on a small object
  // (under 15 cm across) they need to come from opposite sides.
  const Aabb& box = world_.pre->subassemblies[a.subassembly].aabb_A;
  const double limit = (box.max - box.min).norm() < 0.15 ? 0.0 : 0.5;
  return X_AGa.linear().col(2).dot(X_AGb.linear().col(2)) < limit;
}

bool TaskSearch::HandsApart(int robot_a, int grasp_a, int robot_b, int grasp_b) {
  if (!GraspsApart(grasp_a, grasp_b)) return false;
  // Robot-free: robots with the same end effector answer alike.
  const std::uint64_t key =
      HashMix(HashMix(HashMix(HashMix(104, world_.robots[robot_a].grasp_set), grasp_a),
                      world_.robots[robot_b].grasp_set),
              grasp_b);
  auto [it, inserted] = hands_apart_.try_emplace(key, true);
  if (inserted) it->second = solver_.GrippersApart(robot_a, grasp_a, robot_b, grasp_b);
  return it->second;
}

int TaskSearch::Heuristic(const SymState& s, const Milestone& m) {
  int h = 0;
  if (m.flat && !window_.empty()) {
    // A window of milestones: per step still to assemble the assembly and, when its moved input
    // rests on the table, a pick; a release per object held that no step still needs.
    const int done = WindowDone(s);
    const int n = static_cast<int>(window_.size());
    for (int t = done; t < n; ++t)
      h += 1 + (s.loc[world_.interface(window_[t]).moved] >= 0 ? 1 : 0);
    for (int r = 0; r < n_robots_; ++r) {
      const int o = s.held[r];
      if (o < 0 || o == m.keep[0] || o == m.keep[1]) continue;
      bool needed = false;
      for (int t = done; t < n && !needed; ++t) {
        needed = o == world_.interface(window_[t]).moved || o == world_.interface(window_[t]).base;
      }
      if (!needed) h += 1;
    }
    return h;
  }
  if (m.flat) {
    // Flat lazy: per step not yet assembled the assembly and, when its moved input exists but
    // is not in a hand, a pick; a release per robot holding something.
    for (int step : flat_order_) {
      if (s.loc[step] != kInactive) continue;
      h += 1;
      const int moved = world_.interface(step).moved;
      if (s.loc[moved] >= 0) h += 1;
    }
    for (int r = 0; r < n_robots_; ++r) h += s.held[r] >= 0 ? 1 : 0;
    return h;
  }
  const bool done = s.loc[m.step] != kInactive;
  if (use_backward_ && !done) {
    // WRAP: the abstract distance to the assembly, the releases of other objects, and the
    // release of the product when no later step takes it from the hands that hold it.
    h = BackwardDistance(s);
    for (int r = 0; r < n_robots_; ++r) {
      const int o = s.held[r];
      if (o >= 0 && o != m.moved && o != m.base && o != m.keep[0] && o != m.keep[1]) h += 1;
    }
    if (m.final || (m.step != m.keep[0] && m.step != m.keep[1])) h += 1;
    return h;
  }
  bool m_needs_grasp = false;
  if (!done) {
    h += 1;
    m_needs_grasp = s.NumHolders(m.moved) == 0 || s.loc[m.moved] >= 0;
    if (m_needs_grasp) h += 1;
  }
  for (int r = 0; r < n_robots_; ++r) {
    if (s.held[r] >= 0 && s.held[r] != m.keep[0] && s.held[r] != m.keep[1]) h += 1;
  }
  if (m.final && m_needs_grasp) h += 1;
  if (!done && target_.rm >= 0) h += TargetDistance(s, m);
  return h;
}

bool TaskSearch::IsGoal(const SymState& s, const Milestone& m,
                        const std::set<std::uint64_t>& excluded) const {
  if (s.loc[m.step] == kInactive) return false;
  if (m.flat && !window_.empty()) {
    for (int r = 0; r < n_robots_; ++r) {
      if (s.held[r] >= 0 && s.held[r] != m.keep[0] && s.held[r] != m.keep[1]) return false;
    }
    return true;
  }
  if (m.flat) {
    for (int r = 0; r < n_robots_; ++r) {
      if (s.held[r] >= 0) return false;
    }
    return true;
  }
  for (int r = 0; r < n_robots_; ++r) {
    if (s.held[r] >= 0 && s.held[r] != m.keep[0] && s.held[r] != m.keep[1]) return false;
  }
  return excluded.empty() || !excluded.contains(s.Hash());
}

SymState TaskSearch::Apply(const SymState& s, const TaskAction& a) const {
  SymState n = s;
  switch (a.type) {
    case ActionType::kPick:
      n.loc[a.obj] = kInAir;
      n.held[a.r1] = a.obj;
      n.grasp[a.r1] = a.grasp;
      break;
    case ActionType::kPlace:
      n.loc[a.obj] = static_cast<int16_t>(a.loc);
      n.held[a.r1] = -1;
      n.grasp[a.r1] = -1;
      break;
    case ActionType::kHandover:
      n.held[a.r1] = -1;
      n.grasp[a.r1] = -1;
      n.held[a.r2] = a.obj;
      n.grasp[a.r2] = a.grasp;
      break;
    case ActionType::kAddGrasp:
      n.held[a.r1] = a.obj;
      n.grasp[a.r1] = a.grasp;
      break;
    case ActionType::kRelease:
      n.held[a.r1] = -1;
      n.grasp[a.r1] = -1;
      break;
    case ActionType::kAssemble: {
      const StepInterface& st = world_.interface(a.obj);
      const int16_t base_loc = s.loc[st.base];
      n.loc[a.obj] = base_loc >= 0
                         ? static_cast<int16_t>(const_cast<TaskTables&>(tables_).DerivedLocation(
                               a.obj, base_loc, tables_.location(base_loc).X_WA))
                         : kInAir;
      n.loc[st.moved] = kInactive;
      n.loc[st.base] = kInactive;
      for (int r = 0; r < n_robots_; ++r) {
        if (n.held[r] == st.moved || n.held[r] == st.base) n.held[r] = static_cast<int16_t>(a.obj);
      }
      break;
    }
  }
  return n;
}

bool TaskSearch::CheapPick(int robot, int node, int loc, int grasp) {
  std::uint64_t key = HashMix(HashMix(HashMix(HashMix(101, robot), node), loc), grasp);
  if (auto it = cheap_.find(key); it != cheap_.end()) return Recall(key, it->second);
  const Iso3 X_WA = tables_.location(loc).X_WA;
  const Iso3 target = solver_.GraspTarget(X_WA, grasp);
  bool ok = solver_.InReach(robot, target);
  CheckSubject about;
  about.object = node;
  about.robot = robot;
  about.grasp = grasp;
  about.loc = loc;
  if (!ok)
    tally_.Add(Gate::kReach,
               "'" + world_.robots[robot].name + "' cannot reach grasp " +
                   std::to_string(tables_.grasp(grasp).index) + " of '" +
                   world_.tree->nodes[node].name + "' where it rests",
               about);
  if (ok && !solver_.ClearOfTable(robot, target, solver_.GraspOpening(grasp))) {
    ok = false;
    CheckSubject hit = about;
    hit.hit_table = true;
    tally_.Add(Gate::kGripperTable,
               "grasp " + std::to_string(tables_.grasp(grasp).index) + " of '" +
                   world_.tree->nodes[node].name +
                   "' puts the gripper into the table where it rests",
               hit);
  }
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
    const std::uint64_t lp_key =
        HashMix(HashMix(HashMix(1, static_cast<std::uint64_t>(loc) + 100), robot), grasp);
    ok = solver_.Wrench(WrenchGate::kTransport, {&obj, 1}, -1, lp_key, &why);
    if (!ok) tally_.Add(Gate::kWrenchTransport, why, about);
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
  std::vector<std::pair<long long, std::string>> reasons = {
      {table, "gripper into the table"},
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
  if (auto it = cheap_.find(key); it != cheap_.end()) return Recall(key, it->second);
  const Iso3 X_WA = tables_.location(loc).X_WA;
  const Iso3 target = solver_.GraspTarget(X_WA, grasp);
  bool ok = solver_.InReach(robot, target);
  CheckSubject about;
  about.object = node;
  about.robot = robot;
  about.grasp = grasp;
  about.loc = loc;
  if (!ok)
    tally_.Add(Gate::kReach,
               "'" + world_.robots[robot].name + "' cannot reach to set '" +
                   world_.tree->nodes[node].name + "' down there",
               about);
  if (ok && !solver_.ClearOfTable(robot, target, solver_.GraspOpening(grasp))) {
    ok = false;
    CheckSubject hit = about;
    hit.hit_table = true;
    tally_.Add(Gate::kGripperTable,
               "setting '" + world_.tree->nodes[node].name + "' down with grasp " +
                   std::to_string(tables_.grasp(grasp).index) + " puts the gripper into the table",
               hit);
  }
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
  if (auto it = cheap_.find(key); it != cheap_.end()) return Recall(key, it->second);
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
  // Context-free: no gripper may touch the other input at the mating pose.
  {
    const Iso3 X = b_rests ? tables_.location(s.loc[m.base]).X_WA : Iso3::Identity();
    for (const auto& [r, g] : mh) {
      if (ok && !solver_.GripperClear(r, g, X, m.base, X)) {
        ok = false;
        tally_.Add(Gate::kCollision,
                   "the gripper of '" + world_.robots[r].name + "' at grasp " +
                       std::to_string(tables_.grasp(g).index) + " of '" +
                       world_.tree->nodes[m.moved].name + "' hits '" +
                       world_.tree->nodes[m.base].name + "' when mated",
                   about(r, g, m.moved, m.base));
      }
    }
    for (const auto& [r, g] : bh) {
      if (ok && !solver_.GripperClear(r, g, X, m.moved, X)) {
        ok = false;
        tally_.Add(Gate::kCollision,
                   "the gripper of '" + world_.robots[r].name + "' at grasp " +
                       std::to_string(tables_.grasp(g).index) + " of '" +
                       world_.tree->nodes[m.base].name + "' hits '" +
                       world_.tree->nodes[m.moved].name + "' when mated",
                   about(r, g, m.base, m.moved));
      }
    }
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
      ok = solver_.Wrench(WrenchGate::kAssembly, objs, m.step,
                          AssemblyLpKey(m.step, s.loc[m.base], mh, bh), &why);
      if (!ok) tally_.Add(Gate::kWrenchAssembly, why, about(r0, g0, m.moved, -1));
    }
  } else {
    ok = solver_.AirAssemblyPossible(m.step, mh, bh, key, &why);
    if (!ok) tally_.Add(Gate::kWrenchAssembly, why, about(r0, g0, m.moved, -1));
  }
  Remember(key, ok);
  return ok;
}

void TaskSearch::Successors(const SymState& s, const Milestone& m, const Resolution& res,
                            std::vector<std::pair<TaskAction, SymState>>& out) {
  if (m.flat) {
    FlatSuccessors(s, res, out);
    return;
  }
  out.clear();
  const bool done = s.loc[m.step] != kInactive;
  int focus[2] = {-1, -1};
  int n_focus = 0;
  if (!done) {
    focus[n_focus++] = m.moved;
    focus[n_focus++] = m.base;
  } else if (m.final) {
    focus[n_focus++] = m.step;
  }
  auto push = [&](const TaskAction& a) { out.push_back({a, Apply(s, a)}); };
  const TableSlots& slots = world_.pre->table_slots;

  for (int r = 0; r < n_robots_; ++r) {
    if (s.held[r] < 0) {
      for (int f = 0; f < n_focus; ++f) {
        const int o = focus[f];
        const int16_t loc = s.loc[o];
        const int holders = s.NumHolders(o);
        const std::vector<int>& ids = GraspIds(o, r);
        const int n_grasps = std::min<int>(res.grasps, static_cast<int>(ids.size()));
        // Pick a resting object nobody holds.
        if (loc >= 0 && holders == 0 && !done) {
          for (int i = 0; i < n_grasps; ++i) {
            if (!CheapPick(r, o, loc, ids[i])) continue;
            TaskAction a;
            a.type = ActionType::kPick;
            a.r1 = static_cast<int8_t>(r);
            a.obj = static_cast<int16_t>(o);
            a.grasp = ids[i];
            push(a);
          }
        }
        // Add a grasp: a brace on a resting base, or a second hand on an object in the air.
        const bool brace = loc >= 0 && o == m.base && !done;
        const bool carry = loc == kInAir && holders >= 1;
        if ((brace || carry) && holders < options_.max_holders) {
          for (int i = 0; i < n_grasps; ++i) {
            bool apart = true;
            for (int q = 0; q < n_robots_; ++q) {
              if (s.held[q] == o && !HandsApart(q, s.grasp[q], r, ids[i])) apart = false;
            }
            if (!apart) continue;
            if (loc >= 0 && !CheapPick(r, o, loc, ids[i])) continue;
            TaskAction a;
            a.type = ActionType::kAddGrasp;
            a.r1 = static_cast<int8_t>(r);
            a.obj = static_cast<int16_t>(o);
            a.grasp = ids[i];
            push(a);
          }
        }
        // Handover from a sole holder in the air.
        if (loc == kInAir && holders == 1) {
          int giver = -1;
          for (int q = 0; q < n_robots_; ++q) {
            if (s.held[q] == o) giver = q;
          }
          for (int i = 0; i < n_grasps; ++i) {
            if (!HandsApart(giver, s.grasp[giver], r, ids[i])) continue;
            TaskAction a;
            a.type = ActionType::kHandover;
            a.r1 = static_cast<int8_t>(giver);
            a.r2 = static_cast<int8_t>(r);
            a.obj = static_cast<int16_t>(o);
            a.grasp = ids[i];
            push(a);
          }
        }
      }
      continue;
    }
    // r holds something.
    const int o = s.held[r];
    const int16_t loc = s.loc[o];
    const int holders = s.NumHolders(o);
    if (loc >= 0 || holders >= 2) {
      TaskAction a;
      a.type = ActionType::kRelease;
      a.r1 = static_cast<int8_t>(r);
      a.obj = static_cast<int16_t>(o);
      push(a);
    }
    if (loc == kInAir && holders == 1) {
      const auto& placements = world_.pre->subassemblies[o].placements;
      const int n_place = std::min<int>(res.placements, static_cast<int>(placements.size()));
      int slots_used = 0;
      for (size_t si = 0; si < slots.slots.size() && slots_used < res.slots; ++si) {
        const TableSlot& slot = slots.slots[si];
        if (std::find(slot.robots.begin(), slot.robots.end(), r) == slot.robots.end()) continue;
        // Skip slots next to another resting object.
        bool free = true;
        const Aabb& box_o = world_.pre->subassemblies[o].aabb_A;
        const double r_o = 0.5 * (box_o.max - box_o.min).head<2>().norm();
        for (int n = 0; n < world_.num_nodes && free; ++n) {
          if (n == o || s.loc[n] < 0) continue;
          const Aabb& box_n = world_.pre->subassemblies[n].aabb_A;
          const double r_n = 0.5 * (box_n.max - box_n.min).head<2>().norm();
          const Vec3 c_n =
              tables_.location(s.loc[n]).X_WA * Vec3(world_.pre->subassemblies[n].com_A);
          if ((c_n - slot.p_W).head<2>().norm() < r_o + r_n) free = false;
        }
        if (!free) continue;
        ++slots_used;
        const int n_yaws = static_cast<int>(slots.yaws_rad.size());
        const int yaw_step = std::max(1, n_yaws / std::max(1, std::min(res.yaws, n_yaws)));
        for (int p = 0; p < n_place; ++p) {
          for (int y = 0; y < n_yaws; y += yaw_step) {
            const Iso3 X = PlacementPose(slot, slots.yaws_rad[y], placements[p]);
            const int id = tables_.PlacedLocation(o, p, static_cast<int>(si), y, X);
            if (!CheapPlace(r, o, id, s.grasp[r])) continue;
            TaskAction a;
            a.type = ActionType::kPlace;
            a.r1 = static_cast<int8_t>(r);
            a.obj = static_cast<int16_t>(o);
            a.loc = id;
            push(a);
          }
        }
      }
    }
  }
  // Assemble.
  if (!done && s.loc[m.moved] == kInAir && s.NumHolders(m.moved) >= 1 &&
      (s.loc[m.base] >= 0 || s.NumHolders(m.base) >= 1) && TargetAllows(s, m) &&
      CheapAssemble(s, m)) {
    TaskAction a;
    a.type = ActionType::kAssemble;
    a.obj = static_cast<int16_t>(m.step);
    push(a);
  }
}

TaskSearch::SearchStatus TaskSearch::BestFirst(
    const SymState& s0, const Milestone& m, const Resolution& res, int effort,
    const std::set<std::uint64_t>& excluded,
    const std::unordered_map<std::uint64_t, bool>& dead_ends,
    const std::unordered_set<std::uint64_t>& forbidden, long long node_budget, int g0, int max_cost,
    std::vector<int>& path) {
  nodes_.clear();
  std::unordered_map<std::uint64_t, int> best_g;
  using Entry = std::tuple<int, int, long long, int>;  // f, -g, sequence, node
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  long long sequence = 0;
  const int h0 = Heuristic(s0, m);
  if (g0 + h0 > max_cost) return SearchStatus::kExhausted;
  nodes_.push_back({s0, 0, -1, {}});
  best_g[s0.Hash()] = 0;
  open.push({weight_ * h0, 0, sequence++, 0});
  const std::size_t memory_limit = static_cast<std::size_t>(options_.memory_limit_mb) << 20;
  std::vector<std::pair<TaskAction, SymState>> successors;
  while (!open.empty()) {
    if ((++expansions_ & 127) == 0) {
      if (ctx_.ShouldStop()) return SearchStatus::kStopped;
      if (MemoryBytes(open.size(), best_g.size()) > memory_limit) {
        return SearchStatus::kOutOfMemory;
      }
      // What the estimate misses (caches of the solver, the allocator's slack): the process's
      // growth since the planner started.
      if ((expansions_ & 4095) == 0) {
        const std::size_t rss = ResidentMemoryBytes();
        if (rss > rss0_ && rss - rss0_ > memory_limit) return SearchStatus::kOutOfMemory;
      }
    }
    const auto [f, neg_g, seq, index] = open.top();
    open.pop();
    const int g = nodes_[index].g;
    const std::uint64_t h = nodes_[index].s.Hash();
    if (best_g[h] < g) continue;
    if (IsGoal(nodes_[index].s, m, excluded)) {
      path.clear();
      for (int i = index; i > 0; i = nodes_[i].parent) path.push_back(i);
      std::reverse(path.begin(), path.end());
      return SearchStatus::kFound;
    }
    if (static_cast<long long>(nodes_.size()) > node_budget) return SearchStatus::kNodeLimit;
    const SymState s = nodes_[index].s;
    Successors(s, m, res, successors);
    for (auto& [a, s2] : successors) {
      const std::uint64_t edge = EdgeKey(s, a);
      auto failed = failed_level_.find(edge);
      if (failed != failed_level_.end() && failed->second >= effort) continue;
      if (!dead_ends.empty() && dead_ends.contains(edge)) continue;
      const int g2 = g + 1;
      const std::uint64_t h2 = s2.Hash();
      if (!forbidden.empty() && forbidden.contains(h2)) continue;
      auto [it, inserted] = best_g.try_emplace(h2, g2);
      if (!inserted) {
        if (it->second <= g2) continue;
        it->second = g2;
      }
      const int hv = Heuristic(s2, m);
      if (g0 + g2 + hv > max_cost) continue;  // plan improvement: cannot beat the bound
      const int child = static_cast<int>(nodes_.size());
      nodes_.push_back({std::move(s2), g2, index, a});
      open.push({g2 + weight_ * hv, -g2, sequence++, child});
    }
  }
  return SearchStatus::kExhausted;
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

PlanAction TaskSearch::MakeAction(const SymState& s, const TaskAction& a, const EdgeOutcome& e,
                                  int milestone) const {
  PlanAction p;
  p.type = a.type;
  p.milestone = milestone;
  p.edge = EdgeKey(s, a);
  p.keyframe = e.keyframe;
  p.approach = e.approach;
  auto hold = [&](int robot, int grasp_id) {
    const GraspRef& g = tables_.grasp(grasp_id);
    PlanHold h;
    h.robot = robot;
    h.grasp.subassembly = g.subassembly;
    h.grasp.index = g.index;
    h.grasp.part = g.part;
    h.grasp.X_PG = g.X_PG;
    h.grasp.width_m = g.width_m;
    return h;
  };
  switch (a.type) {
    case ActionType::kPick:
    case ActionType::kAddGrasp:
      p.robots = {a.r1};
      p.objects = {a.obj};
      p.grasps = {hold(a.r1, a.grasp)};
      break;
    case ActionType::kPlace: {
      p.robots = {a.r1};
      p.objects = {a.obj};
      p.grasps = {hold(a.r1, s.grasp[a.r1])};
      p.placement = tables_.location(a.loc).placement;
      break;
    }
    case ActionType::kRelease:
      p.robots = {a.r1};
      p.objects = {a.obj};
      p.grasps = {hold(a.r1, s.grasp[a.r1])};
      break;
    case ActionType::kHandover:
      p.robots = {a.r1, a.r2};
      p.objects = {a.obj};
      p.grasps = {hold(a.r1, s.grasp[a.r1]), hold(a.r2, a.grasp)};
      break;
    case ActionType::kAssemble: {
      const StepInterface& st = world_.interface(a.obj);
      p.objects = {st.moved, st.base, a.obj};
      for (int node : {st.moved, st.base}) {
        for (int r = 0; r < n_robots_; ++r) {
          if (s.held[r] == node) {
            p.robots.push_back(r);
            p.grasps.push_back(hold(r, s.grasp[r]));
          }
        }
      }
      break;
    }
  }
  return p;
}

std::string TaskSearch::StepWords(int step) const {
  const StepInterface& st = world_.interface(step);
  return "'" + world_.tree->nodes[step].name + "' (moving '" + world_.tree->nodes[st.moved].name +
         "' onto '" + world_.tree->nodes[st.base].name + "')";
}

MilestoneResult TaskSearch::Fill(int index, int step, int next_step, const SymState& s0,
                                 const ContState& c0, const std::set<std::uint64_t>& excluded,
                                 const FillLimits& limits) {
  const auto start = Clock::now();
  const Milestone m = StepMilestone(step, next_step);
  weight_ = limits.weight >= 0 ? limits.weight : default_weight_;
  tally_ = GateTally{};
  tallied_.clear();
  fill_failures_ = 0;
  MilestoneResult result;
  const std::string words = "milestone " + std::to_string(index + 1) + " " + StepWords(step);
  if (std::string why; !AssemblyPossible(m, &why)) {
    const std::string reason =
        "no combination of grasps and supports balances the mating wrench, whatever the "
        "robots' reach: " +
        why;
    result.failure = words + ": " + reason;
    FailureCase fc;
    fc.check = std::string(GateName(Gate::kWrenchAssembly));
    fc.count = 1;
    fc.text = reason;
    fc.example = why;
    fc.object = m.moved;
    result.start = SceneOf(s0, c0);
    fc.scene = result.start;
    result.cases = {std::move(fc)};
    return result;
  }
  const int levels = 3;
  std::string abstract_failure;  // why the backward abstraction found no way, at the last level
  auto finish = [&]() {
    target_ = AssemblyTarget{};
    search_s_ += std::chrono::duration<double>(Clock::now() - start).count();
  };
  for (int level = 0; level < levels; ++level) {
    const Resolution res = ResolutionAt(level);
    if (use_backward_) {
      const auto t0 = Clock::now();
      BuildBackward(m, res, s0);
      bwd_s_ += std::chrono::duration<double>(Clock::now() - t0).count();
      if (ctx_.Logs("task")) {
        ctx_.Log("task", StrFormat("milestone %d level %d: backward distance %d at the start",
                                   index, level, BackwardDistance(s0)));
      }
      if (!backward_.why.empty()) {
        // The relaxation cannot reach the assembly: neither can the search at this resolution.
        abstract_failure = backward_.why;
        if (level + 1 < levels) ++widenings_;
        continue;
      }
      abstract_failure.clear();  // this level searches: its failures are the report
    }
    std::vector<AssemblyTarget> targets{AssemblyTarget{}};
    if (optimistic_) targets = OptimisticTargets(m, res, s0);
    for (const AssemblyTarget& target : targets) {
      target_ = target;
      const SearchStatus status = Rounds(index, m, res, s0, c0, excluded, limits, result);
      if (status != SearchStatus::kExhausted) {
        finish();
        return result;
      }
    }
    if (optimistic_ && targets.empty()) {
      abstract_failure = "no assembly grasp of '" + world_.tree->nodes[m.moved].name +
                         "' with a support of '" + world_.tree->nodes[m.base].name +
                         "' balances the mating wrench";
    }
    if (level + 1 < levels) ++widenings_;
  }
  finish();
  result.failure =
      words + ": no plan with every grasp, placement and effort level" +
      (limits.max_cost < (1 << 30) ? " within " + std::to_string(limits.max_cost) + " actions"
                                   : std::string()) +
      "; " + (abstract_failure.empty() ? tally_.Summary() : abstract_failure);
  if (abstract_failure.empty()) {
    Explain(s0, c0, result);
  } else {
    FailureCase fc;
    fc.check = "abstraction";
    fc.count = 1;
    fc.text = abstract_failure;
    fc.example = abstract_failure;
    fc.object = m.moved;
    result.start = SceneOf(s0, c0);
    fc.scene = result.start;
    result.cases = {std::move(fc)};
  }
  return result;
}

int TaskSearch::StartHeuristic(int step, int next_step, const SymState& s) {
  const Milestone m = StepMilestone(step, next_step);
  if (use_backward_) BuildBackward(m, ResolutionAt(2), s);
  return Heuristic(s, m);
}

TaskSearch::SearchStatus TaskSearch::Rounds(int index, const Milestone& m, const Resolution& res,
                                            const SymState& s0, const ContState& c0,
                                            const std::set<std::uint64_t>& excluded,
                                            const FillLimits& limits, MilestoneResult& result) {
  // The committed prefix: validated states from s0 on. The search starts from its last state;
  // a candidate plan's validated edges are committed (greedy, like the paper's lazy greedy fill);
  // when the search from a committed state finds nothing, that state is abandoned (its entering
  // edge marked a dead end for this resolution and effort) and the search backs up one state.
  struct Committed {
    SymState s;
    ContState c;
    std::uint64_t entering_edge = 0;
  };
  const int max_actions =
      std::min(limits.max_cost,
               m.flat ? kMaxMilestoneActions *
                            static_cast<int>(window_.empty() ? flat_order_.size() : window_.size())
                      : kMaxMilestoneActions);
  // Flat lazy searches the whole task at once: only the memory limit bounds it.
  const long long max_nodes = limits.max_nodes > 0 ? limits.max_nodes : options_.max_nodes;
  const long long root_budget = target_.rm >= 0 ? std::min(max_nodes, kTargetNodes)
                                : !m.flat       ? max_nodes
                                : window_.empty()
                                    ? (1LL << 62)
                                    : max_nodes * static_cast<long long>(window_.size());
  const long long local_budget = m.flat ? max_nodes : std::min(max_nodes, kLocalNodes);
  auto stop = [&](SearchStatus status) {
    result.stopped = status == SearchStatus::kStopped;
    result.out_of_memory = status == SearchStatus::kOutOfMemory;
    result.failure = tally_.Summary();
    Explain(s0, c0, result);
    return status;
  };
  std::vector<int> path;
  int target_failures = 0;
  for (int effort = 0; effort <= options_.max_effort; ++effort) {
    bool suspended_below = false;  // an edge that failed at this effort could be retried
    std::vector<Committed> prefix{{s0, c0, 0}};
    std::vector<PlanAction> actions;
    std::unordered_map<std::uint64_t, bool> dead_ends;  // edges into abandoned states
    int root_failures = 0;
    int round_failures = 0;
    std::unordered_set<std::uint64_t> on_prefix;  // states the committed prefix visited
    while (!prefix.empty()) {
      on_prefix.clear();
      for (const Committed& p : prefix) on_prefix.insert(p.s.Hash());
      const int g0 = static_cast<int>(prefix.size()) - 1;
      SearchStatus status =
          BestFirst(prefix.back().s, m, res, effort, excluded, dead_ends, on_prefix,
                    prefix.size() == 1 ? root_budget : local_budget, g0, max_actions, path);
      if (ctx_.Logs("task")) {
        ctx_.Log("task", StrFormat("milestone %d effort %d depth %d: status %d, %zu nodes, path %zu",
                                   index, effort, g0, static_cast<int>(status), nodes_.size(),
                                   path.size()));
      }
      if (status == SearchStatus::kStopped || status == SearchStatus::kOutOfMemory) {
        return stop(status);
      }
      if (status == SearchStatus::kFound && g0 + static_cast<int>(path.size()) > max_actions) {
        status = SearchStatus::kExhausted;  // too long: treat as a dead end
      }
      if (status != SearchStatus::kFound) {
        // Nothing from here: abandon this state.
        if (prefix.size() == 1) break;
        dead_ends[prefix.back().entering_edge] = true;
        prefix.pop_back();
        actions.pop_back();
        continue;
      }
      // Validate the candidate plan edge by edge, committing what holds.
      bool valid = true;
      for (int node_index : path) {
        if (ctx_.ShouldStop()) return stop(SearchStatus::kStopped);
        const SymState& s = prefix.back().s;
        const ContState& c = prefix.back().c;
        const TaskAction a = nodes_[node_index].a;
        const SymState next = nodes_[node_index].s;
        const std::uint64_t edge = EdgeKey(s, a);
        const std::uint64_t witness_key = HashMix(c.Fingerprint(s), a.Hash());
        auto w = witnesses_.find(witness_key);
        if (w == witnesses_.end()) {
          auto failed = failed_level_.find(edge);
          const int edge_level = failed == failed_level_.end() ? 0 : failed->second + 1;
          // The first failure of each collision-like gate in a milestone keeps its picture.
          solver_.set_explain(tally_.count[static_cast<int>(Gate::kCollision)] == 0 ||
                              tally_.count[static_cast<int>(Gate::kSkill)] == 0 ||
                              tally_.count[static_cast<int>(Gate::kApproach)] == 0);
          EdgeOutcome outcome = solver_.Validate(s, c, a, next, edge_level, HashMix(seed_, edge));
          solver_.set_explain(false);
          if (!outcome.ok) {
            if (ctx_.Logs("task")) {
              ctx_.Log("task", StrFormat("  edge %s r%d r%d obj %d g%d l%d: %s: %s%s",
                                         std::string(ToString(a.type)).c_str(), a.r1, a.r2, a.obj, a.grasp, a.loc,
                                         std::string(GateName(outcome.gate)).c_str(),
                                         outcome.message.c_str(),
                                         outcome.permanent ? " (permanent)" : ""));
            }
            CheckSubject about;
            about.object = a.obj;
            about.robot = a.type == ActionType::kHandover ? a.r2 : a.r1;
            about.grasp = a.grasp;
            about.loc = a.loc;
            if (a.type == ActionType::kAssemble) {
              about.object = world_.interface(a.obj).moved;
              about.robot = -1;
              for (int r = 0; r < n_robots_ && about.robot < 0; ++r) {
                if (s.held[r] == about.object) {
                  about.robot = r;
                  about.grasp = s.grasp[r];
                }
              }
            }
            if (about.loc < 0 && about.object >= 0 &&
                about.object < static_cast<int>(c.X_WA.size())) {
              about.X_WA = c.X_WA[about.object];
            }
            tally_.Add(outcome.gate, outcome.message, about);
            if (tally_.count[static_cast<int>(outcome.gate)] == 1) {
              tally_.scene[static_cast<int>(outcome.gate)] = std::move(outcome.scene);
            }
            failed_level_[edge] = outcome.permanent ? kPermanent : edge_level;
            if (++fill_failures_ > limits.max_failures) return SearchStatus::kExhausted;
            // Optimistic: an assembly with the target's grasps that fails several times is a
            // bad choice of target, not of the way there.
            if (target_.rm >= 0 && a.type == ActionType::kAssemble &&
                ++target_failures >= kTargetFailures) {
              return SearchStatus::kExhausted;
            }
            if (!outcome.permanent && edge_level < options_.max_effort) suspended_below = true;
            valid = false;
            break;
          }
          w = witnesses_.emplace(witness_key, std::move(outcome)).first;
        }
        actions.push_back(MakeAction(s, a, w->second,
                                     m.flat && !window_.empty() ? index + WindowDone(s) : index));
        prefix.push_back({next, w->second.next, edge});
      }
      if (!valid && ++round_failures > kRoundFailures) break;  // try more effort or width
      if (!valid && ++root_failures <= kRootFailures) {
        // Early on, search again from the milestone's start: shorter plans.
        prefix.resize(1);
        actions.clear();
      }
      if (valid) {
        result.ok = true;
        result.actions = std::move(actions);
        result.after.clear();
        for (size_t i = 1; i < prefix.size(); ++i)
          result.after.push_back({prefix[i].s, prefix[i].c});
        result.end = prefix.back().s;
        result.end_c = prefix.back().c;
        return SearchStatus::kFound;
      }
    }
    if (!suspended_below) break;  // more effort would search the same graph
  }
  return SearchStatus::kExhausted;
}

}  // namespace wrap
