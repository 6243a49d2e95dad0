#include "robot/ik.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "robot/detail/check.h"

namespace wrap {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// ---------------------------------------------------------------------------------------------
// UR closed form.

// True when X equals Tz(d) Tx(a) Rx(alpha) up to `tol` (the joint origin a DH row produces).
bool IsDhRow(const Iso3& X, double d, double a, double alpha, double tol) {
  Iso3 expected = Iso3::Identity();
  expected.translation() = Vec3(a, 0.0, d);
  expected.linear() = Eigen::AngleAxisd(alpha, Vec3::UnitX()).toRotationMatrix();
  return (X.matrix() - expected.matrix()).cwiseAbs().maxCoeff() <= tol;
}

// Wraps into (-pi, pi], then into [lower, upper] by +-2 pi; false when no equivalent fits.
bool WrapIntoLimits(double& q, double lower, double upper) {
  q = WrapToPi(q);
  if (q >= lower && q <= upper) return true;
  for (const double shifted : {q + kTwoPi, q - kTwoPi}) {
    if (shifted >= lower && shifted <= upper) {
      q = shifted;
      return true;
    }
  }
  return false;
}

// acos and asin of a value that rounding may push slightly past +-1; NaN when clearly outside.
double SafeAcos(double c) {
  if (std::abs(c) > 1.0 + 1e-12) return std::numeric_limits<double>::quiet_NaN();
  return std::acos(std::clamp(c, -1.0, 1.0));
}

double SafeAsin(double s) {
  if (std::abs(s) > 1.0 + 1e-12) return std::numeric_limits<double>::quiet_NaN();
  return std::asin(std::clamp(s, -1.0, 1.0));
}

// ---------------------------------------------------------------------------------------------
// Numeric IK.

using Vec6 = Eigen::Matrix<double, 6, 1>;
using SquareMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxDof, kMaxDof>;

// Pose error of the TCP: position [m] and rotation vector [rad] that take the current pose to the
// target, both in the base frame (matching the Jacobian's rows).
struct Residual {
  Vec6 e = Vec6::Zero();    // [dp; w * dtheta].
  double position_m = 0.0;  // |dp|.
  double rotation_rad = 0.0;
  double cost = 0.0;  // |e|^2.
};

Residual ComputeResidual(const Iso3& X_BT_target, const Iso3& X_BT, double rotation_weight) {
  Residual r;
  r.e.head<3>() = X_BT_target.translation() - X_BT.translation();
  const Eigen::AngleAxisd error(X_BT_target.linear() * X_BT.linear().transpose());
  r.e.tail<3>() = (rotation_weight * error.angle()) * error.axis();
  r.position_m = r.e.head<3>().norm();
  r.rotation_rad = error.angle();
  r.cost = r.e.squaredNorm();
  return r;
}

bool Converged(const Residual& r, const NumericIkOptions& options) {
  return r.position_m <= options.position_tolerance_m &&
         r.rotation_rad <= options.rotation_tolerance_rad;
}

// The damped least-squares step dq = (Jw^T Jw + lambda I)^-1 Jw^T e of the weighted Jacobian
// Jw (rotation rows scaled by `w`), with the joints at a limit whose gradient points out of the
// range held (their columns of Jw zeroed, dq_i = 0). For 6 or more joints it is solved in the
// task space, dq = Jw^T (Jw Jw^T + lambda I)^-1 e (the same step: a fixed 6 x 6 system, the
// planner's IK hot path); for fewer joints in the joint space, the smaller system.
JointVector DampedStep(const Chain& chain, const Jacobian& J, double w, const JointVector& q,
                       const Vec6& e, double lambda) {
  const int n = chain.dof();
  Jacobian Jw = J;
  Jw.bottomRows<3>() *= w;
  for (int i = 0; i < n; ++i) {
    const Joint& joint = chain.joints[i];
    const double g = Jw.col(i).dot(e);
    const bool at_lower = q[i] <= joint.lower + 1e-12 && g < 0.0;
    const bool at_upper = q[i] >= joint.upper - 1e-12 && g > 0.0;
    if (at_lower || at_upper) Jw.col(i).setZero();
  }
  if (n >= 6) {
    Eigen::Matrix<double, 6, 6> M = Eigen::Matrix<double, 6, 6>::Zero();
    for (int i = 0; i < n; ++i) M.noalias() += Jw.col(i) * Jw.col(i).transpose();
    M.diagonal().array() += lambda;
    const Vec6 y = M.llt().solve(e);
    JointVector dq(n);
    for (int i = 0; i < n; ++i) dq[i] = Jw.col(i).dot(y);
    return dq;
  }
  SquareMatrix A = Jw.transpose().lazyProduct(Jw);
  A.diagonal().array() += lambda;
  const JointVector g = Jw.transpose().lazyProduct(e);
  return A.llt().solve(g);
}

// One Levenberg-Marquardt descent from `q` (clamped into the limits). Returns the last iterate
// and its residual; `iterations` counts the FK + Jacobian evaluations.
struct Descent {
  JointVector q;
  Residual residual;
  int iterations = 0;
};

Descent Descend(const Chain& chain, const NumericIkRequest& request, const JointVector& start,
                const NumericIkOptions& options) {
  const Iso3 X_BB = Iso3::Identity();
  const double w = options.rotation_weight_m;
  Descent d;
  d.q = ClampToLimits(chain, start);
  Iso3 X_BT;
  Jacobian J;
  TcpJacobian(chain, X_BB, d.q, request.X_FT, &X_BT, &J);
  d.residual = ComputeResidual(request.X_BT, X_BT, w);
  double lambda = options.initial_damping;
  int slow = 0;
  while (d.iterations < options.max_iterations && !Converged(d.residual, options)) {
    JointVector dq = DampedStep(chain, J, w, d.q, d.residual.e, lambda);
    const double largest = dq.cwiseAbs().maxCoeff();
    if (!(largest <= options.max_step)) {
      if (!std::isfinite(largest)) break;
      dq *= options.max_step / largest;
    }
    JointVector q_new = ClampToLimits(chain, d.q + dq);
    Iso3 X_new;
    Jacobian J_new;
    TcpJacobian(chain, X_BB, q_new, request.X_FT, &X_new, &J_new);
    ++d.iterations;
    const Residual r_new = ComputeResidual(request.X_BT, X_new, w);
    if (r_new.cost < d.residual.cost) {
      // Progress: accept and trust the Gauss-Newton model more.
      slow = r_new.cost > 0.999 * d.residual.cost ? slow + 1 : 0;
      d.q = q_new;
      J = J_new;
      d.residual = r_new;
      lambda = std::max(lambda * 0.2, 1e-12);
      // Many accepted steps with no real progress: a local minimum (often at a limit).
      if (slow >= 10) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e6) break;  // No step decreases the cost: a local minimum.
    }
  }
  return d;
}

