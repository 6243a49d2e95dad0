// The one adapter to OMPL (paper §IV-E): a collision-free path between two configurations of a
// composite joint space, found by RRT-Connect and shortened by shortcutting. Nothing else in Wrap
// includes OMPL headers.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace wrap {

/// A path query in a box-bounded joint space.
struct PathQuery {
  Eigen::VectorXd lower;  ///< Lower bound per coordinate [rad or m].
  Eigen::VectorXd upper;  ///< Upper bound per coordinate.
  Eigen::VectorXd start;  ///< Start configuration (must be valid).
  Eigen::VectorXd goal;   ///< Goal configuration.
  /// Other configurations that serve as well as `goal` (e.g. other IK solutions of the same
  /// TCP pose); the path ends at whichever it reaches. The bounds must hold them.
  std::vector<Eigen::VectorXd> other_goals;
  /// State validity (collision-free); called from the planner's thread only.
  std::function<bool(const Eigen::VectorXd&)> valid;
  /// Motions are checked at states no farther apart than this in any coordinate [rad or m].
  double resolution = 0.02;
  /// The returned path is checked at this finer resolution (shortcuts too); a path that fails
  /// it is not returned. 0: the same as `resolution`.
  double final_resolution = 0.0;
  /// RRT-Connect's work budget: state validity checks (its states and motions, the re-checks
  /// of the paths it returns). Counted in work, not time, so that the same seed finds the same
  /// path whatever the machine's load; the run's deadline comes through `stop`.
  long long max_checks = 20000;
  std::uint64_t seed = 0;  ///< Seeds sampling and shortcutting (deterministic per seed).
  /// Checked while planning: true stops at once (cancellation, the run's wall-clock deadline).
  std::function<bool()> stop;
  /// Random shortcut attempts after the path is found and shortcut greedily (each waypoint
  /// straight to the farthest later one it sees).
  int shortcut_attempts = 16;
  /// RRT-Connect's extension length, per square root of the dimension [rad]. OMPL's RRT-Connect
  /// keeps an extension only when all of it is free, so a tree rooted in a pocket (a pre-grasp
  /// pose next to a part, a hand between two arms) grows only by short ones: at 0.4 the ten
  /// example projects got motion in 27 of 30 runs (seeds 0-2, 60 s), at 0.2 in 29, with the
  /// easy ones as fast as before.
  double range_per_sqrt_dim = 0.2;
  /// Hubs: configurations (e.g. the robots' home) through which a path start -> hub -> goal is
  /// searched when RRT-Connect finds no direct one within the budget, each leg within a quarter
  /// of `max_checks` of its own, then shortcut as one path. Samples of a leg may reach beyond
  /// `lower`/`upper` as far as its hub.
  std::vector<Eigen::VectorXd> via;
  std::string via_name = "the hub";  ///< The hubs in words, for `PathAnswer::why`.
};

/// What PlanPath found.
struct PathAnswer {
  bool solved = false;                ///< A path was found.
  bool timed_out = false;             ///< Not solved within the work budget (more effort may help).
  std::vector<Eigen::VectorXd> path;  ///< Waypoints from start to goal (solved only).
  /// The goal reached: 0 for `goal`, k for `other_goals[k - 1]` (solved only).
  int goal_index = 0;
  long long checks = 0;  ///< State validity checks.
  std::string why;       ///< When not solved: why, in words.
};

/// True when the straight motion from a to b is valid at the query's resolution (both ends
/// included); counts checks.
bool StraightMotionValid(const PathQuery& query, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                         long long* checks = nullptr);

/// A path from query.start to query.goal: the straight motion when it is valid, else RRT-Connect
/// (OMPL) within the work budget, then shortcutting (random pairs of points along the path joined
/// by straight motions) and removal of waypoints whose neighbours see each other; every piece of
/// the result is valid at `final_resolution` (RRT-Connect is run again with a new seed, within
/// the budget, while its path is not); where that finds none within the budget, the same through
/// each of `via` in turn. Deterministic for a given seed unless `stop` stops it.
PathAnswer PlanPath(const PathQuery& query);

}  // namespace wrap
