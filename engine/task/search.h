// The milestone fill of the task planner (paper Alg. 2; the heuristic is the variant's: WRAP's
// backward abstraction, or counting for the "counting" variant and plan improvement): a lazy
// weighted best-first search over the symbolic state of one assembly step, edges validated by
// the KeyframeSolver only on the best candidate plan, effort levels for suspended edges and
// widening of the grasp and placement subsets. Its sources: search.cpp (milestones, heuristic),
// successors.cpp (the actions of a state), cheap_checks.cpp, lazy_search.cpp (best-first search,
// edge validation, commits), backward.cpp (WRAP's heuristic), variants.cpp, search_failure.cpp.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "core/flat_map.h"
#include "core/run_context.h"
#include "task/failure.h"
#include "task/keyframes.h"
#include "task/makespan_estimate.h"
#include "task/planner.h"
#include "task/state.h"
#include "task/world.h"

namespace wrap {

/// What a failed check was about, for the failure record (FailureCase): ids of the task world
/// and its tables, -1 where the check names none. Plain data, cheap to pass on every failure.
struct CheckSubject {
  int object = -1;           ///< Node id of the object tried.
  int robot = -1;            ///< Robot that could not reach, or whose gripper hit something.
  int grasp = -1;            ///< Grasp id (TaskTables) tried.
  int loc = -1;              ///< Location id where the object was tried.
  std::optional<Iso3> X_WA;  ///< Or its pose, where it is not a location.
  int hit_node = -1;         ///< Node the gripper (or the object) hit.
  bool hit_table = false;    ///< The gripper hit the table.
};

/// Why edges failed within one milestone, for the report.
struct GateTally {
  std::array<long long, kNumGates> count{};
  std::array<std::string, kNumGates> example;
  std::array<CheckSubject, kNumGates> subject;  ///< What each example was about.
  std::array<FailureScene, kNumGates> scene;    ///< The cell each example saw, when captured.
  void Add(Gate gate, const std::string& message, const CheckSubject& about = {});
  Gate last_gate = Gate::kNone;  ///< Gate of the last Add.
  std::string last_message;      ///< Message of the last Add.
  CheckSubject last_subject;     ///< Subject of the last Add.
  /// e.g. "wrench (assembly) 120x (e.g. ...), IK 40x (...)".
  std::string Summary(int max_gates = 3) const;
  /// The gates that failed, most failures first (the order of Summary).
  std::vector<Gate> Order() const;
  /// Summary's words for one gate.
  std::string Words(Gate gate) const;
};

/// One milestone's answer.
struct MilestoneResult {
  bool ok = false;
  bool stopped = false;             ///< Cancelled or out of time.
  std::vector<PlanAction> actions;  ///< The validated actions.
  /// The state after each action (plan improvement splits a window's actions by milestone).
  std::vector<std::pair<SymState, ContState>> after;
  SymState end;                    ///< Symbolic state at its end.
  ContState end_c;                 ///< Continuous state at its end.
  TaskClock end_clock;             ///< The makespan estimate's clock at its end.
  bool out_of_memory = false;      ///< Stopped by TaskPlannerOptions::memory_limit_mb.
  std::string failure;             ///< Why not, when !ok.
  std::vector<FailureCase> cases;  ///< The same as data, blocker first (FailureCase::scene: the
                                   ///< tried object moved, robots as at the milestone's start).
  FailureScene start;              ///< The cell at the milestone's start (failure record).
  /// The first level searched its whole graph within its budget and found nothing, and the fill
  /// stopped there (FillLimits::stop_when_first_exhausted).
  bool first_level_exhausted = false;
};

/// Limits of one fill beyond the variant's own, for plan improvement.
struct FillLimits {
  int weight = -1;             ///< f = g + weight h; -1: the variant's (2, exact 1); 0: none.
  int max_cost = 1 << 30;      ///< Most actions in the milestone (A* prunes g + h above it).
  int max_failures = 1 << 30;  ///< Edge validation failures before the fill gives up.
  long long max_nodes = 0;     ///< Nodes per search; 0: TaskPlannerOptions::max_nodes.
  int first_level = 0;  ///< Resolution level to start at (a probe's caller skips a level done).
  /// Expansions a level that is not the last may take; 0: the search's own budget.
  long long level_expansions = 0;
  /// Stop after the first level searched (whether or not it found a plan): a backtracking probe.
  bool first_level_only = false;
  /// Stop when the first level searched its whole graph within its budget and found nothing
  /// (MilestoneResult::first_level_exhausted): the caller may probe another end of the milestone
  /// before, rather than after, the wider levels.
  bool stop_when_first_exhausted = false;
};

/// The lazy search of the task planner.
class TaskSearch {
 public:
  /// Backward distance of a state from which the abstraction cannot reach the assembly.
  static constexpr int kFarDistance = 1000;

