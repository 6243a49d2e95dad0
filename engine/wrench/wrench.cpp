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
// Robust satisfaction: feasible iff every vertex has s >= 1 - tolerance. Each support reports the
// largest utilisation over the vertices; a table reports the friction its resultant force uses,
// |F_t| / (mu F_n). When infeasible, explain.cpp names the binding limits at the worst vertex.
#include <cmath>
#include <limits>
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

  Result<WrenchCheck> Compute(const StepConfiguration& config, const WrenchQuery& query);
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

Result<WrenchCheck> WrenchChecker::Impl::Compute(const StepConfiguration& config,
                                                 const WrenchQuery& query) {
  if (auto valid = detail::Validate(config, query); !valid) return std::unexpected(valid.error());
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

  // Columns: every gripper and connection component that can carry load, every table generator.
  const Vec3 p_WO = detail::ReferencePoint(config);
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
      add_limited(SupportKind::kGripper, g, detail::GripperLimits(config.grippers[g], gate),
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
    } else {
      detail::ComponentBounds(config, gate, c, lower[j], upper[j]);
    }
    problem.lower[j] = lower[j];
    problem.upper[j] = upper[j];
  }
  problem.cost[n] = -1.0;  // Maximise s.
  problem.lower[n] = 0.0;
  problem.upper[n] = kInf;

  detail::BuildVertices(config, query, p_WO, vertices);
  out.vertex_count = vertices.count;
  const double s_feasible = 1.0 - options.tolerance;
  double worst = -1.0;
  lp->LoadBase(problem, n);
  for (int v = 0; v < vertices.count; ++v) {
    const double* w = vertices.vertex(v);
    std::copy(w, w + rows, problem.column(n));  // The zero-utilisation variant starts from it.
    LpStatus status = lp->SolveWithColumn(w, solution);
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
      zero_problem = problem;
      zero_problem.cost[n] = 0.0;
      zero_problem.lower[n] = zero_problem.upper[n] = 1.0;
      for (int j = 0; j < n; ++j) {
        if (std::isfinite(zero_problem.lower[j])) zero_problem.lower[j] = 0.0;
        if (std::isfinite(zero_problem.upper[j])) zero_problem.upper[j] = 0.0;
      }
      status = lp->Solve(zero_problem, solution);
      if (status != LpStatus::kOptimal) {
        return Fail(ErrorCode::kInternal, "wrench: LP backend '" + std::string(lp->name()) +
                                              "' found the load factor unbounded but no " +
                                              "balance at zero utilisation (" +
                                              std::string(ToString(status)) + ")");
      }
      Accumulate(config, solution.x, 1.0, v, out);
    } else {
      return Fail(ErrorCode::kInternal, "wrench: LP backend '" + std::string(lp->name()) +
                                            "' returned " + std::string(ToString(status)) +
                                            " on the load-factor LP of vertex " +
                                            std::to_string(v));
    }
    if (failing) ++out.failing_vertex_count;
    if (utilisation > worst) {
      worst = utilisation;
      out.worst_vertex = v;
    }
  }
  out.utilisation = worst < 0.0 ? 0.0 : worst;
  out.feasible = out.failing_vertex_count == 0;
  if (out.worst_vertex >= 0)
    out.worst_vertex_label = detail::VertexLabel(vertices, out.worst_vertex);
  if (out.feasible) return out;

  // Why not: the binding limits at the worst vertex.
  if (options.explain) {
    Result<std::vector<Shortfall>> shortfalls =
        detail::FindShortfalls(config, query, p_WO, vertices.vertex(out.worst_vertex), *lp);
    if (!shortfalls) return std::unexpected(shortfalls.error());
    out.shortfalls = std::move(*shortfalls);
  }
  std::string reason(ToString(gate));
  if (vertices.count == 1) {
    reason += " (" + out.worst_vertex_label + "): ";
  } else {
    reason += ": vertex " + std::to_string(out.worst_vertex + 1) + "/" +
              std::to_string(vertices.count) + " (" + out.worst_vertex_label + "): ";
  }
  if (out.shortfalls.empty()) {
    reason += std::isinf(out.utilisation)
                  ? std::string("no support can balance the load")
                  : "the supports would need " + detail::FormatNumber(100.0 * out.utilisation) +
                        "% of their limits";
  } else {
    reason += detail::DescribeShortfalls(config, query, out.shortfalls, kMaxShortfallsInReason);
  }
  if (out.failing_vertex_count > 1) {
    reason += " (" + std::to_string(out.failing_vertex_count - 1) + " more of the " +
              std::to_string(vertices.count) + " vertices fail)";
  }
  out.reason = std::move(reason);
  return out;
}

WrenchChecker::WrenchChecker(const WrenchOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->lp =
      options.backend == WrenchLpBackend::kClp ? MakeClpBackend() : MakeDenseSimplexBackend();
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

void WrenchChecker::ClearCache() {
  impl_->by_hash.clear();
  impl_->by_key.clear();
  impl_->hits = 0;
  impl_->misses = 0;
}

const WrenchOptions& WrenchChecker::options() const { return impl_->options; }

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
