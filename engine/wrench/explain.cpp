// Why a step is infeasible: the minimum-violation LP and its sentences.
//
// At the failing vertex of U the external wrenches are fixed (load factor 1) and every limit may
// be exceeded at a price: each finite bound of a gripper or connection component gets a slack
// column (the component beyond that bound), each table vertex gets friction slacks (tangential
// force beyond the pyramid) and a lift slack (the table pulling down), and each equilibrium row
// a residual slack (load that nothing balances). Prices: 1 per N and 10 per N m (1 N m counts as
// 1 N at 0.1 m) for limits and the table; residuals cost 1000 times more, so they appear only
// where no support at all can act. The LP is always feasible (the residuals alone balance any
// load) and its optimum names the cheapest set of limits to raise: the binding ones.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "wrench/detail/lp_model.h"

namespace wrap::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMomentWeight = 10.0;   // 1 N m costs as much as 1 N at 0.1 m.
constexpr double kResidualWeight = 1e3;  // Unbalanced load: the last resort.

enum class Role { kMain, kOver, kUnder, kTable, kFriction, kLift, kResidual };

struct Column {
  Role role = Role::kMain;
  SupportKind kind = SupportKind::kGripper;
  int owner = 0;      // Gripper, connection, table or body index.
  int component = 0;  // Limits: 0..5. Friction: 0..3 (+t1, -t1, +t2, -t2). Residual: row.
};

const char* kAxis[3] = {"x", "y", "z"};

double Weight(int component) { return component < 3 ? 1.0 : kMomentWeight; }

// The minimum-violation LP, grown column by column: each Add* appends the columns of one kind of
// support, in the order ReadShortfalls expects.
class ViolationLp {
 public:
  ViolationLp(const StepConfiguration& config, const WrenchQuery& query, const Vec3& p_WO)
      : config_(config),
        query_(query),
        p_WO_(p_WO),
        rows_(static_cast<int>(config.bodies.size()) * 6),
        unit_(rows_) {}

  // Grippers and connections: the component within its bounds plus a priced slack per finite
  // bound (a component fixed at 0, e.g. a vacuum cup's Fx while mating, is all slack).
  void AddLimited(SupportKind kind, int owner) {
    for (int i = 0; i < 6; ++i) {
      const ColumnInfo info{kind, owner, i};
      FillColumn(config_, p_WO_, info, unit_.data());
      double lo, hi;
      ComponentBounds(config_, query_.gate, info, lo, hi);
      if (!(lo == 0.0 && hi == 0.0)) Add({Role::kMain, kind, owner, i}, 1, lo, hi, 0);
      if (std::isfinite(hi)) Add({Role::kOver, kind, owner, i}, 1, 0, kInf, Weight(i));
      if (std::isfinite(lo)) Add({Role::kUnder, kind, owner, i}, -1, 0, kInf, Weight(i));
    }
  }

  // Table t: the pyramid generators, then per polygon vertex the friction and lift slacks.
  void AddTable(int t) {
    const WrenchTableSupport& table = config_.tables[t];
    const int edges = PyramidEdges(table);
    const int generators = static_cast<int>(table.p_WV.size()) * edges;
    for (int e = 0; e < generators; ++e) {
      FillColumn(config_, p_WO_, {SupportKind::kTable, t, e}, unit_.data());
      Add({Role::kTable, SupportKind::kTable, t, e}, 1, 0, kInf, 0);
    }
    Vec3 n, t1, t2;
    TableTangents(table, n, t1, t2);
    const Vec3 dirs[5] = {t1, -t1, t2, -t2, -n};
    for (const Vec3& v : table.p_WV) {
      for (int d = 0; d < 5; ++d) {
        std::fill(unit_.begin(), unit_.end(), 0.0);
        const Vec3 m = (v - p_WO_).cross(dirs[d]);
        for (int i = 0; i < 3; ++i) {
          unit_[table.body * 6 + i] = dirs[d][i];
          unit_[table.body * 6 + 3 + i] = m[i];
        }
        const Role role = d < 4 ? Role::kFriction : Role::kLift;
        Add({role, SupportKind::kTable, t, d}, 1, 0, kInf, 1.0);
      }
    }
  }

