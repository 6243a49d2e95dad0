#include "task/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/frames.h"
#include "robot/home.h"
#include "robot/kinematics.h"
#include "robot/project_chain.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

// Reach sphere of a robot: centre at the mean TCP position of random configurations projected
// on the first joint axis (the shoulder), radius the largest TCP distance from it.
void ComputeReach(TaskRobot& robot) {
  std::mt19937_64 rng(7);
  const Iso3 X_FT = robot.end_effector.X_FT;
  // The first joint's axis passes through the base frame's origin for every catalog arm; use
  // the link-1 origin as the shoulder (the UR shoulder height d1 and the OpenArm's base).
  std::vector<Iso3> frames(robot.chain.links.size());
  ForwardKinematics(robot.chain, robot.X_WB, ZeroConfiguration(robot.chain), frames);
  const Vec3 shoulder = frames.size() > 1 ? frames[1].translation() : robot.X_WB.translation();
  double reach = 0.0;
  for (int i = 0; i < 400; ++i) {
    const JointVector q = RandomConfiguration(robot.chain, rng);
    reach = std::max(reach,
                     (TcpPose(robot.chain, robot.X_WB, q, X_FT).translation() - shoulder).norm());
  }
  robot.shoulder_W = shoulder;
  robot.reach_m = reach * 1.03 + 0.01;
}

// Overlap of two boxes grown by `grow` on each side: volume and centre.
double BoxOverlap(const Aabb& a, const Aabb& b, double grow, Vec3* centre) {
  Vec3 lo = a.min.cwiseMax(b.min) - Vec3::Constant(grow);
  Vec3 hi = a.max.cwiseMin(b.max) + Vec3::Constant(grow);
  const Vec3 d = hi - lo;
  if (d.minCoeff() <= 0.0) return -1.0;
  if (centre) *centre = 0.5 * (lo + hi);
  return d.x() * d.y() * d.z();
}

void CollectSteps(const AssemblyTree& tree, int node, std::vector<int>& out) {
  const AssemblyNode& n = tree.nodes[node];
  if (n.step < 0) return;
  for (int input : n.inputs) CollectSteps(tree, input, out);
  out.push_back(node);
}

// 2-D convex hull (monotone chain) of points by their x, y; keeps z of the input points.
std::vector<Vec3> Hull2d(std::vector<Vec3> points) {
  std::sort(points.begin(), points.end(), [](const Vec3& a, const Vec3& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  auto cross = [](const Vec3& o, const Vec3& a, const Vec3& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Vec3> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 1e-12) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], points[i]) <= 1e-12) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// Sutherland-Hodgman clipping of a convex counter-clockwise polygon (or fewer points) to an
// axis-aligned rectangle in x, y; the result lies at height z.
std::vector<Vec3> ClipToRectangle(std::vector<Vec3> poly, double x0, double x1, double y0,
                                  double y1, double z) {
  auto clip = [](const std::vector<Vec3>& in, auto inside, auto cut) {
    std::vector<Vec3> out;
    const size_t n = in.size();
    if (n == 0) return out;
    if (n == 1) {
      if (inside(in[0])) out.push_back(in[0]);
      return out;
    }
    for (size_t i = 0; i < n; ++i) {
      const Vec3& a = in[i];
      const Vec3& b = in[(i + 1) % n];
      const bool ia = inside(a), ib = inside(b);
      if (ia) out.push_back(a);
      if (ia != ib && (n > 2 || i == 0)) out.push_back(cut(a, b));
    }
    return out;
  };
  auto along_x = [](double x) {
    return [x](const Vec3& a, const Vec3& b) {
      const double t = (x - a.x()) / (b.x() - a.x());
      return Vec3(x, a.y() + t * (b.y() - a.y()), a.z());
    };
  };
  auto along_y = [](double y) {
    return [y](const Vec3& a, const Vec3& b) {
      const double t = (y - a.y()) / (b.y() - a.y());
      return Vec3(a.x() + t * (b.x() - a.x()), y, a.z());
    };
  };
  poly = clip(
      poly, [x0](const Vec3& p) { return p.x() >= x0; }, along_x(x0));
  poly = clip(
      poly, [x1](const Vec3& p) { return p.x() <= x1; }, along_x(x1));
  poly = clip(
      poly, [y0](const Vec3& p) { return p.y() >= y0; }, along_y(y0));
  poly = clip(
      poly, [y1](const Vec3& p) { return p.y() <= y1; }, along_y(y1));
  for (Vec3& p : poly) p.z() = z;
  return poly;
}

