// Inverse kinematics (paper §IV-D "Inverse kinematics"): the closed form for UR-class arms (all
// eight branches) and a damped-least-squares solver with joint limits and random restarts for
// any chain. The number of restarts is the "effort" that the task planner raises when an edge
// fails: an optimisation-based solver cannot prove that a target is unreachable.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "robot/chain.h"
#include "robot/kinematics.h"

namespace wrap {

/// Lengths of a UR-class arm in standard DH (ROBOTS.md §1.1): T_i = Rz(q_i) Tz(d_i) Tx(a_i)
/// Rx(alpha_i) with alpha = (pi/2, 0, 0, pi/2, -pi/2, 0), d2 = d3 = 0, a1 = a4 = a5 = a6 = 0.
struct UrParameters {
  double d1 = 0.0;  ///< Base to shoulder axis [m].
  double a2 = 0.0;  ///< Upper arm [m] (negative on UR arms).
  double a3 = 0.0;  ///< Forearm [m] (negative on UR arms).
  double d4 = 0.0;  ///< Offset between the shoulder and wrist-1 planes [m].
  double d5 = 0.0;  ///< Wrist 1 to wrist 2 [m].
  double d6 = 0.0;  ///< Wrist 2 to the flange [m].
};

/// Options of the UR closed form.
struct UrIkOptions {
  /// q6 used at the wrist singularity (|sin q5| < `singular_tolerance`), where only q4 + q6 or
  /// q4 - q6 is determined [rad]; pass the current q6 to keep the last joint still. Default 0.
  double q6_if_singular = 0.0;
  /// |sin q5| below this is the wrist singularity. Default 1e-12.
  double singular_tolerance = 1e-12;
};

/// The solutions of one UR IK query, stored inline (no heap).
struct UrIkSolutions {
  static constexpr int kMax = 8;    ///< Most solutions: 2 shoulder x 2 wrist x 2 elbow.
  std::array<JointVector, kMax> q;  ///< Valid entries [0, count): six joint angles [rad].
  /// Branch of each solution: bit 2 the shoulder (q1 = phi + asin(d4/r) or phi + pi - asin), bit 1
  /// the wrist (sin q5 >= 0 or < 0), bit 0 the elbow (q3 = +acos or -acos). Stable along smooth
  /// motions away from singularities: keyframe optimisation can count branch changes with it.
  std::array<std::uint8_t, kMax> branch{};
  int count = 0;                ///< Number of solutions.
  bool singular_wrist = false;  ///< True when q6 was set from `UrIkOptions::q6_if_singular`.
};

/// Closed-form IK of a UR-class arm, derived from the DH chain (Hawkins 2013 structure): the wrist
/// centre fixes q1 (two branches), the flange height along the shoulder axis fixes q5 (two), the
/// flange orientation fixes q6, then q2, q3 (two) solve a planar two-link problem and q4 closes
/// the three parallel joints.
///
/// Angle policy: every angle is first wrapped into (-pi, pi]; a value outside its joint's limits is
/// replaced by its +-2 pi equivalent inside them, and the solution is dropped if there is none.
/// With the catalog limits (+-2 pi, elbow +-pi) every canonical angle is kept, so the solutions
/// are exactly the canonical ones; `NearestEquivalent` moves a solution to the 2 pi variant nearest
/// to a reference configuration. Duplicates (at singularities) are removed.
class UrAnalyticIk {
 public:
  /// The solver for `chain` when it has the UR DH structure (as the catalog's ur5e and ur10e
  /// load); kInvalidInput naming the first joint that differs otherwise.
  static Result<UrAnalyticIk> FromChain(const Chain& chain);

  /// The DH lengths read from the chain.
  const UrParameters& parameters() const { return p_; }

  /// Every solution that puts the flange at `X_BF` (flange pose in the chain base frame B).
  /// No solution (count 0) when the pose is out of reach. Allocation-free.
  UrIkSolutions Solve(const Iso3& X_BF, const UrIkOptions& options = {}) const;

  /// Every solution that puts the TCP at `X_BT`, for an end effector with TCP `X_FT` in the
  /// flange frame (solves for X_BF = X_BT X_FT^-1).
  UrIkSolutions SolveTcp(const Iso3& X_BT, const Iso3& X_FT, const UrIkOptions& options = {}) const;

  /// The branch (as in UrIkSolutions::branch) of configuration `q` of `chain`: that of the
  /// closed-form solution nearest to q (revolute joints modulo 2 pi) for q's own flange pose;
  /// -1 when there is none. Along a smooth motion away from singularities it does not change.
  int BranchOf(const Chain& chain, const JointVector& q) const;

