// Our dense simplex against Clp (the reference backend): generic random LPs, and the wrench check
// on random step configurations (same verdict, same utilisation).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "wrench/lp.h"
#include "wrench/wrench.h"

namespace wrap {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
int UniformInt(std::mt19937_64& rng, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}
double Normal(std::mt19937_64& rng) { return std::normal_distribution<double>(0.0, 1.0)(rng); }

// A random LP; with `bounded` every variable has finite bounds (no unbounded objective possible),
// with `feasible` the right-hand side is A x0 for some x0 within the bounds.
LpProblem RandomLp(std::mt19937_64& rng, bool bounded, bool feasible) {
  LpProblem p;
  const int m = UniformInt(rng, 1, 8);
  const int n = UniformInt(rng, 1, 20);
  p.Reset(m, n);
  for (double& v : p.a) v = Uniform(rng, 0, 1) < 0.3 ? 0.0 : Normal(rng);
  std::vector<double> x0(n);
  for (int j = 0; j < n; ++j) {
    const int type = bounded ? UniformInt(rng, 0, 1) : UniformInt(rng, 0, 5);
    const double a = Uniform(rng, -3, 0), b = Uniform(rng, 0, 3);
    switch (type) {
      case 0:  // Box around 0.
        p.lower[j] = a;
        p.upper[j] = b;
        break;
      case 1:  // Box away from 0, or fixed.
        p.lower[j] = b;
        p.upper[j] = Uniform(rng, 0, 1) < 0.2 ? b : b + Uniform(rng, 0, 2);
        break;
      case 2:  // Non-negative.
        p.lower[j] = 0;
        p.upper[j] = kInf;
        break;
      case 3:  // Non-positive.
        p.lower[j] = -kInf;
        p.upper[j] = 0;
        break;
      case 4:  // Free.
        p.lower[j] = -kInf;
        p.upper[j] = kInf;
        break;
      default:  // Lower bound only, away from 0.
        p.lower[j] = a;
        p.upper[j] = kInf;
        break;
    }
    const double lo = std::isfinite(p.lower[j]) ? p.lower[j] : p.upper[j] - 3.0;
    const double hi = std::isfinite(p.upper[j]) ? p.upper[j] : lo + 3.0;
    x0[j] = Uniform(rng, std::min(lo, hi), std::max(lo, hi));
    if (!std::isfinite(x0[j])) x0[j] = 0.0;
    p.cost[j] = Normal(rng);
  }
  for (int i = 0; i < m; ++i) {
    double r = 0.0;
    for (int j = 0; j < n; ++j) r += p.a[j * m + i] * x0[j];
    p.rhs[i] = feasible ? r : 3.0 * Normal(rng);
  }
  return p;
}

double Violation(const LpProblem& p, const std::vector<double>& x) {
  double worst = 0.0;
  for (int i = 0; i < p.rows; ++i) {
    double r = -p.rhs[i];
    for (int j = 0; j < p.cols; ++j) r += p.a[j * p.rows + i] * x[j];
    worst = std::max(worst, std::abs(r));
  }
  for (int j = 0; j < p.cols; ++j) {
    worst = std::max({worst, p.lower[j] - x[j], x[j] - p.upper[j]});
  }
  return worst;
}

TEST(DenseSimplex, MatchesClpOnRandomLps) {
  std::mt19937_64 rng(20240611);
  std::unique_ptr<LpBackend> dense = MakeDenseSimplexBackend();
  std::unique_ptr<LpBackend> clp = MakeClpBackend();
  LpSolution a, b;
  int optimal = 0, infeasible = 0, unbounded = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const bool feasible = trial % 3 != 0;
    const bool bounded = !feasible || trial % 2 == 0;
    const LpProblem p = RandomLp(rng, bounded, feasible);
    const LpStatus sa = dense->Solve(p, a);
    const LpStatus sb = clp->Solve(p, b);
    ASSERT_EQ(sa, sb) << "trial " << trial << ": dense " << ToString(sa) << ", clp "
                      << ToString(sb);
    if (sa == LpStatus::kOptimal) {
      ++optimal;
      EXPECT_NEAR(a.objective, b.objective, 1e-6 * (1.0 + std::abs(b.objective)))
          << "trial " << trial;
      EXPECT_LT(Violation(p, a.x), 1e-7) << "trial " << trial;
    } else if (sa == LpStatus::kInfeasible) {
      ++infeasible;
    } else if (sa == LpStatus::kUnbounded) {
      ++unbounded;
    }
  }
  // The generator exercises every outcome.
  EXPECT_GT(optimal, 1000);
  EXPECT_GT(infeasible, 100);
  EXPECT_GT(unbounded, 100);
}

