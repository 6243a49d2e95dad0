// Welding of coincident vertices while a triangle mesh is assembled (shared by the mesh
// importers: assimp's meshes in mesh_import.cpp, OpenCASCADE's face triangulations in
// step_import.cpp).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/pose.h"

namespace wrap::detail {

/// Integer cell of a point in a grid of spacing `cell` [m].
struct CellKey {
  int64_t x = 0, y = 0, z = 0;
  bool operator==(const CellKey&) const = default;
};

struct CellKeyHash {
  size_t operator()(const CellKey& k) const {
    uint64_t h = static_cast<uint64_t>(k.x) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<uint64_t>(k.y) + 0x632BE59BD9B4E019ull + (h << 6) + (h >> 2);
    h ^= static_cast<uint64_t>(k.z) + 0x85EBCA77C2B2AE63ull + (h << 6) + (h >> 2);
    return static_cast<size_t>(h);
  }
};

/// Merges vertices into a growing vertex list: exact duplicates (`tolerance` 0) or points within
/// `tolerance` of an earlier kept vertex (grid hash with cells of the tolerance's size, so only
/// the 27 cells around a point can hold a match). The first vertex of a cluster is kept, so the
/// result depends only on the input order.
class VertexWelder {
 public:
  explicit VertexWelder(double tolerance) : tolerance_(tolerance) {}

  /// Index of `p` in `vertices()`, adding it when no kept vertex matches.
  int Add(const Vec3& p) {
    if (tolerance_ <= 0.0) {
      // +0.0 folds -0 into +0 so that the two compare and hash equal.
      const CellKey key{std::bit_cast<int64_t>(p.x() + 0.0), std::bit_cast<int64_t>(p.y() + 0.0),
                        std::bit_cast<int64_t>(p.z() + 0.0)};
      const auto [it, inserted] = cells_.try_emplace(key, static_cast<int>(vertices_.size()));
      if (inserted) vertices_.push_back(p);
      return it->second;
    }
    const CellKey c = CellOf(p);
    const double tol2 = tolerance_ * tolerance_;
    int best = -1;
    for (int64_t dx = -1; dx <= 1; ++dx) {
      for (int64_t dy = -1; dy <= 1; ++dy) {
        for (int64_t dz = -1; dz <= 1; ++dz) {
          const auto range = multi_cells_.equal_range(CellKey{c.x + dx, c.y + dy, c.z + dz});
          for (auto it = range.first; it != range.second; ++it) {
            const int i = it->second;
            if ((vertices_[static_cast<size_t>(i)] - p).squaredNorm() <= tol2 &&
                (best < 0 || i < best)) {
              best = i;
            }
          }
        }
      }
    }
    if (best >= 0) return best;
    const int index = static_cast<int>(vertices_.size());
    vertices_.push_back(p);
    multi_cells_.emplace(c, index);
    return index;
  }

  std::vector<Vec3>& vertices() { return vertices_; }

 private:
  CellKey CellOf(const Vec3& p) const {
    // Clamped so that far points with a tiny tolerance cannot overflow the integer cell.
    const auto cell = [&](double x) {
      return static_cast<int64_t>(std::clamp(std::floor(x / tolerance_), -4e18, 4e18));
    };
    return CellKey{cell(p.x()), cell(p.y()), cell(p.z())};
  }

  double tolerance_ = 0.0;
  std::vector<Vec3> vertices_;
  std::unordered_map<CellKey, int, CellKeyHash> cells_;             // exact mode
  std::unordered_multimap<CellKey, int, CellKeyHash> multi_cells_;  // tolerance mode
};

}  // namespace wrap::detail