  TaskSearch(const TaskWorld& world, TaskTables& tables, KeyframeSolver& solver,
             const TaskPlannerOptions& options, RunContext& ctx, std::uint64_t seed, bool widen);

  /// Plans milestone `index` (step node `step`). At its end robots may hold only the inputs of
  /// `next_step` (the next milestone's step; -1 for the last milestone: every robot free). End
  /// states whose hash is in `excluded` do not count as goals (backtracking). `t0`: the makespan
  /// estimate's clock after the plan before the milestone (ties between candidates as long are
  /// broken by it).
  MilestoneResult Fill(int index, int step, int next_step, const SymState& s0, const ContState& c0,
                       const TaskClock& t0, const std::set<std::uint64_t>& excluded,
                       const FillLimits& limits = {});
  /// The paper's "Flat lazy": one lazy search over the whole task from s0 to the final product
  /// released, any step whose inputs exist may be assembled next (no milestones). The actions'
  /// milestone index is the number of steps assembled before them.
  MilestoneResult FillFlat(const SymState& s0, const ContState& c0);
  /// Plan improvement: one search over the milestones `steps` (in their order; the first is
  /// milestone `index`) from s0, ending with robots holding only the inputs of `next_step` (-1:
  /// nothing). Counting heuristic; the actions carry their milestone indices.
  MilestoneResult FillWindow(int index, const std::vector<int>& steps, int next_step,
                             const SymState& s0, const ContState& c0, const TaskClock& t0,
                             const FillLimits& limits);

  /// The variant's heuristic of `s` at the start of milestone (`step`, `next_step`), with the
  /// backward abstraction built from `s` at the widest resolution (tests: admissibility).
  int StartHeuristic(int step, int next_step, const SymState& s);

  /// The failure record's cases of the current tally, blocker first, with the scene `start`
  /// (robots' joints and parts' poses at the milestone's start) and each tried object moved.
  std::vector<FailureCase> Cases(const FailureScene& start) const;
  /// True when some robot can pick `node` at location `loc` with one of its first `max_grasps`
  /// grasps (the search's cheap pick checks).
  bool CanBePicked(int node, int loc, int max_grasps);
  /// Why no robot picks `node` at `loc`: the first check that each of the robots' first
  /// `max_grasps` grasps fails, counted, e.g. "no grasp of 'x' can be taken where it rests (every
  /// one of the 80 robot grasps: gripper into the table)".
  std::string PickCensus(int node, int loc, int max_grasps);

  long long expansions() const { return expansions_; }
  int widenings() const { return widenings_; }
  double search_seconds() const { return search_s_; }
  double backward_seconds() const { return bwd_s_; }