std::string FormatTarget(const Iso3& X) {
  const Pose pose = FromIsometry(X);
  char text[160];
  std::snprintf(text, sizeof(text), "xyz (%.4f, %.4f, %.4f) m rpy (%.4f, %.4f, %.4f) rad",
                pose.xyz.x(), pose.xyz.y(), pose.xyz.z(), pose.rpy.x(), pose.rpy.y(), pose.rpy.z());
  return text;
}

}  // namespace

Result<UrAnalyticIk> UrAnalyticIk::FromChain(const Chain& chain) {
  const auto fail = [&](const std::string& what) {
    return Fail(ErrorCode::kInvalidInput,
                "UR analytic IK: chain '" + chain.name + "' is not a UR-class DH chain: " + what);
  };
  if (chain.dof() != 6) return fail("it has " + std::to_string(chain.dof()) + " joints, not 6");
  for (const Joint& joint : chain.joints) {
    if (joint.type != Joint::Type::kRevolute || (joint.axis - Vec3::UnitZ()).norm() > 1e-12) {
      return fail("joint '" + joint.name + "' is not revolute about its z axis");
    }
  }
  // The catalog places joint i at DH row i-1 (C_{i-1} = Tz(d) Tx(a) Rx(alpha)) and the flange at
  // row 6; read the lengths and check that every other entry is the UR pattern.
  UrAnalyticIk ik;
  UrParameters& p = ik.p_;
  p.d1 = chain.joints[1].X_PJ.translation().z();
  p.a2 = chain.joints[2].X_PJ.translation().x();
  p.a3 = chain.joints[3].X_PJ.translation().x();
  p.d4 = chain.joints[4].X_PJ.translation().z();
  p.d5 = chain.joints[5].X_PJ.translation().z();
  p.d6 = chain.X_LF.translation().z();
  constexpr double kTol = 1e-9;
  const double half_pi = kPi / 2.0;
  const struct {
    const Iso3& X;
    double d, a, alpha;
    const char* what;
  } rows[] = {
      {chain.joints[0].X_PJ, 0.0, 0.0, 0.0, "shoulder_pan origin (expected identity)"},
      {chain.joints[1].X_PJ, p.d1, 0.0, half_pi, "joint 2 origin (expected Tz(d1) Rx(pi/2))"},
      {chain.joints[2].X_PJ, 0.0, p.a2, 0.0, "joint 3 origin (expected Tx(a2))"},
      {chain.joints[3].X_PJ, 0.0, p.a3, 0.0, "joint 4 origin (expected Tx(a3))"},
      {chain.joints[4].X_PJ, p.d4, 0.0, half_pi, "joint 5 origin (expected Tz(d4) Rx(pi/2))"},
      {chain.joints[5].X_PJ, p.d5, 0.0, -half_pi, "joint 6 origin (expected Tz(d5) Rx(-pi/2))"},
      {chain.X_LF, p.d6, 0.0, 0.0, "flange (expected Tz(d6))"},
  };
  for (const auto& row : rows) {
    if (!IsDhRow(row.X, row.d, row.a, row.alpha, kTol)) return fail(row.what);
  }
  if (std::abs(p.a2) < 1e-6 || std::abs(p.a3) < 1e-6 || std::abs(p.d6) < 1e-6) {
    return fail("a2, a3 and d6 must be non-zero");
  }
  for (int i = 0; i < 6; ++i) {
    ik.lower_[i] = chain.joints[i].lower;
    ik.upper_[i] = chain.joints[i].upper;
  }
  return ik;
}

