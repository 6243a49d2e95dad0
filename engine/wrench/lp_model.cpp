// Columns of the wrench LP and validation of its input.
//
// A support's variable is a wrench (or a force) in its own frame; its column is that variable's
// contribution to the equilibrium rows of the bodies it touches, as a world wrench about the
// reference point O (see vertices.cpp for the conventions). A unit wrench component e_i given in
// a frame F with rotation R_WF and origin p_WF becomes
//     force component i (i < 3):  [ R e_i ; (p_WF - O) x (R e_i) ]
//     moment component i (i >= 3): [ 0 ; R e_(i-3) ]
// Gripper G on body k: + on k's rows. Connection C from body a onto body b: + on b's rows and
// - on a's rows (action and reaction, paper eq. 1's t_qp = -t_pq). Table generator at polygon
// vertex v: one newton of normal force along the pyramid edge e, [ e ; (v - O) x e ] on the
// resting body's rows, with a non-negative coefficient.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "wrench/detail/lp_model.h"

namespace wrap::detail {
namespace {

bool Finite(const Vec3& v) { return v.allFinite(); }

Result<void> Invalid(const std::string& what) {
  return Fail(ErrorCode::kInvalidInput, "wrench: " + what);
}

Result<void> CheckPose(const Iso3& X, const std::string& field) {
  if (!X.matrix().allFinite()) return Invalid(field + " is not finite");
  const Mat3 R = X.linear();
  if ((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
      R.determinant() < 0.0) {
    return Invalid(field + " rotation is not a rotation matrix");
  }
  return {};
}

Result<void> CheckBounds(const WrenchBounds& b, const std::string& field) {
  for (int i = 0; i < 6; ++i) {
    // NaN fails both comparisons.
    if (!(b.lower[i] <= 0.0) || !(b.upper[i] >= 0.0)) {
      return Invalid(field + " component " + std::to_string(i) +
                     " must satisfy lower <= 0 <= upper (the box must contain the zero wrench)");
    }
  }
  return {};
}

Result<void> CheckBody(int index, int bodies, const std::string& field) {
  if (index < 0 || index >= bodies) {
    return Invalid(field + " = " + std::to_string(index) + " is out of range (" +
                   std::to_string(bodies) + " bodies)");
  }
  return {};
}

void AddWrenchColumn(const Mat3& R, const Vec3& p_OF, int component, double sign, double* rows) {
  if (component < 3) {
    const Vec3 f = R.col(component);
    const Vec3 m = p_OF.cross(f);
    for (int i = 0; i < 3; ++i) {
      rows[i] += sign * f[i];
      rows[3 + i] += sign * m[i];
    }
  } else {
    const Vec3 m = R.col(component - 3);
    for (int i = 0; i < 3; ++i) rows[3 + i] += sign * m[i];
  }
}

}  // namespace

void TableTangents(const WrenchTableSupport& t, Vec3& n, Vec3& t1, Vec3& t2) {
  n = t.normal_W.normalized();
  const Vec3 seed = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  t1 = (seed - seed.dot(n) * n).normalized();
  t2 = n.cross(t1);
}

Vec3 PyramidEdge(const WrenchTableSupport& t, int edge) {
  Vec3 n, t1, t2;
  TableTangents(t, n, t1, t2);
  const int edges = PyramidEdges(t);
  if (edges == 1) return n;
  const double th = 2.0 * std::numbers::pi * edge / edges;
  // Exact zeros on the axes keep the x/y thresholds exact.
  const double c = (edge * 4) % edges == 0 ? std::round(std::cos(th)) : std::cos(th);
  const double s = (edge * 4) % edges == 0 ? std::round(std::sin(th)) : std::sin(th);
  return n + t.friction * (c * t1 + s * t2);
}

void FillColumn(const StepConfiguration& config, const Vec3& p_WO, const ColumnInfo& info,
                double* col) {
  const std::size_t rows = config.bodies.size() * 6;
  for (std::size_t i = 0; i < rows; ++i) col[i] = 0.0;
  switch (info.kind) {
    case SupportKind::kGripper: {
      const WrenchGripper& g = config.grippers[info.owner];
      AddWrenchColumn(g.X_WG.linear(), g.X_WG.translation() - p_WO, info.component, 1.0,
                      col + g.body * 6);
      break;
    }
    case SupportKind::kConnection: {
      const WrenchConnection& c = config.connections[info.owner];
      const Mat3 R = c.X_WC.linear();
      const Vec3 p = c.X_WC.translation() - p_WO;
      AddWrenchColumn(R, p, info.component, 1.0, col + c.body_b * 6);
      AddWrenchColumn(R, p, info.component, -1.0, col + c.body_a * 6);
      break;
    }
    case SupportKind::kTable: {
      const WrenchTableSupport& t = config.tables[info.owner];
      const int edges = PyramidEdges(t);
      const Vec3 e = PyramidEdge(t, info.component % edges);
      const Vec3 m = (t.p_WV[info.component / edges] - p_WO).cross(e);
      double* rows_k = col + t.body * 6;
      for (int i = 0; i < 3; ++i) {
        rows_k[i] = e[i];
        rows_k[3 + i] = m[i];
      }
      break;
    }
  }
}

void ComponentBounds(const StepConfiguration& config, WrenchGate gate, const ColumnInfo& info,
                     double& lower, double& upper) {
  const WrenchBounds& b = info.kind == SupportKind::kGripper
                              ? GripperLimits(config.grippers[info.owner], gate)
                              : config.connections[info.owner].limits;
  lower = b.lower[info.component];
  upper = b.upper[info.component];
}

Result<void> Validate(const StepConfiguration& config, const WrenchQuery& query) {
  const int nb = static_cast<int>(config.bodies.size());
  if (nb == 0) return Invalid("the configuration has no bodies");
  for (int k = 0; k < nb; ++k) {
    const WrenchBody& b = config.bodies[k];
    const std::string field = "bodies[" + std::to_string(k) + "]";
    if (!std::isfinite(b.mass_kg) || b.mass_kg < 0.0) {
      return Invalid(field + ".mass_kg must be finite and >= 0");
    }
    if (!Finite(b.p_WBcm)) return Invalid(field + ".p_WBcm is not finite");
  }
  for (std::size_t i = 0; i < config.connections.size(); ++i) {
    const WrenchConnection& c = config.connections[i];
    const std::string field = "connections[" + std::to_string(i) + "]";
    if (auto r = CheckBody(c.body_a, nb, field + ".body_a"); !r) return r;
    if (auto r = CheckBody(c.body_b, nb, field + ".body_b"); !r) return r;
    if (c.body_a == c.body_b)
      return Invalid(field + " connects body " + std::to_string(c.body_a) + " to itself");
    if (auto r = CheckPose(c.X_WC, field + ".X_WC"); !r) return r;
    if (auto r = CheckBounds(c.limits, field + ".limits"); !r) return r;
  }
  for (std::size_t i = 0; i < config.grippers.size(); ++i) {
    const WrenchGripper& g = config.grippers[i];
    const std::string field = "grippers[" + std::to_string(i) + "]";
    if (auto r = CheckBody(g.body, nb, field + ".body"); !r) return r;
    if (auto r = CheckPose(g.X_WG, field + ".X_WG"); !r) return r;
    if (auto r = CheckBounds(g.assembly_limits, field + ".assembly_limits"); !r) return r;
    if (auto r = CheckBounds(g.transport_limits, field + ".transport_limits"); !r) return r;
  }
  for (std::size_t i = 0; i < config.tables.size(); ++i) {
    const WrenchTableSupport& t = config.tables[i];
    const std::string field = "tables[" + std::to_string(i) + "]";
    if (auto r = CheckBody(t.body, nb, field + ".body"); !r) return r;
    if (t.p_WV.empty()) return Invalid(field + ".p_WV has no vertices");
    for (const Vec3& v : t.p_WV) {
      if (!Finite(v)) return Invalid(field + ".p_WV has a vertex that is not finite");
    }
    if (!std::isfinite(t.friction) || t.friction < 0.0) {
      return Invalid(field + ".friction must be finite and >= 0");
    }
    if (t.pyramid_edges < 4 || t.pyramid_edges > 64) {
      return Invalid(field + ".pyramid_edges = " + std::to_string(t.pyramid_edges) +
                     " must be in [4, 64]");
    }
    if (!Finite(t.normal_W) || t.normal_W.norm() < 1e-9) {
      return Invalid(field + ".normal_W must be a finite non-zero vector");
    }
  }
  if (!Finite(config.gravity_W)) return Invalid("gravity_W is not finite");
  if (config.mating) {
    const MatingLoad& m = *config.mating;
    if (auto r = CheckBody(m.base, nb, "mating.base"); !r) return r;
    if (m.moved != -1) {
      if (auto r = CheckBody(m.moved, nb, "mating.moved"); !r) return r;
      if (m.moved == m.base) return Invalid("mating.moved and mating.base are the same body");
    }
    if (!Finite(m.axis_W) || m.axis_W.norm() < 1e-9) {
      return Invalid("mating.axis_W must be a finite non-zero vector");
    }
    if (!Finite(m.p_WContact)) return Invalid("mating.p_WContact is not finite");
    if (!std::isfinite(m.force_N) || m.force_N < 0.0) {
      return Invalid("mating.force_N must be finite and >= 0");
    }
    if (!std::isfinite(m.torque_Nm)) return Invalid("mating.torque_Nm is not finite");
    if (!std::isfinite(m.transverse_fraction) || m.transverse_fraction < 0.0) {
      return Invalid("mating.transverse_fraction must be finite and >= 0");
    }
    if (!std::isfinite(m.offset_m) || m.offset_m < 0.0) {
      return Invalid("mating.offset_m must be finite and >= 0");
    }
  }
  if (!std::isfinite(query.lambda) || query.lambda < 0.0) {
    return Invalid("query.lambda must be finite and >= 0");
  }
  if (!std::isfinite(query.accel_margin_mps2) || query.accel_margin_mps2 < 0.0) {
    return Invalid("query.accel_margin_mps2 must be finite and >= 0");
  }
  return {};
}

std::string FormatNumber(double v) {
  char buf[64];
  if (std::abs(v) >= 1000.0) {
    std::snprintf(buf, sizeof(buf), "%.0f", v);
  } else {
    std::snprintf(buf, sizeof(buf), "%.3g", v);
  }
  return buf;
}

}  // namespace wrap::detail
