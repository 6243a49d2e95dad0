// The best split of an object's load among its supports (verify/, used by the simulation when a
// gripper's weld reads beyond its limits on an object that has other supports). Where a rigid
// object is held by several grippers, or by a gripper and the table, the split of its load among
// them is statically indeterminate: MuJoCo's rigid welds and soft friction choose one split
// (its solver's regularisation), the plan's wrench LP another, a compliant controller a third.
// This LP asks whether some split keeps every gripper within its limits: the least lambda such
// that each gripper's wrench lies within lambda times its box and the table's force at each
// support point within its friction pyramid balances the measured load.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/pose.h"
#include "model/project.h"
#include "wrench/lp.h"
#include "wrench/wrench.h"

namespace wrap::detail {

/// A gripper holding the object.
struct SplitHolder {
  /// Maps its wrench [f; tau] in its grasp frame G, at G's origin, to the world wrench about
  /// the reference point O: [R 0; [p_OG]x R  R] (R = R_WG, p_OG = G's origin - O).
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Identity();
  bool vacuum = false;   ///< A cup (transport and assembly boxes) or two-finger (one box).
  WrenchLimits limits;   ///< The project's (or its robot's) boxes.
};

/// The question: the load the supports must supply, who can supply it.
struct SplitQuery {
  std::vector<SplitHolder> holders;
  /// Support points on the table, relative to O [m] (world axes); the table's normal is +z.
  std::vector<Vec3> support_points;
  double friction = 0.4;  ///< Coulomb coefficient at the support points.
  /// What the supports together exert on the object (world force; world torque about O): the
  /// measured sum of every support's wrench.
  Vec6 whole = Vec6::Zero();
  /// The supports' share of the mating wrench (minus the mating wrench applied on the object);
  /// nonzero during an insertion. With a cup among the holders the split is "held, then mated"
  /// as the planner's (wrench.h): the load without it held with every cup within its transport
  /// box, and what the mating adds to a cup's wrench within its assembly box.
  Vec6 mating = Vec6::Zero();
  double floor_N = 1.0;    ///< A zero force bound counts as this [N] (measurement noise).
  double floor_Nm = 0.05;  ///< A zero torque bound counts as this [N m].
};

/// SplitHolder::A of a grasp frame with axes R_WG (columns in the world) at p_OG from O.
Eigen::Matrix<double, 6, 6> GraspWrenchToWorld(const Mat3& R_WG, const Vec3& p_OG);

/// Per holder (in order), its utilisation in the split of least lambda (its largest
/// |component| / bound; lambda found by bisection to 0.5%, or below 0.1%); nothing when the query
/// has no holder, a single support (one holder and no support point: its wrench is determined),
/// or no split with lambda up to 1e4 (or the LP failed). `lp` and `problem`/`solution` are
/// scratch, reused between calls.
std::optional<std::vector<double>> BestSplit(const SplitQuery& query, LpBackend& lp,
                                             LpProblem& problem, LpSolution& solution);

}  // namespace wrap::detail