// Each part in the assembly frame: pose, mass, centre of mass, box, and where it starts.
Result<void> AddParts(const Project& project, const ProjectCheck& check, TaskWorld& w) {
  for (int p = 0; p < w.num_parts; ++p) {
    const Part& part = project.parts[p];
    const PartGeometry& g = check.parts[p];
    if (!g.loaded) {
      return Fail(ErrorCode::kInvalidInput, "planner: part '" + part.name + "' has no mesh");
    }
    const Iso3 X_AP = ToIsometry(part.assembled_pose);
    w.X_AP.push_back(X_AP);
    w.part_mass.push_back(g.mass_kg);
    const bool closed = g.mass_properties.volume_m3 > 0.0;
    const Vec3 com_P = closed ? g.mass_properties.com : 0.5 * (g.aabb.min + g.aabb.max);
    w.part_com_A.push_back(X_AP * com_P);
    Aabb box;
    box.min = Vec3::Constant(std::numeric_limits<double>::infinity());
    box.max = -box.min;
    for (const Vec3& v : g.mesh.vertices) {
      const Vec3 a = X_AP * v;
      box.min = box.min.cwiseMin(a);
      box.max = box.max.cwiseMax(a);
    }
    w.part_box_A.push_back(box);
    w.initial_X_WA.push_back(ToIsometry(part.initial_pose) * X_AP.inverse());
  }
  return {};
}

// Where the step's inputs meet: the pair of their parts whose boxes overlap most (the middle of
// the overlap), else the nearest pair of box centres (the middle between them).
void FindInterfacePoint(const TaskWorld& w, const AssemblyTree& tree, StepInterface& s) {
  double best = -2.0;
  for (int pm : tree.nodes[s.moved].parts) {
    for (int pb : tree.nodes[s.base].parts) {
      Vec3 c = Vec3::Zero();  // BoxOverlap leaves it unset when the boxes are apart
      const double v = BoxOverlap(w.part_box_A[pm], w.part_box_A[pb], 1e-3, &c);
      if (v > best) {
        best = v;
        s.part_moved = pm;
        s.part_base = pb;
        s.p_A = c;
      }
    }
  }
  if (best > 0.0) return;
  double nearest = std::numeric_limits<double>::infinity();
  for (int pm : tree.nodes[s.moved].parts) {
    for (int pb : tree.nodes[s.base].parts) {
      const Vec3 cm = 0.5 * (w.part_box_A[pm].min + w.part_box_A[pm].max);
      const Vec3 cb = 0.5 * (w.part_box_A[pb].min + w.part_box_A[pb].max);
      if ((cm - cb).norm() < nearest) {
        nearest = (cm - cb).norm();
        s.part_moved = pm;
        s.part_base = pb;
        s.p_A = 0.5 * (cm + cb);
      }
    }
  }
}

// Each step's interface (inputs, insertion axis, connection frame and limits) and each node's
// steps.
Result<void> AddSteps(const Project& project, const AssemblyTree& tree, TaskWorld& w) {
  w.steps.resize(w.num_nodes - w.num_parts);
  for (int node = w.num_parts; node < w.num_nodes; ++node) {
    const AssemblyNode& n = tree.nodes[node];
    const Step& step = project.steps[n.step];
    StepInterface& s = w.steps[node - w.num_parts];
    s.node = node;
    s.step = n.step;
    s.mating = &step.mating;
    s.moved = tree.Find(step.mating.moved);
    s.base = tree.Find(step.mating.base);
    if (s.moved < 0 || s.base < 0) {
      return Fail(ErrorCode::kInvalidInput,
                  "planner: step '" + step.name + "': mating inputs are not DAG nodes");
    }
    s.axis_A = step.mating.axis.normalized();
    s.approach_m = step.mating.approach_m;
    FindInterfacePoint(w, tree, s);
    s.X_AC = Iso3::Identity();
    s.X_AC.linear() = RotationWithZ(s.axis_A);
    s.X_AC.translation() = s.p_A;
    s.connection = BoundsFromBox(step.mating.connection_limits.value_or(project.connection_limits));
  }
  w.subtree_steps.resize(w.num_nodes);
  for (int node = 0; node < w.num_nodes; ++node) CollectSteps(tree, node, w.subtree_steps[node]);
  return {};
}

