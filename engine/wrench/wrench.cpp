// The wrench check (paper §IV-A): one load-factor LP per vertex of the uncertainty set U.
//
// Paper eq. (2) asks whether supports within their wrench sets balance the external wrench of
// every body (eq. 1). We answer a slightly stronger question with the same LP size: how far can
// the external load be scaled and still be balanced? With x the support variables (gripper and
// connection wrench components in their frames, table pyramid coefficients), A x the wrenches
// they put on the bodies (lp_model.cpp) and w the external wrenches of one vertex (vertices.cpp):
//
//     maximise s   subject to   A x + s w = 0,   lower <= x <= upper,   table coefficients >= 0.
//
// s is the load factor: the vertex is balanced within the limits iff s >= 1. Substituting
// x = s x' shows that 1 / s is the smallest uniform scaling of all limits (grippers and
// connections; friction cones are scale-free) that still balances the unscaled load, i.e.
//
//     utilisation = 1 / s* = min over balancing wrenches of max_i |w_i| / limit_i,
//
// the minimised largest utilisation: a property of the problem, not of the solver (the
// per-support values at the optimum are the solver's deterministic choice among the optima; the
// largest is unique). Why this objective: x = 0, s = 0 is always feasible, so the simplex needs no
// phase 1, and the answer is a margin rather than a yes/no. When s is unbounded, unlimited supports
// (the table, infinite bounds) carry the whole load: utilisation 0, and a second LP with s = 1 and
// every finite bound scaled to 0 returns such a balancing wrench.
//
// Grippers whose assembly box differs from their transport box (a vacuum cup: only its axial
// force while mating, paper table of limits). Before the parts touch, the grippers already hold
// their weight, as in transport; the paper's assembly box bounds what the insertion adds, since
// it is the insertion's transverse load that deflects a cup. Such a step is checked in two
// stages ("held, then mated"). Stage 1: the gravity-only load-factor LP with transport limits;
// when the weight cannot be held (s < 1) the step fails there. Stage 2, per vertex w of the
// mating set without gravity: one LP over the holding wrenches h and the totals t together,
//
//     maximise s   subject to   A h = -w_grav,   A (t - h) + s w = 0,
//                               h and t within the total bounds (grippers' transport boxes,
//                               connections' limits, table coefficients >= 0),
//                               t - h within the assembly box for each component of a
//                               gripper whose assembly box differs (vacuum),
//
// so the holding split is chosen with the mating load in view (no h is fixed beforehand). s
// scales the mating load alone; a vertex's utilisation is the larger of stage 1's and 1 / s, and
// the loads it reports are h + (t - h) / s. Configurations whose grippers have one box for both
// modes take the single LP. When a vertex fails, the explanation fixes the worst vertex's h and
// names what the mating load needs beyond what that h leaves.
//
// Robust satisfaction: feasible iff every vertex has s >= 1 - tolerance. Each support reports the
// largest utilisation over the vertices; a table reports the friction its resultant force uses,
// |F_t| / (mu F_n). When infeasible, explain.cpp names the binding limits at the worst vertex.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

#include "wrench/detail/canonical_key.h"
#include "wrench/detail/lp_model.h"
#include "wrench/detail/vertices.h"
#include "wrench/wrench.h"

namespace wrap {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxShortfallsInReason = 3;
constexpr double kTinyLoadFactor = 1e-9;  // Utilisation above 1e9: treated as infinite.
constexpr double kNoiseN = 1e-9;          // Loads below this [N, N m] count as 0.

}  // namespace

struct WrenchChecker::Impl {
  WrenchOptions options;
  std::unique_ptr<LpBackend> lp;
  LpProblem problem;       // The load-factor LP; only its last column (s) changes per vertex.
  LpProblem zero_problem;  // The utilisation-0 variant (s = 1, finite bounds scaled to 0).
  LpSolution solution;
  detail::VertexSet vertices;
  std::vector<detail::ColumnInfo> columns;
  std::vector<double> lower;  // Bounds of the limited columns (support frame).
  std::vector<double> upper;
  std::vector<int> support_of;       // Index into WrenchCheck::supports of each column.
  std::vector<Vec3> edge;            // Table columns: the pyramid edge (force per unit).
  std::vector<Vec3> table_force;     // Scratch: resultant force of each table.
  std::vector<std::uint64_t> words;  // Scratch: the canonical key.
  int table_base = -1;               // Index of the first table in WrenchCheck::supports, or -1.

