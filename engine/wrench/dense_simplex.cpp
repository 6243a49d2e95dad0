// Our dense bounded-variable primal simplex: the fast LP backend of the wrench stage.
//
// The LPs of one assembly step are tiny (6 rows per body, a few dozen columns), where the set-up
// cost of a general sparse solver dominates: Clp needs ~40-120 us where a dense tableau needs a
// few. The method is the textbook two-phase primal simplex on the full tableau T = B^-1 A:
//  - every variable starts nonbasic at 0 clipped into its bounds (0 may lie strictly inside the
//    bounds, e.g. a free variable: such a variable may move either way);
//  - one artificial per row, signed so that it starts at |residual| >= 0, forms the first basis;
//    artificials are never stored as columns and, once they leave the basis, never come back;
//  - phase 1 minimises the sum of artificials; phase 2 keeps the remaining ones fixed at 0;
//  - pricing: Dantzig (largest reduced cost, lowest index on ties); ratio test: Harris' two
//    passes with a feasibility tolerance, preferring the largest pivot; after a run of
//    degenerate pivots Bland's rule takes over until progress resumes, which rules out cycling.
// LoadBase/SolveWithColumn serve the wrench LP, solved once per vertex of U with only the load
// column changing and a start without residual (x = 0): the artificials are crashed out of the
// basis once (Gauss-Jordan, keeping B^-1), and each vertex starts phase 2 from that basis with
// its column B^-1 w. That skips the ~m degenerate pivots a cold start spends per vertex.
// With set_shared_phase1, a start with a residual (the joint "held, then mated" LP, whose holding
// rows balance gravity) is treated alike: phase 1 runs once with the varying column held at 0,
// carrying B^-1 through its pivots, and every later vertex starts phase 2 from that basis. The
// first vertex is solved cold: many checks stop there, and carrying B^-1 costs.
// When the varying column has a finite upper bound (the planner's load factor capped at 1) and the
// last solve ended with it nonbasic at that bound, the next solve first tries that final basis:
// with the column's variable fixed at its bound, a new column changes only the basic values
// (x_B = x_B + (B^-1 w_old - B^-1 w_new) u); when they stay within bounds, that basis is optimal
// for the new column too (its variable at its upper bound cannot rise) and no pivot is needed.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "wrench/lp.h"

namespace wrap {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Tableau entries smaller than this are not pivots. 1e-9 let degenerate phase-1 steps pivot on
// entries of ~3e-8 in redundant rows, and the tableau lost every digit (tests/wrench/data).
constexpr double kPivotTol = 1e-7;
constexpr double kOptTol = 1e-9;   // Reduced costs within this of 0 are optimal.
constexpr double kFeasTol = 1e-9;  // Harris' bound relaxation.
constexpr int kDegenerateRunForBland = 8;

class DenseSimplex final : public LpBackend {
 public:
  std::string_view name() const override { return "dense"; }
  LpStatus Solve(const LpProblem& problem, LpSolution& solution) override;
  void LoadBase(const LpProblem& problem, int varying_column) override;
  LpStatus SolveWithColumn(const double* values, LpSolution& solution) override;

