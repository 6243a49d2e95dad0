// The LP backend interface of the wrench stage: a small dense linear program and the solvers
// behind it. Two implementations: our dense bounded primal simplex (fast on the 12-row LPs of
// one assembly step) and Clp (the reference, the only place Clp is included: clp_backend.cpp).
#pragma once

#include <memory>
#include <string_view>
#include <vector>

namespace wrap {

/// A linear program: minimise cost . x subject to A x = rhs and lower <= x <= upper.
/// Bounds may be infinite (+-std::numeric_limits<double>::infinity()).
struct LpProblem {
  int rows = 0;               ///< Number of equality rows m.
  int cols = 0;               ///< Number of variables n.
  std::vector<double> a;      ///< A, dense, column-major: a[j * rows + i] = A(i, j).
  std::vector<double> rhs;    ///< Right-hand side, size m.
  std::vector<double> cost;   ///< Objective coefficients, size n.
  std::vector<double> lower;  ///< Variable lower bounds, size n (may be -inf).
  std::vector<double> upper;  ///< Variable upper bounds, size n (may be +inf).

  /// Resizes to m rows and n columns: A and costs zero, rhs zero, bounds [0, +inf).
  void Reset(int m, int n);
  /// Pointer to column j of A (rows entries).
  double* column(int j) { return a.data() + static_cast<std::size_t>(j) * rows; }
  /// Pointer to column j of A (rows entries).
  const double* column(int j) const { return a.data() + static_cast<std::size_t>(j) * rows; }
};

/// Outcome of one LP solve.
enum class LpStatus {
  kOptimal,         ///< An optimal solution was found.
  kInfeasible,      ///< No x satisfies the constraints.
  kUnbounded,       ///< The objective decreases without bound.
  kIterationLimit,  ///< The solver gave up (cycling or a numerical problem).
  kError,           ///< The backend failed (bad input, internal error).
};

/// Short lower-case name of a status, e.g. "infeasible".
std::string_view ToString(LpStatus status);

/// A solution: status, objective value and the variables (valid when optimal).
struct LpSolution {
  LpStatus status = LpStatus::kError;  ///< What the solver found.
  double objective = 0.0;              ///< cost . x at the solution.
  std::vector<double> x;               ///< Variable values, size n.
  int iterations = 0;                  ///< Simplex pivots (including bound flips).
};

/// A linear-program solver. Not thread-safe: one instance per thread. Implementations may keep
/// scratch memory between calls; every call solves the problem it is given from scratch.
class LpBackend {
 public:
  virtual ~LpBackend() = default;
  /// Name for reports ("dense", "clp").
  virtual std::string_view name() const = 0;
  /// Solves `problem` into `solution` (whose vectors are reused) and returns its status.
  virtual LpStatus Solve(const LpProblem& problem, LpSolution& solution) = 0;

  /// Loads a problem to be solved repeatedly with different values of one column (the load
  /// factor's column of the wrench LP, one value set per vertex of U). Implementations may do
  /// work here that every SolveWithColumn shares. The default keeps a copy.
  virtual void LoadBase(const LpProblem& problem, int varying_column);
  /// Solves the loaded problem with column `varying_column` replaced by `values` (rows entries).
  /// The default copies the values in and calls Solve.
  virtual LpStatus SolveWithColumn(const double* values, LpSolution& solution);
  /// Lets LoadBase solve once the phase 1 that every SolveWithColumn would repeat: when the
  /// start leaves a residual (A x0 != rhs) that the varying column, starting at 0, does not
  /// change, each SolveWithColumn then starts phase 2 from that feasible basis. The optimal
  /// objective is the same; x may be another optimum. Off by default; the dense simplex uses it.
  void set_shared_phase1(bool on) { shared_phase1_ = on; }

 protected:
  LpProblem base_;              ///< The problem of LoadBase.
  int varying_column_ = 0;      ///< Its varying column.
  bool shared_phase1_ = false;  ///< See set_shared_phase1.
};

/// Our dense bounded-variable primal simplex (two phases, Dantzig pricing, Harris ratio test,
/// Bland's rule after a run of degenerate pivots). Meant for LPs of a few dozen rows.
std::unique_ptr<LpBackend> MakeDenseSimplexBackend();

/// Clp's dual simplex (COIN-OR), the reference backend.
std::unique_ptr<LpBackend> MakeClpBackend();

}  // namespace wrap