  struct Entry {
    std::vector<std::uint64_t> words;
    WrenchCheck check;
  };
  std::unordered_map<std::uint64_t, Entry> by_hash;
  std::unordered_map<std::uint64_t, WrenchCheck> by_key;
  std::uint64_t hits = 0;
  std::uint64_t misses = 0;
  std::unique_ptr<LpBackend> reference;  // Clp, made when the dense simplex first gives no answer
  std::uint64_t fallbacks = 0;
  std::uint64_t solves = 0;  // LPs solved (one per vertex, the zero-utilisation variants).
  std::uint64_t pivots = 0;  // Their simplex pivots.
  int first_vertex = 0;      // first_failure_suffices: where the next vertex loop starts.

  // The i-th vertex a loop over `count` visits: all of them in order, or, when the first failure
  // suffices, starting where the last failure was (the next question is often like the last).
  int VertexAt(int i, int count) const {
    return options.first_failure_suffices ? (first_vertex + i) % count : i;
  }
  // The load factor's upper bound: none, or 1 when only the verdict counts. Capped, a passing
  // vertex stops at the first balance of its full load (often pivots before the largest load
  // factor), the LP is never unbounded, and a failing vertex still gets its exact s* < 1.
  double MaxLoadFactor() const { return options.first_failure_suffices ? 1.0 : kInf; }
  // After vertex v failed: true when the loop may stop there.
  bool StopAfterFailure(int v) {
    if (!options.first_failure_suffices) return false;
    first_vertex = v;
    return true;
  }

  // The backend's answer, or Clp's when the dense simplex ends without one (infeasible, an
  // iteration limit, an error) on an LP that has an answer by construction (x = 0, s = 0 is
  // feasible; the joint LP is feasible once the holding LP passed): a numerical failure of ours,
  // not of the configuration. `full` is the problem with its varying column in place.
  LpStatus SolveVarying(const LpProblem& full, const double* values) {
    const LpStatus status = lp->SolveWithColumn(values, solution);
    ++solves;
    pivots += static_cast<std::uint64_t>(solution.iterations);
    return status == LpStatus::kOptimal || status == LpStatus::kUnbounded ? status
                                                                          : SolveReference(full);
  }
  LpStatus SolveFull(const LpProblem& full) {
    const LpStatus status = lp->Solve(full, solution);
    ++solves;
    pivots += static_cast<std::uint64_t>(solution.iterations);
    return status == LpStatus::kOptimal || status == LpStatus::kUnbounded ? status
                                                                          : SolveReference(full);
  }
  LpStatus SolveReference(const LpProblem& full) {
    if (options.backend == WrenchLpBackend::kClp) return solution.status;
    if (!reference) reference = MakeClpBackend();
    ++fallbacks;
    return reference->Solve(full, solution);
  }

  Result<WrenchCheck> Compute(const StepConfiguration& config, const WrenchQuery& query);
  // The variant of `problem` with s = 1 and every finite bound at 0 (the load factor was
  // unbounded: unlimited supports carry the load); its solution into `solution`.
  Result<void> SolveAtZeroUtilisation(int n);
  // The internal error of an LP that ended with `status` instead of an answer.
  std::unexpected<Error> LpFailed(LpStatus status, const std::string& which) const {
    return Fail(ErrorCode::kInternal, "wrench: LP backend '" + std::string(lp->name()) +
                                          "' returned " + std::string(ToString(status)) + " on " +
                                          which);
  }
  // The "held, then mated" assembly check (see the top of this file); `out` has its supports.
  Result<WrenchCheck> ComputeHeldThenMated(const StepConfiguration& config,
                                           const WrenchQuery& query, WrenchCheck out);
  // Stage 2 of ComputeHeldThenMated: the joint LP over holding wrenches h and totals t (see the
  // top of this file) into zero_problem, with `w_grav` on the gravity rows; returns the column of
  // s, whose mating rows each vertex fills.
  int BuildJointProblem(const StepConfiguration& config, const double* w_grav);
  // Stage 2's loop over `vertices` (the mating set without gravity): the vertex results into
  // `out`, its utilisation at least `hold_utilisation`; returns the worst vertex's h.
  Result<std::vector<double>> SolveMatingVertices(const StepConfiguration& config, int s_col,
                                                  double hold_utilisation, WrenchCheck& out);
  // Columns of every support of an assembly check (grippers with their transport components);
  // fills columns, support_of, edge, lower, upper (the total bounds) and problem's columns.
  void BuildColumns(const StepConfiguration& config, WrenchGate gate, const Vec3& p_WO,
                    bool transport_boxes);
  // Finishes `out` from the vertex loop's results: worst-vertex label, explanation, reason.
  Result<WrenchCheck> Finish(const StepConfiguration& explain_config, const WrenchQuery& query,
                             const Vec3& p_WO, const detail::VertexSet& set, WrenchCheck out,
                             const std::string& prefix);
  // Utilisations of one vertex's solution x (actual loads = x * scale) into `out`.
  void Accumulate(const StepConfiguration& config, const std::vector<double>& x, double scale,
                  int vertex, WrenchCheck& out);
};