// The robots: kinematics, end effector, home, IK, wrench limits, grasp set and reach.
Result<void> AddRobots(const Project& project, const Preprocessed& pre,
                       const fs::path& project_file, TaskWorld& w) {
  for (const Robot& r : project.robots) {
    TaskRobot robot;
    robot.name = r.name;
    auto chain = LoadProjectChain(project, r, project_file, false);
    if (!chain) {
      return Fail(ErrorCode::kInvalidInput,
                  "planner: robot '" + r.name + "': " + chain.error().message);
    }
    robot.chain = std::move(*chain);
    auto ee = LoadEndEffector(r.end_effector);
    if (!ee) {
      return Fail(ErrorCode::kInvalidInput,
                  "planner: robot '" + r.name + "': " + ee.error().message);
    }
    robot.end_effector = std::move(*ee);
    robot.X_WB = RobotBaseInWorld(project, r);
    robot.X_BW = robot.X_WB.inverse();
    robot.home = FacingHomeConfiguration(robot.chain, robot.X_WB, w.table_center);
    if (auto ur = UrAnalyticIk::FromChain(robot.chain)) robot.ur = *ur;
    robot.limits = r.wrench_limits.value_or(project.wrench_limits);
    for (size_t i = 0; i < pre.end_effectors.size(); ++i) {
      if (pre.end_effectors[i] == r.end_effector) robot.grasp_set = static_cast<int>(i);
    }
    ComputeReach(robot);
    w.robots.push_back(std::move(robot));
  }
  return {};
}

// The collision cell: robots (grippers without their fingers), parts and table.
void BuildCellDef(const Project& project, const ProjectCheck& check, TaskWorld& w) {
  for (size_t ri = 0; ri < w.robots.size(); ++ri) {
    const TaskRobot& robot = w.robots[ri];
    CellRobot cr;
    cr.name = robot.name;
    cr.chain = robot.chain;
    cr.X_WB = robot.X_WB;
    cr.end_effector.name = robot.end_effector.name;
    cr.end_effector.X_FT = robot.end_effector.X_FT;
    // The gripper body without its fingers: the planner adds the two finger boxes as bodies of
    // their own, opened to each keyframe's grasp width (KeyframeSolver).
    cr.end_effector.collision.clear();
    for (size_t i = 0; i < robot.end_effector.collision.size(); ++i) {
      const auto& f = robot.end_effector.finger_shapes;
      if (static_cast<int>(i) == f[0] || static_cast<int>(i) == f[1]) continue;
      cr.end_effector.collision.push_back(robot.end_effector.collision[i]);
    }
    cr.reference_link_frames.resize(robot.chain.links.size());
    ForwardKinematics(robot.chain, robot.X_WB, robot.home, cr.reference_link_frames);
    w.cell_def.robots.push_back(std::move(cr));
  }
  for (int p = 0; p < w.num_parts; ++p) {
    w.cell_def.objects.push_back(
        {project.parts[p].name, check.parts[p].mesh, ToIsometry(project.parts[p].initial_pose)});
  }
  w.cell_def.table.present = true;
  w.cell_def.table.size = project.table.size;
  w.cell_def.table.top_center = w.table_center;
}

}  // namespace

