#include "sim/scene.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <tuple>

#include "robot/home.h"
#include "robot/project_chain.h"

namespace wrap {

namespace fs = std::filesystem;

namespace {

// A base counts as standing on a surface when it is within this height of it [m].
constexpr double kStandingTolerance = 0.005;
// The pedestal is this much wider than the base's footprint, and at least kMinPedestal [m].
constexpr double kPedestalMargin = 1.05;
constexpr double kMinPedestalRadius = 0.06;

Aabb EmptyBox() {
  Aabb box;
  box.min = Vec3::Constant(std::numeric_limits<double>::infinity());
  box.max = Vec3::Constant(-std::numeric_limits<double>::infinity());
  return box;
}

void Grow(Aabb& box, const Vec3& p) {
  box.min = box.min.cwiseMin(p);
  box.max = box.max.cwiseMax(p);
}

void Grow(Aabb& box, const Aabb& other) {
  if ((other.min.array() > other.max.array()).any()) return;
  Grow(box, other.min);
  Grow(box, other.max);
}

// Largest distance of a link-0 shape from the base's z axis, in the base's xy plane [m].
double FootprintRadius(const Link& base) {
  double r = 0.0;
  for (const Shape& s : base.visual) {
    const Aabb b = ShapeBounds(s, Iso3::Identity());
    for (int i = 0; i < 4; ++i) {
      const Vec3 c((i & 1) ? b.max.x() : b.min.x(), (i & 2) ? b.max.y() : b.min.y(), 0.0);
      r = std::max(r, c.norm());
    }
  }
  return r;
}

// Decides the pedestal of a robot that is not on a mobile base: from the table top when the
// base is above the table's footprint, else from the floor.
void PlacePedestal(const SceneTable& table, SceneRobot& robot) {
  const Vec3 p = robot.X_WB.translation();
  const Vec3 half = 0.5 * table.size;
  const bool over_table = std::abs(p.x() - table.top_center.x()) <= half.x() &&
                          std::abs(p.y() - table.top_center.y()) <= half.y();
  const double bottom = over_table ? table.top_center.z() : 0.0;
  if (p.z() - bottom <= kStandingTolerance) return;
  const double footprint = robot.chain.links.empty() ? 0.0 : FootprintRadius(robot.chain.links[0]);
  robot.pedestal_radius_m = std::max(kMinPedestalRadius, kPedestalMargin * footprint);
  robot.pedestal_bottom_z = bottom;
}

// Pose of every part in the assembly frame A after exploding: each step moves the parts of its
// moved input back along its insertion axis by `distance` [m].
std::vector<Iso3> ExplodedAssembly(const CellScene& scene, double distance) {
  std::vector<Iso3> X_AP;
  X_AP.reserve(scene.parts.size());
  for (const ScenePart& part : scene.parts) X_AP.push_back(part.X_AP);
  if (distance <= 0.0) return X_AP;
  for (const SceneStep& step : scene.steps) {
    for (int i : step.moved_parts) X_AP[i].pretranslate(-distance * step.axis_A);
  }
  return X_AP;
}

// Box of the parts' vertices with part i at X[i].
Aabb PartsBox(const CellScene& scene, const std::vector<Iso3>& X) {
  Aabb box = EmptyBox();
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    for (const Vec3& v : scene.parts[i].mesh->vertices) Grow(box, X[i] * v);
  }
  return box;
}

}  // namespace

