// The best split of an object's load among its supports (detail/best_split.h).
//
// The LP, for a given lambda (feasibility only; lambda by bisection):
//   rows 0-5:   sum_h A_h w_h + sum_e E_e c_e = whole            (the whole load)
//   rows 6-11:  sum_h A_h v_h + sum_e E_e d_e = whole - mating   (staged: the load of holding)
// Columns per holder (staged): a cup's held wrench (in both row blocks, within lambda times its
// transport box) and what the mating adds (whole rows only, lambda times its assembly box); a
// two-finger gripper's whole wrench (whole rows, lambda times its box) and its share of the
// holding (holding rows only, free: its box bounds only its whole). Not staged: one wrench per
// holder in its box (a cup's transport box). Per support point, the 8 edges of its friction
// pyramid (inscribed in the cone, the first along world x), non-negative, as wrenches about O:
// the whole force (whole rows) and, staged, the force while only holding (holding rows). The
// normal force is unbounded: a gripper may press the object onto the table.
#include "verify/detail/best_split.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace wrap::detail {
namespace {

constexpr int kPyramidEdges = 8;
constexpr double kMaxLambda = 1e4;      // no split within 10^4 times the boxes: none at all
constexpr double kRelTolerance = 0.005;  // lambda to 0.5% ...
constexpr double kAbsTolerance = 1e-3;   // ... or below 0.1%

Vec6 Bounds(const WrenchBox& box, double floor_N, double floor_Nm) {
  Vec6 b;
  for (int i = 0; i < 3; ++i) {
    b[i] = std::max(box.force_N[i], floor_N);
    b[3 + i] = std::max(box.torque_Nm[i], floor_Nm);
  }
  return b;
}

}  // namespace

Eigen::Matrix<double, 6, 6> GraspWrenchToWorld(const Mat3& R_WG, const Vec3& p_OG) {
  Mat3 skew;
  skew << 0.0, -p_OG.z(), p_OG.y(), p_OG.z(), 0.0, -p_OG.x(), -p_OG.y(), p_OG.x(), 0.0;
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  A.topLeftCorner<3, 3>() = R_WG;
  A.bottomRightCorner<3, 3>() = R_WG;
  A.bottomLeftCorner<3, 3>() = skew * R_WG;
  return A;
}

std::optional<std::vector<double>> BestSplit(const SplitQuery& q, LpBackend& backend,
                                             LpProblem& lp, LpSolution& solution) {
  const int nh = static_cast<int>(q.holders.size());
  if (nh == 0 || (nh == 1 && q.support_points.empty())) return std::nullopt;
  const bool staged = q.mating.norm() > 1e-9 &&
                      std::any_of(q.holders.begin(), q.holders.end(),
                                  [](const SplitHolder& h) { return h.vacuum; });
  const int blocks = staged ? 2 : 1;
  std::vector<Vec6> edges;  // unit-normal pyramid edges, as wrenches about O
  for (const Vec3& p : q.support_points) {
    for (int k = 0; k < kPyramidEdges; ++k) {
      const double th = 2.0 * M_PI * k / kPyramidEdges;
      const Vec3 e = Vec3::UnitZ() + q.friction * Vec3(std::cos(th), std::sin(th), 0.0);
      Vec6 w;
      w << e, p.cross(e);
      edges.push_back(w);
    }
  }
  const int ne = static_cast<int>(edges.size());
  const int per_holder = 6 * blocks;
  lp.Reset(6 * blocks, nh * per_holder + ne * blocks);
  for (int i = 0; i < 6; ++i) {
    lp.rhs[i] = q.whole[i];
    if (staged) lp.rhs[6 + i] = q.whole[i] - q.mating[i];
  }
  std::vector<Vec6> box(static_cast<size_t>(nh * blocks));  // per holder and block
  for (int h = 0; h < nh; ++h) {
    const SplitHolder& H = q.holders[h];
    for (int part = 0; part < blocks; ++part) {
      const bool in_whole = H.vacuum || part == 0;
      const bool in_holding = staged && (H.vacuum ? part == 0 : part == 1);
      for (int j = 0; j < 6; ++j) {
        double* col = lp.column(h * per_holder + 6 * part + j);
        for (int i = 0; i < 6; ++i) {
          if (in_whole) col[i] = H.A(i, j);
          if (in_holding) col[6 + i] = H.A(i, j);
        }
      }
      Vec6& b = box[static_cast<size_t>(h * blocks + part)];
      if (!H.vacuum) {
        b = part == 0 ? Bounds(H.limits.two_finger, q.floor_N, q.floor_Nm)
                      : Vec6::Constant(std::numeric_limits<double>::infinity());
      } else {
        b = Bounds(part == 0 ? H.limits.vacuum_transport : H.limits.vacuum_assembly, q.floor_N,
                   q.floor_Nm);
      }
    }
  }
  for (int k = 0; k < ne; ++k) {
    for (int part = 0; part < blocks; ++part) {
      double* col = lp.column(nh * per_holder + part * ne + k);
      for (int i = 0; i < 6; ++i) col[6 * part + i] = edges[k][i];
    }
  }
  auto feasible = [&](double lambda) {
    for (int h = 0; h < nh; ++h) {
      for (int part = 0; part < blocks; ++part) {
        const Vec6& b = box[static_cast<size_t>(h * blocks + part)];
        for (int j = 0; j < 6; ++j) {
          const int c = h * per_holder + 6 * part + j;
          lp.lower[c] = std::isfinite(b[j]) ? -lambda * b[j] : -b[j];
          lp.upper[c] = std::isfinite(b[j]) ? lambda * b[j] : b[j];
        }
      }
    }
    return backend.Solve(lp, solution) == LpStatus::kOptimal;
  };
  // The least lambda: bracketed, then bisected.
  double lo = 0.0, hi = 1.0;
  while (!feasible(hi)) {
    lo = hi;
    hi *= 2.0;
    if (hi > kMaxLambda) return std::nullopt;
  }
  while (hi - lo > std::max(kRelTolerance * hi, kAbsTolerance)) {
    const double mid = 0.5 * (lo + hi);
    if (feasible(mid)) {
      hi = mid;
    } else {
      lo = mid;
    }
  }
  if (!feasible(hi)) return std::nullopt;
  std::vector<double> u(static_cast<size_t>(nh), 0.0);
  for (int h = 0; h < nh; ++h) {
    for (int part = 0; part < blocks; ++part) {
      const Vec6& b = box[static_cast<size_t>(h * blocks + part)];
      for (int j = 0; j < 6; ++j) {
        if (!std::isfinite(b[j])) continue;
        const double x = solution.x[static_cast<size_t>(h * per_holder + 6 * part + j)];
        u[static_cast<size_t>(h)] = std::max(u[static_cast<size_t>(h)], std::abs(x) / b[j]);
      }
    }
  }
  return u;
}

}  // namespace wrap::detail