const GraspSet* TaskWorld::grasp_set(int node, int robot) const {
  const int set = robots[robot].grasp_set;
  if (set < 0) return nullptr;
  const auto& sets = pre->subassemblies[node].grasp_sets;
  if (set < static_cast<int>(sets.size()) &&
      sets[set].end_effector == robots[robot].end_effector.name) {
    return &sets[set];
  }
  for (const GraspSet& s : sets) {
    if (s.end_effector == robots[robot].end_effector.name) return &s;
  }
  return nullptr;
}

Result<TaskWorld> BuildTaskWorld(const Project& project, const ProjectCheck& check,
                                 const Preprocessed& pre, const fs::path& project_file) {
  if (!check.tree) return Fail(ErrorCode::kInvalidInput, "planner: the project has no valid DAG");
  TaskWorld w;
  w.project = &project;
  w.check = &check;
  w.tree = &*check.tree;
  w.pre = &pre;
  w.num_parts = static_cast<int>(project.parts.size());
  w.num_nodes = static_cast<int>(check.tree->nodes.size());
  if (static_cast<int>(pre.subassemblies.size()) != w.num_nodes) {
    return Fail(ErrorCode::kInvalidInput,
                "planner: the preprocessing has " + std::to_string(pre.subassemblies.size()) +
                    " subassemblies, the project's DAG " + std::to_string(w.num_nodes) + " nodes");
  }
  if (static_cast<int>(project.robots.size()) > kMaxCellRobots) {
    return Fail(ErrorCode::kInvalidInput,
                "planner: at most " + std::to_string(kMaxCellRobots) + " robots are supported");
  }
  w.table_top = project.table.height;
  w.table_center = Vec3(project.table.center_xy.x(), project.table.center_xy.y(), w.table_top);
  if (auto parts = AddParts(project, check, w); !parts) return std::unexpected(parts.error());
  if (auto steps = AddSteps(project, *check.tree, w); !steps) {
    return std::unexpected(steps.error());
  }
  if (auto robots = AddRobots(project, pre, project_file, w); !robots) {
    return std::unexpected(robots.error());
  }
  BuildCellDef(project, check, w);
  return w;
}

std::vector<std::pair<int, std::vector<Vec3>>> TableContacts(const TaskWorld& world, int node,
                                                             const Iso3& X_WA, double tolerance_m) {
  // Each part's own hull vertices (a part's node is its subassembly), as the plan validator
  // counts them: a vertex shared by two touching parts supports both.
  const AssemblyNode& n = world.tree->nodes[node];
  std::vector<std::pair<int, std::vector<Vec3>>> out;
  for (int part : n.parts) {
    std::vector<Vec3> points;
    for (const Vec3& v_A : world.pre->subassemblies[part].hull.mesh.vertices) {  // in A
      const Vec3 v_W = X_WA * v_A;
      if (v_W.z() > world.table_top + tolerance_m) continue;
      points.push_back(Vec3(v_W.x(), v_W.y(), world.table_top));
    }
    if (!points.empty()) out.push_back({part, std::move(points)});
  }
  const Vec3 half = 0.5 * world.project->table.size;
  for (auto& [part, points] : out) {
    if (points.size() >= 3) points = Hull2d(std::move(points));
    // Only what lies over the table top is supported: clip to the table's rectangle.
    points = ClipToRectangle(std::move(points), world.table_center.x() - half.x(),
                             world.table_center.x() + half.x(), world.table_center.y() - half.y(),
                             world.table_center.y() + half.y(), world.table_top);
    if (points.size() > 16) {  // a round base: keep 16 corners spread along the hull
      std::vector<Vec3> kept;
      for (int i = 0; i < 16; ++i) kept.push_back(points[i * points.size() / 16]);
      points = std::move(kept);
    }
  }
  std::erase_if(out, [](const auto& e) { return e.second.empty(); });
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return out;
}

double LowestPoint(const TaskWorld& world, int node, const Iso3& X_WA) {
  double z = std::numeric_limits<double>::infinity();
  for (const Vec3& v : world.pre->subassemblies[node].hull.mesh.vertices) {
    z = std::min(z, (X_WA * v).z());
  }
  return z;
}

}  // namespace wrap