void WrenchChecker::Impl::Accumulate(const StepConfiguration& config, const std::vector<double>& x,
                                     double scale, int vertex, WrenchCheck& out) {
  const int n = static_cast<int>(columns.size());
  for (Vec3& f : table_force) f.setZero();
  for (int j = 0; j < n; ++j) {
    const detail::ColumnInfo& c = columns[j];
    if (c.kind == SupportKind::kTable) {
      table_force[c.owner] += x[j] * edge[j];
      continue;
    }
    const double value = x[j] * scale;
    // Solver noise (e.g. -1e-13 against a bound of 0) is no load.
    if (std::abs(value) <= kNoiseN) continue;
    const double limit = value > 0.0 ? upper[j] : -lower[j];
    const double ratio = std::isinf(limit) ? 0.0 : std::abs(value) / limit;
    SupportLoad& s = out.supports[support_of[j]];
    if (ratio > s.utilisation) {
      s.utilisation = ratio;
      s.component = c.component;
      s.vertex = vertex;
    }
  }
  if (table_base < 0) return;  // The gate ignores tables.
  for (int t = 0; t < static_cast<int>(config.tables.size()); ++t) {
    const WrenchTableSupport& table = config.tables[t];
    Vec3 nrm, t1, t2;
    detail::TableTangents(table, nrm, t1, t2);
    const Vec3& f = table_force[t];
    const double fn = f.dot(nrm);
    const double ft = (f - fn * nrm).norm();
    double ratio = 0.0;
    if (ft > kNoiseN + 1e-12 * std::abs(fn)) {
      ratio = table.friction * fn > 0.0 ? ft / (table.friction * fn) : kInf;
    }
    SupportLoad& s = out.supports[table_base + t];
    if (ratio > s.utilisation) {
      s.utilisation = ratio;
      s.vertex = vertex;
    }
  }
}

void WrenchChecker::Impl::BuildColumns(const StepConfiguration& config, WrenchGate gate,
                                       const Vec3& p_WO, bool transport_boxes) {
  const bool grippers_on = detail::GrippersActive(gate);
  const bool tables_on = detail::TablesActive(gate);
  const int ng = static_cast<int>(config.grippers.size());
  const int nc = static_cast<int>(config.connections.size());
  const int nt = static_cast<int>(config.tables.size());
  const int rows = static_cast<int>(config.bodies.size()) * 6;
  columns.clear();
  support_of.clear();
  const int gripper_base = 0;
  const int connection_base = grippers_on ? ng : 0;
  table_base = tables_on ? connection_base + nc : -1;
  auto add_limited = [&](SupportKind kind, int owner, const WrenchBounds& b, int support) {
    for (int i = 0; i < 6; ++i) {
      if (b.lower[i] == 0.0 && b.upper[i] == 0.0) continue;  // Carries nothing: no column.
      columns.push_back({kind, owner, i});
      support_of.push_back(support);
    }
  };
  if (grippers_on) {
    for (int g = 0; g < ng; ++g) {
      const WrenchGripper& gr = config.grippers[g];
      add_limited(SupportKind::kGripper, g,
                  transport_boxes ? gr.transport_limits : detail::GripperLimits(gr, gate),
                  gripper_base + g);
    }
  }
  for (int c = 0; c < nc; ++c) {
    add_limited(SupportKind::kConnection, c, config.connections[c].limits, connection_base + c);
  }
  if (tables_on) {
    for (int t = 0; t < nt; ++t) {
      const WrenchTableSupport& table = config.tables[t];
      const int generators = static_cast<int>(table.p_WV.size()) * detail::PyramidEdges(table);
      for (int e = 0; e < generators; ++e) {
        columns.push_back({SupportKind::kTable, t, e});
        support_of.push_back(table_base + t);
      }
    }
  }
  table_force.assign(nt, Vec3::Zero());

  const int n = static_cast<int>(columns.size());
  problem.Reset(rows, n + 1);
  lower.assign(n, 0.0);
  upper.assign(n, kInf);
  edge.assign(n, Vec3::Zero());
  for (int j = 0; j < n; ++j) {
    const detail::ColumnInfo& c = columns[j];
    detail::FillColumn(config, p_WO, c, problem.column(j));
    if (c.kind == SupportKind::kTable) {
      const WrenchTableSupport& table = config.tables[c.owner];
      edge[j] = detail::PyramidEdge(table, c.component % detail::PyramidEdges(table));
    } else if (transport_boxes && c.kind == SupportKind::kGripper) {
      const WrenchBounds& b = config.grippers[c.owner].transport_limits;
      lower[j] = b.lower[c.component];
      upper[j] = b.upper[c.component];
    } else {
      detail::ComponentBounds(config, gate, c, lower[j], upper[j]);
    }
    problem.lower[j] = lower[j];
    problem.upper[j] = upper[j];
  }
  problem.cost[n] = -1.0;  // Maximise s.
  problem.lower[n] = 0.0;
  problem.upper[n] = MaxLoadFactor();
}

