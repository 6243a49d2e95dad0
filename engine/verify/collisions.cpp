#include <algorithm>
#include <cmath>
#include <limits>

#include "geometry/convex_hull.h"
#include "verify/detail/collisions.h"

namespace wrap::detail {

Shape ShrinkShape(const Shape& shape, double by_m) {
  Shape s = shape;
  auto less = [by_m](double v) { return std::max(v - by_m, 0.25 * v); };
  switch (shape.type) {
    case Shape::Type::kCapsule:
    case Shape::Type::kSphere:
      s.radius = less(shape.radius);
      break;
    case Shape::Type::kCylinder: {
      s.radius = less(shape.radius);
      const Vec3 axis = shape.p1 - shape.p0;
      const double length = axis.norm();
      if (length > 0.0) {
        const double cut = 0.5 * (length - less(length));
        s.p0 = shape.p0 + cut * axis / length;
        s.p1 = shape.p1 - cut * axis / length;
      }
      break;
    }
    case Shape::Type::kBox:
      for (int i = 0; i < 3; ++i) s.half_extents[i] = less(shape.half_extents[i]);
      break;
    case Shape::Type::kMesh:
      break;
  }
  return s;
}

Result<SimCollisions> SimCollisions::Build(const CellScene& scene, double tolerance_m) {
  SimCollisions out;
  out.scene_ = &scene;
  out.tolerance_m_ = std::max(0.0, tolerance_m);
  for (const ScenePart& part : scene.parts) {
    auto hull = ComputeConvexHull(*part.mesh);
    out.hull_.push_back(hull ? hull->mesh.vertices : part.mesh->vertices);
  }
  for (const SceneRobot& robot : scene.robots) {
    out.frames_.emplace_back(robot.chain.links.size(), Iso3::Identity());
  }
  // Build the fully open cell now, so that a bad shape is an error before the run.
  std::vector<double> open(scene.robots.size(), -1.0);
  std::vector<JointVector> q;
  for (const SceneRobot& robot : scene.robots) q.push_back(robot.home);
  std::vector<Iso3> X_WP;
  for (const ScenePart& part : scene.parts) X_WP.push_back(part.X_WP_initial);
  ContactRules none;
  const size_t np = scene.parts.size();
  none.robot_part_ok.assign(scene.robots.size(), std::vector<char>(np, 1));
  none.part_pair_ok.assign(np, std::vector<char>(np, 1));
  none.held.assign(np, 0);
  if (auto first = out.Check(q, open, X_WP, none); !first) return std::unexpected(first.error());
  return out;
}

Result<std::optional<CollisionHit>> SimCollisions::Check(const std::vector<JointVector>& q,
                                                         const std::vector<double>& openings,
                                                         const std::vector<Iso3>& X_WP,
                                                         const ContactRules& rules) {
  const CellScene& scene = *scene_;
  const int nr = static_cast<int>(scene.robots.size());
  const int np = static_cast<int>(scene.parts.size());
  // The cell for these openings (finger boxes move with them).
  std::vector<long long> key;
  for (double o : openings) key.push_back(o < 0.0 ? -1 : std::llround(o * 1e4));
  auto it = cells_.find(key);
  if (it == cells_.end()) {
    CellDef def;
    for (int r = 0; r < nr; ++r) {
      const SceneRobot& robot = scene.robots[r];
      CellRobot cr;
      cr.name = robot.name;
      cr.chain = robot.chain;
      for (Link& link : cr.chain.links) {
        for (Shape& s : link.collision) s = ShrinkShape(s, tolerance_m_);
      }
      cr.X_WB = robot.X_WB;
      const EndEffector& ee = robot.end_effector;
      cr.end_effector.name = ee.name;
      cr.end_effector.X_FT = ee.X_FT;
      for (const Shape& s : openings[r] >= 0.0 ? EndEffectorShapesAt(ee, openings[r])
                                               : ee.collision) {
        cr.end_effector.collision.push_back(ShrinkShape(s, tolerance_m_));
      }
      def.robots.push_back(std::move(cr));
    }
    for (const ScenePart& part : scene.parts) {
      def.objects.push_back({part.name, *part.mesh, part.X_WP_initial});
    }
    def.table.size = scene.table.size;
    def.table.top_center = scene.table.top_center;
    auto cell = Cell::Build(def);
    if (!cell) {
      return Fail(ErrorCode::kInvalidInput,
                  "sim: the collision cell does not build: " + cell.error().message);
    }
    it = cells_.emplace(key, std::move(*cell)).first;
    CollisionWorld& w = it->second.world();
    // A robot's own bodies are not judged (the planner keeps its arms clear of themselves).
    for (int r = 0; r < nr; ++r) {
      w.SetGroupPairAllowed(CellLinkGroup(r), CellLinkGroup(r), true);
      w.SetGroupPairAllowed(CellLinkGroup(r), CellEndEffectorGroup(r), true);
    }
  }
  Cell& cell = it->second;
  CollisionWorld& world = cell.world();
  for (int r = 0; r < nr; ++r) {
    const SceneRobot& robot = scene.robots[r];
    ForwardKinematics(robot.chain, robot.X_WB, q[r], frames_[r]);
    cell.SetConfiguration(r, std::span<const double>(q[r].data(), q[r].size()), frames_[r]);
  }
  for (int p = 0; p < np; ++p) {
    cell.SetObjectPose(p, X_WP[p]);
    for (int o = p + 1; o < np; ++o) cell.SetObjectPairAllowed(p, o, rules.part_pair_ok[p][o]);
    for (int r = 0; r < nr; ++r) {
      const bool ok = rules.robot_part_ok[r][p];
      const int links = static_cast<int>(scene.robots[r].chain.links.size());
      for (int l = 0; l < links; ++l) world.SetAllowed(cell.object_body(p), cell.link_body(r, l), ok);
      world.SetAllowed(cell.object_body(p), cell.end_effector_body(r), ok);
    }
  }
  CollisionResult hits;
  CollisionRequest request;
  request.all_pairs = true;
  cell.InCollision(&hits, request);
  auto part_of = [&](BodyId body) {
    for (int p = 0; p < np; ++p) {
      if (cell.object_body(p) == body) return p;
    }
    return -1;
  };
  for (const ShapePair& hit : hits.pairs) {
    const BodyId a = hit.body_a, b = hit.body_b;
    // Two parts (meshes, not shrunk): a contact no deeper than the tolerance goes away when one
    // of them moves by the tolerance along some world axis (faces sliding on each other).
    const int pa = part_of(a), pb = part_of(b);
    if (pa >= 0 && pb >= 0) {
      bool shallow = false;
      for (int k = 0; k < 6 && !shallow; ++k) {
        Iso3 X = X_WP[pa];
        X.translation()[k / 2] += (k % 2 == 0 ? 1.0 : -1.0) * tolerance_m_;
        world.SetPose(a, X);
        shallow = !world.Collide(a, b);
      }
      world.SetPose(a, X_WP[pa]);
      if (shallow) continue;
    }
    CollisionHit out;
    out.body_a = world.body_name(a);
    out.body_b = world.body_name(b);
    out.robot_a = cell.robot_of(a);
    out.robot_b = cell.robot_of(b);
    out.part_a = pa;
    out.part_b = pb;
    return std::optional<CollisionHit>(out);
  }
  // A held part pressed into the table: its lowest hull point over the table, below the top.
  const Vec3 lo = scene.table.top_center - 0.5 * scene.table.size;
  const Vec3 hi = scene.table.top_center + 0.5 * scene.table.size;
  const double top = scene.table.top_center.z();
  for (int p = 0; p < np; ++p) {
    if (!rules.held[p]) continue;
    double lowest = std::numeric_limits<double>::infinity();
    for (const Vec3& v : hull_[p]) {
      const Vec3 w = X_WP[p] * v;
      if (w.x() >= lo.x() && w.x() <= hi.x() && w.y() >= lo.y() && w.y() <= hi.y()) {
        lowest = std::min(lowest, w.z());
      }
    }
    if (top - lowest > tolerance_m_) {
      CollisionHit out;
      out.body_a = scene.parts[p].name;
      out.part_a = p;
      out.body_b = "table";
      out.depth_m = top - lowest;
      return std::optional<CollisionHit>(out);
    }
  }
  return std::optional<CollisionHit>();
}

}  // namespace wrap::detail