  // Residuals: a free wrench on each body, expensive.
  void AddResiduals() {
    for (int r = 0; r < rows_; ++r) {
      std::fill(unit_.begin(), unit_.end(), 0.0);
      unit_[r] = 1.0;
      const double price = kResidualWeight * Weight(r % 6);
      Add({Role::kResidual, SupportKind::kGripper, r / 6, r % 6}, 1, 0, kInf, price);
      Add({Role::kResidual, SupportKind::kGripper, r / 6, r % 6}, -1, 0, kInf, price);
    }
  }

  const std::vector<Column>& columns() const { return cols_; }

  // The problem with right-hand side -w_ext (moves the columns out).
  LpProblem TakeProblem(const double* w_ext) {
    LpProblem problem;
    problem.rows = rows_;
    problem.cols = static_cast<int>(cols_.size());
    problem.a = std::move(a_);
    problem.lower = std::move(lower_);
    problem.upper = std::move(upper_);
    problem.cost = std::move(cost_);
    problem.rhs.resize(rows_);
    for (int i = 0; i < rows_; ++i) problem.rhs[i] = -w_ext[i];
    return problem;
  }

 private:
  // Appends `sign` times the scratch column `unit_`.
  void Add(const Column& c, double sign, double lo, double hi, double price) {
    cols_.push_back(c);
    for (int i = 0; i < rows_; ++i) a_.push_back(sign * unit_[i]);
    lower_.push_back(lo);
    upper_.push_back(hi);
    cost_.push_back(price);
  }

  const StepConfiguration& config_;
  const WrenchQuery& query_;
  const Vec3& p_WO_;
  int rows_ = 0;
  std::vector<Column> cols_;
  std::vector<double> a_;  // Column-major.
  std::vector<double> lower_, upper_, cost_;
  std::vector<double> unit_;  // Scratch: the column being added.
};

// The shortfalls the optimal slacks `x` of `cols` show (those above `eps`), each with the price
// it costs, in column order.
void ReadShortfalls(const StepConfiguration& config, const WrenchQuery& query,
                    const std::vector<Column>& cols, const std::vector<double>& x, double eps,
                    std::vector<Shortfall>& out, std::vector<double>& weight) {
  auto push = [&](const Shortfall& s, double w) {
    out.push_back(s);
    weight.push_back(w);
  };
  for (std::size_t j = 0; j < cols.size();) {
    const Column& c = cols[j];
    if (c.role == Role::kMain || c.role == Role::kOver || c.role == Role::kUnder) {
      // The columns of one component are adjacent: main, over, under (each optional).
      double main = 0.0, over = 0.0, under = 0.0;
      std::size_t k = j;
      for (; k < cols.size() && cols[k].kind == c.kind && cols[k].owner == c.owner &&
             cols[k].component == c.component &&
             (cols[k].role == Role::kMain || cols[k].role == Role::kOver ||
              cols[k].role == Role::kUnder);
           ++k) {
        if (cols[k].role == Role::kMain) main = x[k];
        if (cols[k].role == Role::kOver) over = x[k];
        if (cols[k].role == Role::kUnder) under = x[k];
      }
      double lo, hi;
      ComponentBounds(config, query.gate, {c.kind, c.owner, c.component}, lo, hi);
      const ShortfallKind kind = c.kind == SupportKind::kGripper ? ShortfallKind::kGripperLimit
                                                                 : ShortfallKind::kConnectionLimit;
      const double needed = main + over - under;
      if (over > eps) push({kind, c.owner, c.component, needed, hi}, over * Weight(c.component));
      if (under > eps) push({kind, c.owner, c.component, needed, lo}, under * Weight(c.component));
      j = k;
      continue;
    }
    if (c.role == Role::kFriction || c.role == Role::kLift) {
      // All slacks of one table: friction summed as tangential vectors per vertex.
      double friction = 0.0, lift = 0.0;
      std::size_t k = j;
      while (k < cols.size() && cols[k].owner == c.owner &&
             (cols[k].role == Role::kFriction || cols[k].role == Role::kLift)) {
        // Five columns per vertex: +t1, -t1, +t2, -t2, -n.
        const double f1 = x[k] - x[k + 1];
        const double f2 = x[k + 2] - x[k + 3];
        friction += std::hypot(f1, f2);
        lift += x[k + 4];
        k += 5;
      }
      if (friction > eps) push({ShortfallKind::kTableFriction, c.owner, -1, friction, 0}, friction);
      if (lift > eps) push({ShortfallKind::kTableLift, c.owner, -1, lift, 0}, lift);
      j = k;
      continue;
    }
    if (c.role == Role::kResidual) {
      const double r = x[j] - x[j + 1];
      if (std::abs(r) > eps) {
        push({ShortfallKind::kUnbalanced, c.owner, c.component, r, 0},
             std::abs(r) * kResidualWeight * Weight(c.component));
      }
      j += 2;
      continue;
    }
    ++j;
  }
}

