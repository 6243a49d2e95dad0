// Internals shared by the task search's sources (search.cpp, successors.cpp, cheap_checks.cpp,
// lazy_search.cpp): the key of a symbolic edge and the mark of an edge that never holds.
#pragma once

#include <climits>
#include <cstdint>

#include "task/state.h"

namespace wrap {

/// TaskSearch's failed-level mark of an edge that fails at every effort level (or is banned).
inline constexpr int kPermanentFailure = INT_MAX;

/// The key of the symbolic edge taking action `a` from a state whose SymState::Hash is `s_hash`.
inline std::uint64_t EdgeKey(std::uint64_t s_hash, const TaskAction& a) {
  return HashMix(s_hash, a.Hash());
}

/// The key of the symbolic edge taking action `a` from `s` (PlanAction::edge).
inline std::uint64_t EdgeKey(const SymState& s, const TaskAction& a) {
  return EdgeKey(s.Hash(), a);
}

}  // namespace wrap