UrIkSolutions UrAnalyticIk::Solve(const Iso3& X_BF, const UrIkOptions& options) const {
  UrIkSolutions out;
  const Mat3& R = X_BF.linear();
  const Vec3 p = X_BF.translation();
  const Vec3 n = R.col(0);
  const Vec3 o = R.col(1);
  const Vec3 a = R.col(2);

  // q1: the wrist-2 point p5 = p - d6 z6 lies at distance d4 from the arm plane, whose normal is
  // z1 = (sin q1, -cos q1, 0):  r sin(q1 - phi) = d4.
  const Vec3 p5 = p - p_.d6 * a;
  const double r = std::hypot(p5.x(), p5.y());
  if (r < 1e-12) return out;
  const double phi = std::atan2(p5.y(), p5.x());
  const double shoulder = SafeAsin(p_.d4 / r);
  if (std::isnan(shoulder)) return out;  // Target inside the cylinder of radius |d4|.
  const double q1_candidates[2] = {phi + shoulder, phi + kPi - shoulder};

  for (int si = 0; si < 2; ++si) {
    const double q1 = q1_candidates[si];
    const double s1 = std::sin(q1);
    const double c1 = std::cos(q1);
    // q5: z1 seen from the flange frame is (s5 c6, -s5 s6, c5). (The flange height along z1,
    // d4 + d6 c5, gives the same c5 once q1 holds; acos of it would lose precision near the
    // wrist singularity, atan2 does not.)
    const double n_z1 = n.x() * s1 - n.y() * c1;
    const double o_z1 = o.x() * s1 - o.y() * c1;
    const double a_z1 = a.x() * s1 - a.y() * c1;
    const double wrist_sin = std::hypot(n_z1, o_z1);
    for (int wi = 0; wi < 2; ++wi) {
      const double q5 = std::atan2(wi == 0 ? wrist_sin : -wrist_sin, a_z1);
      const double s5 = std::sin(q5);
      const double c5 = std::cos(q5);
      // q6 from the flange orientation; free at the wrist singularity.
      double q6 = options.q6_if_singular;
      const bool singular = std::abs(s5) < options.singular_tolerance;
      if (!singular) q6 = std::atan2(-o_z1 / s5, n_z1 / s5);
      const double s6 = std::sin(q6);
      const double c6 = std::cos(q6);
      // Wrist-1 point p4 = p5 + d5 y5 (z4 = -y5), and x4 = c5 x5 - s5 z5, in the plane of joints
      // 2-4 (frame 1 coordinates: x along the arm, y up along the base z).
      const Vec3 p4 = p5 + p_.d5 * (s6 * n + c6 * o);
      const Vec3 x4 = c5 * (c6 * n - s6 * o) - s5 * a;
      const double px = c1 * p4.x() + s1 * p4.y();
      const double py = p4.z() - p_.d1;
      const double q234 = std::atan2(x4.z(), c1 * x4.x() + s1 * x4.y());
      // q3 and q2: the planar two-link arm a2, a3 reaching (px, py).
      const double elbow =
          SafeAcos((px * px + py * py - p_.a2 * p_.a2 - p_.a3 * p_.a3) / (2.0 * p_.a2 * p_.a3));
      if (std::isnan(elbow)) continue;
      for (int ei = 0; ei < 2; ++ei) {
        const double q3 = ei == 0 ? elbow : -elbow;
        const double q2 =
            std::atan2(py, px) - std::atan2(p_.a3 * std::sin(q3), p_.a2 + p_.a3 * std::cos(q3));
        const double q4 = q234 - q2 - q3;
        JointVector q(6);
        q << q1, q2, q3, q4, q5, q6;
        bool ok = true;
        for (int j = 0; j < 6 && ok; ++j) ok = WrapIntoLimits(q[j], lower_[j], upper_[j]);
        if (!ok) continue;
        bool duplicate = false;
        for (int k = 0; k < out.count && !duplicate; ++k) {
          duplicate = (out.q[k] - q).cwiseAbs().maxCoeff() < 1e-10;
        }
        if (duplicate) continue;
        out.q[out.count] = q;
        out.branch[out.count] = static_cast<std::uint8_t>(si << 2 | wi << 1 | ei);
        ++out.count;
        out.singular_wrist = out.singular_wrist || singular;
      }
    }
  }
  return out;
}

