// Canonical encoding and hash of a wrench question (the cache key).
#include <bit>
#include <cstring>
#include <string>

#include "wrench/detail/canonical_key.h"

namespace wrap::detail {
namespace {

class Encoder {
 public:
  explicit Encoder(std::vector<std::uint64_t>& words) : words_(words) { words_.clear(); }
  void Int(std::int64_t v) { words_.push_back(static_cast<std::uint64_t>(v)); }
  void Real(double v) { words_.push_back(std::bit_cast<std::uint64_t>(v == 0.0 ? 0.0 : v)); }
  void Vec(const Vec3& v) {
    Real(v.x());
    Real(v.y());
    Real(v.z());
  }
  void Six(const Vec6& v) {
    for (int i = 0; i < 6; ++i) Real(v[i]);
  }
  void Text(const std::string& s) {
    Int(static_cast<std::int64_t>(s.size()));
    for (std::size_t i = 0; i < s.size(); i += 8) {
      std::uint64_t w = 0;
      std::memcpy(&w, s.data() + i, std::min<std::size_t>(8, s.size() - i));
      words_.push_back(w);
    }
  }
  void Pose(const Iso3& X, const Vec3& p_WO) {
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) Real(X.linear()(r, c));
    }
    Vec(X.translation() - p_WO);
  }
  void Bounds(const WrenchBounds& b) {
    Six(b.lower);
    Six(b.upper);
  }

 private:
  std::vector<std::uint64_t>& words_;
};

std::uint64_t Mix(std::uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return x;
}

}  // namespace

Vec3 ReferencePoint(const StepConfiguration& config) {
  if (config.bodies.empty()) return Vec3::Zero();
  Vec3 sum = Vec3::Zero();
  for (const WrenchBody& b : config.bodies) sum += b.p_WBcm;
  return sum / static_cast<double>(config.bodies.size());
}

void EncodeQuestion(const StepConfiguration& config, const WrenchQuery& query,
                    std::vector<std::uint64_t>& words) {
  const Vec3 p_WO = ReferencePoint(config);
  Encoder e(words);
  e.Int(static_cast<int>(query.gate));
  e.Int(static_cast<int>(query.mode));
  e.Real(query.lambda);
  e.Real(query.accel_margin_mps2);
  e.Vec(config.gravity_W);
  e.Int(static_cast<std::int64_t>(config.bodies.size()));
  for (const WrenchBody& b : config.bodies) {
    e.Text(b.name);
    e.Real(b.mass_kg);
    e.Vec(b.p_WBcm - p_WO);
  }
  e.Int(static_cast<std::int64_t>(config.connections.size()));
  for (const WrenchConnection& c : config.connections) {
    e.Int(c.body_a);
    e.Int(c.body_b);
    e.Pose(c.X_WC, p_WO);
    e.Bounds(c.limits);
    e.Text(c.name);
  }
  e.Int(static_cast<std::int64_t>(config.grippers.size()));
  for (const WrenchGripper& g : config.grippers) {
    e.Text(g.name);
    e.Int(g.body);
    e.Int(static_cast<int>(g.kind));
    e.Pose(g.X_WG, p_WO);
    e.Bounds(g.assembly_limits);
    e.Bounds(g.transport_limits);
  }
  e.Int(static_cast<std::int64_t>(config.tables.size()));
  for (const WrenchTableSupport& t : config.tables) {
    e.Int(t.body);
    e.Real(t.friction);
    e.Int(t.pyramid_edges);
    e.Vec(t.normal_W);
    e.Int(static_cast<std::int64_t>(t.p_WV.size()));
    for (const Vec3& v : t.p_WV) e.Vec(v - p_WO);
  }
  e.Int(config.mating ? 1 : 0);
  if (config.mating) {
    const MatingLoad& m = *config.mating;
    e.Int(m.moved);
    e.Int(m.base);
    e.Vec(m.axis_W);
    e.Vec(m.p_WContact - p_WO);
    e.Real(m.force_N);
    e.Real(m.torque_Nm);
    e.Real(m.transverse_fraction);
    e.Real(m.offset_m);
  }
}

std::uint64_t HashWords(const std::vector<std::uint64_t>& words) {
  // Two independent multiply-rotate lanes (short dependency chains), mixed at the end.
  std::uint64_t h0 = 0x9e3779b97f4a7c15ULL ^ words.size();
  std::uint64_t h1 = 0xc2b2ae3d27d4eb4fULL;
  std::size_t i = 0;
  for (; i + 1 < words.size(); i += 2) {
    h0 = std::rotl((h0 ^ words[i]) * 0x9e3779b97f4a7c15ULL, 31);
    h1 = std::rotl((h1 ^ words[i + 1]) * 0xc2b2ae3d27d4eb4fULL, 29);
  }
  if (i < words.size()) h0 = std::rotl((h0 ^ words[i]) * 0x9e3779b97f4a7c15ULL, 31);
  return Mix(h0 ^ Mix(h1));
}

}  // namespace wrap::detail
