// Internals of the keyframe solver shared by its source files: the edge under validation, the
// keyframe problem each action type builds (keyframe_actions.cpp), the state of the search for
// its keyframe (keyframe_validate.cpp, keyframe_checks.cpp), and a few constants and helpers.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "task/keyframes.h"

namespace wrap {
namespace detail {

using Clock = std::chrono::steady_clock;

/// Seconds elapsed since `since`.
inline double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

/// An object this close above the table [m] rests on it.
inline constexpr double kTouchTolerance = 2e-3;

}  // namespace detail

/// One edge under validation: the action, the states around it and the random generator that
/// draws its sampled poses and its numeric IK restarts.
struct KeyframeSolver::Edge {
  const SymState& s;     ///< Symbolic state before the action.
  const ContState& c;    ///< Continuous state before the action.
  const TaskAction& a;   ///< The action.
  const SymState& next;  ///< Symbolic state after the action.
  int effort = 0;        ///< Effort level, clamped to 0..2.
  int n_robots = 0;      ///< Robots in the cell.
  std::mt19937_64 rng;   ///< Seeded from the edge's seed and its (unclamped) effort.
};

/// The keyframe problem of an edge, filled per action type (keyframe_actions.cpp). Its
/// functions refer back to it and to the edge, so it is built in place and never copied.
struct KeyframeSolver::Problem {
  Problem() = default;
  Problem(const Problem&) = delete;
  Problem& operator=(const Problem&) = delete;

  /// Adds a robot that reaches for `grasp` on `node` at the keyframe.
  void AddMover(const TaskWorld& world, int robot, int node, int grasp) {
    movers.push_back({robot, node, grasp});
    if (!world.robots[robot].ur) numeric = true;
  }

  std::vector<Mover> movers;  ///< Robots whose joints the keyframe chooses.
  std::vector<int> reposed;   ///< Nodes whose pose is sampled.
  int n_candidates = 1;       ///< Candidate poses tried.
  /// Candidate `k`'s object poses, written into the node-indexed poses of the state; false when
  /// the object would be below the table top.
  std::function<bool(int, std::vector<Iso3>&)> make;
  /// The wrench gates of the action at the candidate's poses; false with the gate and why.
  std::function<bool(const std::vector<Iso3>&, Gate&, std::string&)> gates;
  std::vector<int> keyframe_nodes;     ///< Objects listed in the keyframe.
  std::vector<bool> keyframe_resting;  ///< Per node: it rests on the table at the keyframe.
  int allow_a = -1;                    ///< Mated pair at the keyframe (assemble), else -1.
  int allow_b = -1;
  std::vector<int> freed;                              ///< Robots that go home after the action.
  std::vector<std::pair<int, int>> holds_at_keyframe;  ///< (robot, grasp) holding at the keyframe.
  bool numeric = false;  ///< Some mover's IK is numeric (sampled), not closed-form.
};

/// The search for an edge's keyframe: the candidate under test, what its checks found, and the
/// most advanced failure over all candidates.
struct KeyframeSolver::Attempt {
  /// Keeps the most advanced failure: table < wrench < reach < IK < collision < clearance <
  /// approach or skill (a later one of the same rank replaces an earlier one).
  void Note(Gate g, const std::string& what);

  std::vector<Iso3> X;               ///< Node-indexed object poses of the candidate under test.
  std::vector<PlanObject> objects;   ///< The candidate's objects at the keyframe.
  std::vector<JointVector> chosen;   ///< Per mover: the joints of the keyframe.
  std::optional<Keyframe> approach;  ///< Assemble: the keyframe at the insertion's approach.
  bool park_home = true;             ///< Freed robots go home (else they stay, gripper open).
  Gate gate = Gate::kNone;           ///< The candidate's failed check (the combination search's).
  std::string message;               ///< ... why, in words (empty: every IK solution collides).
  Gate worst = Gate::kNone;          ///< The most advanced failure over all candidates.
  std::string why;                   ///< ... why, in words.
};

}  // namespace wrap