int UrAnalyticIk::BranchOf(const Chain& chain, const JointVector& q) const {
  UrIkOptions options;
  options.q6_if_singular = q[5];
  const UrIkSolutions sols = Solve(FlangePose(chain, Iso3::Identity(), q), options);
  int best = -1;
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < sols.count; ++k) {
    const double d = (NearestEquivalent(chain, sols.q[k], q) - q).cwiseAbs().maxCoeff();
    if (d < nearest) {
      nearest = d;
      best = sols.branch[k];
    }
  }
  return best;
}

UrIkSolutions UrAnalyticIk::SolveTcp(const Iso3& X_BT, const Iso3& X_FT,
                                     const UrIkOptions& options) const {
  return Solve(X_BT * X_FT.inverse(), options);
}

Result<NumericIkResult> SolveNumericIk(const Chain& chain, const NumericIkRequest& request,
                                       std::mt19937_64& rng, const NumericIkOptions& options) {
  WRAP_ROBOT_CHECK(chain.dof() >= 1 && chain.dof() <= kMaxDof);
  for (const JointVector& seed : request.seeds) WRAP_ROBOT_CHECK(seed.size() == chain.dof());
  WRAP_ROBOT_CHECK(!request.reference || request.reference->size() == chain.dof());

  std::optional<JointVector> reference = request.reference;
  if (!reference && !request.seeds.empty()) reference = request.seeds.front();
  const bool reference_is_start = request.seeds.empty() && request.reference.has_value();
  const int seed_starts = static_cast<int>(request.seeds.size()) + (reference_is_start ? 1 : 0);
  const int total_starts = seed_starts + std::max(options.restarts, 0);

  NumericIkResult result;
  std::vector<Residual> residuals;  // Of each branch, parallel to result.branches.
  Residual best;
  best.cost = std::numeric_limits<double>::infinity();
  double best_position_m = std::numeric_limits<double>::infinity();
  for (int start = 0; start < total_starts; ++start) {
    JointVector q0;
    if (reference_is_start && start == 0) {
      q0 = *request.reference;
    } else if (start < seed_starts) {
      q0 = request.seeds[start - (reference_is_start ? 1 : 0)];
    } else {
      q0 = RandomConfiguration(chain, rng);
    }
    const Descent d = Descend(chain, request, q0, options);
    ++result.starts;
    result.iterations += d.iterations;
    if (d.residual.cost < best.cost) best = d.residual;
    if (d.residual.position_m < best_position_m) best_position_m = d.residual.position_m;
    if (!Converged(d.residual, options)) {
      if (result.branches.empty() && start + 1 == options.give_up_after &&
          best_position_m > options.give_up_residual_m) {
        break;
      }
      continue;
    }

    const JointVector q = reference ? NearestEquivalent(chain, d.q, *reference) : d.q;
    // A known branch: keep whichever of the two is nearer the reference.
    bool known = false;
    for (std::size_t k = 0; k < result.branches.size() && !known; ++k) {
      if (JointDistanceMax(chain, q, result.branches[k], true) < options.branch_separation) {
        known = true;
        if (reference && (q - *reference).norm() < (result.branches[k] - *reference).norm()) {
          result.branches[k] = q;
          residuals[k] = d.residual;
        }
      }
    }
    if (!known) {
      result.branches.push_back(q);
      residuals.push_back(d.residual);
    }
    if (!options.all_branches) break;
    if (options.max_branches > 0 &&
        static_cast<int>(result.branches.size()) >= options.max_branches) {
      break;
    }
  }

  if (result.branches.empty()) {
    char residual[96];
    std::snprintf(residual, sizeof(residual), "%.3g m / %.3g rad", best.position_m,
                  best.rotation_rad);
    char tolerance[96];
    std::snprintf(tolerance, sizeof(tolerance), "%.3g m / %.3g rad", options.position_tolerance_m,
                  options.rotation_tolerance_rad);
    return Fail(
        ErrorCode::kInfeasible,
        "numeric IK: robot '" + chain.name + "': no configuration puts the TCP at " +
            FormatTarget(request.X_BT) + " (base frame) within " + tolerance + " after " +
            std::to_string(result.starts) + " starts (" + std::to_string(seed_starts) +
            " seeds + " + std::to_string(result.starts - seed_starts) + " restarts, " +
            std::to_string(result.iterations) + " iterations" +
            (result.starts < total_starts ? ", gave up early: every start ended far away" : "") +
            "); best residual " + residual +
            ". Hint: the target may be out of reach; raise the effort (restarts) or "
            "the tolerance");
  }

  // Nearest the reference first (stable: discovery order among equals).
  std::vector<std::size_t> order(result.branches.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  if (reference) {
    std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
      return (result.branches[i] - *reference).norm() < (result.branches[j] - *reference).norm();
    });
  }
  std::vector<JointVector> sorted;
  sorted.reserve(order.size());
  for (const std::size_t k : order) sorted.push_back(result.branches[k]);
  result.branches = std::move(sorted);
  result.q = result.branches.front();
  result.position_error_m = residuals[order.front()].position_m;
  result.rotation_error_rad = residuals[order.front()].rotation_rad;
  return result;
}

}  // namespace wrap
