// Forward kinematics and geometric Jacobians of serial chains, without heap allocation: the
// planner evaluates them hundreds of thousands of times per run (IK, collision, clearance).
#pragma once

#include <Eigen/Core>
#include <random>
#include <span>

#include "core/pose.h"
#include "robot/chain.h"

namespace wrap {

/// Most joints a chain may have for the kinematics and IK functions (inline buffers).
inline constexpr int kMaxDof = 10;

/// A joint configuration [rad or m], one entry per joint, base to tip; stored inline (no heap).
using JointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxDof, 1>;

/// A 6 x dof geometric Jacobian stored inline. Column i maps the rate of joint i to the spatial
/// velocity of the TCP: rows 0-2 the linear velocity of the TCP point [m/s], rows 3-5 the angular
/// velocity [rad/s], both expressed in the frame the base pose is given in (usually world W).
using Jacobian = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::ColMajor, 6, kMaxDof>;

/// Poses of every link frame in W: `X_WL[i]` for link i = 0..dof (link 0 is the base link, fixed
/// at X_WB). `X_WL` must hold at least dof + 1 entries and `q` dof entries (a bug otherwise:
/// abort). Allocation-free.
void ForwardKinematics(const Chain& chain, const Iso3& X_WB, const JointVector& q,
                       std::span<Iso3> X_WL);

/// Pose of the flange F in W: the last link's frame times `chain.X_LF`. Allocation-free.
Iso3 FlangePose(const Chain& chain, const Iso3& X_WB, const JointVector& q);

/// Pose of the TCP T in W: the flange pose times `X_FT` (the end effector's TCP in the flange
/// frame; identity for the bare flange). Allocation-free.
Iso3 TcpPose(const Chain& chain, const Iso3& X_WB, const JointVector& q,
             const Iso3& X_FT = Iso3::Identity());

/// The TCP pose and the geometric Jacobian of the TCP (see `Jacobian`) in one pass; either output
/// may be null. Revolute column: [w x (p_T - p_J); w]; prismatic: [w; 0], with w the joint axis
/// and p_J the joint origin in W. Allocation-free.
void TcpJacobian(const Chain& chain, const Iso3& X_WB, const JointVector& q, const Iso3& X_FT,
                 Iso3* X_WT, Jacobian* J);

/// The configuration with every joint at 0 (the chain's zero pose).
JointVector ZeroConfiguration(const Chain& chain);

/// True when every joint of `q` lies within its limits, widened by `tolerance` [rad or m].
bool WithinLimits(const Chain& chain, const JointVector& q, double tolerance = 0.0);

/// `q` with every joint clamped into its limits.
JointVector ClampToLimits(const Chain& chain, const JointVector& q);

/// A configuration drawn uniformly within the joint limits from `rng` (deterministic per seed).
JointVector RandomConfiguration(const Chain& chain, std::mt19937_64& rng);

/// `q` with each revolute joint moved by a multiple of 2 pi to the equivalent angle nearest to
/// `reference` that still lies within the joint's limits (same pose, shortest motion). Joints
/// with no such alternative keep their value.
JointVector NearestEquivalent(const Chain& chain, const JointVector& q,
                              const JointVector& reference);

/// Largest per-joint difference |a_i - b_i|; revolute joints compared modulo 2 pi when
/// `modulo_2pi` [rad or m].
double JointDistanceMax(const Chain& chain, const JointVector& a, const JointVector& b,
                        bool modulo_2pi);

/// Angle wrapped into (-pi, pi] [rad].
double WrapToPi(double angle);

}  // namespace wrap
