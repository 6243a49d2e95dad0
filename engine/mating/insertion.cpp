#include "mating/insertion.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace wrap {

namespace {

constexpr double kSameAxisCos = 0.99863;  // cos 3 deg
constexpr double kNear_m = 2e-3;          // nearer than this the sweep takes fixed steps
constexpr int kDistanceEvery = 16;        // ... with a distance every so many

// The world whose meshes are inset so that an intersection means more than `allowed` overlap.
CollisionWorld& WorldFor(AssemblyGeometry& g, double allowed_overlap_m) {
  return g.world(0.5 * allowed_overlap_m);
}

// Overlap allowed at `s` back from the mating pose.
double AllowedAt(const InsertionPath& path, double s) {
  const double band = path.interference_travel_m;
  return s <= band + 1e-12 ? std::max(path.interference_depth_m, path.touch_depth_m)
                           : path.touch_depth_m;
}

// Poses the moved parts at `s` in `world` and returns the least distance between the moved and
// the base parts (0 at an overlap, then `hit` names the pair).
double PoseAndMeasure(AssemblyGeometry& g, CollisionWorld& world, const InsertionPath& path,
                      double s, double horizon, PathHit* hit, SweepStats* stats) {
  for (int p : path.moved) world.SetPose(BodyId{p}, PathPose(g, path, p, s));
  for (int p : path.base) world.SetPose(BodyId{p}, g.X_AP(p));
  if (stats) ++stats->poses;
  double least = horizon;
  for (int m : path.moved) {
    if (!g.has_mesh(m)) continue;
    for (int b : path.base) {
      if (!g.has_mesh(b)) continue;
      DistanceRequest request;
      request.nearest_points = false;
      request.upper_bound_m = least;
      const DistanceResult d = world.Distance(BodyId{m}, BodyId{b}, request);
      if (stats) stats->pair_tests += d.narrowphase_tests > 0 ? 1 : 0;
      if (!d.has_pair() || d.distance >= least) continue;
      least = d.distance;
      if (least <= 0.0) {
        hit->blocked = true;
        hit->at_m = s;
        hit->moved_part = m;
        hit->base_part = b;
        return 0.0;
      }
    }
  }
  return least;
}

// Poses the moved parts at `s` and asks FCL whether any moved part overlaps a base part (exact,
// with early exit: cheaper than a distance when the surfaces slide along each other).
bool PoseAndCollide(AssemblyGeometry& g, CollisionWorld& world, const InsertionPath& path,
                    double s, PathHit* hit, SweepStats* stats) {
  for (int p : path.moved) world.SetPose(BodyId{p}, PathPose(g, path, p, s));
  for (int p : path.base) world.SetPose(BodyId{p}, g.X_AP(p));
  if (stats) ++stats->poses;
  for (int m : path.moved) {
    if (!g.has_mesh(m)) continue;
    const Aabb box_m = world.body_aabb(BodyId{m});
    for (int b : path.base) {
      if (!g.has_mesh(b)) continue;
      const Aabb box_b = world.body_aabb(BodyId{b});
      if ((box_m.max.array() < box_b.min.array()).any() ||
          (box_b.max.array() < box_m.min.array()).any()) {
        continue;
      }
      if (stats) ++stats->pair_tests;
      if (world.Collide(BodyId{m}, BodyId{b})) {
        hit->blocked = true;
        hit->at_m = s;
        hit->moved_part = m;
        hit->base_part = b;
        return true;
      }
    }
  }
  return false;
}

// Sweeps s from `from` to `to` (either way), stopping at the first overlap. Far from the base,
// conservative advancement: each step is the distance the meshes are apart. Within kNear_m of
// it (the surfaces sliding along each other), fixed steps of path.min_step_m with FCL's
// collision test, and a distance now and then to see whether the input has got clear.
PathHit Sweep(AssemblyGeometry& g, const InsertionPath& path, double from, double to,
              SweepStats* stats) {
  PathHit hit;
  const double sign = to >= from ? 1.0 : -1.0;
  const double band = path.interference_travel_m;
  double s = from;
  int near_steps = -1;  // fixed steps since the last distance; -1: far
  for (;;) {
    CollisionWorld& world = WorldFor(g, AllowedAt(path, s));
    const double remaining = std::abs(to - s);
    double step = path.min_step_m;
    if (near_steps < 0 || near_steps >= kDistanceEvery) {
      const double d = PoseAndMeasure(g, world, path, s, remaining + 1e-3, &hit, stats);
      if (hit.blocked || remaining <= 0.0) return hit;
      near_steps = d > kNear_m ? -1 : 0;
      step = std::max(d, path.min_step_m);
    } else {
      if (PoseAndCollide(g, world, path, s, &hit, stats) || remaining <= 0.0) return hit;
      ++near_steps;
    }
    // Do not step over the edge of the interference band: the allowance changes there.
    if ((s - band) * (s + sign * step - band) < 0.0) step = std::abs(band - s);
    if (step <= 0.0) step = path.min_step_m;
    s = sign > 0 ? std::min(to, s + step) : std::max(to, s - step);
  }
}

}  // namespace

Iso3 PathPose(const AssemblyGeometry& g, const InsertionPath& path, int part, double s_m) {
  Iso3 X = path.X_BM * g.X_AP(part);
  X.translation() -= s_m * path.axis_A;
  return X;
}

PathHit SweepInsertion(AssemblyGeometry& g, const InsertionPath& path, SweepStats* stats) {
  return Sweep(g, path, std::max(0.0, path.length_m), 0.0, stats);
}

bool IsPathFree(AssemblyGeometry& g, const InsertionPath& path, PathHit* hit, SweepStats* stats) {
  const PathHit h = Sweep(g, path, 0.0, std::max(0.0, path.length_m), stats);
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
                                         const std::vector<int>& set_b,
                                         const std::vector<Iso3>& X, double allowed_m) {
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