 private:
  // Sizes, bounds, the starting point and the artificial basis of `problem`; kOptimal when the
  // problem is well formed (need_phase1: some artificial is not zero).
  LpStatus Setup(const LpProblem& problem, bool& need_phase1);
  // Phases 1 (when needed) and 2 from the current basis, then the solution.
  LpStatus Run(bool need_phase1, const std::vector<double>& cost, LpSolution& solution);
  // Runs simplex iterations of one phase until optimal, unbounded or the iteration limit.
  LpStatus Iterate(bool phase1);
  // Reduced costs of the structural columns for the current basis and phase.
  void PriceAll(bool phase1, const std::vector<double>& cost);
  // Pivots the tableau on row p, column q (and the reduced-cost row with it; B^-1 too while
  // track_binv_).
  void Pivot(int p, int q);
  // LoadBase for a start with a residual: phase 1 once, the varying column held at 0; true when
  // it found a feasible basis (then binv_ is its inverse).
  bool SharedPhase1(int varying_column);
  // Saves the current basis as the start of every SolveWithColumn.
  void SaveStart();
  // Back to the basis SaveStart saved (tableau, heads, values; not B^-1).
  void RestoreStart();
  // col_ = B^-1 * values with the current binv_: the varying column in the basis's terms.
  void ColumnInBasis(const double* values);
  // The last solve's final basis with the varying column replaced by `col` (B^-1 of the new
  // values), its variable at its upper bound: kOptimal into `solution` when the basic values
  // stay within bounds, else kError and nothing changed.
  LpStatus TryLastBasis(const std::vector<double>& col, LpSolution& solution);
  // The solution of the current basis: x (basic values clipped into their bounds), objective.
  void Extract(const std::vector<double>& cost, LpSolution& solution);
  // Bounds of the basic variable of row r.
  void HeadBounds(int r, bool phase1, double& lb, double& ub) const {
    const int h = head_[r];
    if (h < n_) {
      lb = lo_[h];
      ub = up_[h];
    } else {
      lb = 0.0;
      ub = phase1 ? kInf : 0.0;
    }
  }

  int m_ = 0;
  int n_ = 0;
  int w_ = 0;  // Row stride of the tableau: n rounded up to a multiple of 4 (zero padding).
  int iterations_ = 0;
  int max_iterations_ = 0;
  std::vector<double> t_;    // Tableau B^-1 A, row-major m x w (columns >= n are 0).
  std::vector<double> xb_;   // Value of the basic variable of each row.
  std::vector<int> head_;    // Basic variable of each row: j < n structural, n + r artificial.
  std::vector<int> row_of_;  // Row where structural j is basic, or -1.
  std::vector<double> x_;    // Values of the nonbasic structurals.
  std::vector<double> lo_;   // Bounds of the structurals.
  std::vector<double> up_;
  std::vector<double> d_;       // Reduced costs of the structurals (w entries, padding 0).
  std::vector<double> zero_;    // Phase-1 structural costs (all zero).
  double scale_ = 1.0;          // Largest |rhs|, at least 1: scales the phase-1 tolerance.
  std::vector<double> sign_;    // Setup's sign of each row (its artificial starts at |residual|).
  bool track_binv_ = false;     // Pivot updates binv_ as well (SharedPhase1).
  int pending_iterations_ = 0;  // LoadBase's phase-1 pivots, reported by the next solve.

