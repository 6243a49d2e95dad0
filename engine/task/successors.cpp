// The actions of a symbolic state in the task search (search.h): pick, add a grasp (a brace or
// a second hand), handover, release, place and assemble, each passing its cheap checks
// (cheap_checks.cpp), the grasp ids of a node for a robot, and the state an action leads to.
#include <algorithm>
#include <span>

#include "grasp/table_slots.h"
#include "task/search.h"

namespace wrap {
namespace {

// An action of `type` by `robot` (-1: none) on `node`; the caller adds its grasp, receiver or
// location.
TaskAction ActionOn(ActionType type, int robot, int node) {
  TaskAction a;
  a.type = type;
  a.r1 = static_cast<int8_t>(robot);
  a.obj = static_cast<int16_t>(node);
  return a;
}

}  // namespace

const std::vector<int>& TaskSearch::GraspIds(int node, int robot) {
  const std::pair<int, int> key{node, world_.robots[robot].grasp_set};
  auto [it, inserted] = grasp_ids_.try_emplace(key);
  // Full-pad grasps when first asked; the reduced ones (after them in the set) once the last
  // resolution level allows them.
  const bool add_full = inserted;
  const bool add_reduced = reduced_grasps_ && reduced_ids_.insert(key).second;
  if (add_full || add_reduced) {
    if (const GraspSet* set = world_.grasp_set(node, robot)) {
      for (size_t i = 0; i < set->grasps.size(); ++i) {
        const Grasp& g = set->grasps[i];
        if ((g.type == GraspType::kFullPad ? add_full : add_reduced) == false) continue;
        GraspRef ref{node,      static_cast<int>(i), g.part, g.X_PG,
                     g.width_m, g.quality,           g.type, g.torque_scale};
        // Grasp sets of different end effectors of one node are told apart by the index offset.
        const int key_index = world_.robots[robot].grasp_set * 100000 + static_cast<int>(i);
        it->second.push_back(tables_.Grasp(node, key_index, ref));
      }
    }
  }
  return it->second;
}

const TaskSearch::GraspAxis& TaskSearch::AxisOf(int grasp) const {
  if (grasp >= static_cast<int>(grasp_axes_.size())) grasp_axes_.resize(grasp + 1);
  GraspAxis& axis = grasp_axes_[grasp];
  if (!axis.known) {
    const GraspRef& g = tables_.grasp(grasp);
    const Iso3 X_AG = world_.X_AP[g.part] * g.X_PG;
    axis.p_A = X_AG.translation();
    axis.z_A = X_AG.linear().col(2);
    const Aabb& box = world_.pre->subassemblies[g.subassembly].aabb_A;
    axis.small = (box.max - box.min).norm() < 0.15;
    axis.known = true;
  }
  return axis;
}

bool TaskSearch::GraspsApart(int grasp_a, int grasp_b) const {
  const GraspAxis& a = AxisOf(grasp_a);
  const GraspAxis& b = AxisOf(grasp_b);
  if ((a.p_A - b.p_A).norm() < 0.04) return false;
  // Two grippers coming from nearly the same side of an object collide; on a small object
  // (under 15 cm across) they need to come from opposite sides.
  const double limit = a.small ? 0.0 : 0.5;
  return a.z_A.dot(b.z_A) < limit;
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

void TaskSearch::Push(const SymState& s, const TaskAction& a, SuccessorList& out) const {
  out.push_back({a, Apply(s, a)});
}

void TaskSearch::PickSuccessors(const SymState& s, int robot, int node, std::span<const int> grasps,
                                SuccessorList& out) {
  // Pick a resting object nobody holds.
  const int16_t loc = s.loc[node];
  if (loc < 0 || s.NumHolders(node) != 0) return;
  const std::uint64_t neighbours = RestingNeighbours(s, node);
  for (int grasp : grasps) {
    if (!CheapPick(robot, node, loc, grasp) ||
        !ApproachClear(s, neighbours, robot, node, loc, grasp)) {
      continue;
    }
    TaskAction a = ActionOn(ActionType::kPick, robot, node);
    a.grasp = grasp;
    Push(s, a, out);
  }
}

void TaskSearch::AddGraspSuccessors(const SymState& s, const Milestone& m, bool done, int robot,
                                    int node, std::span<const int> grasps, SuccessorList& out) {
  // Add a grasp: a brace on a resting base, or a second hand on an object in the air.
  const int16_t loc = s.loc[node];
  const int holders = s.NumHolders(node);
  const bool brace = loc >= 0 && node == m.base && !done;
  const bool carry = loc == kInAir && holders >= 1;
  if (!(brace || carry) || holders >= options_.max_holders) return;
  const std::uint64_t neighbours = loc >= 0 ? RestingNeighbours(s, node) : 0;
  for (int grasp : grasps) {
    bool apart = true;
    for (int q = 0; q < n_robots_; ++q) {
      if (s.held[q] == node && !HandsApart(q, s.grasp[q], robot, grasp)) apart = false;
    }
    if (!apart) continue;
    if (loc >= 0 && (!CheapPick(robot, node, loc, grasp) ||
                     !ApproachClear(s, neighbours, robot, node, loc, grasp))) {
      continue;
    }
    TaskAction a = ActionOn(ActionType::kAddGrasp, robot, node);
    a.grasp = grasp;
    Push(s, a, out);
  }
}

void TaskSearch::HandoverSuccessors(const SymState& s, int robot, int node,
                                    std::span<const int> grasps, SuccessorList& out) {
  // Handover from a sole holder in the air.
  if (s.loc[node] != kInAir || s.NumHolders(node) != 1) return;
  int giver = -1;
  for (int q = 0; q < n_robots_; ++q) {
    if (s.held[q] == node) giver = q;
  }
  for (int grasp : grasps) {
    if (!HandsApart(giver, s.grasp[giver], robot, grasp)) continue;
    TaskAction a = ActionOn(ActionType::kHandover, giver, node);
    a.r2 = static_cast<int8_t>(robot);
    a.grasp = grasp;
    Push(s, a, out);
  }
}

void TaskSearch::ReleaseSuccessor(const SymState& s, int robot, SuccessorList& out) {
  // Let go of an object that rests or that another hand holds.
  const int o = s.held[robot];
  if (s.loc[o] < 0 && s.NumHolders(o) < 2) return;
  Push(s, ActionOn(ActionType::kRelease, robot, o), out);
}

void TaskSearch::PlaceSuccessors(const SymState& s, const Resolution& res, int robot,
                                 SuccessorList& out) {
  // Set down an object held by one hand alone: the first `res.slots` free table slots the robot
  // serves, the first `res.placements` stable placements, `res.yaws` yaws spread over the slot's.
  const int o = s.held[robot];
  if (s.loc[o] != kInAir || s.NumHolders(o) != 1) return;
  const TableSlots& slots = world_.pre->table_slots;
  const auto& placements = world_.pre->subassemblies[o].placements;
  const int n_place = std::min<int>(res.placements, static_cast<int>(placements.size()));
  int slots_used = 0;
  for (size_t si = 0; si < slots.slots.size() && slots_used < res.slots; ++si) {
    const TableSlot& slot = slots.slots[si];
    if (std::find(slot.robots.begin(), slot.robots.end(), robot) == slot.robots.end()) continue;
    if (!SlotFree(s, o, slot)) continue;
    ++slots_used;
    const int n_yaws = static_cast<int>(slots.yaws_rad.size());
    const int yaw_step = std::max(1, n_yaws / std::max(1, std::min(res.yaws, n_yaws)));
    for (int p = 0; p < n_place; ++p) {
      for (int y = 0; y < n_yaws; y += yaw_step) {
        const Iso3 X = PlacementPose(slot, slots.yaws_rad[y], placements[p]);
        const int id = tables_.PlacedLocation(o, p, static_cast<int>(si), y, X);
        if (!CheapPlace(robot, o, id, s.grasp[robot])) continue;
        TaskAction a = ActionOn(ActionType::kPlace, robot, o);
        a.loc = id;
        Push(s, a, out);
      }
    }
  }
}

bool TaskSearch::SlotFree(const SymState& s, int node, const TableSlot& slot) const {
  // Skip slots next to another resting object.
  const Aabb& box_o = world_.pre->subassemblies[node].aabb_A;
  const double r_o = 0.5 * (box_o.max - box_o.min).head<2>().norm();
  for (int n = 0; n < world_.num_nodes; ++n) {
    if (n == node || s.loc[n] < 0) continue;
    const Aabb& box_n = world_.pre->subassemblies[n].aabb_A;
    const double r_n = 0.5 * (box_n.max - box_n.min).head<2>().norm();
    const Vec3 c_n = tables_.location(s.loc[n]).X_WA * Vec3(world_.pre->subassemblies[n].com_A);
    if ((c_n - slot.p_W).head<2>().norm() < r_o + r_n) return false;
  }
  return true;
}

void TaskSearch::AssembleSuccessor(const SymState& s, const Milestone& m, SuccessorList& out) {
  // The milestone's step: the moved input in the air in some hand, the base resting or held.
  if (s.loc[m.moved] == kInAir && s.NumHolders(m.moved) >= 1 &&
      (s.loc[m.base] >= 0 || s.NumHolders(m.base) >= 1) && TargetAllows(s, m) &&
      CheapAssemble(s, m)) {
    Push(s, ActionOn(ActionType::kAssemble, -1, m.step), out);
  }
}

void TaskSearch::Successors(const SymState& s, const Milestone& m, const Resolution& res,
                            SuccessorList& out) {
  if (m.flat) {
    FlatSuccessors(s, res, out);
    return;
  }
  out.clear();
  const bool done = s.loc[m.step] != kInactive;
  // The objects free hands may take: the step's inputs, or the product of the last step.
  int focus[2] = {-1, -1};
  int n_focus = 0;
  if (!done) {
    focus[n_focus++] = m.moved;
    focus[n_focus++] = m.base;
  } else if (m.final) {
    focus[n_focus++] = m.step;
  }
  for (int r = 0; r < n_robots_; ++r) {
    if (s.held[r] >= 0) {
      ReleaseSuccessor(s, r, out);
      PlaceSuccessors(s, res, r, out);
      continue;
    }
    for (int f = 0; f < n_focus; ++f) {
      const int o = focus[f];
      const std::vector<int>& ids = GraspIds(o, r);
      const std::span<const int> grasps(ids.data(),
                                        std::min<int>(res.grasps, static_cast<int>(ids.size())));
      if (!done) PickSuccessors(s, r, o, grasps, out);
      AddGraspSuccessors(s, m, done, r, o, grasps, out);
      HandoverSuccessors(s, r, o, grasps, out);
    }
  }
  if (!done) AssembleSuccessor(s, m, out);
}

}  // namespace wrap
