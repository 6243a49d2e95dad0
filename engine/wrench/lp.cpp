// LpProblem helpers and status names.
#include "wrench/lp.h"

#include <algorithm>
#include <limits>

namespace wrap {

void LpProblem::Reset(int m, int n) {
  rows = m;
  cols = n;
  a.assign(static_cast<std::size_t>(m) * n, 0.0);
  rhs.assign(m, 0.0);
  cost.assign(n, 0.0);
  lower.assign(n, 0.0);
  upper.assign(n, std::numeric_limits<double>::infinity());
}

void LpBackend::LoadBase(const LpProblem& problem, int varying_column) {
  base_ = problem;
  varying_column_ = varying_column;
}

LpStatus LpBackend::SolveWithColumn(const double* values, LpSolution& solution) {
  if (varying_column_ < 0 || varying_column_ >= base_.cols) {
    solution.status = LpStatus::kError;
    return solution.status;
  }
  std::copy(values, values + base_.rows, base_.column(varying_column_));
  return Solve(base_, solution);
}

std::string_view ToString(LpStatus status) {
  switch (status) {
    case LpStatus::kOptimal:
      return "optimal";
    case LpStatus::kInfeasible:
      return "infeasible";
    case LpStatus::kUnbounded:
      return "unbounded";
    case LpStatus::kIterationLimit:
      return "iteration limit";
    case LpStatus::kError:
      return "error";
  }
  return "error";
}

}  // namespace wrap