TEST(DenseSimplex, EdgeCases) {
  std::unique_ptr<LpBackend> dense = MakeDenseSimplexBackend();
  LpSolution s;
  LpProblem p;
  p.Reset(0, 2);  // No rows: each variable goes to the bound its cost prefers.
  p.cost = {1.0, -1.0};
  p.lower = {-1.0, 0.0};
  p.upper = {1.0, 2.0};
  ASSERT_EQ(dense->Solve(p, s), LpStatus::kOptimal);
  EXPECT_EQ(s.x[0], -1.0);
  EXPECT_EQ(s.x[1], 2.0);
  p.upper[1] = kInf;
  EXPECT_EQ(dense->Solve(p, s), LpStatus::kUnbounded);
  p.lower[0] = 2.0;  // lower > upper.
  EXPECT_EQ(dense->Solve(p, s), LpStatus::kInfeasible);
  p.rhs.push_back(1.0);  // Inconsistent sizes.
  EXPECT_EQ(dense->Solve(p, s), LpStatus::kError);
}

/// Reads an LP written as in tests/wrench/data ('#' comment lines, then rows cols, A
/// column-major, rhs, cost, lower, upper; "inf" allowed).
LpProblem ReadLp(const std::string& file) {
  std::ifstream in(file);
  std::string line, text;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != '#') text += line + "\n";
  }
  std::istringstream words(text);
  int m = -1, n = -1;
  words >> m >> n;
  LpProblem p;
  if (m < 0 || n < 0) return p;
  p.Reset(m, n);
  auto read = [&](std::vector<double>& v) {
    for (double& x : v) {
      std::string w;
      words >> w;
      x = std::strtod(w.c_str(), nullptr);
    }
  };
  read(p.a);
  read(p.rhs);
  read(p.cost);
  read(p.lower);
  read(p.upper);
  return p;
}

// A mating LP of the stool that the dense simplex once called infeasible (degenerate phase-1
// pivots on tiny entries): it must find Clp's optimum, from a cold start and through the varying
// column, and at other scales.
TEST(DenseSimplex, SolvesTheStoolMatingLpThatOnceFailed) {
  const LpProblem p =
      ReadLp(std::string(WRAP_SOURCE_DIR) + "/tests/wrench/data/stool_seed2_mating_lp.txt");
  ASSERT_EQ(p.rows, 30);
  ASSERT_EQ(p.cols, 43);
  std::unique_ptr<LpBackend> dense = MakeDenseSimplexBackend();
  std::unique_ptr<LpBackend> clp = MakeClpBackend();
  for (double scale : {1.0, 0.5, 2.0, 10.0}) {
    LpProblem q = p;
    for (double& r : q.rhs) r *= scale;
    for (double& l : q.lower) l *= scale;
    for (double& u : q.upper) u *= scale;
    LpSolution a, b;
    ASSERT_EQ(clp->Solve(q, b), LpStatus::kOptimal);
    ASSERT_EQ(dense->Solve(q, a), LpStatus::kOptimal) << "scale " << scale;
    EXPECT_NEAR(a.objective, b.objective, 1e-6 * (1.0 + std::abs(b.objective))) << scale;
    EXPECT_LT(Violation(q, a.x), 1e-7) << "scale " << scale;
  }
  EXPECT_NEAR(
      [&] {
        LpSolution b;
        clp->Solve(p, b);
        return b.objective;
      }(),
      -3.9607, 1e-3)
      << "the load factor s = 3.96";
}

