#include "task/state.h"

#include <cmath>

namespace wrap {

int TaskTables::Grasp(int subassembly, int index, const GraspRef& ref) {
  auto [it, inserted] =
      grasp_ids_.try_emplace({subassembly, index}, static_cast<int>(grasps_.size()));
  if (inserted) grasps_.push_back(ref);
  return it->second;
}

int TaskTables::PlacedLocation(int node, int placement, int slot, int yaw, const Iso3& X_WA) {
  auto [it, inserted] = location_ids_.try_emplace({node, 0, placement, slot, yaw},
                                                  static_cast<int>(locations_.size()));
  if (inserted) locations_.push_back({node, X_WA, {placement, slot, yaw}});
  return it->second;
}

int TaskTables::InitialLocation(int node, const Iso3& X_WA) {
  auto [it, inserted] =
      location_ids_.try_emplace({node, 1, 0, 0, 0}, static_cast<int>(locations_.size()));
  if (inserted) locations_.push_back({node, X_WA, {}});
  return it->second;
}

int TaskTables::DerivedLocation(int node, int from_location, const Iso3& X_WA) {
  auto [it, inserted] = location_ids_.try_emplace({node, 2, from_location, 0, 0},
                                                  static_cast<int>(locations_.size()));
  if (inserted) locations_.push_back({node, X_WA, {}});
  return it->second;
}

std::uint64_t SymState::Hash() const {
  std::uint64_t h = 0x5157;
  for (int16_t v : loc) h = HashMix(h, static_cast<std::uint16_t>(v));
  for (int16_t v : held) h = HashMix(h, static_cast<std::uint16_t>(v));
  for (int32_t v : grasp) h = HashMix(h, static_cast<std::uint32_t>(v));
  return h;
}

int SymState::Holders(int node, int* out) const {
  int n = 0;
  for (size_t r = 0; r < held.size(); ++r) {
    if (held[r] == node) out[n++] = static_cast<int>(r);
  }
  return n;
}

int SymState::NumHolders(int node) const {
  int n = 0;
  for (int16_t h : held) n += h == node;
  return n;
}

std::uint64_t TaskAction::Hash() const {
  std::uint64_t h = HashMix(0xac71, static_cast<std::uint64_t>(type));
  h = HashMix(h, static_cast<std::uint8_t>(r1));
  h = HashMix(h, static_cast<std::uint8_t>(r2));
  h = HashMix(h, static_cast<std::uint16_t>(obj));
  h = HashMix(h, static_cast<std::uint32_t>(grasp));
  return HashMix(h, static_cast<std::uint32_t>(loc));
}

std::uint64_t ContState::Fingerprint(const SymState& sym) const {
  std::uint64_t h = sym.Hash();
  auto mix = [&h](double v) { h = HashMix(h, static_cast<std::uint64_t>(std::llround(v * 1e7))); };
  for (const JointVector& qi : q) {
    for (int i = 0; i < qi.size(); ++i) mix(qi[i]);
  }
  for (size_t n = 0; n < X_WA.size(); ++n) {
    if (n < sym.loc.size() && sym.loc[n] == -2) continue;
    for (int i = 0; i < 3; ++i) mix(X_WA[n].translation()[i]);
    for (int i = 0; i < 9; ++i) mix(X_WA[n].linear().data()[i]);
  }
  return h;
}

}  // namespace wrap