Result<WrenchCheck> WrenchChecker::Impl::Finish(const StepConfiguration& explain_config,
                                                const WrenchQuery& query, const Vec3& p_WO,
                                                const detail::VertexSet& set, WrenchCheck out,
                                                const std::string& prefix) {
  out.feasible = out.failing_vertex_count == 0;
  if (out.worst_vertex >= 0) out.worst_vertex_label = detail::VertexLabel(set, out.worst_vertex);
  if (out.feasible) return out;

  // Why not: the binding limits at the worst vertex.
  if (options.explain) {
    Result<std::vector<Shortfall>> shortfalls =
        detail::FindShortfalls(explain_config, query, p_WO, set.vertex(out.worst_vertex), *lp);
    if (!shortfalls) return std::unexpected(shortfalls.error());
    out.shortfalls = std::move(*shortfalls);
  }
  std::string reason = prefix;
  if (set.count == 1) {
    reason += " (" + out.worst_vertex_label + "): ";
  } else {
    reason += ": vertex " + std::to_string(out.worst_vertex + 1) + "/" + std::to_string(set.count) +
              " (" + out.worst_vertex_label + "): ";
  }
  if (out.shortfalls.empty()) {
    reason += std::isinf(out.utilisation)
                  ? std::string("no support can balance the load")
                  : "the supports would need " + detail::FormatNumber(100.0 * out.utilisation) +
                        "% of their limits";
  } else {
    reason +=
        detail::DescribeShortfalls(explain_config, query, out.shortfalls, kMaxShortfallsInReason);
  }
  if (out.failing_vertex_count > 1) {
    reason += " (" + std::to_string(out.failing_vertex_count - 1) + " more of the " +
              std::to_string(set.count) + " vertices fail)";
  }
  out.reason = std::move(reason);
  return out;
}

