// Wrench stage (paper §IV-A "Force constraints"): can the grippers, the table and the connections
// already made balance the wrenches of one moment of the plan (an assembly step, a transport, a
// release, a part resting on the table) for every wrench the moment may really produce?
//
// The question is a StepConfiguration (plain structs: bodies, connections, grippers, table
// supports, gravity, mating) plus a WrenchQuery (which gate, which mating-wrench mode, the scale
// lambda). WrenchChecker answers it with a WrenchCheck: feasible or not, the utilisation of every
// support, and when infeasible a reason a person can act on. The LP, its objective and the sign
// conventions are written out in wrench.cpp; the uncertainty set in detail/vertices.h.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "model/project.h"
#include "wrench/lp.h"

namespace wrap {

/// A wrench [fx, fy, fz, mx, my, mz]: force [N] then moment [N m].
using Vec6 = Eigen::Matrix<double, 6, 1>;

/// An axis-aligned box of wrenches with asymmetric bounds, lower <= w <= upper per component, in
/// the frame of the support it belongs to. A bound may be infinite (no limit that way). Every box
/// must contain the zero wrench (lower <= 0 <= upper); a component with lower = upper = 0 cannot
/// be transmitted at all.
struct WrenchBounds {
  Vec6 lower = Vec6::Zero();  ///< Lower bounds [N, N m]; -inf allowed.
  Vec6 upper = Vec6::Zero();  ///< Upper bounds [N, N m]; +inf allowed.
  bool operator==(const WrenchBounds& o) const { return lower == o.lower && upper == o.upper; }
};

/// The symmetric bounds |w_i| <= box_i of a project wrench box.
WrenchBounds BoundsFromBox(const WrenchBox& box);

/// A box that only pushes along +z of its frame: the force z lower bound is 0, the rest as
/// `box`. For a connection whose frame z points from body_a into body_b it takes compression
/// (body_a pressing on body_b) but no tension.
WrenchBounds CompressionOnlyZ(const WrenchBox& box);

/// A box with no limits at all.
WrenchBounds UnboundedWrench();

/// A rigid body of the step: one part, or a subassembly whose parts are already fixed together.
struct WrenchBody {
  std::string name;            ///< Name used in messages, e.g. "seat".
  double mass_kg = 0.0;        ///< Mass [kg], >= 0.
  Vec3 p_WBcm = Vec3::Zero();  ///< Centre of mass in the world [m].
};

/// A connection already made between two bodies (paper: an interface with wrench set T_pq).
/// The connection wrench is the one body_a applies on body_b, at C's origin, expressed in C;
/// body_b receives it and body_a the opposite.
struct WrenchConnection {
  int body_a = 0;                ///< Index into StepConfiguration::bodies.
  int body_b = 1;                ///< Index into StepConfiguration::bodies; != body_a.
  Iso3 X_WC = Iso3::Identity();  ///< Interface frame C in the world.
  WrenchBounds limits;           ///< T_pq: bounds of the wrench body_a applies on body_b, in C.
  std::string name;              ///< Name for messages; empty: "'a'-'b'".
};

/// An end effector holding a body. Its wrench is the one it applies on the body, at the grasp
/// frame's origin, expressed in the grasp frame G.
struct WrenchGripper {
  std::string name;                                    ///< Robot name for messages; may be empty.
  int body = 0;                                        ///< Index of the held body.
  Iso3 X_WG = Iso3::Identity();                        ///< Grasp frame G in the world.
  EndEffectorKind kind = EndEffectorKind::kTwoFinger;  ///< Two-finger or vacuum (messages).
  WrenchBounds assembly_limits;   ///< W_r while mating (vacuum: only Fz, paper table).
  WrenchBounds transport_limits;  ///< W_r while carrying or holding still.
};

/// A gripper with the project's limits for its kind: two-finger uses the same box in both modes,
/// vacuum its assembly and transport boxes (symmetric bounds).
WrenchGripper MakeGripper(std::string name, int body, const Iso3& X_WG, EndEffectorKind kind,
                          const WrenchLimits& limits);

/// A body resting on the table: Coulomb friction at each vertex of its support polygon, as a
/// friction pyramid (inscribed in the cone) with non-negative normal forces.
struct WrenchTableSupport {
  int body = 0;                   ///< Index of the resting body.
  std::vector<Vec3> p_WV;         ///< Support polygon vertices in the world, on the table [m].
  double friction = 0.4;          ///< Coulomb coefficient mu, >= 0.
  int pyramid_edges = 8;          ///< Edges of each pyramid, in [4, 64]; the first lies along
                                  ///< world x projected onto the table. 8 (default) is exact
                                  ///< along x, y and the diagonals (where the transverse
                                  ///< corners of U push for a vertical insertion); 4 loses
                                  ///< 1 - 1/sqrt(2) of the friction along the diagonals.
  Vec3 normal_W = Vec3::UnitZ();  ///< Table normal pointing up, out of the table (unit).
};

/// The mating wrench of an assembly step and its uncertainty (paper §III, §IV-A).
struct MatingLoad {
  int moved = -1;                    ///< Index of the moved body, or -1 when it is not modelled
                                     ///< (then only the base side is checked).
  int base = 0;                      ///< Index of the base body it is mated onto.
  Vec3 axis_W = -Vec3::UnitZ();      ///< Insertion direction, world: the way the moved body
                                     ///< travels into the base (normalised on use).
  Vec3 p_WContact = Vec3::Zero();    ///< Nominal application point of the mating force [m].
  double force_N = 10.0;             ///< Nominal mating force along the axis [N], >= 0.
  double torque_Nm = 0.0;            ///< Nominal torque about the axis (screw motions) [N m].
  double transverse_fraction = 0.0;  ///< Transverse bound as a fraction of force_N, >= 0.
  double offset_m = 0.0;             ///< Bound on the application-point offset [m], >= 0.
};

/// The mating load of a project step: `X_WA` places the assembly frame (where `mating.axis`
/// lives) in the world; `p_WContact` is the nominal contact point.
MatingLoad MatingLoadFromProject(const Mating& mating, const Iso3& X_WA, int moved, int base,
                                 const Vec3& p_WContact);

/// One moment of a plan as the wrench LP sees it: rigid bodies, how they are connected, who holds
/// them, what they rest on, gravity, and the mating between two of them.
struct StepConfiguration {
  std::vector<WrenchBody> bodies;             ///< At least one.
  std::vector<WrenchConnection> connections;  ///< Connections already made.
  std::vector<WrenchGripper> grippers;        ///< Grippers holding bodies.
  std::vector<WrenchTableSupport> tables;     ///< Bodies resting on the table.
  Vec3 gravity_W = Vec3(0.0, 0.0, -9.81);     ///< Gravity [m/s^2].
  std::optional<MatingLoad> mating;           ///< The mating of an assembly step; without
                                              ///< it the assembly gate checks gravity only.
};

/// Which gate of the search asks: decides the external wrenches, the vacuum box and the supports.
enum class WrenchGate {
  kAssembly,   ///< Mating under way: gravity + the mating wrench set U; assembly limits. With
               ///< a gripper whose assembly box differs from its transport box (vacuum), in two
               ///< stages: the weight held within the transport limits, then what the mating
               ///< adds within the assembly box (wrench.cpp, "held, then mated").
  kTransport,  ///< Carried: gravity and every acceleration with components in +-margin; transport
               ///< limits; table supports are ignored (the bodies are in the air).
  kRelease,    ///< Holding still after a release: gravity only; transport limits; the caller
               ///< passes the supports that remain.
  kRest,       ///< Resting on the table alone: gravity only; grippers are ignored.
};

/// How the mating wrench enters (the paper's scaling figure: "w/o wrench", gravity, lambda).
enum class MatingWrenchMode {
  kFull,         ///< Gravity plus lambda times the mating wrench set.
  kGravityOnly,  ///< Gravity only.
  kNone,         ///< No wrench check: every gate passes.
};

/// The question asked of a configuration.
struct WrenchQuery {
  WrenchGate gate = WrenchGate::kAssembly;          ///< Which gate.
  MatingWrenchMode mode = MatingWrenchMode::kFull;  ///< How the mating wrench enters.
  double lambda = 1.0;                              ///< Scale on the mating force and torque, >= 0.
  double accel_margin_mps2 = 1.0;                   ///< Transport: bound on each world component of
                                                    ///< the acceleration [m/s^2], >= 0.
};

/// Name of a gate, e.g. "assembly".
std::string_view ToString(WrenchGate gate);

/// Which LP backend solves the load-factor LPs.
enum class WrenchLpBackend {
  kDense,  ///< Our dense simplex (default; fast).
  kClp,    ///< Clp (reference).
};

/// Options of a WrenchChecker.
struct WrenchOptions {
  WrenchLpBackend backend = WrenchLpBackend::kDense;  ///< Default: our dense simplex.
  bool explain = true;      ///< When infeasible, solve a minimum-violation LP to name the binding
                            ///< limits (costs one more LP on the failing path only).
  double tolerance = 1e-7;  ///< Feasible when the load factor is >= 1 - tolerance.
  /// Stop at the first vertex that fails: `feasible` and the reason (that vertex's) are exact,
  /// but `utilisation`, `worst_vertex`, `failing_vertex_count` and the support loads cover only
  /// the vertices checked. Each check then starts at the vertex that failed last (the planner's
  /// questions come in runs of similar configurations). For searches that need a yes or no.
  /// The load factor is then capped at 1 (a passing vertex stops at the first balance of its
  /// full load: a passing check reports utilisation 1, not its least) and the vertices of a
  /// "held, then mated" check share one phase 1; failing vertices keep their exact load factor.
  bool first_failure_suffices = false;
  /// Called with every question the checker computes (not those its cache answers): how the
  /// planner's real questions are recorded as test data (tests/wrench). Checkers of parallel
  /// searches share it: it must be thread-safe.
  std::function<void(const StepConfiguration&, const WrenchQuery&)> on_question;
  std::size_t cache_capacity = 1 << 16;  ///< Cached answers kept; the cache is emptied when full.
};

/// What a support is.
enum class SupportKind { kGripper, kConnection, kTable };

/// How hard one support works, worst case over the vertices of U.
struct SupportLoad {
  SupportKind kind = SupportKind::kGripper;  ///< Gripper, connection or table.
  int index = 0;             ///< Index into the configuration's grippers, connections or tables.
  double utilisation = 0.0;  ///< Grippers, connections: max_i |w_i| / limit_i (limit on the
                             ///< side of w_i's sign; infinite limits count 0). Table: |F_t| /
                             ///< (mu F_n) of its resultant force (friction used).
  int component = -1;        ///< Component 0..5 (fx..mz, support frame) of the maximum; -1 table.
  int vertex = -1;           ///< Vertex of U where the maximum occurs; -1 if unloaded.
};

/// What a support would need beyond what it can give, at the failing vertex.
enum class ShortfallKind {
  kGripperLimit,     ///< A gripper component beyond its bound.
  kConnectionLimit,  ///< A connection component beyond its bound.
  kTableFriction,    ///< The table would need more friction: the body slides.
  kTableLift,        ///< The table would have to pull the body down: it tips.
  kUnbalanced,       ///< Nothing can balance this part of the body's load.
};

/// One binding limit found by the minimum-violation LP.
struct Shortfall {
  ShortfallKind kind = ShortfallKind::kGripperLimit;  ///< What is short.
  int index = 0;        ///< Gripper, connection, table or body index (by kind).
  int component = 0;    ///< 0..5 for limits (support frame) and unbalanced (world); -1 table.
  double needed = 0.0;  ///< Signed component needed (limits) or magnitude (table, unbalanced).
  double limit = 0.0;   ///< The bound it exceeds (limits), else 0.
};

/// The answer of one wrench check.
struct WrenchCheck {
  bool feasible = true;  ///< Every vertex of U is balanced within every limit.
  /// The smallest achievable largest utilisation, worst case over U (1 / load factor): > 1 when
  /// infeasible, +inf when no support can take some part of the load, 0 when only unlimited
  /// supports (the table) carry it.
  double utilisation = 0.0;
  int vertex_count = 0;               ///< Vertices of U checked (0 in mode kNone).
  int failing_vertex_count = 0;       ///< Vertices that are not balanced (at least one, and the
                                      ///< rest not counted, with first_failure_suffices).
  int worst_vertex = -1;              ///< Vertex with the largest utilisation (0-based).
  std::string worst_vertex_label;     ///< Its description, e.g. "transverse +x, offset -y".
  std::vector<SupportLoad> supports;  ///< Grippers, then connections, then tables, in order
                                      ///< (supports the gate ignores are left out).
  std::vector<Shortfall> shortfalls;  ///< At the worst vertex, largest first (infeasible only).
  std::string reason;  ///< Empty when feasible, else e.g. "assembly: vertex 3/16 (transverse +x):
                       ///< the vacuum gripper 'r1' on 'seat' would need 4.1 N along x in
                       ///< assembly mode (limit 0)".
};

/// One vertex of the uncertainty set U: the external wrench on every body.
struct WrenchVertex {
  std::string label;          ///< E.g. "gravity", "transverse +x -y, offset +x", "accel +x +y -z".
  std::vector<Vec6> w_ext_W;  ///< External wrench on each body, moments about the reference point,
                              ///< world frame [N, N m].
};

/// The vertices of U for `query` (paper §IV-A "Robust satisfaction"), moments about p_WO.
/// Fails with kInvalidInput on a malformed configuration.
Result<std::vector<WrenchVertex>> UncertaintyVertices(const StepConfiguration& config,
                                                      const WrenchQuery& query,
                                                      const Vec3& p_WO = Vec3::Zero());

/// Checks configurations against the wrench LP, with a cache of answers. Holds the LP backend and
/// scratch memory: not thread-safe, use one per thread (answers are identical across instances).
class WrenchChecker {
 public:
  /// A checker with `options`.
  explicit WrenchChecker(const WrenchOptions& options = {});
  ~WrenchChecker();
  WrenchChecker(WrenchChecker&&) noexcept;
  WrenchChecker& operator=(WrenchChecker&&) noexcept;

