#include "model/catalog.h"

#include <numbers>

namespace wrap {

namespace {

template <typename T>
const T* FindByName(const std::vector<T>& items, std::string_view name) {
  for (const T& item : items) {
    if (item.name == name) return &item;
  }
  return nullptr;
}

template <typename T>
std::string JoinNames(const std::vector<T>& items) {
  std::string out;
  for (const T& item : items) {
    if (!out.empty()) out += ", ";
    out += item.name;
  }
  return out;
}

// Husky dual-UR5e mount (../shared/robots ROBOTS.md §4.2-4.3, verified): a mobile base's pose is
// its footprint on the floor; base_link stands 0.13228 m above it, the bulkhead at z 0.224 in
// base_link, each arm base 0.1225 forward, 0.14891 to the side, 0.13371 up, rolled 45 deg outward
// (arm bases 0.490 m above the floor).
constexpr double kHuskyBaseLinkHeight_m = 0.1651 - 0.03282;

Pose HuskyMount(double side) {
  Pose p;
  p.xyz = Vec3(0.1225, side * 0.14891, kHuskyBaseLinkHeight_m + 0.224 + 0.13371);
  p.rpy = side > 0 ? Vec3(0.785398, 0.0, 3.14159) : Vec3(0.785398, 0.0, 0.0);
  return p;
}

}  // namespace

const std::vector<RobotModelInfo>& RobotModels() {
  // Reach and payload from ../shared/robots: UR5e 0.85 m / 5 kg, UR10e 1.3 m / 12.5 kg,
  // OpenArm shoulder-to-TCP 0.617 m / 4.1 kg nominal.
  static const std::vector<RobotModelInfo> kModels = {
      {"ur5e", "Universal Robots UR5e", 6, 0.85, 5.0},
      {"ur10e", "Universal Robots UR10e", 6, 1.30, 12.5},
      {"openarm", "Enactic OpenArm v1.0", 7, 0.617, 4.1},
  };
  return kModels;
}

const std::vector<EndEffectorInfo>& EndEffectors() {
  // TCP offsets: 2F-85 0.1493 m (+0.01 m coupling not included), VGC10 one-cup lip ~0.179 m,
  // OpenArm hand: hand frame 0.1001 + TCP 0.08 from link8.
  static const std::vector<EndEffectorInfo> kEffectors = {
      {"robotiq_2f85", "Robotiq 2F-85 two-finger gripper", EndEffectorKind::kTwoFinger, 0.1493},
      {"vacuum_cup", "Single 40 mm vacuum cup (OnRobot VGC10 class)", EndEffectorKind::kVacuum,
       0.179},
      {"openarm_hand", "OpenArm parallel gripper", EndEffectorKind::kTwoFinger, 0.1801},
  };
  return kEffectors;
}

const std::vector<MobileBaseInfo>& MobileBasePresets() {
  static const std::vector<MobileBaseInfo> kBases = {
      {"husky_dual_ur5e",
       "Clearpath Husky A200 with the dual-UR5e bulkhead",
       {{"left", HuskyMount(+1.0)}, {"right", HuskyMount(-1.0)}}},
  };
  return kBases;
}

const RobotModelInfo* FindRobotModel(std::string_view name) {
  return FindByName(RobotModels(), name);
}
const EndEffectorInfo* FindEndEffector(std::string_view name) {
  return FindByName(EndEffectors(), name);
}
const MobileBaseInfo* FindMobileBasePreset(std::string_view name) {
  return FindByName(MobileBasePresets(), name);
}

std::string RobotModelNames() { return JoinNames(RobotModels()); }
std::string EndEffectorNames() { return JoinNames(EndEffectors()); }
std::string MobileBasePresetNames() { return JoinNames(MobileBasePresets()); }

std::string_view ToString(EndEffectorKind kind) {
  return kind == EndEffectorKind::kTwoFinger ? "two-finger" : "vacuum";
}

}  // namespace wrap