Result<WrenchCheck> WrenchChecker::Impl::Compute(const StepConfiguration& config,
                                                 const WrenchQuery& query) {
  if (auto valid = detail::Validate(config, query); !valid) return std::unexpected(valid.error());
  if (options.on_question) options.on_question(config, query);
  const WrenchGate gate = query.gate;
  const bool grippers_on = detail::GrippersActive(gate);
  const bool tables_on = detail::TablesActive(gate);
  const int ng = static_cast<int>(config.grippers.size());
  const int nc = static_cast<int>(config.connections.size());
  const int nt = static_cast<int>(config.tables.size());

  WrenchCheck out;
  if (grippers_on) {
    for (int g = 0; g < ng; ++g) out.supports.push_back({SupportKind::kGripper, g});
  }
  for (int c = 0; c < nc; ++c) out.supports.push_back({SupportKind::kConnection, c});
  if (tables_on) {
    for (int t = 0; t < nt; ++t) out.supports.push_back({SupportKind::kTable, t});
  }
  if (query.mode == MatingWrenchMode::kNone) return out;
  if (gate == WrenchGate::kAssembly) {
    for (const WrenchGripper& g : config.grippers) {
      if (!(g.assembly_limits == g.transport_limits)) {
        return ComputeHeldThenMated(config, query, std::move(out));
      }
    }
  }

  // Columns: every gripper and connection component that can carry load, every table generator.
  const Vec3 p_WO = detail::ReferencePoint(config);
  const int rows = static_cast<int>(config.bodies.size()) * 6;
  BuildColumns(config, gate, p_WO, false);
  const int n = static_cast<int>(columns.size());

  detail::BuildVertices(config, query, p_WO, vertices);
  out.vertex_count = vertices.count;
  const double s_feasible = 1.0 - options.tolerance;
  double worst = -1.0;
  lp->LoadBase(problem, n);
  for (int i = 0; i < vertices.count; ++i) {
    const int v = VertexAt(i, vertices.count);
    const double* w = vertices.vertex(v);
    std::copy(w, w + rows, problem.column(n));  // The zero-utilisation variant starts from it.
    LpStatus status = SolveVarying(problem, w);
    double utilisation = 0.0;
    bool failing = false;
    if (status == LpStatus::kOptimal) {
      // A load factor within solver noise of 0 means no scaling of the limits balances it.
      const double s = solution.x[n] > kTinyLoadFactor ? solution.x[n] : 0.0;
      failing = s < s_feasible;
      utilisation = s > 0.0 ? 1.0 / s : kInf;
      if (s > 0.0) Accumulate(config, solution.x, 1.0 / s, v, out);
    } else if (status == LpStatus::kUnbounded) {
      // Unlimited supports carry everything: find such a balance for the table's friction use.
      if (auto zero = SolveAtZeroUtilisation(n); !zero) return std::unexpected(zero.error());
      Accumulate(config, solution.x, 1.0, v, out);
    } else {
      return LpFailed(status, "the load-factor LP of vertex " + std::to_string(v));
    }
    if (failing) ++out.failing_vertex_count;
    if (utilisation > worst) {
      worst = utilisation;
      out.worst_vertex = v;
    }
    // A failing vertex is the worst so far (every earlier one passed), so the reason explains it.
    if (failing && StopAfterFailure(v)) break;
  }
  out.utilisation = worst < 0.0 ? 0.0 : worst;
  return Finish(config, query, p_WO, vertices, std::move(out), std::string(ToString(gate)));
}

Result<void> WrenchChecker::Impl::SolveAtZeroUtilisation(int n) {
  zero_problem = problem;
  zero_problem.cost[n] = 0.0;
  zero_problem.lower[n] = zero_problem.upper[n] = 1.0;
  for (int j = 0; j < n; ++j) {
    if (std::isfinite(zero_problem.lower[j])) zero_problem.lower[j] = 0.0;
    if (std::isfinite(zero_problem.upper[j])) zero_problem.upper[j] = 0.0;
  }
  const LpStatus status = SolveFull(zero_problem);
  if (status != LpStatus::kOptimal) {
    return Fail(ErrorCode::kInternal, "wrench: LP backend '" + std::string(lp->name()) +
                                          "' found the load factor unbounded but no " +
                                          "balance at zero utilisation (" +
                                          std::string(ToString(status)) + ")");
  }
  return {};
}

namespace {

// The configuration whose assembly check names what the mating load needs beyond what the
// holding wrenches `hold` (per column of `columns`) leave: `mating_only` (no gravity) with totals
// within limits and mode-dependent grippers within their assembly box.
StepConfiguration LeftForMating(const StepConfiguration& config,
                                const StepConfiguration& mating_only,
                                const std::vector<detail::ColumnInfo>& columns,
                                const std::vector<double>& lower, const std::vector<double>& upper,
                                const std::vector<double>& hold) {
  StepConfiguration left = mating_only;
  for (WrenchGripper& g : left.grippers) g.assembly_limits = WrenchBounds{};
  for (WrenchConnection& c : left.connections) c.limits = WrenchBounds{};
  const int n = static_cast<int>(columns.size());
  for (int j = 0; j < n; ++j) {
    const detail::ColumnInfo& c = columns[j];
    if (c.kind == SupportKind::kTable) continue;
    double lo = std::min(0.0, lower[j] - hold[j]);
    double hi = std::max(0.0, upper[j] - hold[j]);
    if (c.kind == SupportKind::kGripper) {
      const WrenchBounds& box = config.grippers[c.owner].assembly_limits;
      lo = std::min(0.0, std::max(lo, box.lower[c.component]));
      hi = std::max(0.0, std::min(hi, box.upper[c.component]));
      left.grippers[c.owner].assembly_limits.lower[c.component] = lo;
      left.grippers[c.owner].assembly_limits.upper[c.component] = hi;
    } else {
      left.connections[c.owner].limits.lower[c.component] = lo;
      left.connections[c.owner].limits.upper[c.component] = hi;
    }
  }
  return left;
}

}  // namespace