  /// Answers `query` for `config` without the cache. Fails with kInvalidInput on a malformed
  /// configuration (bad index, negative mass, a box not containing 0, ...) and with kInternal
  /// when the LP backend fails; an infeasible step is an answer (feasible = false), not an error.
  Result<WrenchCheck> Check(const StepConfiguration& config, const WrenchQuery& query = {});

  /// As Check, through the cache keyed by a canonical encoding of (config, query): positions
  /// enter relative to the mean centre of mass, so a translated copy hits the same entry.
  Result<WrenchCheck> CheckCached(const StepConfiguration& config, const WrenchQuery& query = {});

  /// As Check, through the cache keyed by `key` alone, which the caller guarantees identifies
  /// (config, query), e.g. a hash of (subassembly, grasp ids, placement, mating, mode). Cheapest.
  Result<WrenchCheck> CheckCached(std::uint64_t key, const StepConfiguration& config,
                                  const WrenchQuery& query = {});

  /// Cache hits and misses since construction or the last ClearCache().
  std::uint64_t cache_hits() const;
  /// Cache misses (answers computed) since construction or the last ClearCache().
  std::uint64_t cache_misses() const;
  /// LPs the dense simplex ended without an answer that has one by construction (a numerical
  /// failure), answered by Clp instead. 0 with the Clp backend.
  std::uint64_t lp_fallbacks() const;
  /// LPs solved since construction (one per vertex of U checked, plus the zero-utilisation
  /// variants; the explanation's minimum-violation LPs not counted).
  std::uint64_t lp_solves() const;
  /// Simplex pivots of those LPs (bound flips included).
  std::uint64_t lp_pivots() const;
  /// Forgets every cached answer.
  void ClearCache();
  /// The options.
  const WrenchOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Whether `config`'s assembly check goes "held, then mated" (a gripper whose assembly box
/// differs from its transport box: vacuum).
bool HeldThenMated(const StepConfiguration& config);

/// A relaxation of the "held, then mated" assembly check of `config` that no rigid motion of the
/// whole configuration changes, for configurations without table supports (parts in the air):
/// gravity off, and every gripper's transport box and every connection's box widened to the
/// differences of two wrenches within it ([lower - upper, upper - lower]); assembly boxes as they
/// are; the transverse and offset bounds of the mating shrunk by 1/sqrt(2) (the square they span
/// then lies inside the one of every turn of the pair about its axis, wherever the world puts
/// the square's sides). What the mating load adds to the holding wrenches must fit these,
/// whatever gravity does, so when the relaxation fails the check fails in every orientation.
StepConfiguration MatingIncrementRelaxation(const StepConfiguration& config);

/// One-shot check without a cache (builds a checker; use a WrenchChecker in loops).
Result<WrenchCheck> CheckWrench(const StepConfiguration& config, const WrenchQuery& query = {},
                                const WrenchOptions& options = {});

}  // namespace wrap
