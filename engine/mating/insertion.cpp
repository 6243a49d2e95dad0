#include "mating/insertion.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

namespace wrap {

namespace {

constexpr double kSameAxisCos = 0.99863;  // cos 3 deg
// The far range starts this much beyond the interference band: a contact exactly at its edge
// belongs to the band [m].
constexpr double kBandEdge_m = 1e-9;

// The world whose meshes are inset so that an intersection means more than `allowed` overlap.
CollisionWorld& WorldFor(AssemblyGeometry& g, double allowed_overlap_m) {
  return g.world(0.5 * allowed_overlap_m);
}

// The first (or, with `last`, the last) s in [s_lo, s_hi] at which the moved parts, on their
// meshes inset by half of `allowed_m`, meet the base parts: one exact sweep per pair of parts
// (SweepContact), each bounded by the best contact found before it.
PathHit SweepRange(AssemblyGeometry& g, const InsertionPath& path, double allowed_m, double s_lo,
                   double s_hi, bool last, SweepStats* stats) {
  PathHit hit;
  if (!(s_lo <= s_hi)) return hit;
  const double inset = 0.5 * allowed_m;
  // The moved input at s is at its mating pose moved by -s along the axis: t = s, d = -axis.
  SweepQuery query;
  query.d_F = -path.axis_A;
  query.t_min = s_lo;
  query.t_max = s_hi;
  query.last = last;
  const bool in_place = path.X_BM.matrix() == Iso3::Identity().matrix();
  SweepContactStats work;
  for (int m : path.moved) {
    if (!g.has_mesh(m)) continue;
    // The cached tree is at the assembled pose; another final pose needs its own.
    std::optional<SweepMesh> own;
    if (!in_place) own.emplace(g.inset_mesh(m, inset), path.X_BM * g.X_AP(m));
    const SweepMesh& moving = in_place ? g.sweep_mesh(m, inset) : *own;
    for (int b : path.base) {
      if (!g.has_mesh(b)) continue;
      if (stats) ++stats->part_pairs;
      const auto c = SweepContact(moving, g.sweep_mesh(b, inset), query, &work);
      if (!c) continue;
      if (hit.blocked && (last ? c->t <= hit.at_m : c->t >= hit.at_m)) continue;
      hit.blocked = true;
      hit.at_m = c->t;
      hit.moved_part = m;
      hit.base_part = b;
      (last ? query.t_min : query.t_max) = c->t;
    }
  }
  if (stats) {
    stats->box_tests += work.box_tests;
    stats->triangle_tests += work.triangle_tests;
  }
  return hit;
}

// The path's contact nearest the start (`last`: coming in from length_m, the largest s) or
// nearest the mating pose (the smallest s). The last interference_travel_m before the mating pose
// allow the band's overlap, the rest touch_depth_m: two inset meshes over two ranges of s.
PathHit Sweep(AssemblyGeometry& g, const InsertionPath& path, bool last, SweepStats* stats) {
  const double length = std::max(0.0, path.length_m);
  const double band = std::clamp(path.interference_travel_m, 0.0, length);
  const double band_allowed = AllowedOverlap(path.interference_travel_m, path.interference_depth_m,
                                             path.touch_depth_m, 0.0);
  if (band_allowed == path.touch_depth_m) {
    return SweepRange(g, path, band_allowed, 0.0, length, last, stats);
  }
  const auto near = [&] { return SweepRange(g, path, band_allowed, 0.0, band, last, stats); };
  const auto far = [&] {
    return SweepRange(g, path, path.touch_depth_m, band + kBandEdge_m, length, last, stats);
  };
  const PathHit first = last ? far() : near();
  return first.blocked ? first : (last ? near() : far());
}

}  // namespace

double AllowedOverlap(double interference_travel_m, double interference_depth_m,
                      double touch_depth_m, double s_m) {
  return s_m <= interference_travel_m + 1e-9 ? std::max(interference_depth_m, touch_depth_m)
                                             : touch_depth_m;
}

Iso3 PathPose(const AssemblyGeometry& g, const InsertionPath& path, int part, double s_m) {
  Iso3 X = path.X_BM * g.X_AP(part);
  X.translation() -= s_m * path.axis_A;
  return X;
}

PathHit SweepInsertion(AssemblyGeometry& g, const InsertionPath& path, SweepStats* stats) {
  return Sweep(g, path, true, stats);
}

bool IsPathFree(AssemblyGeometry& g, const InsertionPath& path, PathHit* hit, SweepStats* stats) {
  const PathHit h = Sweep(g, path, false, stats);
  if (hit) *hit = h;
  return !h.blocked;
}

std::vector<Vec3> CandidateAxes(const ContactGraph& contacts, const std::vector<int>& moved,
                                const std::vector<int>& base, int sphere) {
  std::vector<Vec3> out;
  auto add = [&](const Vec3& d) {
    if (!(d.norm() > 0.0)) return;
    const Vec3 u = d.normalized();
    for (const Vec3& e : out) {
      if (e.dot(u) >= kSameAxisCos) return;
    }
    out.push_back(u);
  };
  for (int a = 0; a < 3; ++a) {
    add(-Vec3::Unit(a));
    add(Vec3::Unit(a));
  }
  // The moved input leaves the base along a contact normal out of the base, so it comes in
  // against it.
  for (int m : moved) {
    for (int b : base) {
      const Contact* c = contacts.Find(m, b);
      if (!c) continue;
      for (const ContactNormal& n : c->normals) add(c->a == m ? -n.n_A : Vec3(n.n_A));
    }
  }
  // A Fibonacci sphere: even spread, the same every time.
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < sphere; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / sphere;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    add(Vec3(r * std::cos(golden * i), r * std::sin(golden * i), z));
  }
  return out;
}

std::vector<Vec3> FreeAxes(AssemblyGeometry& g, InsertionPath path,
                           const std::vector<Vec3>& candidates, SweepStats* stats) {
  std::vector<Vec3> out;
  for (const Vec3& axis : candidates) {
    path.axis_A = axis;
    if (IsPathFree(g, path, nullptr, stats)) out.push_back(axis);
  }
  return out;
}

std::optional<PartOverlap> OverlapBeyond(AssemblyGeometry& g, const std::vector<int>& set_a,
                                         const std::vector<int>& set_b, const std::vector<Iso3>& X,
                                         double allowed_m) {
  CollisionWorld& world = WorldFor(g, allowed_m);
  for (int p : set_a) world.SetPose(BodyId{p}, X[p]);
  for (int p : set_b) world.SetPose(BodyId{p}, X[p]);
  for (int a : set_a) {
    if (!g.has_mesh(a)) continue;
    for (int b : set_b) {
      if (!g.has_mesh(b) || a == b) continue;
      if (world.Collide(BodyId{a}, BodyId{b})) return PartOverlap{a, b};
    }
  }
  return std::nullopt;
}

double AxisPreference(const Vec3& axis) {
  const double down = -axis.z();
  const bool aligned = axis.cwiseAbs().maxCoeff() > 0.999;
  return (down > 0.5 ? 2.0 : down > -0.5 ? 1.0 : 0.0) + (aligned ? 0.5 : 0.0) + 0.1 * down;
}

std::string FormatDirection(const Vec3& d) {
  std::string out = "[";
  for (int i = 0; i < 3; ++i) {
    double v = std::round(d[i] * 100.0) / 100.0;
    if (v == 0.0) v = 0.0;  // no "-0"
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    out += (i ? ", " : "") + std::string(buf);
  }
  return out + "]";
}

}  // namespace wrap
