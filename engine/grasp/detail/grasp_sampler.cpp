#include "grasp/detail/grasp_sampler.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace wrap::detail {

namespace {

constexpr int kStopCheckEvery = 16;  // samples between ShouldStop() checks (~1 ms)
constexpr double kSelfHit = 1e-6;    // rays ignore hits nearer than this [m]
constexpr int kMaxApproaches = 64;   // approach directions per contact pair, at most

// A unit vector at angle `angle` from `axis`, rotated by `phase` about it.
Vec3 Tilted(const Vec3& axis, double angle, double phase) {
  const Vec3 u = axis.unitOrthogonal();
  const Vec3 v = axis.cross(u);
  return std::cos(angle) * axis + std::sin(angle) * (std::cos(phase) * u + std::sin(phase) * v);
}

// One planar patch of a mesh: triangles sharing a plane (normals within ~1 degree, offsets
// within `tol`), its area-weighted centroid and area.
struct PlanarPatch {
  Vec3 centroid = Vec3::Zero();
  Vec3 normal = Vec3::Zero();
  double area = 0.0;
};

// The planar patches of at least `min_area`, largest first. Where an engineer would put a cup:
// at the middle of a flat face (on a symmetric part, on the line through its centre of mass).
std::vector<PlanarPatch> PlanarPatches(const MeshQuery& part, double tol, double min_area) {
  const TriangleMesh& mesh = part.mesh();
  std::vector<PlanarPatch> patches;
  std::vector<double> offsets;
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    const Vec3& n = part.normal(t);
    if (n.squaredNorm() < 0.5) continue;  // Degenerate.
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const Vec3& a = mesh.vertices[tri[0]];
    const Vec3& b = mesh.vertices[tri[1]];
    const Vec3& c = mesh.vertices[tri[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    const double offset = n.dot(a);
    int found = -1;
    for (int k = 0; k < static_cast<int>(patches.size()) && found < 0; ++k) {
      if (patches[k].normal.dot(n) > 0.99985 && std::abs(offsets[k] - offset) <= tol) found = k;
    }
    if (found < 0) {
      patches.push_back({Vec3::Zero(), n, 0.0});
      offsets.push_back(offset);
      found = static_cast<int>(patches.size()) - 1;
    }
    PlanarPatch& p = patches[found];
    p.centroid += area * (a + b + c) / 3.0;
    p.area += area;
  }
  std::vector<PlanarPatch> out;
  for (PlanarPatch& p : patches) {
    if (p.area < min_area || p.area <= 0.0) continue;
    p.centroid /= p.area;
    out.push_back(p);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const PlanarPatch& a, const PlanarPatch& b) { return a.area > b.area; });
  return out;
}

double AngleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// How much of a finger pad touches the part: rays across the pad rectangle (centre `c`, width
// axis e_w, length axis e_l) toward the part along `in`. The pad settles on the most protruding
// point; points within `tol` of it touch. Returns the touching area [m^2] and the extents of the
// touching rays' cells across the width and along the length, or area -1 when the pad cannot
// reach the contact: something protrudes more than `tol` in front of it, or the ray starts
// inside material. Returns area 0 early once fewer than `min_hits` rays can touch.
PadPatch PadContact(const MeshQuery& part, const Vec3& c, const Vec3& in, const Vec3& e_w,
                    const Vec3& e_l, double width, double length, double tol, double back,
                    int rays_w, int rays_l, int min_hits) {
  double s_min = std::numeric_limits<double>::infinity();
  double s[64];
  int n = 0, hits = 0, misses = 0;
  const int total = rays_w * rays_l;
  for (int i = 0; i < rays_w; ++i) {
    for (int j = 0; j < rays_l; ++j) {
      const Vec3 g = c + e_w * (width * ((i + 0.5) / rays_w - 0.5)) +
                     e_l * (length * ((j + 0.5) / rays_l - 0.5));
      const auto hit = part.Cast(g - back * in, in, 0.0, back + tol);
      double depth = std::numeric_limits<double>::infinity();
      if (hit) {
        if (part.normal(hit->triangle).dot(in) > 0.0) return {-1.0};  // started inside material
        depth = hit->t - back;
        if (depth < -tol) return {-1.0};
        s_min = std::min(s_min, depth);
        ++hits;
      } else if (++misses > total - min_hits) {
        return {0.0};
      }
      if (n < 64) s[n++] = depth;
    }
  }
  if (hits == 0) return {0.0};
  int touching = 0;
  int i_lo = rays_w, i_hi = -1, j_lo = rays_l, j_hi = -1;
  for (int k = 0; k < n; ++k) {
    if (s[k] > s_min + tol) continue;
    ++touching;
    const int i = k / rays_l, j = k % rays_l;
    i_lo = std::min(i_lo, i);
    i_hi = std::max(i_hi, i);
    j_lo = std::min(j_lo, j);
    j_hi = std::max(j_hi, j);
  }
  PadPatch patch;
  patch.area_m2 = width * length * touching / (rays_w * rays_l);
  patch.width_m = touching > 0 ? width * (i_hi - i_lo + 1) / rays_w : 0.0;
  patch.length_m = touching > 0 ? length * (j_hi - j_lo + 1) / rays_l : 0.0;
  return patch;
}

// The smaller of two pads' patches, extent by extent.
PadPatch Smaller(const PadPatch& a, const PadPatch& b) {
  return {std::min(a.area_m2, b.area_m2), std::min(a.width_m, b.width_m),
          std::min(a.length_m, b.length_m)};
}

// The rotation whose columns are the images of the TCP axes (closing c_T, approach a_T) in P.
Mat3 FrameFromAxes(const Vec3& c_P, const Vec3& a_P, const Vec3& c_T, const Vec3& a_T) {
  Mat3 P, T;
  P << c_P, a_P, c_P.cross(a_P);
  T << c_T, a_T, c_T.cross(a_T);
  return P * T.transpose();
}

}  // namespace

