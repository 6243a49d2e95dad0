// Distance queries of the world (the planner's clearance between robots): branch and bound over
// the body pairs of chosen groups, nearest bounding boxes first, and the distance between two
// bodies that ignores the filter.
#include <algorithm>
#include <cmath>

#include "robot/detail/collision_impl.h"

namespace wrap {

using detail::BodyData;
using detail::BoxDistance2;
using detail::ShapeData;

// Candidate body pairs sorted by box distance; stop when the next lower bound is no better than
// the best distance found.
template <typename PairFilter>
DistanceResult CollisionWorld::Impl::MinDistance(PairFilter&& keep,
                                                 const DistanceRequest& request) {
  UpdateBounds();
  DistanceResult out;
  out.distance = request.upper_bound_m;
  candidates.clear();
  // `bound`: the distance is at most this (the request's bound, or two inner balls' distance).
  double bound = request.upper_bound_m;
  for (int i = 0; i < n(); ++i) {
    const BodyData& bi = bodies[i];
    if (!bi.active()) continue;
    for (int j = i + 1; j < n(); ++j) {
      const BodyData& bj = bodies[j];
      if (!bj.active() || !keep(bi.group, bj.group) || Allowed(i, j)) continue;
      const double lb2 = BoxDistance2(bi.lo, bi.hi, bj.lo, bj.hi);
      if (lb2 > bound * bound) continue;
      const double balls = (bi.w_W - bj.w_W).norm() - bi.w_r - bj.w_r;
      bound = std::min(bound, std::max(0.0, balls));
      candidates.push_back({lb2, i, j});
    }
  }
  // Pairs kept before the bound tightened; then nearest boxes first.
  candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                  [&](const Candidate& c) { return c.lb2 > bound * bound; }),
                   candidates.end());
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& x, const Candidate& y) { return x.lb2 < y.lb2; });
  double best = request.upper_bound_m;
  for (const Candidate& c : candidates) {
    if (c.lb2 >= best * best) break;
    BodyPairDistance(c.a, c.b, request, &best, &out);
    if (best <= 0.0) break;
  }
  return out;
}

void CollisionWorld::Impl::BodyPairDistance(int i, int j, const DistanceRequest& request,
                                            double* best, DistanceResult* out) {
  const BodyData& bi = bodies[i];
  const BodyData& bj = bodies[j];
  for (int sa = bi.first; sa < bi.first + bi.count; ++sa) {
    const ShapeData& A = shapes[sa];
    if (BoxDistance2(A.lo, A.hi, bj.lo, bj.hi) >= *best * *best) continue;
    for (int sb = bj.first; sb < bj.first + bj.count; ++sb) {
      const ShapeData& B = shapes[sb];
      if (BoxDistance2(A.lo, A.hi, B.lo, B.hi) >= *best * *best) continue;
      ++out->narrowphase_tests;
      const PairDistance pd = ShapeDistance(A, B, request.nearest_points);
      if (pd.d < *best) {
        *best = pd.d;
        out->distance = pd.d;
        out->pair = ShapePair{BodyId{i}, BodyId{j}, sa - bi.first, sb - bj.first, bi.X_WB, bj.X_WB};
        out->p_A_W = pd.p_a;
        out->p_B_W = pd.p_b;
        if (pd.d <= 0.0) return;
      }
    }
  }
}

DistanceResult CollisionWorld::MinDistance(int group_g, int group_h,
                                           const DistanceRequest& request) {
  return impl_->MinDistance(
      [group_g, group_h](int g, int h) {
        return (g == group_g && h == group_h) || (g == group_h && h == group_g);
      },
      request);
}

DistanceResult CollisionWorld::MinDistance(const GroupPairSet& pairs,
                                           const DistanceRequest& request) {
  return impl_->MinDistance([&pairs](int g, int h) { return pairs.Contains(g, h); }, request);
}

DistanceResult CollisionWorld::Distance(BodyId a, BodyId b, const DistanceRequest& request) {
  Impl& m = *impl_;
  m.body(a);
  m.body(b);
  m.UpdatePair(a, b);
  DistanceResult out;
  out.distance = request.upper_bound_m;
  double best = request.upper_bound_m;
  // Body boxes of disabled bodies are empty: use the shape boxes only.
  const BodyData& ba = m.bodies[a.value];
  const BodyData& bb = m.bodies[b.value];
  for (int sa = ba.first; sa < ba.first + ba.count; ++sa) {
    for (int sb = bb.first; sb < bb.first + bb.count; ++sb) {
      const ShapeData& A = m.shapes[sa];
      const ShapeData& B = m.shapes[sb];
      if (BoxDistance2(A.lo, A.hi, B.lo, B.hi) >= best * best) continue;
      ++out.narrowphase_tests;
      const Impl::PairDistance pd = m.ShapeDistance(A, B, request.nearest_points);
      if (pd.d < best) {
        best = pd.d;
        out.distance = pd.d;
        out.pair = ShapePair{a, b, sa - ba.first, sb - bb.first, ba.X_WB, bb.X_WB};
        out.p_A_W = pd.p_a;
        out.p_B_W = pd.p_b;
      }
    }
  }
  return out;
}

}  // namespace wrap