 private:
  struct Resolution {
    int grasps = 0;
    int placements = 0;
    int slots = 0;
    int yaws = 0;
  };
  struct Milestone {
    int step = -1;
    int moved = -1;
    int base = -1;
    bool final = false;
    int keep[2] = {-2, -2};  ///< Nodes robots may still hold at the end.
    bool flat = false;       ///< Flat lazy: the whole task (step: the final product).
  };
  /// Optimistic (Dogar et al.): the assembly's grasps chosen before the search; the search must
  /// assemble with them. rm < 0: any.
  struct AssemblyTarget {
    int rm = -1, gm = -1;     ///< Robot and grasp id holding the moved input.
    int rb = -1, gb = -1;     ///< Robot and grasp id holding (or bracing) the base; rb < 0: none.
    bool base_rests = false;  ///< The base rests on the table (braced when rb >= 0) ...
    bool base_moved = false;  ///< ... not where it rested at the milestone's start.
  };
  struct Node {
    SymState s;
    int g = 0;
    int parent = -1;
    TaskAction a;
    std::uint64_t hash = 0;  ///< s.Hash(), computed once (the search's hot path).
    TaskClock clock;         ///< The makespan estimate's clock after the path to s (the
                             ///< makespan objective only; empty otherwise).
  };
  enum class SearchStatus { kFound, kExhausted, kNodeLimit, kStopped, kOutOfMemory };
  /// Actions of a state with the states they lead to.
  using SuccessorList = std::vector<std::pair<TaskAction, SymState>>;
  /// A validated state of a fill's committed prefix (Rounds), with the edge into it.
  struct Committed {
    SymState s;
    ContState c;
    std::uint64_t entering_edge = 0;
    TaskClock clock;
  };
  /// How the validation of a candidate plan ended: every edge held, one failed, the run was
  /// stopped, or the fill gives up (its failure limit, or Optimistic's bad target).
  enum class CandidateStatus { kValid, kInvalid, kStopped, kGiveUp };