namespace {

// One pad placement along the approach tried per approach direction: how far the pads are
// pulled back from being centred on the contacts, and the type a grasp found there gets.
struct PadDepth {
  double shift = 0.0;
  GraspType type = GraspType::kFullPad;
  // The smaller pad's contact must be below this [m^2] (a partial-pad grasp: less than full).
  double max_area = std::numeric_limits<double>::infinity();
};

// What distinguishes the full-pad pass from the reduced one.
struct TwoFingerPass {
  int rays_w = 4, rays_l = 6;
  double min_area = 0.0;  // least contact on each pad [m^2]
  std::array<PadDepth, 3> depths{};
  int num_depths = 0;
  // Try first the approach straight down in the assembly's frame (where it has one about the
  // closing line): a fingertip grasp keeps the gripper above what the part stands in, and a
  // tilted one dips the fingers' corners.
  bool from_above_first = false;
};

std::vector<GraspCandidate> SampleTwoFingerPass(const SamplerInput& in,
                                                const TwoFingerGraspOptions& options,
                                                const TwoFingerPass& pass, GripperCollision& world,
                                                std::mt19937_64& rng, const RunContext& ctx) {
  std::vector<GraspCandidate> out;
  const EndEffector& ee = *in.ee;
  const MeshQuery& part = *in.part;
  const double alpha = std::atan(in.friction);
  const double max_width = ee.stroke_m - 2.0 * options.clearance_m;
  // TCP-frame axes: closing (catalog, in F) and approach (F's z), orthonormalised.
  const Mat3 R_TF = ee.X_FT.linear().transpose();
  const Vec3 a_T = (R_TF * Vec3::UnitZ()).normalized();
  Vec3 c_T = R_TF * ee.fingers.closing_axis_F;
  c_T = (c_T - c_T.dot(a_T) * a_T).normalized();
  const Vec3 pad_T = ee.X_FT.inverse() * ee.pad_center_F;
  const double pad_area = ee.pad_width_m * ee.pad_length_m;
  const double back = options.clearance_m + options.contact_tolerance_m + 2e-3;
  const int rays_w = std::clamp(pass.rays_w, 1, 8);
  const int rays_l = std::clamp(pass.rays_l, 1, 8);
  // Each touching ray stands for 1 / (rays_w rays_l) of the pad.
  const int min_hits =
      pad_area > 0.0
          ? static_cast<int>(std::ceil(pass.min_area / pad_area * rays_w * rays_l - 1e-9))
          : 1;

  for (int sample = 0; sample < in.max_samples && static_cast<int>(out.size()) < in.wanted;
       ++sample) {
    if (sample % kStopCheckEvery == 0 && ctx.ShouldStop()) break;
    int tri = -1;
    const Vec3 p = part.SamplePoint(rng, &tri);
    const Vec3& n_p = part.normal(tri);
    // Closing direction from p into the part, inside half the friction cone about -n_p.
    const Vec3 d =
        Tilted(-n_p, 0.5 * alpha * Uniform01(rng), 2.0 * std::numbers::pi * Uniform01(rng));
    const auto hit = part.Cast(p, d, kSelfHit, max_width + kSelfHit);
    if (!hit) continue;
    const Vec3& n_q = part.normal(hit->triangle);
    if (n_q.dot(d) <= 0.0) continue;  // entered material: not an exit point (broken mesh)
    const double width = hit->t;
    if (width < options.min_width_m || width > max_width) continue;
    const double angle_p = AngleBetween(d, -n_p);
    const double angle_q = AngleBetween(d, n_q);
    if (angle_p > alpha || angle_q > alpha) continue;
    const Vec3 q = p + width * d;
    const Vec3 m = 0.5 * (p + q);

    const double phase0 = 2.0 * std::numbers::pi * Uniform01(rng);
    const int approaches = std::clamp(options.approach_samples, 1, kMaxApproaches - 1);
    // A pad rectangle is symmetric under a half turn: approaches pi apart share pad tests.
    const int period = approaches % 2 == 0 ? approaches / 2 : approaches;
    std::array<std::array<PadPatch, kMaxApproaches>, 3> pad_p, pad_q;
    for (auto* pads : {&pad_p, &pad_q}) {
      for (auto& row : *pads) row.fill(PadPatch{std::numeric_limits<double>::quiet_NaN()});
    }
    // Down in A, in P, across the closing line (k = -1 below); none when nearly along it.
    const Vec3 down_P = in.X_AP.linear().transpose() * -Vec3::UnitZ();
    const Vec3 down_across = down_P - down_P.dot(d) * d;
    const int first = pass.from_above_first && down_across.norm() > 0.5 ? -1 : 0;
    bool found = false;
    for (int k = first; k < approaches && !found; ++k) {
      const Vec3 a = k < 0 ? Vec3(down_across.normalized())
                           : Tilted(d, 0.5 * std::numbers::pi,
                                    phase0 + 2.0 * std::numbers::pi * k / approaches);
      const Vec3 e_w = d.cross(a);
      // Pads: the one at -d pushes p along +d, the one at +d pushes q along -d.
      const int key = k < 0 ? kMaxApproaches - 1 : k % period;
      for (int depth = 0; depth < pass.num_depths; ++depth) {
        const double shift = pass.depths[depth].shift;
        PadPatch& patch_p = pad_p[depth][key];
        if (std::isnan(patch_p.area_m2)) {
          patch_p = PadContact(part, p - shift * a, d, e_w, a, ee.pad_width_m, ee.pad_length_m,
                               options.contact_tolerance_m, back, rays_w, rays_l, min_hits);
        }
        if (patch_p.area_m2 < pass.min_area) continue;
        PadPatch& patch_q = pad_q[depth][key];
        if (std::isnan(patch_q.area_m2)) {
          patch_q = PadContact(part, q - shift * a, -d, e_w, a, ee.pad_width_m, ee.pad_length_m,
                               options.contact_tolerance_m, back, rays_w, rays_l, min_hits);
        }
        if (patch_q.area_m2 < pass.min_area) continue;
        const PadPatch patch = Smaller(patch_p, patch_q);
        if (patch.area_m2 >= pass.depths[depth].max_area) continue;
        Iso3 X_PG = Iso3::Identity();
        X_PG.linear() = FrameFromAxes(d, a, c_T, a_T);
        X_PG.translation() = m - X_PG.linear() * pad_T - shift * a;
        if (world.Collides(in.ee_index, in.X_AP * X_PG, width + 2.0 * options.clearance_m)) {
          continue;
        }
        GraspCandidate c;
        c.grasp.part = in.part_index;
        c.grasp.end_effector = ee.name;
        c.grasp.kind = ee.kind;
        c.grasp.X_PG = X_PG;
        c.grasp.width_m = width;
        c.grasp.contacts_P = {q, p};  // the finger on G's +x (+d) side touches q
        c.grasp.contact_area_m2 = patch.area_m2;
        c.grasp.type = pass.depths[depth].type;
        if (c.grasp.type != GraspType::kFullPad) {
          c.grasp.torque_scale = GraspTorqueScale(patch, options.min_pad_contact_m2, c_T, a_T);
        }
        c.center_P = m;
        c.axis_P = d;
        c.approach_P = a;
        c.slack = alpha > 0.0 ? 1.0 - std::max(angle_p, angle_q) / alpha : 0.0;
        c.pad_fraction = pad_area > 0.0 ? std::min(1.0, c.grasp.contact_area_m2 / pad_area) : 0.0;
        out.push_back(std::move(c));
        found = true;  // one approach per contact pair keeps the candidates spread
      }
    }
  }
  return out;
}

}  // namespace