// Order: unbalanced load first, then forces (and the table), then moments, each by size.
std::vector<Shortfall> Sorted(const std::vector<Shortfall>& out,
                              const std::vector<double>& weight) {
  auto tier = [](const Shortfall& f) {
    if (f.kind == ShortfallKind::kUnbalanced) return 0;
    return f.component >= 3 ? 2 : 1;
  };
  std::vector<int> order(out.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(), [&](int l, int r) {
    if (tier(out[l]) != tier(out[r])) return tier(out[l]) < tier(out[r]);
    return weight[l] > weight[r];
  });
  std::vector<Shortfall> sorted;
  sorted.reserve(out.size());
  for (int i : order) sorted.push_back(out[i]);
  return sorted;
}

}  // namespace

Result<std::vector<Shortfall>> FindShortfalls(const StepConfiguration& config,
                                              const WrenchQuery& query, const Vec3& p_WO,
                                              const double* w_ext, LpBackend& lp) {
  ViolationLp builder(config, query, p_WO);
  if (GrippersActive(query.gate)) {
    for (int g = 0; g < static_cast<int>(config.grippers.size()); ++g) {
      builder.AddLimited(SupportKind::kGripper, g);
    }
  }
  for (int c = 0; c < static_cast<int>(config.connections.size()); ++c) {
    builder.AddLimited(SupportKind::kConnection, c);
  }
  if (TablesActive(query.gate)) {
    for (int t = 0; t < static_cast<int>(config.tables.size()); ++t) builder.AddTable(t);
  }
  builder.AddResiduals();

  const LpProblem problem = builder.TakeProblem(w_ext);
  double scale = 1.0;
  for (int i = 0; i < problem.rows; ++i) scale = std::max(scale, std::abs(w_ext[i]));
  LpSolution solution;
  const LpStatus status = lp.Solve(problem, solution);
  if (status != LpStatus::kOptimal) {
    return Fail(ErrorCode::kInternal, "wrench: minimum-violation LP (" + std::string(lp.name()) +
                                          ") returned " + std::string(ToString(status)));
  }

  // Read the slacks back.
  std::vector<Shortfall> out;
  std::vector<double> weight;
  ReadShortfalls(config, query, builder.columns(), solution.x, 1e-6 * scale, out, weight);
  return Sorted(out, weight);
}

