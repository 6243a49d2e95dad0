// Collision queries of the world: sweep and prune over the body boxes (with the cache of pairs
// found apart), then the shape pairs of each candidate body pair; and the two-body test that
// ignores the filter.
#include <algorithm>

#include "robot/detail/collision_impl.h"

namespace wrap {

using detail::BodyData;
using detail::BoxesOverlap;
using detail::ShapeData;

bool CollisionWorld::Impl::BodyPairCollide(int i, int j, const CollisionRequest& request,
                                           CollisionResult* result, bool* hit, bool body_boxes) {
  const BodyData& bi = bodies[i];
  const BodyData& bj = bodies[j];
  for (int sa = bi.first; sa < bi.first + bi.count; ++sa) {
    const ShapeData& A = shapes[sa];
    if (body_boxes && !BoxesOverlap(A.lo, A.hi, bj.lo, bj.hi, request.margin_m)) continue;
    for (int sb = bj.first; sb < bj.first + bj.count; ++sb) {
      const ShapeData& B = shapes[sb];
      if (!BoxesOverlap(A.lo, A.hi, B.lo, B.hi, request.margin_m)) continue;
      if (result) ++result->narrowphase_tests;
      if (!ShapesCollide(A, B, request.margin_m)) continue;
      *hit = true;
      if (!result) return true;
      ShapePair pair{BodyId{i}, BodyId{j}, sa - bi.first, sb - bj.first, bi.X_WB, bj.X_WB};
      if (!result->collision) {
        result->collision = true;
        result->first = pair;
      }
      if (!request.all_pairs) return true;
      result->pairs.push_back(pair);
      if (static_cast<int>(result->pairs.size()) >= request.max_pairs) return true;
    }
  }
  return false;
}

// The order persists between queries, so the insertion sort is near linear when bodies move a
// little.
bool CollisionWorld::Impl::AnyCollision(const CollisionRequest& request, CollisionResult* result) {
  UpdateBounds();
  if (result) result->Clear();
  if (order.size() != bodies.size()) {
    order.resize(bodies.size());
    for (int k = 0; k < n(); ++k) order[k] = k;
  }
  for (std::size_t k = 1; k < order.size(); ++k) {
    const int v = order[k];
    const double key = bodies[v].lo.x();
    std::size_t m = k;
    while (m > 0 && bodies[order[m - 1]].lo.x() > key) {
      order[m] = order[m - 1];
      --m;
    }
    order[m] = v;
  }
  const double margin = request.margin_m;
  if (clean.size() != bodies.size() * bodies.size()) clean.assign(bodies.size() * bodies.size(), 0);
  bool hit = false;
  for (std::size_t ii = 0; ii < order.size(); ++ii) {
    const int i = order[ii];
    const BodyData& bi = bodies[i];
    if (!bi.active()) break;  // inactive bodies sort last
    const bool i_masked = (request.group_mask >> bi.group) & 1u;
    for (std::size_t jj = ii + 1; jj < order.size(); ++jj) {
      const int j = order[jj];
      const BodyData& bj = bodies[j];
      if (bj.lo.x() > bi.hi.x() + margin) break;
      if (!i_masked && !((request.group_mask >> bj.group) & 1u)) continue;
      if (!BoxesOverlap(bi.lo, bi.hi, bj.lo, bj.hi, margin)) continue;
      if (Allowed(i, j)) continue;
      const int a = std::min(i, j);
      const int b = std::max(i, j);
      const std::size_t pair = static_cast<std::size_t>(a) * bodies.size() + b;
      if (margin == 0.0 && clean[pair] > std::max(bodies[a].changed_at, bodies[b].changed_at)) {
        continue;
      }
      bool pair_hit = false;
      const bool done = BodyPairCollide(a, b, request, result, &pair_hit);
      if (pair_hit) {
        hit = true;
      } else if (margin == 0.0) {
        clean[pair] = epoch + 1;
      }
      if (done) return true;
    }
  }
  return hit;
}

bool CollisionWorld::AnyCollision(const CollisionRequest& request, CollisionResult* result) {
  return impl_->AnyCollision(request, result);
}

bool CollisionWorld::Collide(BodyId a, BodyId b, const CollisionRequest& request,
                             CollisionResult* result) {
  Impl& m = *impl_;
  m.body(a);
  m.body(b);
  // Bypasses the enabled flags: refresh the two bodies' shapes even when disabled.
  m.UpdatePair(a, b);
  if (result) result->Clear();
  bool hit = false;
  m.BodyPairCollide(a.value, b.value, request, result, &hit, /*body_boxes=*/false);
  return hit;
}

}  // namespace wrap