std::vector<GraspCandidate> SampleTwoFinger(const SamplerInput& in,
                                            const TwoFingerGraspOptions& options,
                                            GripperCollision& world, std::mt19937_64& rng,
                                            const RunContext& ctx) {
  const EndEffector& ee = *in.ee;
  if (ee.stroke_m <= 0.0 || in.part->area() <= 0.0) return {};
  TwoFingerPass pass;
  pass.rays_w = options.pad_rays_width;
  pass.rays_l = options.pad_rays_length;
  pass.min_area = options.min_pad_contact_m2;
  // Two depths per approach: the pads centred on the contacts, and a shallow grasp with the
  // contacts near the fingertips (the tips 3 mm past them), which picks thin parts lying on a
  // table whose top the centred pads would reach into.
  const double shallow = std::max(0.0, 0.5 * ee.pad_length_m - 0.003);
  pass.depths[pass.num_depths++] = {0.0, GraspType::kFullPad};
  if (shallow > 1e-4) pass.depths[pass.num_depths++] = {shallow, GraspType::kFullPad};
  return SampleTwoFingerPass(in, options, pass, world, rng, ctx);
}

std::vector<GraspCandidate> SampleTwoFingerReduced(const SamplerInput& in,
                                                   const TwoFingerGraspOptions& options,
                                                   GripperCollision& world, std::mt19937_64& rng,
                                                   const RunContext& ctx) {
  const EndEffector& ee = *in.ee;
  if (ee.stroke_m <= 0.0 || in.part->area() <= 0.0 || ee.pad_length_m <= 0.0) return {};
  TwoFingerPass pass;
  pass.rays_w = options.reduced_rays_width;
  pass.rays_l = options.reduced_rays_length;
  pass.min_area = options.min_reduced_contact_m2;
  // Pads centred on the contacts touching less than a full pad (partial-pad), then the tips
  // 3 mm past the contacts (the full-pad pass's shallow depth) touching less than a full pad,
  // then the tips `fingertip_reach_m` past them with any contact (fingertip; the full-pad pass
  // does not reach this far forward). Their limits come from the patch either way.
  const double half = 0.5 * ee.pad_length_m;
  pass.depths[pass.num_depths++] = {0.0, GraspType::kPartialPad, options.min_pad_contact_m2};
  pass.depths[pass.num_depths++] = {std::max(0.0, half - 0.003), GraspType::kFingertip,
                                    options.min_pad_contact_m2};
  pass.depths[pass.num_depths++] = {std::max(0.0, half - std::max(0.0, options.fingertip_reach_m)),
                                    GraspType::kFingertip};
  pass.from_above_first = true;
  return SampleTwoFingerPass(in, options, pass, world, rng, ctx);
}

