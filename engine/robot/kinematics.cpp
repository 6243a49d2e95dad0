#include "robot/kinematics.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "robot/detail/check.h"

namespace wrap {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Post-multiplies R by the rotation of angle q about the unit axis a (Rodrigues), with a fast
// path for the z axis (every UR joint, most URDF joints).
void RotateAbout(const Vec3& a, double q, Mat3& R) {
  const double s = std::sin(q);
  const double c = std::cos(q);
  if (a.x() == 0.0 && a.y() == 0.0 && a.z() == 1.0) {
    const Vec3 c0 = R.col(0);
    R.col(0) = c * c0 + s * R.col(1);
    R.col(1) = c * R.col(1) - s * c0;
    return;
  }
  const double t = 1.0 - c;
  Mat3 M;
  M << t * a.x() * a.x() + c, t * a.x() * a.y() - s * a.z(), t * a.x() * a.z() + s * a.y(),
      t * a.x() * a.y() + s * a.z(), t * a.y() * a.y() + c, t * a.y() * a.z() - s * a.x(),
      t * a.x() * a.z() - s * a.y(), t * a.y() * a.z() + s * a.x(), t * a.z() * a.z() + c;
  R = R * M;
}

// Moves (R, p) from the parent link frame to the joint frame J (X_PJ).
void ToJointFrame(const Joint& joint, Mat3& R, Vec3& p) {
  p += R * joint.X_PJ.translation();
  R = R * joint.X_PJ.linear();
}

// Moves (R, p) from the joint frame J to the child link frame (the joint's motion by q).
void ApplyJointMotion(const Joint& joint, double q, Mat3& R, Vec3& p) {
  if (joint.type == Joint::Type::kRevolute) {
    RotateAbout(joint.axis, q, R);
  } else {
    p += R * (joint.axis * q);
  }
}

Iso3 MakeIso(const Mat3& R, const Vec3& p) {
  Iso3 X;
  X.linear() = R;
  X.translation() = p;
  X.makeAffine();
  return X;
}

void CheckSizes(const Chain& chain, const JointVector& q) {
  WRAP_ROBOT_CHECK(chain.dof() <= kMaxDof);
  WRAP_ROBOT_CHECK(q.size() == chain.dof());
}

// A double in [0, 1) from the top 53 bits of one draw: the same on every standard library
// (std::uniform_real_distribution is implementation-defined).
double UniformUnit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace

void ForwardKinematics(const Chain& chain, const Iso3& X_WB, const JointVector& q,
                       std::span<Iso3> X_WL) {
  CheckSizes(chain, q);
  WRAP_ROBOT_CHECK(X_WL.size() >= static_cast<std::size_t>(chain.dof()) + 1);
  Mat3 R = X_WB.linear();
  Vec3 p = X_WB.translation();
  X_WL[0] = X_WB;
  for (int i = 0; i < chain.dof(); ++i) {
    const Joint& joint = chain.joints[i];
    ToJointFrame(joint, R, p);
    ApplyJointMotion(joint, q[i], R, p);
    X_WL[i + 1] = MakeIso(R, p);
  }
}

Iso3 FlangePose(const Chain& chain, const Iso3& X_WB, const JointVector& q) {
  return TcpPose(chain, X_WB, q, Iso3::Identity());
}

Iso3 TcpPose(const Chain& chain, const Iso3& X_WB, const JointVector& q, const Iso3& X_FT) {
  CheckSizes(chain, q);
  Mat3 R = X_WB.linear();
  Vec3 p = X_WB.translation();
  for (int i = 0; i < chain.dof(); ++i) {
    const Joint& joint = chain.joints[i];
    ToJointFrame(joint, R, p);
    ApplyJointMotion(joint, q[i], R, p);
  }
  // Flange, then TCP.
  p += R * chain.X_LF.translation();
  R = R * chain.X_LF.linear();
  p += R * X_FT.translation();
  R = R * X_FT.linear();
  return MakeIso(R, p);
}

void TcpJacobian(const Chain& chain, const Iso3& X_WB, const JointVector& q, const Iso3& X_FT,
                 Iso3* X_WT, Jacobian* J) {
  CheckSizes(chain, q);
  const int n = chain.dof();
  // Joint axes and origins in W, kept inline for the second pass.
  Eigen::Matrix<double, 3, kMaxDof> axis_W;
  Eigen::Matrix<double, 3, kMaxDof> origin_W;
  Mat3 R = X_WB.linear();
  Vec3 p = X_WB.translation();
  for (int i = 0; i < n; ++i) {
    const Joint& joint = chain.joints[i];
    ToJointFrame(joint, R, p);
    axis_W.col(i) = R * joint.axis;
    origin_W.col(i) = p;
    ApplyJointMotion(joint, q[i], R, p);
  }
  p += R * chain.X_LF.translation();
  R = R * chain.X_LF.linear();
  p += R * X_FT.translation();
  R = R * X_FT.linear();
  if (X_WT != nullptr) *X_WT = MakeIso(R, p);
  if (J == nullptr) return;
  J->resize(6, n);
  for (int i = 0; i < n; ++i) {
    const Vec3 w = axis_W.col(i);
    if (chain.joints[i].type == Joint::Type::kRevolute) {
      J->col(i).head<3>() = w.cross(p - origin_W.col(i));
      J->col(i).tail<3>() = w;
    } else {
      J->col(i).head<3>() = w;
      J->col(i).tail<3>().setZero();
    }
  }
}

JointVector ZeroConfiguration(const Chain& chain) {
  WRAP_ROBOT_CHECK(chain.dof() <= kMaxDof);
  return JointVector::Zero(chain.dof());
}

bool WithinLimits(const Chain& chain, const JointVector& q, double tolerance) {
  CheckSizes(chain, q);
  for (int i = 0; i < chain.dof(); ++i) {
    const Joint& joint = chain.joints[i];
    if (!(q[i] >= joint.lower - tolerance && q[i] <= joint.upper + tolerance)) return false;
  }
  return true;
}

JointVector ClampToLimits(const Chain& chain, const JointVector& q) {
  CheckSizes(chain, q);
  JointVector out = q;
  for (int i = 0; i < chain.dof(); ++i) {
    out[i] = std::clamp(q[i], chain.joints[i].lower, chain.joints[i].upper);
  }
  return out;
}

JointVector RandomConfiguration(const Chain& chain, std::mt19937_64& rng) {
  WRAP_ROBOT_CHECK(chain.dof() <= kMaxDof);
  JointVector q(chain.dof());
  for (int i = 0; i < chain.dof(); ++i) {
    const Joint& joint = chain.joints[i];
    q[i] = joint.lower + (joint.upper - joint.lower) * UniformUnit(rng);
  }
  return q;
}

JointVector NearestEquivalent(const Chain& chain, const JointVector& q,
                              const JointVector& reference) {
  CheckSizes(chain, q);
  CheckSizes(chain, reference);
  JointVector out = q;
  for (int i = 0; i < chain.dof(); ++i) {
    const Joint& joint = chain.joints[i];
    if (joint.type != Joint::Type::kRevolute) continue;
    const double k = std::round((q[i] - reference[i]) / kTwoPi);
    // The nearest equivalent may lie outside the limits; then try its neighbours.
    double best = q[i];
    double best_distance = std::abs(q[i] - reference[i]);
    bool found = q[i] >= joint.lower && q[i] <= joint.upper;
    for (const double shift : {k, k - 1.0, k + 1.0}) {
      const double candidate = q[i] - shift * kTwoPi;
      if (candidate < joint.lower || candidate > joint.upper) continue;
      const double distance = std::abs(candidate - reference[i]);
      if (!found || distance < best_distance) {
        best = candidate;
        best_distance = distance;
        found = true;
      }
    }
    out[i] = best;
  }
  return out;
}

double JointDistanceMax(const Chain& chain, const JointVector& a, const JointVector& b,
                        bool modulo_2pi) {
  CheckSizes(chain, a);
  CheckSizes(chain, b);
  double worst = 0.0;
  for (int i = 0; i < chain.dof(); ++i) {
    double d = a[i] - b[i];
    if (modulo_2pi && chain.joints[i].type == Joint::Type::kRevolute) d = WrapToPi(d);
    worst = std::max(worst, std::abs(d));
  }
  return worst;
}

double WrapToPi(double angle) {
  double wrapped = std::remainder(angle, kTwoPi);  // In [-pi, pi].
  if (wrapped <= -std::numbers::pi) wrapped += kTwoPi;
  return wrapped;
}

}  // namespace wrap