  // LoadBase's crash basis, the start of every SolveWithColumn.
  bool crashed_ = false;
  std::vector<double> binv_;        // B^-1 of the current basis, row-major m x m (see track_binv_).
  std::vector<double> binv0_;       // B^-1 of the start basis.
  std::vector<double> col_;         // Scratch: B^-1 of the varying column's values.
  bool shape_stale_ = false;        // Solve overwrote the sizes and bounds of the start.
  bool phase1_pending_ = false;     // LoadBase left the shared phase 1 for a second solve.
  bool solved_since_load_ = false;  // A SolveWithColumn ran since LoadBase.
  bool last_at_bound_ = false;      // The last SolveWithColumn ended optimal with the varying
                                    // column nonbasic at its finite upper bound (binv_ current).
  std::vector<double> t0_;
  std::vector<int> head0_;
  std::vector<int> row_of0_;
  std::vector<double> xb0_;
  std::vector<double> x0_;
};

// y -= f * x over w entries, w a multiple of 4: four independent statements per step let the
// compiler's straight-line vectoriser use SIMD at -O2 (the tableau update is the hot loop).
inline void Axpy4(double* __restrict y, const double* __restrict x, double f, int w) {
  for (int j = 0; j < w; j += 4) {
    y[j] -= f * x[j];
    y[j + 1] -= f * x[j + 1];
    y[j + 2] -= f * x[j + 2];
    y[j + 3] -= f * x[j + 3];
  }
}

void DenseSimplex::PriceAll(bool phase1, const std::vector<double>& cost) {
  // d_j = c_j - sum_r c_head(r) T_rj, where artificials cost 1 in phase 1 and 0 in phase 2.
  for (int j = 0; j < n_; ++j) d_[j] = cost[j];
  for (int j = n_; j < w_; ++j) d_[j] = 0.0;
  for (int r = 0; r < m_; ++r) {
    const int h = head_[r];
    const double c = h < n_ ? cost[h] : (phase1 ? 1.0 : 0.0);
    if (c == 0.0) continue;
    Axpy4(d_.data(), &t_[static_cast<std::size_t>(r) * w_], c, w_);
  }
  for (int r = 0; r < m_; ++r) {
    if (head_[r] < n_) d_[head_[r]] = 0.0;
  }
}

void DenseSimplex::Pivot(int p, int q) {
  double* tp = &t_[static_cast<std::size_t>(p) * w_];
  double* bp = track_binv_ ? &binv_[static_cast<std::size_t>(p) * m_] : nullptr;
  const double inv = 1.0 / tp[q];
  for (int j = 0; j < w_; ++j) tp[j] *= inv;
  tp[q] = 1.0;
  if (bp) {
    for (int k = 0; k < m_; ++k) bp[k] *= inv;
  }
  for (int r = 0; r < m_; ++r) {
    if (r == p) continue;
    double* tr = &t_[static_cast<std::size_t>(r) * w_];
    const double f = tr[q];
    if (f == 0.0) continue;
    Axpy4(tr, tp, f, w_);
    tr[q] = 0.0;
    if (bp) {
      double* br = &binv_[static_cast<std::size_t>(r) * m_];
      for (int k = 0; k < m_; ++k) br[k] -= f * bp[k];
    }
  }
  const double f = d_[q];
  if (f != 0.0) Axpy4(d_.data(), tp, f, w_);
  d_[q] = 0.0;
}

LpStatus DenseSimplex::Iterate(bool phase1) {
  int degenerate_run = 0;
  bool bland = false;
  for (;;) {
    if (iterations_ >= max_iterations_) return LpStatus::kIterationLimit;

    // Pricing: the entering column q and its direction (+1 increase, -1 decrease).
    int q = -1;
    int dir = 0;
    double best = 0.0;
    for (int j = 0; j < n_; ++j) {
      if (row_of_[j] >= 0) continue;
      const double dj = d_[j];
      int dj_dir = 0;
      if (dj < -kOptTol && x_[j] < up_[j]) {
        dj_dir = 1;
      } else if (dj > kOptTol && x_[j] > lo_[j]) {
        dj_dir = -1;
      } else {
        continue;
      }
      const double score = std::abs(dj);
      if (bland) {
        q = j;
        dir = dj_dir;
        break;
      }
      if (score > best) {
        best = score;
        q = j;
        dir = dj_dir;
      }
    }
    if (q < 0) return LpStatus::kOptimal;

    // Harris ratio test, pass 1: the largest step with every bound relaxed by kFeasTol.
    const double own = dir > 0 ? up_[q] - x_[q] : x_[q] - lo_[q];
    double theta_max = own;
    for (int r = 0; r < m_; ++r) {
      const double alpha = dir * t_[static_cast<std::size_t>(r) * w_ + q];
      if (std::abs(alpha) <= kPivotTol) continue;
      double lb, ub;
      HeadBounds(r, phase1, lb, ub);
      double lim;
      if (alpha > 0.0) {
        if (lb == -kInf) continue;
        lim = (xb_[r] - lb + kFeasTol) / alpha;
      } else {
        if (ub == kInf) continue;
        lim = (ub - xb_[r] + kFeasTol) / -alpha;
      }
      if (lim < theta_max) theta_max = lim;
    }
    if (theta_max == kInf) return LpStatus::kUnbounded;

    // Pass 2: among the rows that block within theta_max, the largest pivot (Bland: lowest
    // basic index). A bound flip of the entering variable needs no pivot: take it when it fits.
    int p = -1;
    double theta = 0.0;
    if (own <= theta_max) {
      theta = own;
    } else {
      double best_alpha = 0.0;
      int best_head = 0;
      for (int r = 0; r < m_; ++r) {
        const double alpha = dir * t_[static_cast<std::size_t>(r) * w_ + q];
        if (std::abs(alpha) <= kPivotTol) continue;
        double lb, ub;
        HeadBounds(r, phase1, lb, ub);
        double lim;
        if (alpha > 0.0) {
          if (lb == -kInf) continue;
          lim = (xb_[r] - lb) / alpha;
        } else {
          if (ub == kInf) continue;
          lim = (ub - xb_[r]) / -alpha;
        }
        if (lim > theta_max) continue;
        const bool better = p < 0 || (bland ? head_[r] < best_head : std::abs(alpha) > best_alpha);
        if (better) {
          p = r;
          best_alpha = std::abs(alpha);
          best_head = head_[r];
          theta = lim < 0.0 ? 0.0 : lim;
        }
      }
      if (p < 0) return LpStatus::kIterationLimit;  // Only tiny pivots block: numerical trouble.
    }
    ++iterations_;

    // Move along the edge.
    x_[q] += dir * theta;
    if (theta != 0.0) {
      for (int r = 0; r < m_; ++r) xb_[r] -= dir * theta * t_[static_cast<std::size_t>(r) * w_ + q];
    }
    if (p < 0) {
      x_[q] = dir > 0 ? up_[q] : lo_[q];  // Bound flip: q stays nonbasic at its other bound.
    } else {
      const int h = head_[p];
      const double alpha = dir * t_[static_cast<std::size_t>(p) * w_ + q];
      if (h < n_) {
        x_[h] = alpha > 0.0 ? lo_[h] : up_[h];
        row_of_[h] = -1;
      }
      head_[p] = q;
      row_of_[q] = p;
      xb_[p] = x_[q];
      Pivot(p, q);
    }

    if (theta <= 1e-12) {
      if (++degenerate_run >= kDegenerateRunForBland) bland = true;
    } else {
      degenerate_run = 0;
      bland = false;
    }
  }
}

LpStatus DenseSimplex::Setup(const LpProblem& problem, bool& need_phase1) {
  m_ = problem.rows;
  n_ = problem.cols;
  if (m_ < 0 || n_ < 0 || problem.a.size() != static_cast<std::size_t>(m_) * n_ ||
      problem.rhs.size() != static_cast<std::size_t>(m_) ||
      problem.cost.size() != static_cast<std::size_t>(n_) ||
      problem.lower.size() != static_cast<std::size_t>(n_) ||
      problem.upper.size() != static_cast<std::size_t>(n_)) {
    return LpStatus::kError;
  }
  for (int j = 0; j < n_; ++j) {
    if (!(problem.lower[j] <= problem.upper[j]) || problem.lower[j] == kInf ||
        problem.upper[j] == -kInf) {
      return LpStatus::kInfeasible;
    }
  }
  iterations_ = 0;
  max_iterations_ = 50 * (m_ + n_) + 100;
  lo_ = problem.lower;
  up_ = problem.upper;
  w_ = (n_ + 3) & ~3;
  x_.resize(n_);
  d_.resize(w_);
  row_of_.assign(n_, -1);
  head_.resize(m_);
  xb_.resize(m_);
  t_.assign(static_cast<std::size_t>(m_) * w_, 0.0);
  sign_.resize(m_);

  // Start: each variable at 0 clipped into its bounds; residuals carried by artificials.
  for (int j = 0; j < n_; ++j) x_[j] = lo_[j] > 0.0 ? lo_[j] : (up_[j] < 0.0 ? up_[j] : 0.0);
  scale_ = 1.0;
  need_phase1 = false;
  for (int r = 0; r < m_; ++r) {
    double res = problem.rhs[r];
    for (int j = 0; j < n_; ++j) {
      if (x_[j] != 0.0) res -= problem.a[static_cast<std::size_t>(j) * m_ + r] * x_[j];
    }
    const double sign = res < 0.0 ? -1.0 : 1.0;
    sign_[r] = sign;
    double* tr = &t_[static_cast<std::size_t>(r) * w_];
    for (int j = 0; j < n_; ++j) tr[j] = sign * problem.a[static_cast<std::size_t>(j) * m_ + r];
    head_[r] = n_ + r;
    xb_[r] = std::abs(res);
    scale_ = std::max(scale_, std::abs(problem.rhs[r]));
    if (xb_[r] > 0.0) need_phase1 = true;
  }
  return LpStatus::kOptimal;
}

LpStatus DenseSimplex::Run(bool need_phase1, const std::vector<double>& cost,
                           LpSolution& solution) {
  solution.x.assign(n_, 0.0);
  solution.objective = 0.0;
  if (need_phase1) {
    zero_.assign(n_, 0.0);
    PriceAll(true, zero_);
    const LpStatus status = Iterate(true);
    if (status != LpStatus::kOptimal) {
      solution.iterations = iterations_;
      return solution.status = status;
    }
    double infeasibility = 0.0;
    for (int r = 0; r < m_; ++r) {
      if (head_[r] >= n_) infeasibility += xb_[r];
    }
    if (infeasibility > 1e-8 * scale_) {
      solution.iterations = iterations_;
      return solution.status = LpStatus::kInfeasible;
    }
  }
  PriceAll(false, cost);
  const LpStatus status = Iterate(false);
  solution.iterations = iterations_;
  if (status != LpStatus::kOptimal) return solution.status = status;

  Extract(cost, solution);
  return solution.status = LpStatus::kOptimal;
}

void DenseSimplex::Extract(const std::vector<double>& cost, LpSolution& solution) {
  solution.x.resize(n_);
  for (int j = 0; j < n_; ++j) solution.x[j] = x_[j];
  for (int r = 0; r < m_; ++r) {
    const int h = head_[r];
    if (h >= n_) continue;
    // Harris lets basic values stray by up to kFeasTol: put them back inside their bounds.
    solution.x[h] = std::min(std::max(xb_[r], lo_[h]), up_[h]);
  }
  double objective = 0.0;
  for (int j = 0; j < n_; ++j) objective += cost[j] * solution.x[j];
  solution.objective = objective;
}

LpStatus DenseSimplex::Solve(const LpProblem& problem, LpSolution& solution) {
  last_at_bound_ = false;  // The tableau, sizes and bounds are this problem's now.
  shape_stale_ = crashed_;
  bool need_phase1 = false;
  const LpStatus status = Setup(problem, need_phase1);
  if (status != LpStatus::kOptimal) {
    solution.x.assign(std::max(problem.cols, 0), 0.0);
    solution.objective = 0.0;
    solution.iterations = 0;
    return solution.status = status;
  }
  return Run(need_phase1, problem.cost, solution);
}

void DenseSimplex::LoadBase(const LpProblem& problem, int varying_column) {
  LpBackend::LoadBase(problem, varying_column);
  crashed_ = false;
  last_at_bound_ = false;
  shape_stale_ = false;
  phase1_pending_ = false;
  solved_since_load_ = false;
  pending_iterations_ = 0;
  bool need_phase1 = true;
  if (varying_column < 0 || varying_column >= problem.cols) return;
  if (Setup(problem, need_phase1) != LpStatus::kOptimal) return;
  // Either start serves every value of the varying column only when that column starts at 0.
  if (x_[varying_column] != 0.0) return;
  // The shared phase 1 waits for a second solve: a check that stops at its first vertex (a
  // failure, or one vertex) then costs one cold solve, as without it.
  if (need_phase1) {
    phase1_pending_ = shared_phase1_;
    return;
  }
  // The crash needs a start without residual: the start must satisfy A x = rhs.

  // Crash: replace artificials by structural columns, widest bounds first (free, one-sided,
  // boxed; never fixed ones nor the varying column), each on the artificial row where it has the
  // largest entry. With no residual these pivots move nothing, so the basis stays feasible.
  // B^-1 is kept beside the tableau for the varying column.
  binv_.assign(static_cast<std::size_t>(m_) * m_, 0.0);
  for (int r = 0; r < m_; ++r) binv_[static_cast<std::size_t>(r) * m_ + r] = 1.0;
  for (int pass = 0; pass < 3; ++pass) {
    for (int j = 0; j < n_; ++j) {
      if (j == varying_column || lo_[j] == up_[j] || row_of_[j] >= 0) continue;
      const int finite = (std::isfinite(lo_[j]) ? 1 : 0) + (std::isfinite(up_[j]) ? 1 : 0);
      if (finite != pass) continue;
      int p = -1;
      double best = 1e-6;
      double column_max = 0.0;
      for (int r = 0; r < m_; ++r) {
        column_max = std::max(column_max, std::abs(t_[static_cast<std::size_t>(r) * w_ + j]));
      }
      for (int r = 0; r < m_; ++r) {
        const double v = std::abs(t_[static_cast<std::size_t>(r) * w_ + j]);
        if (head_[r] >= n_ && v > best && v >= 0.1 * column_max) {
          best = v;
          p = r;
        }
      }
      if (p < 0) continue;
      // Gauss-Jordan on (T | B^-1) at (p, j); the reduced costs are set per solve.
      const double inv = 1.0 / t_[static_cast<std::size_t>(p) * w_ + j];
      double* tp = &t_[static_cast<std::size_t>(p) * w_];
      double* bp = &binv_[static_cast<std::size_t>(p) * m_];
      for (int k = 0; k < w_; ++k) tp[k] *= inv;
      for (int k = 0; k < m_; ++k) bp[k] *= inv;
      tp[j] = 1.0;
      for (int r = 0; r < m_; ++r) {
        if (r == p) continue;
        const double f = t_[static_cast<std::size_t>(r) * w_ + j];
        if (f == 0.0) continue;
        Axpy4(&t_[static_cast<std::size_t>(r) * w_], tp, f, w_);
        double* br = &binv_[static_cast<std::size_t>(r) * m_];
        for (int k = 0; k < m_; ++k) br[k] -= f * bp[k];
        t_[static_cast<std::size_t>(r) * w_ + j] = 0.0;
      }
      xb_[p] = x_[j];
      head_[p] = j;
      row_of_[j] = p;
    }
  }
  SaveStart();
}

void DenseSimplex::SaveStart() {
  t0_ = t_;
  head0_ = head_;
  row_of0_ = row_of_;
  xb0_ = xb_;
  x0_ = x_;
  binv0_ = binv_;
  crashed_ = true;
}

void DenseSimplex::RestoreStart() {
  t_ = t0_;
  head_ = head0_;
  row_of_ = row_of0_;
  xb_ = xb0_;
  x_ = x0_;
}

void DenseSimplex::ColumnInBasis(const double* values) {
  col_.resize(m_);
  for (int r = 0; r < m_; ++r) {
    const double* br = &binv_[static_cast<std::size_t>(r) * m_];
    double v = 0.0;
    for (int k = 0; k < m_; ++k) v += br[k] * values[k];
    col_[r] = v;
  }
}

bool DenseSimplex::SharedPhase1(int varying_column) {
  // The varying column held at 0: its tableau column zeroed, it never prices in nor blocks.
  for (int r = 0; r < m_; ++r) t_[static_cast<std::size_t>(r) * w_ + varying_column] = 0.0;
  // The artificial basis of the sign-scaled rows: B^-1 = diag(sign).
  binv_.assign(static_cast<std::size_t>(m_) * m_, 0.0);
  for (int r = 0; r < m_; ++r) binv_[static_cast<std::size_t>(r) * m_ + r] = sign_[r];
  zero_.assign(n_, 0.0);
  PriceAll(true, zero_);
  track_binv_ = true;
  const LpStatus status = Iterate(true);
  track_binv_ = false;
  pending_iterations_ = iterations_;
  if (status != LpStatus::kOptimal) return false;
  double infeasibility = 0.0;
  for (int r = 0; r < m_; ++r) {
    if (head_[r] >= n_) infeasibility += xb_[r];
  }
  // Infeasible whatever the varying column: the cold solves say so, each on its own.
  return infeasibility <= 1e-8 * scale_;
}

LpStatus DenseSimplex::TryLastBasis(const std::vector<double>& col, LpSolution& solution) {
  const int q = varying_column_;
  const double u = x_[q];
  for (int r = 0; r < m_; ++r) {
    const double v = xb_[r] + (t_[static_cast<std::size_t>(r) * w_ + q] - col[r]) * u;
    double lb, ub;
    HeadBounds(r, false, lb, ub);
    if (v < lb - kFeasTol || v > ub + kFeasTol) return LpStatus::kError;
  }
  for (int r = 0; r < m_; ++r) {
    double& tq = t_[static_cast<std::size_t>(r) * w_ + q];
    xb_[r] += (tq - col[r]) * u;
    tq = col[r];
  }
  solution.iterations = 0;
  Extract(base_.cost, solution);
  return solution.status = LpStatus::kOptimal;
}

LpStatus DenseSimplex::SolveWithColumn(const double* values, LpSolution& solution) {
  if (!crashed_ && phase1_pending_ && solved_since_load_) {
    phase1_pending_ = false;
    bool need_phase1 = true;
    if (Setup(base_, need_phase1) == LpStatus::kOptimal && SharedPhase1(varying_column_)) {
      SaveStart();
    }
  }
  if (!crashed_) {
    solved_since_load_ = true;
    return LpBackend::SolveWithColumn(values, solution);
  }
  if (shape_stale_) {
    // Another problem was solved since LoadBase: its sizes and bounds back to the loaded one's.
    m_ = base_.rows;
    n_ = base_.cols;
    w_ = (n_ + 3) & ~3;
    lo_ = base_.lower;
    up_ = base_.upper;
    d_.resize(w_);
    max_iterations_ = 50 * (m_ + n_) + 100;
    shape_stale_ = false;
  }
  const int q = varying_column_;
  // B^-1 values, for the last basis (when it may serve) or the start basis.
  const bool try_last = last_at_bound_;
  if (!try_last) binv_ = binv0_;
  ColumnInBasis(values);
  if (try_last) {
    if (TryLastBasis(col_, solution) == LpStatus::kOptimal) return LpStatus::kOptimal;
    binv_ = binv0_;
    ColumnInBasis(values);
  }
  RestoreStart();
  iterations_ = pending_iterations_;
  pending_iterations_ = 0;
  for (int r = 0; r < m_; ++r) t_[static_cast<std::size_t>(r) * w_ + q] = col_[r];
  // B^-1 follows the pivots only when the next solve may try this one's final basis.
  track_binv_ = std::isfinite(up_[q]);
  const LpStatus status = Run(false, base_.cost, solution);
  track_binv_ = false;
  last_at_bound_ =
      status == LpStatus::kOptimal && std::isfinite(up_[q]) && row_of_[q] < 0 && x_[q] == up_[q];
  return status;
}

}  // namespace

std::unique_ptr<LpBackend> MakeDenseSimplexBackend() { return std::make_unique<DenseSimplex>(); }

}  // namespace wrap