// The wrench LP's shape: A x + s w = 0, bounds containing 0, maximise s (the last column), solved
// for many w. The crash-basis path (LoadBase + SolveWithColumn) must agree with Clp.
TEST(DenseSimplex, ColumnVariantsMatchClp) {
  std::mt19937_64 rng(99);
  std::unique_ptr<LpBackend> dense = MakeDenseSimplexBackend();
  std::unique_ptr<LpBackend> clp = MakeClpBackend();
  LpSolution a, b;
  int optimal = 0, unbounded = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    LpProblem p;
    const int m = 6 * UniformInt(rng, 1, 3);
    const int n = UniformInt(rng, 1, 30);
    p.Reset(m, n + 1);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < m; ++i) p.a[j * m + i] = Uniform(rng, 0, 1) < 0.5 ? 0.0 : Normal(rng);
      const double r = Uniform(rng, 0, 1);
      p.lower[j] = r < 0.3 ? 0.0 : (r < 0.4 ? -kInf : -Uniform(rng, 0, 5));
      p.upper[j] = r < 0.3 ? kInf : (r < 0.5 ? kInf : (r < 0.6 ? 0.0 : Uniform(rng, 0, 5)));
    }
    p.cost[n] = -1.0;
    dense->LoadBase(p, n);
    for (int v = 0; v < 8; ++v) {
      std::vector<double> w(m);
      for (double& x : w) x = 10.0 * Normal(rng);
      std::copy(w.begin(), w.end(), p.column(n));
      const LpStatus sa = dense->SolveWithColumn(w.data(), a);
      const LpStatus sb = clp->Solve(p, b);
      ASSERT_EQ(sa, sb) << "trial " << trial << " vertex " << v;
      if (sa == LpStatus::kOptimal) {
        ++optimal;
        EXPECT_NEAR(a.objective, b.objective, 1e-6 * (1.0 + std::abs(b.objective)));
        EXPECT_LT(Violation(p, a.x), 1e-7);
      } else {
        ++unbounded;
      }
    }
  }
  EXPECT_GT(optimal, 1000);
  EXPECT_GT(unbounded, 500);
}

// The shared phase 1 by hand: x1 + x2 = 3 (a residual at x = 0) and x1 - x2 + s w1 = 0 with
// 0 <= x1, x2 <= 2. Then x1 - x2 = 2 x1 - 3 ranges over [-1, 1], so s* = 1 / |w1|, unbounded
// when w1 = 0. The phase 1 (x1 + x2 = 3) is solved once, before the column is known.
TEST(DenseSimplex, SharedPhase1ByHand) {
  LpProblem p;
  p.Reset(2, 3);
  p.a = {1, 1, 1, -1, 0, 0};  // Columns x1, x2, s (its values per solve).
  p.rhs = {3, 0};
  p.upper = {2, 2, kInf};
  p.cost = {0, 0, -1};
  for (const bool shared : {false, true}) {
    std::unique_ptr<LpBackend> dense = MakeDenseSimplexBackend();
    dense->set_shared_phase1(shared);
    dense->LoadBase(p, 2);
    LpSolution sol;
    const double w_half[] = {0, 2};
    ASSERT_EQ(dense->SolveWithColumn(w_half, sol), LpStatus::kOptimal);
    EXPECT_NEAR(sol.x[2], 0.5, 1e-12);
    EXPECT_NEAR(sol.x[0] + sol.x[1], 3.0, 1e-12);
    EXPECT_NEAR(sol.x[0] - sol.x[1], -1.0, 1e-12);
    const double w_four[] = {0, -0.25};
    ASSERT_EQ(dense->SolveWithColumn(w_four, sol), LpStatus::kOptimal);
    EXPECT_NEAR(sol.x[2], 4.0, 1e-12);
    EXPECT_NEAR(sol.x[0] - sol.x[1], 1.0, 1e-12);
    const double w_none[] = {0, 0};
    EXPECT_EQ(dense->SolveWithColumn(w_none, sol), LpStatus::kUnbounded);
    // The same column on the first row too: x1 + x2 = 3 - s, x1 - x2 = -s, so x1 = (3 - 2 s) / 2
    // >= 0 and x2 = 3 / 2 <= 2 hold up to s = 1.5.
    const double w_both[] = {1, 1};
    ASSERT_EQ(dense->SolveWithColumn(w_both, sol), LpStatus::kOptimal);
    EXPECT_NEAR(sol.x[2], 1.5, 1e-12);
  }
  // x1 + x2 = 5 cannot be met within the bounds: infeasible whatever the column.
  p.rhs = {5, 0};
  std::unique_ptr<LpBackend> dense = MakeDenseSimplexBackend();
  dense->set_shared_phase1(true);
  dense->LoadBase(p, 2);
  LpSolution sol;
  const double w[] = {0, 1};
  EXPECT_EQ(dense->SolveWithColumn(w, sol), LpStatus::kInfeasible);
}