namespace {

std::string Quote(const std::string& name) { return "'" + name + "'"; }

std::string Amount(int component, double value) {
  const std::string axis = std::string(value < 0.0 ? "-" : "") + kAxis[component % 3];
  return FormatNumber(std::abs(value)) + (component < 3 ? " N along " : " N m about ") + axis;
}

// The subject of a shortfall's sentence: "the vacuum gripper 'r1' on 'seat'".
std::string Subject(const StepConfiguration& config, const Shortfall& s) {
  switch (s.kind) {
    case ShortfallKind::kGripperLimit: {
      const WrenchGripper& g = config.grippers[s.index];
      std::string text = std::string("the ") +
                         (g.kind == EndEffectorKind::kVacuum ? "vacuum" : "two-finger") +
                         " gripper";
      if (!g.name.empty()) text += " " + Quote(g.name);
      return text + " on " + Quote(config.bodies[g.body].name);
    }
    case ShortfallKind::kConnectionLimit: {
      const WrenchConnection& c = config.connections[s.index];
      return "the connection " + (c.name.empty()
                                      ? "between " + Quote(config.bodies[c.body_a].name) + " and " +
                                            Quote(config.bodies[c.body_b].name)
                                      : Quote(c.name));
    }
    case ShortfallKind::kTableFriction:
    case ShortfallKind::kTableLift:
      return "the table under " + Quote(config.bodies[config.tables[s.index].body].name);
    case ShortfallKind::kUnbalanced:
      return "nothing balances " + Quote(config.bodies[s.index].name);
  }
  return "";
}

// What the subject would need; `first` adds the gripper mode after the first amount.
std::string Item(const StepConfiguration& config, const WrenchQuery& query, const Shortfall& s,
                 bool first) {
  switch (s.kind) {
    case ShortfallKind::kGripperLimit: {
      std::string text = Amount(s.component, s.needed);
      if (first && config.grippers[s.index].kind == EndEffectorKind::kVacuum) {
        text += query.gate == WrenchGate::kAssembly ? " in assembly mode" : " in transport mode";
      }
      return text + " (limit " + FormatNumber(std::abs(s.limit)) + ")";
    }
    case ShortfallKind::kConnectionLimit: {
      const WrenchConnection& c = config.connections[s.index];
      std::string text =
          Amount(s.component, s.needed) + " (limit " + FormatNumber(std::abs(s.limit));
      if (s.component == 2 && s.limit == 0.0 && s.needed < 0.0 && c.limits.upper[2] > 0.0) {
        text += ": it takes compression only";
      }
      return text + ")";
    }
    case ShortfallKind::kTableFriction:
      return FormatNumber(s.needed) + " N more friction (mu " +
             FormatNumber(config.tables[s.index].friction) + "): it slides";
    case ShortfallKind::kTableLift:
      return "to hold it down with " + FormatNumber(s.needed) + " N: it tips";
    case ShortfallKind::kUnbalanced:
      return Amount(s.component, s.needed) + " missing";
  }
  return "";
}

}  // namespace

std::string DescribeShortfalls(const StepConfiguration& config, const WrenchQuery& query,
                               const std::vector<Shortfall>& shortfalls, int max_items) {
  // One sentence per support, in the order of its first shortfall, listing its items.
  struct Group {
    ShortfallKind kind;
    int index;
    std::vector<const Shortfall*> items;
  };
  std::vector<Group> groups;
  const int count = std::min<int>(max_items, static_cast<int>(shortfalls.size()));
  for (int i = 0; i < count; ++i) {
    const Shortfall& s = shortfalls[i];
    const bool table =
        s.kind == ShortfallKind::kTableFriction || s.kind == ShortfallKind::kTableLift;
    auto same = [&](const Group& g) {
      const bool g_table =
          g.kind == ShortfallKind::kTableFriction || g.kind == ShortfallKind::kTableLift;
      return g.index == s.index && (g.kind == s.kind || (table && g_table));
    };
    auto it = std::find_if(groups.begin(), groups.end(), same);
    if (it == groups.end()) {
      groups.push_back({s.kind, s.index, {}});
      it = groups.end() - 1;
    }
    it->items.push_back(&s);
  }
  std::string text;
  for (const Group& g : groups) {
    if (!text.empty()) text += "; ";
    const bool nothing = g.kind == ShortfallKind::kUnbalanced;
    text += Subject(config, *g.items[0]) + (nothing ? ": " : " would need ");
    for (std::size_t i = 0; i < g.items.size(); ++i) {
      if (i > 0) text += i + 1 == g.items.size() ? " and " : ", ";
      text += Item(config, query, *g.items[i], i == 0);
    }
  }
  return text;
}

}  // namespace wrap::detail