std::vector<GraspCandidate> SampleVacuum(const SamplerInput& in, const VacuumGraspOptions& options,
                                         GripperCollision& world, std::mt19937_64& rng,
                                         const RunContext& ctx) {
  std::vector<GraspCandidate> out;
  const EndEffector& ee = *in.ee;
  const MeshQuery& part = *in.part;
  const double radius = 0.5 * ee.cup_diameter_m;
  if (radius <= 0.0 || part.area() <= 0.0) return out;
  const double tol = options.flatness_tolerance_m;
  const double cos_dev = std::cos(options.max_normal_deviation_rad);
  const double back = tol + 2e-3;
  const int inner = std::clamp(options.inner_ring_points, 0, 64);
  const int rim = std::clamp(options.rim_points, 3, 128);
  const int total = 1 + inner + rim;
  const int needed = static_cast<int>(std::ceil(options.min_support_fraction * total - 1e-9));
  // TCP axes: z into the part along the cup axis; x is free (the cup is round).
  const Mat3 R_TF = ee.X_FT.linear().transpose();
  const Vec3 a_T = (R_TF * Vec3::UnitZ()).normalized();
  const Vec3 x_T = a_T.unitOrthogonal();

  // First the middle of every flat face the cup fits on (a cup centred on a symmetric part's
  // face lies on the line through its centre of mass: no moment while mating, where the paper's
  // assembly box allows none), then points drawn uniformly over the surface.
  const std::vector<PlanarPatch> patches =
      PlanarPatches(part, tol, std::numbers::pi * radius * radius);
  const int n_patches = static_cast<int>(patches.size());
  for (int sample = 0;
       sample < in.max_samples + n_patches && static_cast<int>(out.size()) < in.wanted; ++sample) {
    if (sample % kStopCheckEvery == 0 && ctx.ShouldStop()) break;
    Vec3 p, n;
    if (sample < n_patches) {
      p = patches[sample].centroid;
      n = patches[sample].normal;
    } else {
      int tri = -1;
      p = part.SamplePoint(rng, &tri);
      n = part.normal(tri);
    }
    const Vec3 u = Tilted(n, 0.5 * std::numbers::pi, 2.0 * std::numbers::pi * Uniform01(rng));
    const Vec3 v = n.cross(u);
    // Disc test points: the centre, a ring at r/2 and the rim.
    int supported = 0;
    double worst = 0.0;  // largest deviation as a fraction of what is allowed
    bool blocked = false;
    for (int k = 0; k < total && !blocked; ++k) {
      Vec3 offset = Vec3::Zero();
      if (k > 0) {
        const bool on_rim = k > inner;
        const int idx = on_rim ? k - 1 - inner : k - 1;
        const int count = on_rim ? rim : inner;
        // The rim points lie on a polygon circumscribing the cup: all of it supported on a
        // flat face means the whole disc is.
        const double r = on_rim ? radius / std::cos(std::numbers::pi / count) : 0.5 * radius;
        const double phi = 2.0 * std::numbers::pi * (idx + (on_rim ? 0.0 : 0.5)) / count;
        offset = r * (std::cos(phi) * u + std::sin(phi) * v);
      }
      const auto hit = part.Cast(p + offset + back * n, -n, 0.0, back + tol);
      if (!hit) continue;
      const Vec3& n_hit = part.normal(hit->triangle);
      const double depth = hit->t - back;
      // Material in front of the tangent plane: the cup would sit on it, not on the patch.
      if (n_hit.dot(n) < 0.0 || depth < -tol) {
        blocked = true;
        break;
      }
      const double cos_hit = n_hit.dot(n);
      if (cos_hit < cos_dev) continue;
      ++supported;
      const double angle = std::acos(std::clamp(cos_hit, -1.0, 1.0));
      worst = std::max({worst, std::abs(depth) / tol,
                        options.max_normal_deviation_rad > 0.0
                            ? angle / options.max_normal_deviation_rad
                            : 0.0});
    }
    if (blocked || supported < needed || supported < 1) continue;

    const double yaw0 = 2.0 * std::numbers::pi * Uniform01(rng);
    const int yaws = std::max(1, options.yaw_samples);
    for (int k = 0; k < yaws; ++k) {
      // The gripper body is square: a quarter turn covers every distinct yaw.
      const double yaw = yaw0 + 0.5 * std::numbers::pi * k / yaws;
      const Vec3 x_P = std::cos(yaw) * u + std::sin(yaw) * v;
      Iso3 X_PG = Iso3::Identity();
      X_PG.linear() = FrameFromAxes(x_P, -n, x_T, a_T);
      X_PG.translation() = p;
      Iso3 X_PG_backed = X_PG;
      X_PG_backed.translation() += options.standoff_m * n;
      if (world.Collides(in.ee_index, in.X_AP * X_PG_backed, 0.0)) continue;
      GraspCandidate c;
      c.grasp.part = in.part_index;
      c.grasp.end_effector = ee.name;
      c.grasp.kind = ee.kind;
      c.grasp.X_PG = X_PG;
      c.grasp.contacts_P = {p, p};
      c.grasp.contact_area_m2 = std::numbers::pi * radius * radius;
      c.center_P = p;
      c.axis_P = -n;
      c.approach_P = -n;
      c.slack = std::clamp(1.0 - worst, 0.0, 1.0);
      out.push_back(std::move(c));
      break;
    }
  }
  return out;
}

}  // namespace wrap::detail