// The same LP with s capped at 1 (the planner's fast path): a solve that ends with s at its cap
// leaves a basis of x1, x2 alone, which the next column may reuse without a pivot when the basic
// values stay within bounds: x1 - x2 = -s w1 and x1 + x2 = 3 give x1 = (3 - w1) / 2.
TEST(DenseSimplex, CappedColumnReusesTheLastBasisByHand) {
  LpProblem p;
  p.Reset(2, 3);
  p.a = {1, 1, 1, -1, 0, 0};
  p.rhs = {3, 0};
  p.upper = {2, 2, 1};
  p.cost = {0, 0, -1};
  std::unique_ptr<LpBackend> dense = MakeDenseSimplexBackend();
  dense->set_shared_phase1(true);
  dense->LoadBase(p, 2);
  LpSolution sol;
  // s* = 2, capped: s = 1, x1 = 1.25, x2 = 1.75. The first solve is cold, the second starts from
  // the shared phase 1.
  const double w_first[] = {0, 0.5};
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(dense->SolveWithColumn(w_first, sol), LpStatus::kOptimal);
    EXPECT_EQ(sol.x[2], 1.0);
    EXPECT_NEAR(sol.x[0], 1.25, 1e-12);
    EXPECT_GT(sol.iterations, 0);
  }
  const double w_reuse[] = {0, -0.5};  // x1 = 1.75, x2 = 1.25: the same basis, no pivot.
  ASSERT_EQ(dense->SolveWithColumn(w_reuse, sol), LpStatus::kOptimal);
  EXPECT_EQ(sol.iterations, 0);
  EXPECT_EQ(sol.x[2], 1.0);
  EXPECT_NEAR(sol.x[0], 1.75, 1e-12);
  EXPECT_NEAR(sol.x[1], 1.25, 1e-12);
  EXPECT_NEAR(sol.objective, -1.0, 1e-12);
  const double w_fail[] = {0, 2};  // x1 = 0.5, x2 = 2.5 > 2: solved again, s* = 0.5.
  ASSERT_EQ(dense->SolveWithColumn(w_fail, sol), LpStatus::kOptimal);
  EXPECT_NEAR(sol.x[2], 0.5, 1e-12);
  EXPECT_GT(sol.iterations, 0);
  const double w_after[] = {0, 0.5};  // After a capped-below answer: solved from the start.
  ASSERT_EQ(dense->SolveWithColumn(w_after, sol), LpStatus::kOptimal);
  EXPECT_EQ(sol.x[2], 1.0);
  EXPECT_NEAR(sol.x[0], 1.25, 1e-12);
}