int WrenchChecker::Impl::BuildJointProblem(const StepConfiguration& config, const double* w_grav) {
  const int nb6 = static_cast<int>(config.bodies.size()) * 6;
  const int n = static_cast<int>(columns.size());
  std::vector<int> coupled;  // Columns of grippers whose assembly box differs.
  for (int j = 0; j < n; ++j) {
    const detail::ColumnInfo& c = columns[j];
    if (c.kind != SupportKind::kGripper) continue;
    const WrenchGripper& g = config.grippers[c.owner];
    if (!(g.assembly_limits == g.transport_limits)) coupled.push_back(j);
  }
  const int nv = static_cast<int>(coupled.size());
  const int rows = 2 * nb6 + nv;
  const int s_col = 2 * n + nv;
  LpProblem& joint = zero_problem;
  joint.Reset(rows, s_col + 1);
  for (int j = 0; j < n; ++j) {
    const double* a = problem.column(j);
    double* hj = joint.column(j);
    double* tj = joint.column(n + j);
    for (int i = 0; i < nb6; ++i) {
      hj[i] = a[i];         // Gravity rows: A h = -w_grav.
      hj[nb6 + i] = -a[i];  // Mating rows: A (t - h) + s w = 0.
      tj[nb6 + i] = a[i];
    }
    joint.lower[j] = joint.lower[n + j] = lower[j];
    joint.upper[j] = joint.upper[n + j] = upper[j];
  }
  for (int k = 0; k < nv; ++k) {
    const int j = coupled[k];
    const detail::ColumnInfo& c = columns[j];
    const WrenchBounds& box = config.grippers[c.owner].assembly_limits;
    joint.column(j)[2 * nb6 + k] = -1.0;
    joint.column(n + j)[2 * nb6 + k] = 1.0;
    joint.column(2 * n + k)[2 * nb6 + k] = -1.0;
    joint.lower[2 * n + k] = box.lower[c.component];
    joint.upper[2 * n + k] = box.upper[c.component];
  }
  for (int i = 0; i < nb6; ++i) joint.rhs[i] = -w_grav[i];
  joint.cost[s_col] = -1.0;  // Maximise s.
  joint.lower[s_col] = 0.0;
  joint.upper[s_col] = MaxLoadFactor();
  return s_col;
}

Result<std::vector<double>> WrenchChecker::Impl::SolveMatingVertices(
    const StepConfiguration& config, int s_col, double hold_utilisation, WrenchCheck& out) {
  const int nb6 = static_cast<int>(config.bodies.size()) * 6;
  const int n = static_cast<int>(columns.size());
  const int nv = s_col - 2 * n;
  const double s_feasible = 1.0 - options.tolerance;
  LpProblem& joint = zero_problem;
  lp->LoadBase(joint, s_col);
  std::vector<double> total(n), hold(n);
  std::vector<double> worst_hold;
  double worst = -1.0;
  for (int i = 0; i < vertices.count; ++i) {
    const int v = VertexAt(i, vertices.count);
    const double* w = vertices.vertex(v);
    std::copy(w, w + nb6, joint.column(s_col) + nb6);
    std::fill(joint.column(s_col), joint.column(s_col) + nb6, 0.0);
    for (int k = 0; k < nv; ++k) joint.column(s_col)[2 * nb6 + k] = 0.0;
    LpStatus status = SolveVarying(joint, joint.column(s_col));
    double s = kInf;
    if (status == LpStatus::kOptimal) {
      s = solution.x[s_col] > kTinyLoadFactor ? solution.x[s_col] : 0.0;
    } else if (status == LpStatus::kUnbounded) {
      // Unlimited supports carry the mating load: any balance at s = 1 for the reports.
      LpProblem at_one = joint;
      at_one.cost[s_col] = 0.0;
      at_one.lower[s_col] = at_one.upper[s_col] = 1.0;
      status = SolveFull(at_one);
      if (status != LpStatus::kOptimal) {
        return Fail(ErrorCode::kInternal, "wrench: LP backend '" + std::string(lp->name()) +
                                              "' found the mating load factor unbounded but no " +
                                              "balance at 1 (" + std::string(ToString(status)) +
                                              ")");
      }
    } else {
      return LpFailed(status, "the mating LP of vertex " + std::to_string(v));
    }
    const bool failing = s < s_feasible;
    const double utilisation =
        std::max(hold_utilisation, s > 0.0 ? (std::isinf(s) ? 0.0 : 1.0 / s) : kInf);
    if (s > 0.0) {
      // Loads at the unscaled mating wrench: h + (t - h) / s.
      const double scale = std::isinf(s) ? 1.0 : 1.0 / s;
      for (int j = 0; j < n; ++j) {
        hold[j] = solution.x[j];
        total[j] = hold[j] + (solution.x[n + j] - hold[j]) * scale;
      }
      Accumulate(config, total, 1.0, v, out);
    } else {
      for (int j = 0; j < n; ++j) hold[j] = solution.x[j];
    }
    if (failing) ++out.failing_vertex_count;
    if (utilisation > worst) {
      worst = utilisation;
      out.worst_vertex = v;
      worst_hold = hold;
    }
    if (failing && StopAfterFailure(v)) break;
  }
  out.utilisation = worst < 0.0 ? hold_utilisation : worst;
  return worst_hold;
}

