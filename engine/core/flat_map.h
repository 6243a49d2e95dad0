// FlatMap: a hash map from 64-bit keys to small values in one array (open addressing, linear
// probing), for the planner's hot caches, whose keys are already well-mixed hashes (HashMix).
// std::unordered_map allocates a node per entry and chases a pointer per lookup; here a lookup
// is a multiply and, mostly, one cache line. No iteration (nothing may depend on an order) and
// no erase; clear() keeps the capacity. Pointers to values stay valid until the next insert.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace wrap {

template <typename V>
class FlatMap {
 public:
  /// The value of `key`, or nullptr.
  V* find(std::uint64_t key) {
    if (size_ == 0) return nullptr;
    for (std::size_t i = Slot(key);; i = (i + 1) & mask_) {
      if (!used_[i]) return nullptr;
      if (slots_[i].first == key) return &slots_[i].second;
    }
  }
  const V* find(std::uint64_t key) const { return const_cast<FlatMap*>(this)->find(key); }
  bool contains(std::uint64_t key) const { return find(key) != nullptr; }

  /// Inserts (key, value) unless `key` is present; the value now stored and whether it was
  /// inserted (like std::unordered_map::try_emplace).
  std::pair<V*, bool> try_emplace(std::uint64_t key, const V& value) {
    if (2 * (size_ + 1) > slots_.size()) Grow();
    std::size_t i = Slot(key);
    for (; used_[i]; i = (i + 1) & mask_) {
      if (slots_[i].first == key) return {&slots_[i].second, false};
    }
    used_[i] = 1;
    slots_[i] = {key, value};
    ++size_;
    return {&slots_[i].second, true};
  }
  /// The value of `key`, inserted as V{} when absent.
  V& operator[](std::uint64_t key) { return *try_emplace(key, V{}).first; }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  /// Removes every entry; the capacity stays.
  void clear() {
    std::fill(used_.begin(), used_.end(), 0);
    size_ = 0;
  }

 private:
  std::size_t Slot(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9e3779b97f4a7c15ULL) >> shift_) & mask_;
  }
  void Grow() {
    std::vector<std::pair<std::uint64_t, V>> old_slots = std::move(slots_);
    std::vector<std::uint8_t> old_used = std::move(used_);
    const std::size_t capacity = old_slots.empty() ? 16 : 2 * old_slots.size();
    slots_.assign(capacity, {0, V{}});
    used_.assign(capacity, 0);
    mask_ = capacity - 1;
    shift_ = 64;
    for (std::size_t c = capacity; c > 1; c >>= 1) --shift_;
    size_ = 0;
    for (std::size_t i = 0; i < old_slots.size(); ++i) {
      if (old_used[i]) try_emplace(old_slots[i].first, old_slots[i].second);
    }
  }

  std::vector<std::pair<std::uint64_t, V>> slots_;
  std::vector<std::uint8_t> used_;
  std::size_t size_ = 0;
  std::size_t mask_ = 0;
  int shift_ = 64;
};

}  // namespace wrap