// The checker solves other problems between the vertices of one LoadBase (the zero-utilisation
// variant after an unbounded vertex): the next SolveWithColumn must still solve the loaded one.
// x1 + x2 + s w = 0, -1 <= x1 <= 1, x2 >= 0: w = -1 is unbounded (x2 = s), w = 1 gives s* = 1.
TEST(DenseSimplex, SolveWithColumnAfterAnotherProblem) {
  LpProblem p;
  p.Reset(1, 3);
  p.a = {1, 1, 0};
  p.lower = {-1, 0, 0};
  p.upper = {1, kInf, kInf};
  p.cost = {0, 0, -1};
  std::unique_ptr<LpBackend> dense = MakeDenseSimplexBackend();
  dense->LoadBase(p, 2);
  LpSolution sol;
  const double w_unbounded[] = {-1};
  EXPECT_EQ(dense->SolveWithColumn(w_unbounded, sol), LpStatus::kUnbounded);
  LpProblem other = p;  // The zero-utilisation variant: finite bounds at 0, s = 1.
  other.a[2] = -1;
  other.lower = {0, 0, 1};
  other.upper = {0, kInf, 1};
  other.cost = {0, 0, 0};
  ASSERT_EQ(dense->Solve(other, sol), LpStatus::kOptimal);
  EXPECT_NEAR(sol.x[1], 1.0, 1e-12);
  const double w_one[] = {1};
  ASSERT_EQ(dense->SolveWithColumn(w_one, sol), LpStatus::kOptimal);
  EXPECT_NEAR(sol.x[2], 1.0, 1e-12);
  EXPECT_NEAR(sol.x[0], -1.0, 1e-12);
}

// The joint LP's shape: a right-hand side that x = 0 does not meet, and a varying column. With
// the shared phase 1 every solve starts phase 2 from one feasible basis; the objective must be
// Clp's, and x feasible.
TEST(DenseSimplex, SharedPhase1VariantsMatchClp) {
  std::mt19937_64 rng(123);
  std::unique_ptr<LpBackend> dense = MakeDenseSimplexBackend();
  dense->set_shared_phase1(true);
  std::unique_ptr<LpBackend> clp = MakeClpBackend();
  LpSolution a, b;
  int optimal = 0, unbounded = 0, infeasible = 0, capped = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    LpProblem p;
    const int m = 6 * UniformInt(rng, 1, 3);
    const int n = UniformInt(rng, 1, 40);
    p.Reset(m, n + 1);
    std::vector<double> x0(n);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < m; ++i) p.a[j * m + i] = Uniform(rng, 0, 1) < 0.5 ? 0.0 : Normal(rng);
      const double r = Uniform(rng, 0, 1);
      p.lower[j] = r < 0.3 ? 0.0 : (r < 0.4 ? -kInf : -Uniform(rng, 0, 5));
      p.upper[j] = r < 0.3 ? kInf : (r < 0.5 ? kInf : (r < 0.6 ? 0.0 : Uniform(rng, 0, 5)));
      const double lo = std::max(p.lower[j], -3.0), hi = std::min(p.upper[j], 3.0);
      x0[j] = Uniform(rng, lo, hi);
    }
    // Mostly a right-hand side some x0 within the bounds meets; one in ten at random.
    const bool reachable = Uniform(rng, 0, 1) < 0.9;
    for (int i = 0; i < m; ++i) {
      double v = 0.0;
      for (int j = 0; j < n; ++j) v += p.a[j * m + i] * x0[j];
      p.rhs[i] = reachable ? v : 5.0 * Normal(rng);
    }
    p.cost[n] = -1.0;
    // Half the trials cap the load factor at 1, as the planner's fast path does.
    p.upper[n] = trial % 2 == 0 ? kInf : 1.0;
    dense->LoadBase(p, n);
    for (int v = 0; v < 8; ++v) {
      std::vector<double> w(m);
      for (double& x : w) x = 10.0 * Normal(rng);
      std::copy(w.begin(), w.end(), p.column(n));
      const LpStatus sa = dense->SolveWithColumn(w.data(), a);
      const LpStatus sb = clp->Solve(p, b);
      ASSERT_EQ(sa, sb) << "trial " << trial << " vertex " << v;
      if (sa == LpStatus::kOptimal) {
        ++optimal;
        EXPECT_NEAR(a.objective, b.objective, 1e-6 * (1.0 + std::abs(b.objective)))
            << "trial " << trial << " vertex " << v;
        EXPECT_LT(Violation(p, a.x), 1e-7);
        if (p.upper[n] == 1.0 && a.x[n] == 1.0) ++capped;
      } else if (sa == LpStatus::kUnbounded) {
        ++unbounded;
      } else {
        ++infeasible;
      }
    }
  }
  EXPECT_GT(optimal, 2000);
  EXPECT_GT(unbounded, 500);
  EXPECT_GT(infeasible, 100);
  EXPECT_GT(capped, 500);
}