Result<WrenchCheck> WrenchChecker::Impl::ComputeHeldThenMated(const StepConfiguration& config,
                                                              const WrenchQuery& query,
                                                              WrenchCheck out) {
  const Vec3 p_WO = detail::ReferencePoint(config);
  const int nb6 = static_cast<int>(config.bodies.size()) * 6;
  BuildColumns(config, WrenchGate::kAssembly, p_WO, true);  // Total bounds: transport boxes.
  const int n = static_cast<int>(columns.size());
  const double s_feasible = 1.0 - options.tolerance;

  // Stage 1: the weight held before the parts touch (transport limits, tables as they are).
  WrenchQuery hold_query = query;
  hold_query.gate = WrenchGate::kRelease;
  hold_query.mode = MatingWrenchMode::kGravityOnly;
  detail::VertexSet hold_set;
  detail::BuildVertices(config, hold_query, p_WO, hold_set);
  const double* w_grav = hold_set.vertex(0);
  double hold_utilisation = 0.0;
  {
    std::copy(w_grav, w_grav + nb6, problem.column(n));
    lp->LoadBase(problem, n);
    const LpStatus status = SolveVarying(problem, w_grav);
    if (status == LpStatus::kOptimal) {
      const double s = solution.x[n] > kTinyLoadFactor ? solution.x[n] : 0.0;
      hold_utilisation = s > 0.0 ? 1.0 / s : kInf;
      if (s < s_feasible) {
        out.vertex_count = 1;
        out.failing_vertex_count = 1;
        out.worst_vertex = 0;
        out.utilisation = hold_utilisation;
        if (s > 0.0) Accumulate(config, solution.x, 1.0 / s, 0, out);
        return Finish(config, hold_query, p_WO, hold_set, std::move(out),
                      "assembly, holding the parts before they touch");
      }
    } else if (status != LpStatus::kUnbounded) {
      return LpFailed(status, "the holding LP");
    }
  }

  // Stage 2, per vertex of the mating set without gravity: holding wrenches h balance gravity,
  // totals t balance gravity plus s times the mating load, both within the total bounds, and a
  // mode-dependent gripper's increment d = t - h within its assembly box.
  const int s_col = BuildJointProblem(config, w_grav);
  StepConfiguration mating_only = config;
  mating_only.gravity_W = Vec3::Zero();
  detail::BuildVertices(mating_only, query, p_WO, vertices);
  out.vertex_count = vertices.count;
  Result<std::vector<double>> worst_hold =
      SolveMatingVertices(config, s_col, hold_utilisation, out);
  if (!worst_hold) return std::unexpected(worst_hold.error());
  if (out.failing_vertex_count == 0) {
    return Finish(config, query, p_WO, vertices, std::move(out), "assembly");
  }
  // The explanation: what the mating load needs beyond what the holding wrenches of the worst
  // vertex leave.
  return Finish(LeftForMating(config, mating_only, columns, lower, upper, *worst_hold), query, p_WO,
                vertices, std::move(out), "assembly");
}

WrenchChecker::WrenchChecker(const WrenchOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->lp =
      options.backend == WrenchLpBackend::kClp ? MakeClpBackend() : MakeDenseSimplexBackend();
  // The planner's fast path: one phase 1 per joint LP instead of one per vertex (x may be
  // another optimum; the load factor is the same). The full check keeps its exact solutions.
  impl_->lp->set_shared_phase1(options.first_failure_suffices);
}