  Resolution ResolutionAt(int level) const;
  const std::vector<int>& GraspIds(int node, int robot);
  int Heuristic(const SymState& s, const Milestone& m);
  /// WRAP's backward abstract heuristic (backward.cpp): the abstract graph of milestone `m` at
  /// resolution `res` from the start state s0, and its distance of a forward state.
  void BuildBackward(const Milestone& m, const Resolution& res, const SymState& s0);
  int BackwardDistance(const SymState& s);
  /// BuildBackward's robot-free tables of one milestone (backward.cpp).
  struct BackwardTables;
  /// The first `t.res.grasps` grasp ids of input `k` for robot `r`.
  std::span<const int> AbstractGrasps(const BackwardTables& t, int k, int r);
  /// The inputs' rest statuses (start location, placements) and their poses; robots alike.
  void BackwardStatuses(const SymState& s0, BackwardTables& t);
  /// Which grasp classes pick (or place) each input in each rest status.
  void BackwardPicks(BackwardTables& t);
  /// Which pairs of grasp classes can hand each input over.
  void BackwardHandovers(BackwardTables& t);
  /// Which robots insert the moved input into the base resting in each status.
  void BackwardRestAssembly(const Milestone& m, BackwardTables& t);
  /// Which pairs of robots assemble with both inputs in the air.
  void BackwardAirAssembly(const Milestone& m, BackwardTables& t);
  /// The abstract graph's distances to the assembly (backward_.dist), breadth-first.
  void BackwardDistances(const BackwardTables& t);
  /// Why the assembly is out of reach from the milestone's start, in words.
  std::string BackwardWhy(const Milestone& m, const BackwardTables& t);
  /// The tables in the "task" log.
  void LogBackward(const BackwardTables& t);
  /// The class of grasp id `grasp` of input `input` held by `robot` in the abstraction: assembly
  /// grasp or not (bit 0) and, for the fine projection, the approach direction in the object's
  /// frame (one of six).
  int GraspClass(int input, int robot, int grasp);
  /// Whether grasp id `grasp` of input 0 (moved) or 1 (base) of the current milestone is an
  /// assembly grasp: the gripper clears the other input at the mating pose. Cached.
  bool AssemblyGrasp(int input, int robot, int grasp);
  bool IsGoal(const SymState& s, const Milestone& m, const std::set<std::uint64_t>& excluded) const;
  /// The actions of `s` within milestone `m` at resolution `res` that pass their cheap checks
  /// (successors.cpp), each with its next state.
  void Successors(const SymState& s, const Milestone& m, const Resolution& res, SuccessorList& out);
  /// Flat lazy: the successors of every step whose inputs exist (and of the final product).
  void FlatSuccessors(const SymState& s, const Resolution& res, SuccessorList& out);
  /// Appends action `a` of `s` with the state it leads to.
  void Push(const SymState& s, const TaskAction& a, SuccessorList& out) const;
  /// Free `robot` picks resting `node` with one of `grasps`.
  void PickSuccessors(const SymState& s, int robot, int node, std::span<const int> grasps,
                      SuccessorList& out);
  /// Free `robot` adds a grasp on `node`: a brace on the resting base, a second hand in the air.
  void AddGraspSuccessors(const SymState& s, const Milestone& m, bool done, int robot, int node,
                          std::span<const int> grasps, SuccessorList& out);
  /// Free `robot` takes `node` from its sole holder in the air.
  void HandoverSuccessors(const SymState& s, int robot, int node, std::span<const int> grasps,
                          SuccessorList& out);
  /// `robot` lets go of what it holds, when that rests or another hand holds it too.
  void ReleaseSuccessor(const SymState& s, int robot, SuccessorList& out);
  /// `robot`, the sole holder of an object in the air, sets it down on the table.
  void PlaceSuccessors(const SymState& s, const Resolution& res, int robot, SuccessorList& out);
  /// No other resting object of `s` is next to `slot` for `node`.
  bool SlotFree(const SymState& s, int node, const TableSlot& slot) const;
  /// The milestone's assembly, when its inputs are where it needs them.
  void AssembleSuccessor(const SymState& s, const Milestone& m, SuccessorList& out);
  Milestone StepMilestone(int step, int next_step) const;
  /// e.g. "'seat+leg0' (moving 'leg0' onto 'seat')".
  std::string StepWords(int step) const;
  /// The effort rounds of one resolution (the lazy search with validation and commits): kFound
  /// with `result` filled, kStopped / kOutOfMemory, or kExhausted.
  SearchStatus Rounds(int index, const Milestone& m, const Resolution& res, const SymState& s0,
                      const ContState& c0, const TaskClock& t0,
                      const std::set<std::uint64_t>& excluded, const FillLimits& limits,
                      MilestoneResult& result);
  /// Optimistic: assembly targets of milestone `m` chosen by the wrench LP alone (no reach).
  std::vector<AssemblyTarget> OptimisticTargets(const Milestone& m, const Resolution& res,
                                                const SymState& s0);
  bool TargetAllows(const SymState& s, const Milestone& m) const;
  /// Optimistic: the actions beyond counting that reaching the target's grasps needs.
  int TargetDistance(const SymState& s, const Milestone& m);
  /// Points the grasp-class caches at milestone `m`'s inputs.
  void SetClasses(const Milestone& m);
  /// Estimated bytes held by the search (nodes, queue, caches), for the memory limit.
  std::size_t MemoryBytes(std::size_t open, std::size_t closed) const;
  SymState Apply(const SymState& s, const TaskAction& a) const;
  /// Runs action `a` of `s` on `clock`: its robots (an assembly's: the holders of its inputs)
  /// and objects as MakeAction lists them.
  void Advance(const SymState& s, const TaskAction& a, TaskClock& clock) const;
  /// One weighted best-first search from s0 (g0 actions after the milestone's start) to a goal,
  /// skipping edges failed at `effort`, dead ends and `forbidden` states; the goal's node path
  /// in `path` (lazy_search.cpp).
  SearchStatus BestFirst(const SymState& s0, const TaskClock& t0, const Milestone& m,
                         const Resolution& res, int effort, const std::set<std::uint64_t>& excluded,
                         const std::unordered_map<std::uint64_t, bool>& dead_ends,
                         const std::unordered_set<std::uint64_t>& forbidden, long long node_budget,
                         int g0, int max_cost, std::vector<int>& path);
  /// Validates the candidate `path` edge by edge from the prefix's last state, committing each
  /// edge that holds to `prefix` and `actions`; a failure is tallied and suspends the edge.
  CandidateStatus CommitCandidate(int index, const Milestone& m, const std::vector<int>& path,
                                  const FillLimits& limits, std::vector<Committed>& prefix,
                                  std::vector<PlanAction>& actions, int& target_failures,
                                  bool& suspended_below);
  /// Tallies an edge `a` from (s, c) that failed validation with `outcome` (its scene moves into
  /// the tally when it is its gate's first).
  void TallyEdgeFailure(const SymState& s, const ContState& c, const TaskAction& a,
                        EdgeOutcome& outcome);
  /// Fills result.start and result.cases from the current tally (the milestone from (s0, c0)).
  void Explain(const SymState& s0, const ContState& c0, MilestoneResult& result) const;
  /// The cell at (s, c) for the failure record: robots' joints, every existing part's pose.
  FailureScene SceneOf(const SymState& s, const ContState& c) const;
  /// The failure record's case for one tallied gate.
  FailureCase Case(Gate gate, const FailureScene& start) const;
  /// The cheap checks of `robot` picking `node` resting at location `loc` at grasp `grasp`:
  /// reach, the gripper clear of the table, IK, carrying it right after the lift (cached).
  bool CheapPick(int robot, int node, int loc, int grasp);
  /// The objects resting in `s` other than `node`, and where (a hash): what ApproachClear's
  /// answer depends on besides the robot and the grasp, computed once per state and node.
  std::uint64_t RestingNeighbours(const SymState& s, int node) const;
  /// The gripper of `robot` approaching grasp `grasp` of `node` resting at `loc` straight along
  /// its axis (the approach the keyframe check asks for) clear of the other objects resting in
  /// `s` (`neighbours`: RestingNeighbours(s, node)): a necessary condition of that check, which
  /// the search would otherwise learn edge by edge in every state with the same neighbours
  /// (cached per neighbours' locations).
  bool ApproachClear(const SymState& s, std::uint64_t neighbours, int robot, int node, int loc,
                     int grasp);
  /// The cheap checks of `robot` setting `node` down at location `loc` at grasp `grasp`: reach,
  /// the gripper clear of the table, the homes clear, IK, the object resting there (cached).
  bool CheapPlace(int robot, int node, int loc, int grasp);
  /// The first two checks of CheapPick and CheapPlace: the TCP at `grasp` of `node` resting at
  /// `loc` within the reach of `robot`, then its gripper clear of the table. A failure is tallied
  /// about `about`, in the words of a pick or (`placing`) of a set-down.
  bool GripperFitsAtRest(int robot, int node, int loc, int grasp, bool placing,
                         const CheckSubject& about);
  bool CheapAssemble(const SymState& s, const Milestone& m);
  /// `node` resting at location `loc` leaves every robot room at home (cached).
  bool HomesClear(int node, int loc);
  bool GraspsApart(int grasp_a, int grasp_b) const;
  /// GraspsApart, and the two end effectors at those grasps keep the robots' clearance
  /// (KeyframeSolver::GrippersApart; cached per pair of end effectors and grasps).
  bool HandsApart(int robot_a, int grasp_a, int robot_b, int grasp_b);
  /// Abstract check before a milestone: some grasps of the moved input (one or two) and some
  /// support of the base (held by one gripper in some orientation, or resting in some
  /// placement, alone or braced) balance the step's mating wrench. Cached per step.
  bool AssemblyPossible(const Milestone& m, std::string* why);
  PlanAction MakeAction(const SymState& s, const TaskAction& a, const EdgeOutcome& e,
                        int milestone) const;