Mat3 RandomRotation(std::mt19937_64& rng) {
  Eigen::Quaterniond q(Normal(rng), Normal(rng), Normal(rng), Normal(rng));
  q.normalize();
  return q.toRotationMatrix();
}

Iso3 RandomPose(std::mt19937_64& rng, const Vec3& around, double spread) {
  Iso3 X = Iso3::Identity();
  X.linear() = RandomRotation(rng);
  X.translation() =
      around + spread * Vec3(Uniform(rng, -1, 1), Uniform(rng, -1, 1), Uniform(rng, -1, 1));
  return X;
}

WrenchBounds RandomBounds(std::mt19937_64& rng) {
  WrenchBox box{Vec3(Uniform(rng, 1, 60), Uniform(rng, 1, 60), Uniform(rng, 1, 120)),
                Vec3(Uniform(rng, 0.2, 6), Uniform(rng, 0.2, 6), Uniform(rng, 0.2, 4))};
  WrenchBounds b = BoundsFromBox(box);
  for (int i = 0; i < 6; ++i) {
    const double r = Uniform(rng, 0, 1);
    if (r < 0.1)
      b.lower[i] = 0.0;  // One-sided.
    else if (r < 0.15)
      b.upper[i] = kInf;  // Unlimited one way.
    else if (r < 0.2)
      b.lower[i] = b.upper[i] = 0.0;  // Cannot transmit.
  }
  return b;
}

StepConfiguration RandomConfiguration(std::mt19937_64& rng) {
  StepConfiguration c;
  const int nb = UniformInt(rng, 1, 3);
  for (int k = 0; k < nb; ++k) {
    c.bodies.push_back({"b" + std::to_string(k), Uniform(rng, 0, 2),
                        Vec3(0, 0, 0.5) + 0.15 * Vec3(Uniform(rng, -1, 1), Uniform(rng, -1, 1),
                                                      Uniform(rng, -1, 1))});
  }
  for (int k = 1; k < nb; ++k) {
    if (Uniform(rng, 0, 1) < 0.7) {
      const Vec3 mid = 0.5 * (c.bodies[k - 1].p_WBcm + c.bodies[k].p_WBcm);
      WrenchConnection conn{k - 1, k, RandomPose(rng, mid, 0.02), RandomBounds(rng), ""};
      if (Uniform(rng, 0, 1) < 0.3) conn.limits.lower[2] = 0.0;
      c.connections.push_back(conn);
    }
  }
  const int ng = UniformInt(rng, 0, 3);
  for (int i = 0; i < ng; ++i) {
    const int body = UniformInt(rng, 0, nb - 1);
    const Iso3 X_WG = RandomPose(rng, c.bodies[body].p_WBcm, 0.1);
    if (Uniform(rng, 0, 1) < 0.5) {
      const EndEffectorKind kind =
          Uniform(rng, 0, 1) < 0.5 ? EndEffectorKind::kVacuum : EndEffectorKind::kTwoFinger;
      c.grippers.push_back(MakeGripper("r" + std::to_string(i), body, X_WG, kind, {}));
    } else {
      WrenchGripper g;
      g.body = body;
      g.X_WG = X_WG;
      g.assembly_limits = RandomBounds(rng);
      g.transport_limits = RandomBounds(rng);
      c.grippers.push_back(g);
    }
  }
  if (Uniform(rng, 0, 1) < 0.5) {
    WrenchTableSupport t;
    t.body = 0;
    const Vec3 com = c.bodies[0].p_WBcm;
    const double h = Uniform(rng, 0.02, 0.15);
    const double z = com.z() - Uniform(rng, 0.01, 0.1);
    const int sides = UniformInt(rng, 1, 5);
    for (int s = 0; s < sides; ++s) {
      const double th = 2.0 * M_PI * s / sides + Uniform(rng, -0.3, 0.3);
      t.p_WV.push_back(Vec3(com.x() + h * std::cos(th), com.y() + h * std::sin(th), z));
    }
    t.friction = Uniform(rng, 0, 1) < 0.1 ? 0.0 : Uniform(rng, 0.1, 0.8);
    t.pyramid_edges = UniformInt(rng, 4, 8);
    c.tables.push_back(t);
  }
  if (nb >= 2 && Uniform(rng, 0, 1) < 0.8) {
    MatingLoad m;
    m.base = UniformInt(rng, 0, nb - 1);
    m.moved = Uniform(rng, 0, 1) < 0.2 ? -1 : (m.base + UniformInt(rng, 1, nb - 1)) % nb;
    m.axis_W = Vec3(Normal(rng), Normal(rng), Normal(rng));
    m.p_WContact = c.bodies[m.base].p_WBcm + 0.05 * Vec3(Normal(rng), Normal(rng), Normal(rng));
    m.force_N = Uniform(rng, 0, 30);
    m.torque_Nm = Uniform(rng, 0, 1) < 0.3 ? Uniform(rng, -2, 2) : 0.0;
    m.transverse_fraction = Uniform(rng, 0, 1) < 0.7 ? Uniform(rng, 0, 0.3) : 0.0;
    m.offset_m = Uniform(rng, 0, 1) < 0.5 ? Uniform(rng, 0, 0.01) : 0.0;
    c.mating = m;
  }
  return c;
}

