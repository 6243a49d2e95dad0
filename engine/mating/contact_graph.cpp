#include "mating/contact_graph.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace wrap {

namespace {

constexpr double kSameNormalCos = 0.9063;  // cos 25 deg: one face of a contact
constexpr double kMinNormalShare = 0.05;   // normals with less of the area are noise
constexpr double kAreaBand_m = 1e-4;       // surfaces this much farther than the closest count

// Accumulates the samples of one part that lie near the other.
struct ContactSamples {
  int count = 0;
  double area = 0.0;  // area each sample stands for, summed
  Vec3 sum = Vec3::Zero();
  Aabb box{Vec3::Constant(std::numeric_limits<double>::infinity()),
           Vec3::Constant(-std::numeric_limits<double>::infinity())};
  std::vector<ContactNormal> normals;

  void Add(const Vec3& p_A, const Vec3& n_A, double area_each) {
    ++count;
    area += area_each;
    sum += p_A;
    box.min = box.min.cwiseMin(p_A);
    box.max = box.max.cwiseMax(p_A);
    for (ContactNormal& c : normals) {
      if (c.n_A.normalized().dot(n_A) >= kSameNormalCos) {
        c.n_A += area_each * n_A;
        c.area_m2 += area_each;
        return;
      }
    }
    normals.push_back({area_each * n_A, area_each});
  }
};

// The samples of part `from` within `tol` of part `to`; normals out of `b` into `a` (sign +1 when
// `to` is b, -1 when `to` is a).
void SampleNear(AssemblyGeometry& g, int from, int to, double tol, double sign,
                ContactSamples& out) {
  const std::vector<Vec3>& samples = g.samples(from);
  if (samples.empty()) return;
  const MeshQuery& target = g.query(to);
  const double area_each = g.query(from).area() / static_cast<double>(samples.size());
  const Iso3 X_TF = g.X_AP(to).inverse() * g.X_AP(from);  // `from` frame into `to` frame
  const Mat3& R_AT = g.X_AP(to).linear();
  for (const Vec3& s : samples) {
    const Vec3 p_T = X_TF * s;
    const std::optional<ClosestPoint> c = target.Closest(p_T, tol);
    if (!c) continue;
    const Vec3 n_A = sign * (R_AT * target.normal(c->triangle));
    if (n_A.squaredNorm() == 0.0) continue;
    out.Add(g.X_AP(to) * c->point, n_A, area_each);
  }
}

Contact Summarise(int a, int b, double distance, const ContactSamples& from_a,
                  const ContactSamples& from_b) {
  Contact c;
  c.a = a;
  c.b = b;
  c.distance_m = distance;
  const int n = from_a.count + from_b.count;
  // Each side sees the contact's area once: their mean estimates it.
  const int sides = (from_a.count > 0 ? 1 : 0) + (from_b.count > 0 ? 1 : 0);
  c.area_m2 = sides > 0 ? (from_a.area + from_b.area) / sides : 0.0;
  if (n > 0) {
    c.centroid_A = (from_a.sum + from_b.sum) / n;
    c.extent_A.min = from_a.box.min.cwiseMin(from_b.box.min);
    c.extent_A.max = from_a.box.max.cwiseMax(from_b.box.max);
  }
  ContactSamples merged;
  for (const ContactSamples* side : {&from_a, &from_b}) {
    for (const ContactNormal& cn : side->normals) {
      const double w = sides > 0 ? cn.area_m2 / sides : 0.0;
      const Vec3 dir = cn.n_A.normalized();
      bool found = false;
      for (ContactNormal& m : merged.normals) {
        if (m.n_A.normalized().dot(dir) >= kSameNormalCos) {
          m.n_A += w * dir;
          m.area_m2 += w;
          found = true;
          break;
        }
      }
      if (!found) merged.normals.push_back({w * dir, w});
    }
  }
  double total = 0.0;
  for (const ContactNormal& m : merged.normals) total += m.area_m2;
  for (const ContactNormal& m : merged.normals) {
    if (total > 0.0 && m.area_m2 >= kMinNormalShare * total) {
      c.normals.push_back({m.n_A.normalized(), m.area_m2});
    }
  }
  std::sort(c.normals.begin(), c.normals.end(),
            [](const ContactNormal& x, const ContactNormal& y) { return x.area_m2 > y.area_m2; });
  return c;
}

}  // namespace

const Contact* ContactGraph::Find(int p, int q) const {
  const int a = std::min(p, q), b = std::max(p, q);
  for (const Contact& c : contacts) {
    if (c.a == a && c.b == b) return &c;
  }
  return nullptr;
}

std::vector<int> ContactGraph::Neighbours(int p) const {
  std::vector<int> out;
  for (const Contact& c : contacts) {
    if (c.a == p) out.push_back(c.b);
    if (c.b == p) out.push_back(c.a);
  }
  std::sort(out.begin(), out.end());
  return out;
}

ContactGraph ComputeContactGraph(AssemblyGeometry& g, const ContactOptions& options) {
  ContactGraph graph;
  graph.tolerance_m = options.tolerance_m;
  CollisionWorld& world = g.world(0.0);
  const int n = g.num_parts();
  for (int p = 0; p < n; ++p) world.SetPose(BodyId{p}, g.X_AP(p));
  for (int a = 0; a < n; ++a) {
    if (!g.has_mesh(a)) continue;
    for (int b = a + 1; b < n; ++b) {
      if (!g.has_mesh(b)) continue;
      DistanceRequest request;
      request.nearest_points = false;
      request.upper_bound_m = options.tolerance_m;
      const DistanceResult d = world.Distance(BodyId{a}, BodyId{b}, request);
      if (!d.has_pair() || d.distance > options.tolerance_m) continue;
      // The contact's surface: samples within a thin band over the closest distance (the whole
      // tolerance would add a strip along every edge of the contact).
      const double band = std::min(options.tolerance_m, d.distance + kAreaBand_m);
      ContactSamples from_a, from_b;
      SampleNear(g, a, b, band, +1.0, from_a);
      SampleNear(g, b, a, band, -1.0, from_b);
      graph.contacts.push_back(Summarise(a, b, d.distance, from_a, from_b));
    }
  }
  return graph;
}

SetDistance DistanceBetween(AssemblyGeometry& g, const std::vector<int>& parts_a,
                            const std::vector<int>& parts_b) {
  SetDistance out;
  out.distance_m = std::numeric_limits<double>::infinity();
  CollisionWorld& world = g.world(0.0);
  for (int p : parts_a) world.SetPose(BodyId{p}, g.X_AP(p));
  for (int p : parts_b) world.SetPose(BodyId{p}, g.X_AP(p));
  for (int a : parts_a) {
    for (int b : parts_b) {
      if (!g.has_mesh(a) || !g.has_mesh(b)) continue;
      DistanceRequest request;
      request.nearest_points = false;
      request.upper_bound_m = out.distance_m;
      const DistanceResult d = world.Distance(BodyId{a}, BodyId{b}, request);
      if (d.has_pair() && d.distance < out.distance_m) {
        out.distance_m = d.distance;
        out.part_a = a;
        out.part_b = b;
      }
    }
  }
  return out;
}

}  // namespace wrap