Aabb ShapeBounds(const Shape& shape, const Iso3& X_WL) {
  Aabb box = EmptyBox();
  switch (shape.type) {
    case Shape::Type::kCapsule:
    case Shape::Type::kSphere:
    case Shape::Type::kCylinder: {
      // A cylinder's box is within its capsule's: good enough for framing a camera.
      const Vec3 r = Vec3::Constant(shape.radius);
      for (const Vec3& p : {X_WL * shape.p0, X_WL * shape.p1}) {
        Grow(box, p - r);
        Grow(box, p + r);
      }
      break;
    }
    case Shape::Type::kBox:
      for (int i = 0; i < 8; ++i) {
        const Vec3 corner((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0);
        Grow(box, X_WL * (shape.X_LS * corner.cwiseProduct(shape.half_extents)));
      }
      break;
    case Shape::Type::kMesh:
      for (const Vec3& v : shape.mesh.vertices) Grow(box, X_WL * v);
      break;
  }
  return box;
}

Result<CellScene> BuildCellScene(const Project& project, const ProjectCheck& check,
                                 const fs::path& project_file) {
  CellScene scene;
  scene.name = project.name;
  scene.table.size = project.table.size;
  scene.table.top_center =
      Vec3(project.table.center_xy.x(), project.table.center_xy.y(), project.table.height);
  scene.table.friction = project.table.friction;

  for (const MobileBase& b : project.mobile_bases) {
    auto model = LoadMobileBase(b.model);
    if (!model) {
      return Fail(ErrorCode::kInvalidInput,
                  "scene: mobile base '" + b.name + "': " + model.error().message);
    }
    scene.mobile_bases.push_back({b.name, std::move(*model), ToIsometry(b.pose)});
  }

  for (const Robot& r : project.robots) {
    auto chain = LoadProjectChain(project, r, project_file);
    if (!chain) {
      return Fail(ErrorCode::kInvalidInput,
                  "scene: robot '" + r.name + "': " + chain.error().message);
    }
    auto ee = LoadEndEffector(r.end_effector);
    if (!ee) {
      return Fail(ErrorCode::kInvalidInput, "scene: robot '" + r.name + "': " + ee.error().message);
    }
    SceneRobot robot;
    robot.name = r.name;
    robot.chain = std::move(*chain);
    robot.end_effector = std::move(*ee);
    robot.X_WB = RobotBaseInWorld(project, r);
    robot.home = FacingHomeConfiguration(robot.chain, robot.X_WB, scene.table.top_center);
    robot.mounted = !r.mounted_on.empty();
    if (!robot.mounted) PlacePedestal(scene.table, robot);
    scene.robots.push_back(std::move(robot));
  }

  // Parts made from the same file (and the same solid of a STEP file) at the same scale share
  // one mesh.
  std::map<std::tuple<std::string, std::string, double>, std::shared_ptr<const TriangleMesh>>
      meshes;
  for (size_t i = 0; i < project.parts.size(); ++i) {
    const Part& p = project.parts[i];
    if (i >= check.parts.size() || !check.parts[i].loaded) {
      return Fail(ErrorCode::kInvalidInput, "scene: part '" + p.name + "': mesh '" + p.mesh +
                                                "' is not loaded (run 'wrap validate')");
    }
    const PartGeometry& geometry = check.parts[i];
    auto& shared = meshes[{geometry.resolved.string(), p.solid, p.scale}];
    if (!shared) shared = std::make_shared<const TriangleMesh>(geometry.mesh);
    scene.parts.push_back(
        {p.name, shared, p.color, ToIsometry(p.initial_pose), ToIsometry(p.assembled_pose)});
    // Mass properties for physics: the mesh's per-unit-density values scaled to the part's mass.
    const MassProperties& mp = geometry.mass_properties;
    ScenePart& added = scene.parts.back();
    added.mass_kg = geometry.mass_kg;
    added.com_P = mp.com;
    if (mp.volume_m3 > 0.0) added.inertia_com = mp.inertia_com * (geometry.mass_kg / mp.volume_m3);
  }

  if (check.tree) {
    const AssemblyTree& tree = *check.tree;
    for (const Step& s : project.steps) {
      const int moved = tree.Find(s.mating.moved);
      if (moved < 0) continue;
      const Vec3 axis = s.mating.axis.norm() > 0.0 ? s.mating.axis.normalized() : Vec3::UnitZ();
      scene.steps.push_back({s.name, tree.nodes[moved].parts, axis});
    }
  }
  return scene;
}

SceneState InitialState(const CellScene& scene) {
  SceneState state;
  for (const SceneRobot& r : scene.robots) {
    state.q.push_back(r.home);
    state.opening_m.push_back(r.end_effector.stroke_m);
  }
  for (const ScenePart& p : scene.parts) state.X_WP.push_back(p.X_WP_initial);
  return state;
}

Result<SceneState> GoalState(const CellScene& scene, const GoalOptions& options) {
  if (!std::isfinite(options.explode) || options.explode < 0.0) {
    return Fail(ErrorCode::kInvalidInput,
                "goal: explode factor " + std::to_string(options.explode) +
                    " must be a finite number >= 0 (a fraction of the assembly's size)");
  }
  SceneState state = InitialState(scene);
  if (scene.parts.empty()) return state;
  const std::vector<Iso3> assembled = ExplodedAssembly(scene, 0.0);
  const double size = PartsBox(scene, assembled).size().maxCoeff();
  const std::vector<Iso3> X_AP = ExplodedAssembly(scene, options.explode * size);
  // Centre the (exploded) assembly over the table centre and rest it on the top.
  const Aabb box = PartsBox(scene, X_AP);
  const Vec3 center = 0.5 * (box.min + box.max);
  const Vec3 shift(scene.table.top_center.x() - center.x(), scene.table.top_center.y() - center.y(),
                   scene.table.top_center.z() - box.min.z());
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    state.X_WP[i] = X_AP[i];
    state.X_WP[i].pretranslate(shift);
  }
  return state;
}

Aabb SceneBounds(const CellScene& scene, const SceneState& state) {
  Aabb box = EmptyBox();
  const Vec3 half(0.5 * scene.table.size.x(), 0.5 * scene.table.size.y(), 0.0);
  Grow(box, scene.table.top_center - half - Vec3(0, 0, scene.table.size.z()));
  Grow(box, scene.table.top_center + half);
  for (size_t r = 0; r < scene.robots.size(); ++r) {
    const SceneRobot& robot = scene.robots[r];
    const Chain& chain = robot.chain;
    const JointVector& q = r < state.q.size() ? state.q[r] : robot.home;
    if (q.size() != chain.dof()) continue;
    std::vector<Iso3> X_WL(chain.links.size());
    ForwardKinematics(chain, robot.X_WB, q, X_WL);
    for (size_t l = 0; l < chain.links.size(); ++l) {
      for (const Shape& s : chain.links[l].visual) Grow(box, ShapeBounds(s, X_WL[l]));
    }
    const Iso3 X_WF = X_WL.back() * chain.X_LF;
    const double opening = r < state.opening_m.size() ? state.opening_m[r] : 0.0;
    for (const Shape& s : EndEffectorShapesAt(robot.end_effector, opening)) {
      Grow(box, ShapeBounds(s, X_WF));
    }
    if (robot.pedestal_radius_m > 0.0) {
      const Vec3 p = robot.X_WB.translation();
      const Vec3 r3(robot.pedestal_radius_m, robot.pedestal_radius_m, 0.0);
      Grow(box, Vec3(p.x(), p.y(), robot.pedestal_bottom_z) - r3);
      Grow(box, p + r3);
    }
  }
  for (const SceneMobileBase& b : scene.mobile_bases) {
    for (const Shape& s : b.model.visual) Grow(box, ShapeBounds(s, b.X_WB));
  }
  for (size_t i = 0; i < scene.parts.size() && i < state.X_WP.size(); ++i) {
    for (const Vec3& v : scene.parts[i].mesh->vertices) Grow(box, state.X_WP[i] * v);
  }
  return box;
}

}  // namespace wrap
