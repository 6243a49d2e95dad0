// The columns of the wrench LP: what each support contributes to the equilibrium rows. Internal
// to the wrench stage (wrench.cpp builds the load-factor LP, explain.cpp the minimum-violation
// LP from the same columns).
#pragma once

#include <string>
#include <vector>

#include "wrench/lp.h"
#include "wrench/wrench.h"

namespace wrap::detail {

/// What one LP column stands for.
struct ColumnInfo {
  SupportKind kind = SupportKind::kGripper;  ///< Gripper, connection or table.
  int owner = 0;      ///< Gripper, connection or table index in the configuration.
  int component = 0;  ///< Grippers, connections: 0..5 (fx..mz, support frame). Tables: the
                      ///< generator, vertex * edges + edge.
};

/// True when the gate lets grippers act (every gate but kRest).
inline bool GrippersActive(WrenchGate gate) { return gate != WrenchGate::kRest; }
/// True when the gate lets table supports act (every gate but kTransport).
inline bool TablesActive(WrenchGate gate) { return gate != WrenchGate::kTransport; }
/// The gripper box for a gate: assembly limits while mating, transport limits otherwise.
inline const WrenchBounds& GripperLimits(const WrenchGripper& g, WrenchGate gate) {
  return gate == WrenchGate::kAssembly ? g.assembly_limits : g.transport_limits;
}

/// Edges actually used by a table pyramid: 1 (the normal alone) when mu is 0.
inline int PyramidEdges(const WrenchTableSupport& t) {
  return t.friction > 0.0 ? t.pyramid_edges : 1;
}

/// Tangent directions of a table: t1 is world x projected onto the table plane, t2 = n x t1.
void TableTangents(const WrenchTableSupport& t, Vec3& n, Vec3& t1, Vec3& t2);

/// Edge direction `edge` of the friction pyramid: n + mu (cos th t1 + sin th t2), th = 2 pi
/// edge / edges (not normalised: a unit coefficient is one newton of normal force).
Vec3 PyramidEdge(const WrenchTableSupport& t, int edge);

/// Writes into `col` (6 * bodies entries, zeroed first) the equilibrium rows of a unit amount of
/// the column's variable: a unit wrench component of a gripper or connection, or one newton of
/// normal force along a table generator.
void FillColumn(const StepConfiguration& config, const Vec3& p_WO, const ColumnInfo& info,
                double* col);

/// The bounds of a gripper or connection component under `gate`.
void ComponentBounds(const StepConfiguration& config, WrenchGate gate, const ColumnInfo& info,
                     double& lower, double& upper);

/// Checks a configuration and a query; kInvalidInput naming the field when malformed.
Result<void> Validate(const StepConfiguration& config, const WrenchQuery& query);

/// Solves the minimum-violation LP at one vertex (external wrenches w_ext, 6 per body) and
/// returns what the supports would need beyond their limits, largest first. See explain.cpp.
Result<std::vector<Shortfall>> FindShortfalls(const StepConfiguration& config,
                                              const WrenchQuery& query, const Vec3& p_WO,
                                              const double* w_ext, LpBackend& lp);

/// Sentences for the first `max_items` shortfalls, one per support, e.g. "the vacuum gripper
/// 'r1' on 'seat' would need 4.1 N along x in assembly mode (limit 0) and 0.2 N m about y
/// (limit 0); the table under 'base' would need 3 N more friction (mu 0.4): it slides".
std::string DescribeShortfalls(const StepConfiguration& config, const WrenchQuery& query,
                               const std::vector<Shortfall>& shortfalls, int max_items);

/// A number for messages: three significant digits, no exponent below 1e6.
std::string FormatNumber(double v);

}  // namespace wrap::detail
