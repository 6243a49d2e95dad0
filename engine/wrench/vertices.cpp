// The uncertainty set U of external wrenches and its vertices (paper §IV-A "Robust
// satisfaction": the nominal mating force, bounded transverse components, an offset of the
// application point, plus gravity).
//
// Conventions. Every wrench is w = [f; m] with the moment m taken about one reference point O
// common to all bodies, expressed in the world frame W. A force f acting at point p contributes
// [f; (p - O) x f]. Equilibrium of body k (paper eq. 1) is
//     sum of support wrenches on k + sum of connection wrenches on k + w_ext(k) = 0,
// and w_ext(k) is what this file computes.
//
// Gravity on body k of mass m_k and centre of mass c_k:
//     w_ext(k) += [ m_k g ; (c_k - O) x m_k g ].
//
// Mating (assembly gate). The moved body M travels along the unit insertion axis a into the base
// body B. Whatever holds M pushes it along +a; the contact between M and B transmits the mating
// wrench: M pushes B along +a and B pushes M back along -a. With lambda the scale, F the nominal
// force, T the nominal torque about the axis, tau the transverse fraction, delta the offset bound
// and t1, t2 unit directions normal to a (TransverseBasis), the contact wrench that M applies on B
// at vertex (e1, e2, d1, d2) in {-1, +1}^4 is
//     f_c = lambda F (a + e1 tau t1 + e2 tau t2)        (force)
//     p_c = p_contact + delta (d1 t1 + d2 t2)           (application point)
//     m_c = lambda T a                                  (screw torque, M on B)
//     w_ext(B) += [ f_c ; (p_c - O) x f_c + m_c ]
//     w_ext(M) -= [ f_c ; (p_c - O) x f_c + m_c ]       (reaction; omitted when M is not modelled)
// So the supports of M must supply +lambda F a (the controller's push) and those of B must resist
// being pushed along +a: a block on the table pressed from above (a = -z) is held by the table.
// The transverse set is the box |f . t1|, |f . t2| <= tau lambda F (its four corners), the offset
// set the square |o . t1|, |o . t2| <= delta. Both f_c and the moment are multilinear in
// (e1, e2, d1, d2), so every external wrench of the parameter box is a convex combination of the
// wrenches of its 16 corners; the set of external wrenches that the supports can balance is
// convex, hence balancing the corners balances all of U. A parameter whose bound is 0 adds no
// vertices (1, 4 or 16 vertices).
//
// Transport. Carried bodies accelerate with some a_W whose components lie in [-A, A] (A the
// margin); in the accelerating frame each body feels the d'Alembert force -m_k a_W:
//     w_ext(k) += [ -m_k a_W ; (c_k - O) x (-m_k a_W) ],   a_W in {-A, +A}^3 (8 vertices).
// Angular accelerations are neglected.
#include <cmath>
#include <cstdio>

#include "wrench/detail/vertices.h"