  /// The backward abstraction of the current milestone (backward.cpp).
  struct Backward {
    int step = -1, moved = -1, base = -1;
    int loc0[2] = {-1, -1};    ///< Start location of each input (-1: held).
    int n_place[2] = {0, 0};   ///< Placements of each input in the abstraction.
    int n_rest[2] = {0, 0};    ///< Rest statuses: the start location, then the placements.
    int n_status[2] = {0, 0};  ///< Rest statuses, then (robot, grasp class) pairs.
    int classes = 2;           ///< Grasp classes: 2, or 12 for the fine projection.
    std::unordered_map<int, bool> assembly_grasp[2];  ///< Grasp id -> assembly class.
    std::vector<int> dist;  ///< Per (moved status, base status): actions to the assembly.
    std::string why;        ///< Why the start is kFarDistance away (empty otherwise).
  };
  Backward backward_;

  const TaskWorld& world_;
  TaskTables& tables_;
  KeyframeSolver& solver_;
  const TaskPlannerOptions& options_;
  RunContext& ctx_;
  std::uint64_t seed_;
  bool widen_;
  int n_robots_ = 0;
  bool use_backward_ = false;    ///< wrap, exact: the backward heuristic replaces counting.
  int default_weight_ = 2;       ///< f = g + weight h: 2 (weighted best-first), 1 for "exact".
  int weight_ = 2;               ///< This fill's weight.
  bool fine_ = false;            ///< "fine": the backward abstraction's classes split by direction.
  bool flat_ = false;            ///< "flat": FillFlat instead of milestones.
  bool optimistic_ = false;      ///< "optimistic": assembly targets chosen first.
  AssemblyTarget target_;        ///< The current optimistic target.
  int target_start_loc_ = -1;    ///< Where the base rested at the target's milestone start.
  std::vector<int> flat_order_;  ///< Steps in the DAG's topological order.
  std::vector<int> window_;      ///< FillWindow's steps (empty: FillFlat's whole task).
  int window_next_ = -1;         ///< The step after the window (-1: none).
  int fill_failures_ = 0;        ///< Edge validation failures in the current fill.
  /// Expansions after which a resolution level that is not the last counts as exhausted (the
  /// fill widens): no cap at the last level, which keeps the fill complete.
  long long level_cap_ = std::numeric_limits<long long>::max();
  /// The level's budget once its search has found a candidate plan (level_cap_ is lower until
  /// then: kBlindExpansions).
  long long level_full_cap_ = std::numeric_limits<long long>::max();
  int level_assembly_failures_ = 0;  // failed assembly edges at this level (lazy_search.cpp)
  std::size_t rss0_ = 0;             ///< Resident memory when the search was made [bytes].
  /// Steps of the window assembled in `s` (they are assembled in order).
  int WindowDone(const SymState& s) const;
  std::vector<Node> nodes_;
  std::map<std::pair<int, int>, std::vector<int>> grasp_ids_;
  /// Keys of grasp_ids_ whose reduced grasps (partial-pad, fingertip) are registered.
  std::set<std::pair<int, int>> reduced_ids_;
  /// Whether GraspIds includes the reduced grasps: from the last resolution level on. Before it,
  /// neither the search nor the grasp ids (which seed the IK of edges) change when a set gains
  /// reduced grasps, so plans found with full-pad grasps stay the same.
  bool reduced_grasps_ = false;
  FlatMap<int> failed_level_;                                 // edge key -> level failed at
  std::unordered_map<std::uint64_t, EdgeOutcome> witnesses_;  // continuous edge key -> outcome
  struct CheapAnswer {
    bool ok = true;
    Gate gate = Gate::kNone;
    std::string why;
    CheckSubject about;
    int tallied_round = -1;  ///< The tally round (milestone) that last counted this failure.
  };
  bool Recall(CheapAnswer& answer);           // tallies a cached failure once per tally round
  void Remember(std::uint64_t key, bool ok);  // caches with the last tallied reason
  // Cheap-check answers: question key -> index into cheap_answers_.
  FlatMap<int> cheap_;
  std::vector<CheapAnswer> cheap_answers_;
  // Cheap failures are tallied once per round (a milestone, or a window of plan improvement):
  // a CheapAnswer counted in this round has tallied_round == tally_round_.
  int tally_round_ = 0;
  std::unordered_map<std::uint64_t, bool> homes_clear_;  // HomesClear per (node, location)
  std::unordered_map<std::uint64_t, bool> hands_apart_;  // HandsApart answers
  std::vector<std::pair<int, Iso3>> approach_others_;    // ApproachClear's scratch
  // What GraspsApart reads of a grasp (by grasp id), computed once: its TCP position and
  // approach axis in the assembly frame, and whether its object is small (under 15 cm across).
  struct GraspAxis {
    Vec3 p_A = Vec3::Zero();
    Vec3 z_A = Vec3::Zero();
    bool small = false;
    bool known = false;
  };
  const GraspAxis& AxisOf(int grasp) const;
  mutable std::vector<GraspAxis> grasp_axes_;
  std::map<int, std::pair<bool, std::string>> possible_;  // AssemblyPossible per step
  std::vector<Iso3> placement_pose_;                      // scratch
  long long expansions_ = 0;
  int widenings_ = 0;
  double search_s_ = 0.0;
  double bwd_s_ = 0.0;
  GateTally tally_;
};

}  // namespace wrap