WrenchQuery RandomQuery(std::mt19937_64& rng) {
  WrenchQuery q;
  q.gate = static_cast<WrenchGate>(UniformInt(rng, 0, 3));
  const double r = Uniform(rng, 0, 1);
  q.mode = r < 0.85 ? MatingWrenchMode::kFull
                    : (r < 0.97 ? MatingWrenchMode::kGravityOnly : MatingWrenchMode::kNone);
  q.lambda = Uniform(rng, 0, 2);
  q.accel_margin_mps2 = Uniform(rng, 0, 3);
  return q;
}

TEST(WrenchBackends, DenseMatchesClpOnRandomConfigurations) {
  std::mt19937_64 rng(7);
  WrenchChecker dense;
  WrenchOptions clp_options;
  clp_options.backend = WrenchLpBackend::kClp;
  WrenchChecker clp(clp_options);
  int feasible = 0, infeasible = 0, close = 0, vertices = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const StepConfiguration c = RandomConfiguration(rng);
    const WrenchQuery q = RandomQuery(rng);
    Result<WrenchCheck> a = dense.Check(c, q);
    Result<WrenchCheck> b = clp.Check(c, q);
    ASSERT_TRUE(a) << "trial " << trial << ": " << a.error().message;
    ASSERT_TRUE(b) << "trial " << trial << ": " << b.error().message;
    vertices += a->vertex_count;
    const double ua = a->utilisation, ub = b->utilisation;
    if (std::isinf(ua) || std::isinf(ub)) {
      EXPECT_EQ(std::isinf(ua), std::isinf(ub)) << "trial " << trial << ": " << ua << " " << ub;
    } else {
      EXPECT_NEAR(ua, ub, 1e-6 * (1.0 + ub)) << "trial " << trial;
    }
    if (std::abs(ub - 1.0) < 1e-6) {
      ++close;  // At the threshold either verdict is right.
      continue;
    }
    EXPECT_EQ(a->feasible, b->feasible) << "trial " << trial << ": " << ua << " " << ub;
    (a->feasible ? feasible : infeasible)++;
  }
  EXPECT_GT(feasible, 500);
  EXPECT_GT(infeasible, 500);
  EXPECT_GT(vertices, 8000);  // Held-then-mated checks that fail holding stop at 1 vertex.
  EXPECT_LT(close, 10);
}

}  // namespace
}  // namespace wrap
