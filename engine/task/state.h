// The search state of the task planner (paper §IV-D, S_fwd) and its actions: symbolic (which
// objects exist, where they rest, who holds them with which grasp) and continuous (joints of
// every robot, pose of every object), plus the tables that intern grasps and resting locations.
#pragma once

#include <cstdint>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include "core/pose.h"
#include "model/project.h"
#include "robot/kinematics.h"
#include "task/plan.h"

namespace wrap {

inline constexpr int16_t kInactive = -2;  ///< SymState::loc: the object does not exist (yet).
inline constexpr int16_t kInAir = -1;     ///< SymState::loc: the object is held in the air.

/// A grasp of the planner: a grasp-set entry (grasps carry over to bigger subassemblies).
struct GraspRef {
  int subassembly = -1;  ///< Node whose grasp set it is from.
  int index = -1;        ///< Index in that set.
  int part = -1;         ///< Held part.
  Iso3 X_PG = Iso3::Identity();
  double width_m = 0.0;
  double quality = 0.0;
  GraspType type = GraspType::kFullPad;  ///< Full-pad, partial-pad or fingertip.
  Vec3 torque_scale = Vec3::Ones();      ///< Its limits: GraspLimits(robot limits, scale).
};

/// A resting location: the pose of an object's assembly frame on the table.
struct Location {
  int node = -1;                 ///< Object it is a location of.
  Iso3 X_WA = Iso3::Identity();  ///< Pose.
  PlanPlacement placement;       ///< Where it came from (-1 fields: initial or derived pose).
};

/// Grasps and locations interned to small integers.
class TaskTables {
 public:
  int Grasp(int subassembly, int index, const GraspRef& ref);
  int PlacedLocation(int node, int placement, int slot, int yaw, const Iso3& X_WA);
  int InitialLocation(int node, const Iso3& X_WA);
  int DerivedLocation(int node, int from_location, const Iso3& X_WA);
  const GraspRef& grasp(int id) const { return grasps_[id]; }
  const Location& location(int id) const { return locations_[id]; }

 private:
  std::vector<GraspRef> grasps_;
  std::map<std::pair<int, int>, int> grasp_ids_;
  std::vector<Location> locations_;
  std::map<std::tuple<int, int, int, int, int>, int> location_ids_;
};

/// Symbolic state: per node its location (kInactive, kInAir or a location id), per robot the
/// object it holds (-1: free) and the grasp id.
struct SymState {
  std::vector<int16_t> loc;
  std::vector<int16_t> held;
  std::vector<int32_t> grasp;
  bool operator==(const SymState&) const = default;
  std::uint64_t Hash() const;
  /// Robots holding `node`, ascending.
  int Holders(int node, int* out) const;
  int NumHolders(int node) const;
};

/// One action of the search.
struct TaskAction {
  ActionType type = ActionType::kPick;
  int8_t r1 = -1;     ///< The robot (giver for a handover); -1 for assemble.
  int8_t r2 = -1;     ///< Receiver of a handover.
  int16_t obj = -1;   ///< Object node; assemble: the step node.
  int32_t grasp = -1; ///< New grasp id (pick, add_grasp, handover).
  int32_t loc = -1;   ///< Location id (place).
  bool operator==(const TaskAction&) const = default;
  std::uint64_t Hash() const;
};

/// Continuous state: joints of every robot, pose of every node (meaningful while it exists).
struct ContState {
  std::vector<JointVector> q;
  std::vector<Iso3> X_WA;
  /// Fingerprint of the continuous data together with `sym` (rounded to 1e-7).
  std::uint64_t Fingerprint(const SymState& sym) const;
};

/// Mixes a value into a hash (splitmix64).
inline std::uint64_t HashMix(std::uint64_t h, std::uint64_t v) {
  std::uint64_t x = h ^ (v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Cache key of the assembly LP of `step` with the base resting at location `base_loc`, the moved
/// input held by `moved_holders` and the base by `base_holders` ((robot, grasp id) pairs): the
/// expansion's cheap check and the edge validation ask the same question under this key.
inline std::uint64_t AssemblyLpKey(int step, int base_loc,
                                   const std::vector<std::pair<int, int>>& moved_holders,
                                   const std::vector<std::pair<int, int>>& base_holders) {
  std::uint64_t key = HashMix(3, static_cast<std::uint64_t>(step));
  key = HashMix(key, static_cast<std::uint64_t>(base_loc) + 7);
  for (const auto& [r, g] : moved_holders) key = HashMix(HashMix(key, r), g);
  key = HashMix(key, 999);
  for (const auto& [r, g] : base_holders) key = HashMix(HashMix(key, r), g);
  return key;
}

/// Cache key of the search's cheap assembly check of `step` (the base resting at `base_loc`, or
/// in the air when -1) with those holders; the in-air check hands it on to the LP cache.
inline std::uint64_t CheapAssembleKey(int step, int base_loc,
                                      const std::vector<std::pair<int, int>>& moved_holders,
                                      const std::vector<std::pair<int, int>>& base_holders) {
  return HashMix(103, AssemblyLpKey(step, base_loc, moved_holders, base_holders));
}

}  // namespace wrap