 private:
  UrAnalyticIk() = default;
  UrParameters p_;
  std::array<double, 6> lower_{};  // Joint limits [rad].
  std::array<double, 6> upper_{};
};

/// Options of the numeric IK, with defaults for the planner's grasp constraint.
struct NumericIkOptions {
  /// Converged when the TCP is this close to the target [m]. Default 1e-5 (0.01 mm); the paper
  /// relaxes the grasp constraint slightly: raise it to a few mm for that.
  double position_tolerance_m = 1e-5;
  /// ... and the rotation between TCP and target is at most this angle [rad]. Default 1e-4.
  double rotation_tolerance_rad = 1e-4;
  /// Random starts after the seeds: the effort level (paper §IV-D). Default 10.
  int restarts = 10;
  /// Iterations per start, each one FK and Jacobian evaluation. Default 100.
  int max_iterations = 100;
  /// Length that weighs rotation error against position error in the least-squares cost
  /// [m/rad]: 0.2 makes 1 rad count like 0.2 m. Default 0.2.
  double rotation_weight_m = 0.2;
  /// Starting Levenberg-Marquardt damping [m^2]; adapted per iteration. Default 1e-3.
  double initial_damping = 1e-3;
  /// Largest change of any joint in one iteration [rad or m]. Default 0.4.
  double max_step = 0.4;
  /// Run every start and return every distinct branch; otherwise stop at the first success.
  bool all_branches = false;
  /// With all_branches: stop once this many distinct branches are found (0: run every start).
  /// A redundant arm finds a new branch at almost every start, so a caller that keeps only the
  /// nearest few saves the remaining starts.
  int max_branches = 0;
  /// Give up early: when none of the first `give_up_after` starts has converged and the best of
  /// them still misses the target's position by more than `give_up_residual_m`, the target is
  /// taken as out of reach and the remaining starts are not run (0: never give up early). On a
  /// 7-DoF arm's task plan, fewer than 4% of such targets converge in later starts.
  int give_up_after = 0;
  double give_up_residual_m = 0.02;  ///< See give_up_after [m].
  /// Solutions that differ by less than this in every joint (revolute joints modulo 2 pi) are one
  /// branch; the one nearer the reference is kept [rad or m]. Default 0.05.
  double branch_separation = 0.05;
};

/// What to solve: a TCP target in the chain's base frame, where to start, what to stay near.
struct NumericIkRequest {
  Iso3 X_BT = Iso3::Identity();  ///< Target TCP pose in the chain base frame B.
  Iso3 X_FT = Iso3::Identity();  ///< TCP in the flange frame (identity: solve for the flange).
  /// Starts tried first, in order (e.g. the current configuration, analytic solutions); clamped
  /// into the limits. Each must have dof entries.
  std::vector<JointVector> seeds;
  /// Configuration to stay near: solutions are moved by 2 pi toward it (`NearestEquivalent`) and
  /// ranked by Euclidean joint distance to it. When empty, the first seed (if any) serves, and is
  /// used as the first start when there are no seeds.
  std::optional<JointVector> reference;
};

/// A numeric IK answer.
struct NumericIkResult {
  JointVector q;  ///< The branch nearest the reference (the first found when there is none).
  /// Every distinct branch found, nearest the reference first; `q` is `branches[0]`. One entry
  /// unless `all_branches`.
  std::vector<JointVector> branches;
  double position_error_m = 0.0;    ///< Residual of `q` [m].
  double rotation_error_rad = 0.0;  ///< Residual of `q` [rad].
  int starts = 0;                   ///< Starts run (seeds and random restarts).
  int iterations = 0;               ///< Iterations over all starts.
};

/// Damped least squares (Levenberg-Marquardt with adaptive damping) on the 6-D pose error, joint
/// limits by projection with an active set (a joint at a limit that the step would push further
/// out is held), from each seed and then from `options.restarts` configurations drawn uniformly
/// within the limits from `rng`. Bounded: at most (seeds + restarts) x max_iterations iterations.
/// Deterministic for a given rng state. Fails with kInfeasible naming the chain, the target and
/// the best residual reached (no start converged: out of reach, or more effort needed).
Result<NumericIkResult> SolveNumericIk(const Chain& chain, const NumericIkRequest& request,
                                       std::mt19937_64& rng, const NumericIkOptions& options = {});

}  // namespace wrap
