// The task planner (paper §IV-D): from a preprocessed project to a validated multi-robot action
// plan whose keyframes are reachable (IK), collision-free with the robots' minimum clearance, and
// wrench-feasible (assembly, transport, release and rest gates of the wrench LP).
//
// "counting" is the paper's "Milestones + counting" variant: one milestone per assembly step in a
// topological order; within a milestone a lazy weighted best-first search whose heuristic counts
// the pick, assemble and release actions still required; edges are validated (IK, collision,
// clearance, the wrench gates that depend on a sampled pose) only when they lie on the best
// candidate plan; witnesses are cached; an edge that fails at one effort level is suspended and
// revisited at the next; grasp and placement subsets are widened when a milestone fails; a
// milestone that fails makes the previous one look for another end state (backtracking).
//
// "wrap" (the default) replaces the counting heuristic by WRAP's backward abstract heuristic
// (search.h, backward.cpp): per milestone a breadth-first search backwards from the assembly over
// the two inputs' projected status (resting where they start or in a placement; held by a robot
// with an assembly grasp or another one); "exact" is the paper's "exact fills": the same with
// f = g + h instead of f = g + 2 h; "fine" splits the abstraction's grasp classes by approach
// direction. "optimistic" (like Dogar et al.) chooses the assembly's grasps first and searches for
// a way to them; "flat" ("Flat lazy") searches the whole task at once (variants.cpp). With
// `optimize`, windows of milestones are searched again for a cheaper plan until the time limit.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "core/result.h"
#include "core/run_context.h"
#include "grasp/preprocess.h"
#include "model/project.h"
#include "model/validate.h"
#include "task/plan.h"
#include "task/skill_geometry.h"
#include "wrench/wrench.h"

namespace wrap {

/// The planner variant: the paper's comparison rows.
enum class PlannerVariant {
  kWrap,        ///< "wrap": WRAP's backward abstract heuristic (the default).
  kOptimistic,  ///< "optimistic": assembly grasps chosen first, like Dogar et al.
  kFlat,        ///< "flat": Flat lazy, one search over the whole task, no milestones.
  kCounting,    ///< "counting": Milestones + counting.
  kExact,       ///< "exact": wrap with weight-one fills (f = g + h).
  kFine,        ///< "fine": wrap with a finer projection (grasp classes split by approach).
};

/// The variant's name as the CLI (`--planner`), the GUI, the bench harness and the plan's JSON
/// (PlanStats::planner) spell it, e.g. "counting".
std::string_view ToString(PlannerVariant variant);

/// The variant named `name` (ToString's words). Fails with kInvalidInput for an unknown name,
/// listing the known ones.
Result<PlannerVariant> ParsePlannerVariant(std::string_view name);

/// What the planner minimises beyond finding a plan.
enum class PlanObjective {
  kActions,   ///< "actions": the number of actions (the paper's cost; the default).
  kMakespan,  ///< "makespan": the task-level makespan estimate (makespan_estimate.h), then the
              ///< number of actions.
};

/// The objective's name as the CLI (`--objective`), the GUI and the plan's JSON spell it.
std::string_view ToString(PlanObjective objective);

/// The objective named `name` (ToString's words). Fails with kInvalidInput for an unknown name.
Result<PlanObjective> ParsePlanObjective(std::string_view name);

/// Options of PlanTask.
struct TaskPlannerOptions {
  /// Variant, the paper's comparison rows (PlannerVariant).
  PlannerVariant planner = PlannerVariant::kWrap;
  /// Anytime plan improvement after the first plan (large neighbourhood search) until the time
  /// limit of the RunContext or until windows of the whole horizon bring nothing more.
  bool optimize = false;
  /// What the planner minimises. kActions: the search as the paper's (ties by depth, then
  /// order), plan improvement keeps only plans with fewer actions. kMakespan: the search breaks
  /// ties in f by the makespan estimate of the candidate (then depth, then the estimate's sum of
  /// action ends), so work spreads over idle robots; plan improvement keeps a plan with a shorter
  /// estimate and at most two actions more than the first plan, or one as short with fewer
  /// actions.
  PlanObjective objective = PlanObjective::kActions;
  /// Memory the search may hold [MiB]: its nodes, queues and caches (estimated) and the
  /// process's growth since planning started (resident memory) must each stay below it; beyond
  /// it the run stops with "out of memory" in stats.failure.
  long long memory_limit_mb = 4096;
  MatingWrenchMode wrench_mode = MatingWrenchMode::kFull;  ///< full, gravity or none.
  double force_scale = 1.0;  ///< Lambda on the mating force and torque, >= 0.
  /// Sees every wrench question the search computes (WrenchOptions::on_question; thread-safe).
  std::function<void(const StepConfiguration&, const WrenchQuery&)> wrench_question_observer;
  /// Skill lengths and the robots' clearance at keyframes (shared with the motion stage).
  SkillGeometry skills;
  int max_effort = 2;  ///< Highest effort level (0-based) of the IK and pose sampling.
  /// Widen the grasp and placement subsets when a milestone fails; absent: the project's
  /// `planner.widen_grasps`.
  std::optional<bool> widen;
  int max_holders = 2;                 ///< Most robots holding one object at once.
  long long max_nodes = 400000;        ///< Search nodes kept per milestone search (memory bound).
  int max_backtracks = 6;              ///< Milestone re-plans after later milestones failed.
  std::filesystem::path project_file;  ///< Resolves URDF robots; may be empty.
  /// Edges (PlanAction::edge of earlier plans) the search must not take: the motion stage's
  /// feedback, an action whose motion could not be made in an earlier task plan.
  std::set<std::uint64_t> banned_edges;
};

/// Plans the task of a validated project (`check` from LoadProject, `pre` from Preprocess).
/// Returns a plan with stats.solved = true, or with solved = false and stats.failure saying which
/// milestone failed and why (the gate that failed most, for which robots and grasps) when none
/// is found within the search space or the time limit of `ctx` (stats.failure then says so).
/// Fails with kInvalidInput for options out of range or a project the planner cannot set up (a
/// robot model that does not load), kCancelled when ctx is cancelled. Deterministic: same inputs
/// and ctx seed, same plan. Adds its stage times to ctx ("bwd", "lp", "fwd", "ik").
[[nodiscard]] Result<Plan> PlanTask(const Project& project, const ProjectCheck& check,
                                    const Preprocessed& pre, const TaskPlannerOptions& options,
                                    RunContext& ctx);

/// A part that no robot can pick where it starts.
struct UnpickablePart {
  int part = -1;    ///< Index into Project::parts.
  std::string why;  ///< e.g. "no grasp of 'leg1' can be taken where it rests (every one of the
                    ///< 80 robot grasps: gripper into the table)".
};

/// The parts that no robot can pick where they rest at the start, by the planner's own pick
/// checks (reach, the gripper clear of the table, IK clear of everything, carrying the weight)
/// over the first `max_grasps` grasps of each robot (every one when 0). For validation's
/// warnings. Fails like PlanTask's set-up.
Result<std::vector<UnpickablePart>> UnpickableAtStart(const Project& project,
                                                      const ProjectCheck& check,
                                                      const Preprocessed& pre,
                                                      const TaskPlannerOptions& options,
                                                      int max_grasps = 0);

}  // namespace wrap