WrenchChecker::~WrenchChecker() = default;
WrenchChecker::WrenchChecker(WrenchChecker&&) noexcept = default;
WrenchChecker& WrenchChecker::operator=(WrenchChecker&&) noexcept = default;

Result<WrenchCheck> WrenchChecker::Check(const StepConfiguration& config,
                                         const WrenchQuery& query) {
  return impl_->Compute(config, query);
}

Result<WrenchCheck> WrenchChecker::CheckCached(const StepConfiguration& config,
                                               const WrenchQuery& query) {
  Impl& im = *impl_;
  detail::EncodeQuestion(config, query, im.words);
  const std::uint64_t hash = detail::HashWords(im.words);
  if (auto it = im.by_hash.find(hash); it != im.by_hash.end() && it->second.words == im.words) {
    ++im.hits;
    return it->second.check;
  }
  ++im.misses;
  Result<WrenchCheck> result = im.Compute(config, query);
  if (!result) return result;
  if (im.by_hash.size() >= im.options.cache_capacity) im.by_hash.clear();
  im.by_hash.insert_or_assign(hash, Impl::Entry{im.words, *result});
  return result;
}

Result<WrenchCheck> WrenchChecker::CheckCached(std::uint64_t key, const StepConfiguration& config,
                                               const WrenchQuery& query) {
  Impl& im = *impl_;
  if (auto it = im.by_key.find(key); it != im.by_key.end()) {
    ++im.hits;
    return it->second;
  }
  ++im.misses;
  Result<WrenchCheck> result = im.Compute(config, query);
  if (!result) return result;
  if (im.by_key.size() >= im.options.cache_capacity) im.by_key.clear();
  im.by_key.insert_or_assign(key, *result);
  return result;
}

std::uint64_t WrenchChecker::cache_hits() const { return impl_->hits; }
std::uint64_t WrenchChecker::cache_misses() const { return impl_->misses; }
std::uint64_t WrenchChecker::lp_fallbacks() const { return impl_->fallbacks; }
std::uint64_t WrenchChecker::lp_solves() const { return impl_->solves; }
std::uint64_t WrenchChecker::lp_pivots() const { return impl_->pivots; }

void WrenchChecker::ClearCache() {
  impl_->by_hash.clear();
  impl_->by_key.clear();
  impl_->hits = 0;
  impl_->misses = 0;
}

const WrenchOptions& WrenchChecker::options() const { return impl_->options; }

bool HeldThenMated(const StepConfiguration& config) {
  for (const WrenchGripper& g : config.grippers) {
    if (!(g.assembly_limits == g.transport_limits)) return true;
  }
  return false;
}

StepConfiguration MatingIncrementRelaxation(const StepConfiguration& config) {
  // A total t and a hold h both within [lo, hi] differ by t - h within [lo - hi, hi - lo]
  // (infinite bounds stay infinite).
  auto widen = [](WrenchBounds& b) {
    const Vec6 span = b.upper - b.lower;
    b.lower = -span;
    b.upper = span;
  };
  StepConfiguration out = config;
  out.gravity_W = Vec3::Zero();
  out.tables.clear();
  if (out.mating) {
    out.mating->transverse_fraction *= std::numbers::sqrt2 / 2.0;
    out.mating->offset_m *= std::numbers::sqrt2 / 2.0;
  }
  for (WrenchGripper& g : out.grippers) widen(g.transport_limits);
  for (WrenchConnection& c : out.connections) widen(c.limits);
  return out;
}

Result<WrenchCheck> CheckWrench(const StepConfiguration& config, const WrenchQuery& query,
                                const WrenchOptions& options) {
  WrenchChecker checker(options);
  return checker.Check(config, query);
}

Result<std::vector<WrenchVertex>> UncertaintyVertices(const StepConfiguration& config,
                                                      const WrenchQuery& query, const Vec3& p_WO) {
  if (auto valid = detail::Validate(config, query); !valid) return std::unexpected(valid.error());
  detail::VertexSet set;
  detail::BuildVertices(config, query, p_WO, set);
  std::vector<WrenchVertex> out(set.count);
  for (int v = 0; v < set.count; ++v) {
    out[v].label = detail::VertexLabel(set, v);
    const double* w = set.vertex(v);
    for (int k = 0; k < set.bodies; ++k) {
      out[v].w_ext_W.push_back(Eigen::Map<const Vec6>(w + k * 6));
    }
  }
  return out;
}

}  // namespace wrap
