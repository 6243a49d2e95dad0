// The collision world and its bodies: body and shape bookkeeping, adding bodies, poses, the
// enabled flags and the allowed-pair filter, the bodies' world bounds, and descriptions of a
// pair for messages. The queries are in collision_query.cpp (collision) and distance_query.cpp
// (distance), the shape-pair tests in collision_narrowphase.cpp, shape construction and the
// mesh-tree cache in collision_shapes.cpp; notes on FCL 0.7 behaviour that these files work
// around are next to the code that does it (and in ../shared/STACK.md).
#include "robot/collision.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <source_location>
#include <sstream>
#include <utility>

#include "robot/detail/collision_impl.h"

namespace wrap {

namespace detail {

void CollisionFatal(const char* what, const std::source_location& loc) {
  std::fprintf(stderr, "%s:%u: collision world: %s\n", loc.file_name(),
               static_cast<unsigned>(loc.line()), what);
  std::abort();
}

}  // namespace detail

namespace {

using detail::BodyData;
using detail::CollisionCheck;
using detail::ShapeData;
using detail::ShapeKind;

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string PoseText(const Iso3& X) {
  const Vec3 p = X.translation();
  const Vec3 rpy = RpyFromRotation(X.linear());
  char buf[200];
  std::snprintf(buf, sizeof(buf), "xyz=(%.10g, %.10g, %.10g) rpy=(%.10g, %.10g, %.10g)", p.x(),
                p.y(), p.z(), rpy.x(), rpy.y(), rpy.z());
  return buf;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// GroupPairSet

void GroupPairSet::Add(int g, int h) {
  CollisionCheck(g >= 0 && g < kMaxCollisionGroups && h >= 0 && h < kMaxCollisionGroups,
                 "group id out of range");
  rows_[g] |= std::uint64_t{1} << h;
  rows_[h] |= std::uint64_t{1} << g;
}

void GroupPairSet::Remove(int g, int h) {
  CollisionCheck(g >= 0 && g < kMaxCollisionGroups && h >= 0 && h < kMaxCollisionGroups,
                 "group id out of range");
  rows_[g] &= ~(std::uint64_t{1} << h);
  rows_[h] &= ~(std::uint64_t{1} << g);
}

bool GroupPairSet::Contains(int g, int h) const {
  if (g < 0 || g >= kMaxCollisionGroups || h < 0 || h >= kMaxCollisionGroups) return false;
  return (rows_[g] >> h) & 1u;
}

bool GroupPairSet::empty() const {
  return std::all_of(rows_.begin(), rows_.end(), [](std::uint64_t r) { return r == 0; });
}

void CollisionResult::Clear() {
  collision = false;
  first = ShapePair{};
  pairs.clear();
  narrowphase_tests = 0;
}

// ---------------------------------------------------------------------------------------------
// Bounds

void CollisionWorld::Impl::UpdateShape(ShapeData& s, const Iso3& X_WB) {
  switch (s.kind) {
    case ShapeKind::kSwept:
      s.pose_stale = true;
      s.a_W = X_WB * s.a_B;
      s.b_W = X_WB * s.b_B;
      s.lo = s.a_W.cwiseMin(s.b_W).array() - s.radius;
      s.hi = s.a_W.cwiseMax(s.b_W).array() + s.radius;
      return;
    case ShapeKind::kConvex:
      if (s.type == Shape::Type::kCylinder) {
        // Exact box of a cylinder: the caps' discs reach r * sqrt(1 - u_k^2) along axis k.
        s.pose_stale = true;
        s.a_W = X_WB * s.a_B;
        s.b_W = X_WB * s.b_B;
        const Vec3 u = (s.b_W - s.a_W).normalized();
        const Vec3 ext = s.radius * (Vec3::Ones() - u.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
        s.lo = s.a_W.cwiseMin(s.b_W) - ext;
        s.hi = s.a_W.cwiseMax(s.b_W) + ext;
        return;
      }
      [[fallthrough]];
    case ShapeKind::kMesh: {
      s.X_WS = X_WB * s.X_BS;
      s.pose_stale = false;
      const Vec3 c = s.X_WS * s.c_S;
      const Vec3 h = s.X_WS.linear().cwiseAbs() * s.h_S;
      s.lo = c - h;
      s.hi = c + h;
      return;
    }
  }
}

void CollisionWorld::Impl::UpdateBounds() {
  if (!any_dirty) return;
  for (BodyData& b : bodies) {
    if (!b.dirty) continue;
    b.dirty = false;
    if (!b.active()) {
      // Sorts last in the sweep and overlaps nothing.
      b.lo = Vec3::Constant(kInf);
      b.hi = Vec3::Constant(-kInf);
      continue;
    }
    b.lo = Vec3::Constant(kInf);
    b.hi = Vec3::Constant(-kInf);
    for (int k = b.first; k < b.first + b.count; ++k) {
      UpdateShape(shapes[k], b.X_WB);
      b.lo = b.lo.cwiseMin(shapes[k].lo);
      b.hi = b.hi.cwiseMax(shapes[k].hi);
    }
    b.w_W = b.X_WB * shapes[b.first].w_B;
    b.w_r = shapes[b.first].w_r;
  }
  any_dirty = false;
}

void CollisionWorld::Impl::UpdatePair(BodyId a, BodyId b) {
  UpdateBounds();
  for (BodyId id : {a, b}) {
    const BodyData& bd = bodies[id.value];
    if (!bd.active()) {
      for (int k = bd.first; k < bd.first + bd.count; ++k) UpdateShape(shapes[k], bd.X_WB);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// CollisionWorld

CollisionWorld::CollisionWorld() : impl_(std::make_unique<Impl>()) {}
CollisionWorld::~CollisionWorld() = default;
CollisionWorld::CollisionWorld(const CollisionWorld& other)
    : impl_(std::make_unique<Impl>(*other.impl_)) {}
CollisionWorld& CollisionWorld::operator=(const CollisionWorld& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
CollisionWorld::CollisionWorld(CollisionWorld&&) noexcept = default;
CollisionWorld& CollisionWorld::operator=(CollisionWorld&&) noexcept = default;

int CollisionWorld::LiveMeshTrees() { return detail::LiveMeshTreeCount(); }

Result<BodyId> CollisionWorld::AddBody(const BodyDef& def) {
  Impl& m = *impl_;
  const std::string where = "collision world: body '" + def.name + "'";
  if (def.group < 0 || def.group >= kMaxCollisionGroups) {
    return Fail(ErrorCode::kInvalidInput, where + ": group " + std::to_string(def.group) +
                                              " outside [0, " +
                                              std::to_string(kMaxCollisionGroups) + ")");
  }
  if (!def.X_WB.matrix().allFinite()) {
    return Fail(ErrorCode::kInvalidInput, where + ": pose is not finite");
  }
  std::vector<ShapeData> added;
  added.reserve(def.shapes.size());
  for (std::size_t k = 0; k < def.shapes.size(); ++k) {
    Result<ShapeData> s = detail::MakeShapeData(def.shapes[k], k, where);
    if (!s) return std::unexpected(s.error());
    added.push_back(std::move(*s));
  }

  const int id = m.n();
  BodyData b;
  b.name = def.name;
  b.group = def.group;
  b.X_WB = def.X_WB;
  b.first = static_cast<int>(m.shapes.size());
  b.count = static_cast<int>(added.size());
  for (ShapeData& s : added) {
    s.body = id;
    m.shapes.push_back(std::move(s));
  }
  m.bodies.push_back(std::move(b));

  // Grow the symmetric allowed matrix by one row and column.
  const std::size_t n_old = static_cast<std::size_t>(id);
  const std::size_t n_new = n_old + 1;
  std::vector<std::uint8_t> grown(n_new * n_new, 0);
  for (std::size_t r = 0; r < n_old; ++r) {
    std::copy_n(m.allowed.begin() + r * n_old, n_old, grown.begin() + r * n_new);
  }
  m.allowed = std::move(grown);
  m.order.clear();
  m.candidates.reserve(n_new * (n_new - 1) / 2);
  m.any_dirty = true;
  return BodyId{id};
}

int CollisionWorld::num_bodies() const { return impl_->n(); }
const std::string& CollisionWorld::body_name(BodyId body) const { return impl_->body(body).name; }
int CollisionWorld::body_group(BodyId body) const { return impl_->body(body).group; }
int CollisionWorld::num_shapes(BodyId body) const { return impl_->body(body).count; }

const std::string& CollisionWorld::shape_name(BodyId body, int shape) const {
  const BodyData& b = impl_->body(body);
  CollisionCheck(shape >= 0 && shape < b.count, "shape index out of range");
  return impl_->shapes[b.first + shape].name;
}

BodyId CollisionWorld::FindBody(const std::string& name) const {
  for (int i = 0; i < impl_->n(); ++i) {
    if (impl_->bodies[i].name == name) return BodyId{i};
  }
  return BodyId{};
}

void CollisionWorld::SetPose(BodyId body, const Iso3& X_WB) {
  BodyData& b = impl_->body(body);
  if (b.X_WB.matrix() == X_WB.matrix()) return;
  b.X_WB = X_WB;
  b.dirty = true;
  b.changed_at = ++impl_->epoch;
  impl_->any_dirty = true;
}

const Iso3& CollisionWorld::pose(BodyId body) const { return impl_->body(body).X_WB; }

void CollisionWorld::SetPoses(std::span<const Iso3> X_WB) {
  CollisionCheck(static_cast<int>(X_WB.size()) == impl_->n(),
                 "SetPoses: one pose per body expected");
  for (int i = 0; i < impl_->n(); ++i) {
    BodyData& b = impl_->bodies[i];
    if (b.X_WB.matrix() == X_WB[i].matrix()) continue;
    b.X_WB = X_WB[i];
    b.dirty = true;
    b.changed_at = ++impl_->epoch;
  }
  impl_->any_dirty = true;
}

void CollisionWorld::SetEnabled(BodyId body, bool on) {
  BodyData& b = impl_->body(body);
  if (b.enabled == on) return;
  b.enabled = on;
  b.dirty = true;
  impl_->any_dirty = true;
}

bool CollisionWorld::enabled(BodyId body) const { return impl_->body(body).enabled; }

void CollisionWorld::SetAllowed(BodyId a, BodyId b, bool allowed) {
  impl_->body(a);
  impl_->body(b);
  const std::size_t n = impl_->bodies.size();
  const std::uint8_t v = allowed ? 1 : 0;
  impl_->allowed[a.value * n + b.value] = v;
  impl_->allowed[b.value * n + a.value] = v;
}

void CollisionWorld::SetGroupPairAllowed(int g, int h, bool allowed) {
  if (allowed) {
    impl_->allowed_groups.Add(g, h);
  } else {
    impl_->allowed_groups.Remove(g, h);
  }
}

bool CollisionWorld::IsAllowed(BodyId a, BodyId b) const {
  impl_->body(a);
  impl_->body(b);
  return impl_->Allowed(a.value, b.value);
}

Aabb CollisionWorld::body_aabb(BodyId body) {
  impl_->UpdateBounds();
  const BodyData& b = impl_->body(body);
  Aabb box;
  if (!b.active()) {
    box.min = box.max = b.X_WB.translation();
    if (b.count > 0) {
      // Disabled: still report where its shapes are.
      box.min = Vec3::Constant(kInf);
      box.max = Vec3::Constant(-kInf);
      for (int k = b.first; k < b.first + b.count; ++k) {
        impl_->UpdateShape(impl_->shapes[k], b.X_WB);
        box.min = box.min.cwiseMin(impl_->shapes[k].lo);
        box.max = box.max.cwiseMax(impl_->shapes[k].hi);
      }
    }
    return box;
  }
  box.min = b.lo;
  box.max = b.hi;
  return box;
}

std::string CollisionWorld::Describe(const ShapePair& pair) const {
  if (!pair.body_a.valid() || !pair.body_b.valid()) return "no pair";
  std::ostringstream os;
  auto one = [&](BodyId id, int shape, const Iso3& X) {
    const BodyData& b = impl_->body(id);
    os << "body '" << b.name << "' (id " << id.value << ", group " << b.group << ") shape '"
       << (shape >= 0 && shape < b.count ? impl_->shapes[b.first + shape].name : "?") << "' at "
       << PoseText(X);
  };
  one(pair.body_a, pair.shape_a, pair.X_WA);
  os << " vs ";
  one(pair.body_b, pair.shape_b, pair.X_WB);
  return os.str();
}

}  // namespace wrap
