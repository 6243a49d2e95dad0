// The Clp adapter: the only file that includes Clp. Clp is the reference backend that the tests
// compare our dense simplex against; it solves every problem cold with its dual simplex.
#include <coin/ClpSimplex.hpp>

#include <cmath>
#include <exception>
#include <limits>
#include <vector>

#include "wrench/lp.h"

namespace wrap {
namespace {

class ClpBackend final : public LpBackend {
 public:
  std::string_view name() const override { return "clp"; }

  LpStatus Solve(const LpProblem& problem, LpSolution& solution) override {
    const int m = problem.rows;
    const int n = problem.cols;
    solution.x.assign(n, 0.0);
    solution.objective = 0.0;
    solution.iterations = 0;
    if (m < 0 || n < 0 || problem.a.size() != static_cast<std::size_t>(m) * n ||
        problem.rhs.size() != static_cast<std::size_t>(m) ||
        problem.cost.size() != static_cast<std::size_t>(n) ||
        problem.lower.size() != static_cast<std::size_t>(n) ||
        problem.upper.size() != static_cast<std::size_t>(n)) {
      return solution.status = LpStatus::kError;
    }
    // Dense column-major to Clp's compressed columns; infinities to COIN_DBL_MAX.
    starts_.assign(n + 1, 0);
    index_.clear();
    value_.clear();
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < m; ++i) {
        const double v = problem.a[static_cast<std::size_t>(j) * m + i];
        if (v != 0.0) {
          index_.push_back(i);
          value_.push_back(v);
        }
      }
      starts_[j + 1] = static_cast<CoinBigIndex>(index_.size());
    }
    lower_.resize(n);
    upper_.resize(n);
    for (int j = 0; j < n; ++j) {
      lower_[j] = std::isinf(problem.lower[j]) ? -COIN_DBL_MAX : problem.lower[j];
      upper_[j] = std::isinf(problem.upper[j]) ? COIN_DBL_MAX : problem.upper[j];
    }
    try {
      // Clp 1.17's scaled dual simplex is wrong now and then: it calls an unbounded problem
      // infeasible, stops without an answer on a planner's LP that has one, or stops at a load
      // factor of 0 where the unscaled primal simplex (and our dense simplex) balance the load
      // (questions recorded from the planner's searches, tests/wrench/data). So both run: two
      // optima, the lower objective (a feasible point attains it); one answer, that one; else
      // the primal's verdict on infeasible or unbounded, else the dual's.
      ClpSimplex model;
      Load(problem, model);
      model.dual();
      ClpSimplex check;
      Load(problem, check);
      check.scaling(0);
      int primal_status = -1;  // -1: it threw
      try {
        check.primal();
        primal_status = check.status();
      } catch (...) {  // CoinError is not a std::exception.
      }
      solution.iterations = model.numberIterations() + check.numberIterations();
      const int dual_status = model.status();
      if (dual_status == 0 && primal_status == 0) {
        const double dual = model.objectiveValue();
        const bool lower = check.objectiveValue() < dual - 1e-9 * (1.0 + std::abs(dual));
        return Take(lower ? check : model, solution);
      }
      if (dual_status == 0) return Take(model, solution);
      if (primal_status == 0) return Take(check, solution);
      const int status = primal_status == 1 || primal_status == 2 ? primal_status : dual_status;
      switch (status) {
        case 1:
          return solution.status = LpStatus::kInfeasible;
        case 2:
          return solution.status = LpStatus::kUnbounded;
        case 3:
          return solution.status = LpStatus::kIterationLimit;
        default:
          return solution.status = LpStatus::kError;
      }
    } catch (const std::exception&) {
      return solution.status = LpStatus::kError;
    } catch (...) {  // CoinError is not a std::exception.
      return solution.status = LpStatus::kError;
    }
  }

 private:
  // The optimum `model` found, into `solution`.
  static LpStatus Take(const ClpSimplex& model, LpSolution& solution) {
    const double* x = model.primalColumnSolution();
    for (std::size_t j = 0; j < solution.x.size(); ++j) solution.x[j] = x[j];
    solution.objective = model.objectiveValue();
    return solution.status = LpStatus::kOptimal;
  }

  void Load(const LpProblem& problem, ClpSimplex& model) const {
    model.setLogLevel(0);
    model.loadProblem(problem.cols, problem.rows, starts_.data(), index_.data(), value_.data(),
                      lower_.data(), upper_.data(), problem.cost.data(), problem.rhs.data(),
                      problem.rhs.data());
    model.setPrimalTolerance(1e-9);
    model.setDualTolerance(1e-9);
  }

  std::vector<CoinBigIndex> starts_;
  std::vector<int> index_;
  std::vector<double> value_;
  std::vector<double> lower_;
  std::vector<double> upper_;
};

}  // namespace

std::unique_ptr<LpBackend> MakeClpBackend() { return std::make_unique<ClpBackend>(); }

}  // namespace wrap