namespace wrap::detail {
namespace {

// Adds the force f acting at point p (moment about O) to the 6 entries of w.
void AddForce(double* w, const Vec3& f, const Vec3& p_OP, double sign) {
  const Vec3 m = p_OP.cross(f);
  for (int i = 0; i < 3; ++i) {
    w[i] += sign * f[i];
    w[3 + i] += sign * m[i];
  }
}

}  // namespace

void TransverseBasis(const Vec3& a, Vec3& t1, Vec3& t2) {
  const Vec3 seed = std::abs(a.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  t1 = (seed - seed.dot(a) * a).normalized();
  t2 = a.cross(t1);
}

std::string DirectionName(const Vec3& d) {
  static const char* kAxis[3] = {"x", "y", "z"};
  const double n = d.norm();
  if (n > 0.0) {
    for (int i = 0; i < 3; ++i) {
      if (std::abs(d[i]) >= n * (1.0 - 1e-9)) return std::string(d[i] > 0 ? "+" : "-") + kAxis[i];
    }
  }
  char buf[64];
  const Vec3 u = n > 0.0 ? Vec3(d / n) : d;
  std::snprintf(buf, sizeof(buf), "(%.2f, %.2f, %.2f)", u.x(), u.y(), u.z());
  return buf;
}

void BuildVertices(const StepConfiguration& config, const WrenchQuery& query, const Vec3& p_WO,
                   VertexSet& out) {
  const int nb = static_cast<int>(config.bodies.size());
  out.bodies = nb;
  out.transverse = false;
  out.offset = false;
  out.t1 = Vec3::UnitX();
  out.t2 = Vec3::UnitY();

  // Gravity, shared by every vertex.
  std::vector<double>& w = out.w;
  const std::size_t stride = static_cast<std::size_t>(nb) * 6;
  w.assign(stride, 0.0);
  for (int k = 0; k < nb; ++k) {
    const WrenchBody& b = config.bodies[k];
    AddForce(&w[k * 6], b.mass_kg * config.gravity_W, b.p_WBcm - p_WO, 1.0);
  }

  const MatingLoad* mating = config.mating ? &*config.mating : nullptr;
  const bool mating_on =
      query.gate == WrenchGate::kAssembly && query.mode == MatingWrenchMode::kFull &&
      mating != nullptr &&
      (query.lambda * mating->force_N != 0.0 || query.lambda * mating->torque_Nm != 0.0);
  const bool transport_on = query.gate == WrenchGate::kTransport && query.accel_margin_mps2 > 0.0;

  out.signs.clear();
  if (mating_on) {
    out.kind = VertexKind::kMating;
    const Vec3 a = mating->axis_W.normalized();
    TransverseBasis(a, out.t1, out.t2);
    const double force = query.lambda * mating->force_N;
    const double transverse = mating->transverse_fraction * force;
    out.transverse = transverse > 0.0;
    out.offset = mating->offset_m > 0.0 && force > 0.0;
    const int ne = out.transverse ? 2 : 1;
    const int nd = out.offset ? 2 : 1;
    const Vec3 m_c = query.lambda * mating->torque_Nm * a;
    const std::vector<double> gravity = w;
    w.clear();
    for (int i1 = 0; i1 < ne; ++i1) {
      for (int i2 = 0; i2 < ne; ++i2) {
        for (int j1 = 0; j1 < nd; ++j1) {
          for (int j2 = 0; j2 < nd; ++j2) {
            const double e1 = i1 == 0 ? 1.0 : -1.0, e2 = i2 == 0 ? 1.0 : -1.0;
            const double d1 = j1 == 0 ? 1.0 : -1.0, d2 = j2 == 0 ? 1.0 : -1.0;
            const Vec3 f_c = force * a + (out.transverse ? transverse * (e1 * out.t1 + e2 * out.t2)
                                                         : Vec3::Zero().eval());
            const Vec3 p_c =
                mating->p_WContact +
                (out.offset ? mating->offset_m * (d1 * out.t1 + d2 * out.t2) : Vec3::Zero().eval());
            const std::size_t base = w.size();
            w.insert(w.end(), gravity.begin(), gravity.end());
            double* wb = &w[base + static_cast<std::size_t>(mating->base) * 6];
            AddForce(wb, f_c, p_c - p_WO, 1.0);
            for (int i = 0; i < 3; ++i) wb[3 + i] += m_c[i];
            if (mating->moved >= 0) {
              double* wm = &w[base + static_cast<std::size_t>(mating->moved) * 6];
              AddForce(wm, f_c, p_c - p_WO, -1.0);
              for (int i = 0; i < 3; ++i) wm[3 + i] -= m_c[i];
            }
            out.signs.push_back({static_cast<std::int8_t>(e1), static_cast<std::int8_t>(e2),
                                 static_cast<std::int8_t>(d1), static_cast<std::int8_t>(d2)});
          }
        }
      }
    }
  } else if (transport_on) {
    out.kind = VertexKind::kTransport;
    const double A = query.accel_margin_mps2;
    const std::vector<double> gravity = w;
    w.clear();
    for (int sx = 0; sx < 2; ++sx) {
      for (int sy = 0; sy < 2; ++sy) {
        for (int sz = 0; sz < 2; ++sz) {
          const Vec3 sign(sx == 0 ? 1.0 : -1.0, sy == 0 ? 1.0 : -1.0, sz == 0 ? 1.0 : -1.0);
          const Vec3 accel = A * sign;
          const std::size_t base = w.size();
          w.insert(w.end(), gravity.begin(), gravity.end());
          for (int k = 0; k < nb; ++k) {
            const WrenchBody& b = config.bodies[k];
            AddForce(&w[base + static_cast<std::size_t>(k) * 6], -b.mass_kg * accel,
                     b.p_WBcm - p_WO, 1.0);
          }
          out.signs.push_back({static_cast<std::int8_t>(sign.x()),
                               static_cast<std::int8_t>(sign.y()),
                               static_cast<std::int8_t>(sign.z()), 0});
        }
      }
    }
  } else {
    out.kind = VertexKind::kGravity;
    out.signs.push_back({0, 0, 0, 0});
  }
  out.count = static_cast<int>(out.signs.size());
}

std::string VertexLabel(const VertexSet& set, int v) {
  const auto& s = set.signs[v];
  switch (set.kind) {
    case VertexKind::kGravity:
      return "gravity";
    case VertexKind::kTransport:
      return "accel " + DirectionName(s[0] * Vec3::UnitX()) + " " +
             DirectionName(s[1] * Vec3::UnitY()) + " " + DirectionName(s[2] * Vec3::UnitZ());
    case VertexKind::kMating: {
      if (!set.transverse && !set.offset) return "nominal";
      std::string label;
      if (set.transverse) {
        label = "transverse " + DirectionName(s[0] * set.t1) + " " + DirectionName(s[1] * set.t2);
      }
      if (set.offset) {
        if (!label.empty()) label += ", ";
        label += "offset " + DirectionName(s[2] * set.t1) + " " + DirectionName(s[3] * set.t2);
      }
      return label;
    }
  }
  return "";
}

}  // namespace wrap::detail
