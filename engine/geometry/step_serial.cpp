// A StepAssembly as bytes and back (see detail/step_serial.h).
#include "geometry/detail/step_serial.h"

#include <bit>
#include <cstring>
#include <utility>

namespace wrap::detail {

namespace {

constexpr char kMagic[8] = {'W', 'R', 'A', 'P', 'S', 'T', 'E', 'P'};

uint64_t Mix(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdull;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ull;
  return x ^ (x >> 33);
}

}  // namespace

Digest HashBytes(std::string_view bytes) {
  uint64_t fnv = 0xcbf29ce484222325ull;
  for (const char c : bytes) fnv = (fnv ^ static_cast<unsigned char>(c)) * 0x100000001b3ull;
  uint64_t h = 0x9E3779B97F4A7C15ull ^ bytes.size();
  size_t i = 0;
  for (; i + 8 <= bytes.size(); i += 8) {
    uint64_t w = 0;
    std::memcpy(&w, bytes.data() + i, 8);
    h = std::rotl(h ^ (w * 0x87c37b91114253d5ull), 31) * 0x4cf5ad432745937full;
  }
  uint64_t last = 0;
  std::memcpy(&last, bytes.data() + i, bytes.size() - i);
  h = std::rotl(h ^ (last * 0x87c37b91114253d5ull), 31) * 0x4cf5ad432745937full;
  return {Mix(fnv ^ bytes.size()), Mix(h)};
}

std::string Hex16(uint64_t v) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, v >>= 4) s[static_cast<size_t>(i)] = kDigits[v & 15];
  return s;
}

namespace {

// ---- The layout: host byte order, checked by a trailing digest ----------------------------------

class Writer {
 public:
  template <typename T>
  void Put(const T& v) {
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void Put(const std::string& s) {
    Put(static_cast<uint64_t>(s.size()));
    out_ += s;
  }
  std::string& bytes() { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  template <typename T>
  bool Get(T& v) {
    if (in_.size() < sizeof(T)) return false;
    std::memcpy(&v, in_.data(), sizeof(T));
    in_.remove_prefix(sizeof(T));
    return true;
  }
  bool Get(std::string& s) {
    uint64_t n = 0;
    if (!Get(n) || n > in_.size()) return false;
    s.assign(in_.substr(0, n));
    in_.remove_prefix(n);
    return true;
  }
  /// A count of items of at least `item_bytes` each that the rest can hold.
  bool Count(uint64_t& n, size_t item_bytes) { return Get(n) && n <= in_.size() / item_bytes; }
  bool done() const { return in_.empty(); }

 private:
  std::string_view in_;
};

}  // namespace

std::string SerializeStepAssembly(const StepAssembly& a, const std::string& key) {
  Writer w;
  for (const char c : kMagic) w.Put(c);
  w.Put(kStepFormatVersion);
  w.Put(key);
  w.Put(a.unit);
  w.Put(static_cast<uint64_t>(a.solids.size()));
  for (const StepSolid& s : a.solids) {
    w.Put(s.name);
    w.Put(s.product);
    w.Put(s.entity);
    w.Put(static_cast<uint64_t>(s.mesh.vertices.size()));
    for (const Vec3& v : s.mesh.vertices) w.Put(v.x()), w.Put(v.y()), w.Put(v.z());
    w.Put(static_cast<uint64_t>(s.mesh.triangles.size()));
    for (const auto& t : s.mesh.triangles) w.Put(t[0]), w.Put(t[1]), w.Put(t[2]);
  }
  w.Put(static_cast<uint64_t>(a.instances.size()));
  for (const StepInstance& inst : a.instances) {
    w.Put(inst.name);
    w.Put(static_cast<int32_t>(inst.solid));
    const auto& m = inst.X_AS.matrix();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) w.Put(m(r, c));
    }
    w.Put(static_cast<uint8_t>(inst.color.has_value()));
    for (double v : inst.color.value_or(std::array<double, 4>{})) w.Put(v);
  }
  w.Put(static_cast<uint64_t>(a.warnings.size()));
  for (const std::string& s : a.warnings) w.Put(s);
  const Digest d = HashBytes(w.bytes());
  w.Put(d.a);
  w.Put(d.b);
  return std::move(w.bytes());
}

/// The assembly in `bytes`, or nothing when they are not a complete, intact entry for `key`.
std::optional<StepAssembly> DeserializeStepAssembly(std::string_view bytes,
                                                    const std::string& key) {
  if (bytes.size() < 16 + sizeof(kMagic)) return std::nullopt;
  Digest stored;
  std::memcpy(&stored.a, bytes.data() + bytes.size() - 16, 8);
  std::memcpy(&stored.b, bytes.data() + bytes.size() - 8, 8);
  bytes.remove_suffix(16);
  if (!(HashBytes(bytes) == stored)) return std::nullopt;
  Reader r(bytes);
  char magic[sizeof(kMagic)];
  for (char& c : magic) r.Get(c);
  uint32_t version = 0;
  std::string stored_key;
  if (std::memcmp(magic, kMagic, sizeof(kMagic)) != 0 || !r.Get(version) ||
      version != kStepFormatVersion || !r.Get(stored_key) || stored_key != key) {
    return std::nullopt;
  }
  StepAssembly a;
  uint64_t n = 0;
  if (!r.Get(a.unit) || !r.Count(n, 40)) return std::nullopt;
  a.solids.resize(n);
  for (StepSolid& s : a.solids) {
    uint64_t nv = 0, nt = 0;
    if (!r.Get(s.name) || !r.Get(s.product) || !r.Get(s.entity) || !r.Count(nv, 24)) {
      return std::nullopt;
    }
    s.mesh.vertices.resize(nv);
    for (Vec3& v : s.mesh.vertices) {
      if (!r.Get(v.x()) || !r.Get(v.y()) || !r.Get(v.z())) return std::nullopt;
    }
    if (!r.Count(nt, 12)) return std::nullopt;
    s.mesh.triangles.resize(nt);
    for (auto& t : s.mesh.triangles) {
      if (!r.Get(t[0]) || !r.Get(t[1]) || !r.Get(t[2])) return std::nullopt;
      if (t.minCoeff() < 0 || static_cast<uint64_t>(t.maxCoeff()) >= nv) return std::nullopt;
    }
  }
  if (!r.Count(n, 8 + 4 + 96 + 1 + 32)) return std::nullopt;
  a.instances.resize(n);
  for (StepInstance& inst : a.instances) {
    int32_t solid = -1;
    if (!r.Get(inst.name) || !r.Get(solid) || solid < 0 ||
        static_cast<size_t>(solid) >= a.solids.size()) {
      return std::nullopt;
    }
    inst.solid = solid;
    Eigen::Matrix<double, 3, 4> m;
    for (int row = 0; row < 3; ++row) {
      for (int c = 0; c < 4; ++c) {
        if (!r.Get(m(row, c))) return std::nullopt;
      }
    }
    inst.X_AS.linear() = m.leftCols<3>();
    inst.X_AS.translation() = m.col(3);
    uint8_t has_color = 0;
    std::array<double, 4> color{};
    if (!r.Get(has_color)) return std::nullopt;
    for (double& v : color) {
      if (!r.Get(v)) return std::nullopt;
    }
    if (has_color) inst.color = color;
  }
  if (!r.Count(n, 8)) return std::nullopt;
  a.warnings.resize(n);
  for (std::string& s : a.warnings) {
    if (!r.Get(s)) return std::nullopt;
  }
  if (!r.done()) return std::nullopt;
  return a;
}

}  // namespace wrap::detail
