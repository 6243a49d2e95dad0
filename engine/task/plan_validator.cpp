// The independent plan validator. It shares no code with the search (engine/task/world.h and
// friends): the robots, the part geometry, the step interfaces, the collision cells and the wrench
// configurations are built here again from the project, so a mistake in the planner's model is
// not repeated here. See plan_validator.h for what is checked and task/plan.h for the contract.
#include "task/plan_validator.h"

#include "core/frames.h"
#include "robot/project_chain.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <utility>

#include "geometry/convex_hull.h"
#include "mating/assembly_geometry.h"
#include "mating/insertion.h"
#include "robot/catalog.h"
#include "robot/cell.h"
#include "robot/home.h"
#include "robot/kinematics.h"
#include "robot/project_chain.h"

namespace wrap {

bool PlanValidation::HasIssue(std::string_view gate, int action) const {
  return std::any_of(issues.begin(), issues.end(), [&](const PlanIssue& i) {
    return i.gate == gate && (action == kAnyAction || i.action == action);
  });
}

std::string FormatIssue(const PlanIssue& issue) {
  const std::string where =
      issue.action < 0 ? std::string("initial") : "action " + std::to_string(issue.action);
  return where + ": " + issue.gate + ": " + issue.message;
}

namespace {

// The fingers are checked this much wider than the grasp on each side (the grasp sampler's
// clearance): a two-finger gripper holding a part is drawn open to width + 2 mm.
constexpr double kFingerClearanceM = 1e-3;
// Most colliding pairs reported per keyframe.
constexpr int kMaxCollisionPairsReported = 4;
// The validator sweeps an insertion path in steps of this length [m].
constexpr double kInsertionStep_m = 2.5e-4;

std::string Quote(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string Mm(double m) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.1f mm", 1e3 * m);
  return buf;
}

std::string Deg(double rad) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.1f deg", rad * 180.0 / 3.14159265358979323846);
  return buf;
}

std::string Num(double v) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.4g", v);
  return buf;
}

// Translation and rotation-angle difference of two frames.
struct PoseError {
  double position_m = 0.0;
  double rotation_rad = 0.0;
};

PoseError Difference(const Iso3& a, const Iso3& b) {
  PoseError e;
  e.position_m = (a.translation() - b.translation()).norm();
  const Mat3 R = a.linear().transpose() * b.linear();
  e.rotation_rad = std::acos(std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0));
  return e;
}

// The part of the convex counter-clockwise polygon `poly` inside the rectangle [lo, hi]
// (Sutherland-Hodgman, one rectangle side at a time).
std::vector<Eigen::Vector2d> ClipToRectangle(std::vector<Eigen::Vector2d> poly,
                                             const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  for (int side = 0; side < 4 && !poly.empty(); ++side) {
    const int axis = side % 2;
    const double bound = side < 2 ? lo[axis] : hi[axis];
    const double sign = side < 2 ? 1.0 : -1.0;  // inside: sign * (x - bound) >= 0
    auto inside = [&](const Eigen::Vector2d& v) { return sign * (v[axis] - bound) >= 0.0; };
    std::vector<Eigen::Vector2d> out;
    for (size_t k = 0; k < poly.size(); ++k) {
      const Eigen::Vector2d& a = poly[k];
      const Eigen::Vector2d& b = poly[(k + 1) % poly.size()];
      if (inside(a)) out.push_back(a);
      if (inside(a) != inside(b)) {
        const double t = (bound - a[axis]) / (b[axis] - a[axis]);
        out.push_back(a + t * (b - a));
      }
    }
    poly = std::move(out);
  }
  return poly;
}

// A robot as the validator sees it.
struct RobotModel {
  std::string name;
  Chain chain;
  EndEffector ee;
  Iso3 X_WB = Iso3::Identity();
  WrenchLimits limits;
  std::vector<Iso3> reference_frames;  // link frames at home, for the cell's own-contact filter
};

// Where the two inputs of a step meet (computed from the part boxes in the assembly frame).
struct Interface {
  const Step* step = nullptr;
  int moved_node = -1;
  int base_node = -1;
  int moved_part = -1;
  int base_part = -1;
  Vec3 p_A = Vec3::Zero();       // interface point in A
  Vec3 axis_A = Vec3::UnitZ();   // unit insertion direction in A
  Iso3 X_AC = Iso3::Identity();  // connection frame: origin p_A, z along the axis
  WrenchBounds limits;
};

// An object of the replayed world.
struct ObjectState {
  Iso3 X_WA = Iso3::Identity();
  bool resting = true;
  bool at_rest_pose = true;  // rests, or was picked and has not moved since: may touch the table
  std::vector<PlanHold> holders;
};

// What one keyframe may show, relative to the state before the action.
struct Moment {
  std::set<int> moving;  // objects the action may move (their holders may move too)
  std::vector<std::pair<int, PlanHold>> new_holds;  // grasps closed at this keyframe: (node, hold)
  std::set<int> rest_check;                         // objects that must rest on the table here
  std::set<int> acted;                              // the action's objects (flags not compared)
  std::vector<std::pair<int, int>> allowed_pairs;   // objects allowed to touch each other
  std::map<int, std::pair<Iso3, std::string>> required;  // node -> pose it must have, and why
};

class Validator {
 public:
  Validator(const Project& project, const ProjectCheck& check, const Plan& plan,
            const PlanValidationOptions& options)
      : project_(project), check_(check), tree_(*check.tree), plan_(plan), options_(options) {}

  Result<void> Setup(const std::filesystem::path& project_file);
  Result<void> CheckInterpretable() const;
  PlanValidation Run();

 private:
  void Issue(int action, std::string gate, std::string message) {
    out_.issues.push_back({action, std::move(gate), std::move(message)});
  }
  const std::string& NodeName(int node) const { return tree_.nodes[node].name; }
  const std::string& RobotName(int r) const { return robots_[r].name; }
  const std::string& PartName(int p) const { return project_.parts[p].name; }
  bool NodeHasPart(int node, int part) const {
    const std::vector<int>& parts = tree_.nodes[node].parts;
    return std::binary_search(parts.begin(), parts.end(), part);
  }

  void CheckNames();
  void CheckInitial();
  void ReplayAction(int index);
  bool ActionShapeOk(int index, const PlanAction& a);
  const PlanHold* HoldOf(int node, int robot) const;
  bool GraspMatches(int index, int node, const PlanHold& hold);
  void RequireFree(int index, int robot, std::string_view role);
  void Detach(int robot);

  // Checks one keyframe against the state before the action; returns every object's pose at it.
  std::map<int, Iso3> CheckKeyframe(int index, const std::string& label, const Keyframe& kf,
                                    const Moment& m);
  void CheckRest(int index, const std::string& label, int node, const Iso3& X_WA);
  // Where part p at X_WP touches the table: the convex hull of its vertices within the table
  // tolerance of the top, clipped to the table's rectangle (a part may overhang the edge).
  std::vector<Eigen::Vector2d> SupportPolygon(int part, const Iso3& X_WP) const;
  void CheckCollisions(int index, const std::string& label, const Keyframe& kf, const Moment& m,
                       const std::map<int, Iso3>& X_WA,
                       const std::vector<std::pair<int, PlanHold>>& holds);
  Cell* CellFor(const std::vector<double>& openings);
  // The moved input's straight path from its approach pose into its mating pose on B (at X_WB),
  // swept against B's meshes every kInsertionStep_m: the validator's own sweep (the planner's
  // is the geometry checks' conservative advancement).
  void CheckInsertionPath(int index, const Interface& f, const Iso3& X_WB);

  // Wrench configurations.
  void AddObject(int node, const Iso3& X_WA, const std::vector<PlanHold>& holders, bool on_table,
                 StepConfiguration& config, std::vector<int>& body_of_part) const;
  void RunGate(int index, WrenchGate gate, const StepConfiguration& config, std::string what);

  const Project& project_;
  const ProjectCheck& check_;
  const AssemblyTree& tree_;
  const Plan& plan_;
  const PlanValidationOptions& options_;

  std::vector<RobotModel> robots_;
  std::vector<Iso3> X_AP_;                 // per part
  std::vector<std::vector<Vec3>> hull_P_;  // per part: hull (or mesh) vertices in P
  std::vector<Aabb> box_A_;                // per part: box in A
  std::vector<Interface> interfaces_;      // per node (valid for steps)
  std::map<std::vector<long long>, Cell> cells_;
  std::optional<AssemblyGeometry> geometry_;  // the parts' meshes, for the insertion sweeps
  bool cells_failed_ = false;
  std::optional<WrenchChecker> checker_;

  // The replayed state.
  std::map<int, ObjectState> objects_;
  std::vector<JointVector> q_;
  std::vector<int> holding_;    // node held by each robot, -1 when free
  std::vector<char> may_move_;  // freed by the last action: may park anywhere at the next keyframe
  std::set<int> freed_now_;     // robots freed by the action being replayed

  PlanValidation out_;
};

Result<RobotModel> LoadRobot(const Project& project, const Robot& robot,
                             const std::filesystem::path& project_file) {
  RobotModel m;
  m.name = robot.name;
  auto chain = LoadProjectChain(project, robot, project_file, false);
  if (!chain) return std::unexpected(chain.error());
  m.chain = std::move(*chain);
  auto ee = LoadEndEffector(robot.end_effector);
  if (!ee) return std::unexpected(ee.error());
  m.ee = std::move(*ee);
  m.X_WB = RobotBaseInWorld(project, robot);
  m.limits = robot.wrench_limits.value_or(project.wrench_limits);
  m.reference_frames.resize(m.chain.links.size());
  ForwardKinematics(m.chain, m.X_WB, HomeConfiguration(m.chain), m.reference_frames);
  return m;
}

Result<void> Validator::Setup(const std::filesystem::path& project_file) {
  for (const Robot& r : project_.robots) {
    auto robot = LoadRobot(project_, r, project_file);
    if (!robot) {
      return Fail(ErrorCode::kInvalidInput,
                  "plan validator: robot " + Quote(r.name) + ": " + robot.error().message);
    }
    if (robot->chain.dof() > kMaxDof) {
      return Fail(ErrorCode::kInvalidInput, "plan validator: robot " + Quote(r.name) + " has " +
                                                std::to_string(robot->chain.dof()) +
                                                " joints, at most " + std::to_string(kMaxDof));
    }
    robots_.push_back(std::move(*robot));
  }

  // Parts: assembled poses, hull vertices (table supports, lowest points), boxes in A.
  const int n_parts = static_cast<int>(project_.parts.size());
  for (int p = 0; p < n_parts; ++p) {
    const PartGeometry& g = check_.parts[p];
    X_AP_.push_back(ToIsometry(project_.parts[p].assembled_pose));
    auto hull = ComputeConvexHull(g.mesh);
    hull_P_.push_back(hull ? hull->mesh.vertices : g.mesh.vertices);
    Aabb box;
    box.min = Vec3::Constant(std::numeric_limits<double>::infinity());
    box.max = -box.min;
    for (const Vec3& v : hull_P_.back()) {
      const Vec3 p_A = X_AP_.back() * v;
      box.min = box.min.cwiseMin(p_A);
      box.max = box.max.cwiseMax(p_A);
    }
    box_A_.push_back(box);
  }

  // Step interfaces: the pair of parts, one per input, whose boxes (grown by 1 mm) overlap most.
  interfaces_.resize(tree_.nodes.size());
  for (size_t n = 0; n < tree_.nodes.size(); ++n) {
    const AssemblyNode& node = tree_.nodes[n];
    if (node.step < 0 || node.inputs.size() != 2) continue;
    Interface& f = interfaces_[n];
    f.step = &project_.steps[node.step];
    f.moved_node = tree_.Find(f.step->mating.moved);
    f.base_node = tree_.Find(f.step->mating.base);
    if (f.moved_node != node.inputs[0] && f.moved_node != node.inputs[1]) {
      f.moved_node = node.inputs[0];
    }
    f.base_node = f.moved_node == node.inputs[0] ? node.inputs[1] : node.inputs[0];
    double best = -1.0;
    double nearest = std::numeric_limits<double>::infinity();
    for (int pm : tree_.nodes[f.moved_node].parts) {
      for (int pb : tree_.nodes[f.base_node].parts) {
        const Vec3 lo = (box_A_[pm].min.cwiseMax(box_A_[pb].min)).array() - 1e-3;
        const Vec3 hi = (box_A_[pm].max.cwiseMin(box_A_[pb].max)).array() + 1e-3;
        const Vec3 extent = (hi - lo).cwiseMax(0.0);
        const double volume = extent.prod();
        const Vec3 c_m = 0.5 * (box_A_[pm].min + box_A_[pm].max);
        const Vec3 c_b = 0.5 * (box_A_[pb].min + box_A_[pb].max);
        if (volume > best || (best <= 0.0 && volume <= 0.0 && (c_m - c_b).norm() < nearest)) {
          best = volume;
          nearest = (c_m - c_b).norm();
          f.moved_part = pm;
          f.base_part = pb;
          f.p_A = volume > 0.0 ? Vec3(0.5 * (lo + hi)) : Vec3(0.5 * (c_m + c_b));
        }
      }
    }
    const Vec3 axis = f.step->mating.axis;
    f.axis_A = axis.norm() > 0.0 ? axis.normalized() : Vec3::UnitZ();
    f.X_AC.linear() = RotationWithZ(f.axis_A);
    f.X_AC.translation() = f.p_A;
    f.limits = BoundsFromBox(f.step->mating.connection_limits.value_or(project_.connection_limits));
  }

  checker_.emplace(WrenchOptions{});
  geometry_.emplace(AssemblyGeometry::FromProject(project_, check_));
  return {};
}

void Validator::CheckInsertionPath(int index, const Interface& f, const Iso3& X_WB) {
  const Mating& mating = f.step->mating;
  const std::vector<int>& moved = tree_.nodes[f.moved_node].parts;
  const std::vector<int>& base = tree_.nodes[f.base_node].parts;
  std::vector<Iso3> X(project_.parts.size(), Iso3::Identity());
  for (int p : base) X[p] = X_WB * X_AP_[p];
  const Vec3 axis_W = X_WB.linear() * f.axis_A;
  const int steps = static_cast<int>(std::ceil(mating.approach_m / kInsertionStep_m));
  for (int k = steps; k >= 0; --k) {
    const double s = steps > 0 ? mating.approach_m * k / steps : 0.0;
    for (int p : moved) {
      X[p] = X_WB * X_AP_[p];
      X[p].translation() -= s * axis_W;
    }
    const double allowed = s <= mating.interference_travel_m + 1e-12
                               ? std::max(mating.interference_depth_m,
                                          project_.geometry.touch_depth_m)
                               : project_.geometry.touch_depth_m;
    if (const auto o = OverlapBeyond(*geometry_, moved, base, X, allowed)) {
      Issue(index, "insertion",
            "assemble: on its way into its mating pose " + Quote(NodeName(f.moved_node)) +
                " (part " + Quote(PartName(o->part_a)) + ") cuts " + Mm(s) +
                " before it into " + Quote(NodeName(f.base_node)) + " (part " +
                Quote(PartName(o->part_b)) + ") deeper than the " + Mm(allowed) + " allowed");
      return;
    }
  }
}

Result<void> Validator::CheckInterpretable() const {
  const int n_robots = static_cast<int>(robots_.size());
  const int n_parts = static_cast<int>(project_.parts.size());
  const int n_nodes = static_cast<int>(tree_.nodes.size());
  auto fail = [](const std::string& where, const std::string& what) -> Result<void> {
    return Fail(ErrorCode::kInvalidInput, "plan validator: " + where + ": " + what);
  };
  auto keyframe = [&](const std::string& where, const Keyframe& kf) -> Result<void> {
    if (static_cast<int>(kf.q.size()) != n_robots) {
      return fail(where, std::to_string(kf.q.size()) + " joint vectors for " +
                             std::to_string(n_robots) + " robots");
    }
    for (int r = 0; r < n_robots; ++r) {
      if (kf.q[r].size() != robots_[r].chain.dof()) {
        return fail(where, "robot " + Quote(robots_[r].name) + " has " +
                               std::to_string(kf.q[r].size()) + " joint values, its chain " +
                               std::to_string(robots_[r].chain.dof()) + " joints");
      }
      if (!kf.q[r].allFinite()) {
        return fail(where, "robot " + Quote(robots_[r].name) + " has a non-finite joint value");
      }
    }
    for (const PlanObject& o : kf.objects) {
      if (o.node < 0 || o.node >= n_nodes) {
        return fail(where, "object node " + std::to_string(o.node) + " out of range (the DAG has " +
                               std::to_string(n_nodes) + " nodes)");
      }
      if (!o.X_WA.matrix().allFinite()) {
        return fail(where, "object " + Quote(tree_.nodes[o.node].name) + " has a non-finite pose");
      }
    }
    return {};
  };
  if (auto ok = keyframe("initial keyframe", plan_.initial); !ok) return ok;
  for (size_t i = 0; i < plan_.actions.size(); ++i) {
    const PlanAction& a = plan_.actions[i];
    const std::string where =
        "action " + std::to_string(i) + " (" + std::string(ToString(a.type)) + ")";
    for (int r : a.robots) {
      if (r < 0 || r >= n_robots) {
        return fail(where, "robot index " + std::to_string(r) + " out of range (the project has " +
                               std::to_string(n_robots) + " robots)");
      }
    }
    for (const PlanHold& h : a.grasps) {
      if (h.robot < 0 || h.robot >= n_robots) {
        return fail(where, "grasp robot index " + std::to_string(h.robot) + " out of range");
      }
      if (h.grasp.part < 0 || h.grasp.part >= n_parts) {
        return fail(where, "grasp part index " + std::to_string(h.grasp.part) +
                               " out of range (the project has " + std::to_string(n_parts) +
                               " parts)");
      }
      if (!h.grasp.X_PG.matrix().allFinite() || !std::isfinite(h.grasp.width_m)) {
        return fail(where, "the grasp of robot " + Quote(robots_[h.robot].name) +
                               " has a non-finite pose or width");
      }
    }
    for (int o : a.objects) {
      if (o < 0 || o >= n_nodes) {
        return fail(where, "object node " + std::to_string(o) + " out of range (the DAG has " +
                               std::to_string(n_nodes) + " nodes)");
      }
    }
    if (auto ok = keyframe(where + " keyframe", a.keyframe); !ok) return ok;
    if (a.approach) {
      if (auto ok = keyframe(where + " approach", *a.approach); !ok) return ok;
    }
  }
  return {};
}

void Validator::CheckNames() {
  auto compare = [&](const std::vector<std::string>& in_plan, auto&& name_of, size_t count,
                     const char* what) {
    if (in_plan.empty()) return;
    if (in_plan.size() != count) {
      Issue(-1, "plan",
            std::string("the plan names ") + std::to_string(in_plan.size()) + " " + what +
                ", the project has " + std::to_string(count));
      return;
    }
    for (size_t i = 0; i < count; ++i) {
      if (in_plan[i] != name_of(i)) {
        Issue(-1, "plan",
              std::string(what) + " " + std::to_string(i) + " is " + Quote(in_plan[i]) +
                  " in the plan but " + Quote(name_of(i)) + " in the project");
        return;
      }
    }
  };
  compare(
      plan_.robots, [&](size_t i) { return project_.robots[i].name; }, project_.robots.size(),
      "robots");
  compare(
      plan_.parts, [&](size_t i) { return project_.parts[i].name; }, project_.parts.size(),
      "parts");
  compare(
      plan_.nodes, [&](size_t i) { return tree_.nodes[i].name; }, tree_.nodes.size(), "nodes");
}

const PlanHold* Validator::HoldOf(int node, int robot) const {
  auto it = objects_.find(node);
  if (it == objects_.end()) return nullptr;
  for (const PlanHold& h : it->second.holders) {
    if (h.robot == robot) return &h;
  }
  return nullptr;
}

// The grasp an action names for a robot that already holds `node` must be the one it holds.
bool Validator::GraspMatches(int index, int node, const PlanHold& hold) {
  const PlanHold* held = HoldOf(node, hold.robot);
  if (held == nullptr) {
    Issue(index, "precondition",
          "robot " + Quote(RobotName(hold.robot)) + " does not hold " + Quote(NodeName(node)));
    return false;
  }
  const PoseError e = Difference(held->grasp.X_PG, hold.grasp.X_PG);
  if (held->grasp.part != hold.grasp.part || e.position_m > options_.position_tolerance_m ||
      e.rotation_rad > options_.rotation_tolerance_rad) {
    Issue(index, "precondition",
          "robot " + Quote(RobotName(hold.robot)) + " holds " + Quote(NodeName(node)) +
              " by a grasp on " + Quote(PartName(held->grasp.part)) +
              ", but the action names another grasp (on " + Quote(PartName(hold.grasp.part)) +
              ", " + Mm(e.position_m) + " / " + Deg(e.rotation_rad) + " away)");
    return false;
  }
  return true;
}

void Validator::RequireFree(int index, int robot, std::string_view role) {
  if (holding_[robot] >= 0) {
    Issue(index, "precondition",
          std::string(role) + " " + Quote(RobotName(robot)) + " must be free but holds " +
              Quote(NodeName(holding_[robot])) + " (a robot holds one object at most)");
  }
}

// Takes a robot off whatever it holds (keeps the state sane after a precondition failure).
void Validator::Detach(int robot) {
  const int node = holding_[robot];
  holding_[robot] = -1;
  if (auto it = objects_.find(node); it != objects_.end()) {
    std::erase_if(it->second.holders, [&](const PlanHold& h) { return h.robot == robot; });
  }
}

std::vector<Eigen::Vector2d> Validator::SupportPolygon(int part, const Iso3& X_WP) const {
  const Table& t = project_.table;
  std::vector<Eigen::Vector2d> xy;
  for (const Vec3& v : hull_P_[part]) {
    const Vec3 p_W = X_WP * v;
    if (std::abs(p_W.z() - t.height) <= options_.table_tolerance_m) xy.push_back(p_W.head<2>());
  }
  if (xy.empty()) return {};
  std::vector<Eigen::Vector2d> hull;
  for (int k : ConvexHull2d(xy)) hull.push_back(xy[k]);
  const Eigen::Vector2d half = 0.5 * t.size.head<2>();
  return ClipToRectangle(std::move(hull), t.center_xy.head<2>() - half,
                         t.center_xy.head<2>() + half);
}

void Validator::CheckRest(int index, const std::string& label, int node, const Iso3& X_WA) {
  const Table& t = project_.table;
  double lowest = std::numeric_limits<double>::infinity();
  bool supported = false;
  for (int p : tree_.nodes[node].parts) {
    const Iso3 X_WP = X_WA * X_AP_[p];
    for (const Vec3& v : hull_P_[p]) lowest = std::min(lowest, (X_WP * v).z());
    supported = supported || !SupportPolygon(p, X_WP).empty();
  }
  const double gap = lowest - t.height;
  if (std::abs(gap) > options_.table_tolerance_m) {
    Issue(index, "pose",
          label + Quote(NodeName(node)) + " should rest on the table, but its lowest point is " +
              Mm(std::abs(gap)) + (gap > 0 ? " above" : " below") + " the table top");
  } else if (!supported) {
    Issue(index, "pose",
          label + Quote(NodeName(node)) + " should rest on the table, but it is beside it");
  }
}

Cell* Validator::CellFor(const std::vector<double>& openings) {
  std::vector<long long> key;
  for (double o : openings) key.push_back(o < 0.0 ? -1 : std::llround(o * 1e5));
  if (auto it = cells_.find(key); it != cells_.end()) return &it->second;
  CellDef def;
  for (size_t r = 0; r < robots_.size(); ++r) {
    const RobotModel& m = robots_[r];
    CellRobot robot;
    robot.name = m.name;
    robot.chain = m.chain;
    robot.X_WB = m.X_WB;
    robot.end_effector.name = m.ee.name;
    robot.end_effector.X_FT = m.ee.X_FT;
    robot.end_effector.collision =
        openings[r] < 0.0 ? m.ee.collision : EndEffectorShapesAt(m.ee, openings[r]);
    robot.reference_link_frames = m.reference_frames;
    def.robots.push_back(std::move(robot));
  }
  for (size_t p = 0; p < project_.parts.size(); ++p) {
    def.objects.push_back({project_.parts[p].name, check_.parts[p].mesh, Iso3::Identity()});
  }
  def.table.present = true;
  def.table.size = project_.table.size;
  def.table.top_center =
      Vec3(project_.table.center_xy.x(), project_.table.center_xy.y(), project_.table.height);
  CellOptions options;
  options.objects_touch_table = false;  // decided per keyframe
  auto cell = Cell::Build(def, options);
  if (!cell) {
    if (!cells_failed_) {
      Issue(-1, "collision", "the collision cell could not be built: " + cell.error().message);
    }
    cells_failed_ = true;
    return nullptr;
  }
  return &cells_.emplace(std::move(key), std::move(*cell)).first->second;
}

void Validator::CheckCollisions(int index, const std::string& label, const Keyframe& kf,
                                const Moment& m, const std::map<int, Iso3>& X_WA,
                                const std::vector<std::pair<int, PlanHold>>& holds) {
  const int n_robots = static_cast<int>(robots_.size());
  const int n_parts = static_cast<int>(project_.parts.size());
  std::vector<double> openings(n_robots, -1.0);
  std::vector<int> held_part(n_robots, -1);
  for (const auto& [node, h] : holds) {
    held_part[h.robot] = h.grasp.part;
    if (robots_[h.robot].ee.kind == EndEffectorKind::kTwoFinger) {
      openings[h.robot] = h.grasp.width_m + 2.0 * kFingerClearanceM;
    }
  }
  Cell* cell = CellFor(openings);
  if (cell == nullptr) return;

  std::vector<Iso3> frames;
  for (int r = 0; r < n_robots; ++r) {
    frames.resize(robots_[r].chain.links.size());
    ForwardKinematics(robots_[r].chain, robots_[r].X_WB, kf.q[r], frames);
    cell->SetConfiguration(r, std::span<const double>(kf.q[r].data(), kf.q[r].size()), frames);
  }
  // Each part belongs to one object at this moment.
  std::vector<int> object_of(n_parts, -1);
  for (const auto& [node, X] : X_WA) {
    for (int p : tree_.nodes[node].parts) {
      object_of[p] = node;
      cell->SetObjectPose(p, X * X_AP_[p]);
    }
  }
  auto pair_allowed = [&](int a, int b) {
    if (a == b) return true;
    return std::any_of(m.allowed_pairs.begin(), m.allowed_pairs.end(), [&](const auto& pr) {
      return (pr.first == a && pr.second == b) || (pr.first == b && pr.second == a);
    });
  };
  CollisionWorld& world = cell->world();
  for (int p = 0; p < n_parts; ++p) {
    cell->SetObjectEnabled(p, object_of[p] >= 0);
    for (int s = p + 1; s < n_parts; ++s) {
      cell->SetObjectPairAllowed(
          p, s, object_of[p] >= 0 && object_of[s] >= 0 && pair_allowed(object_of[p], object_of[s]));
    }
    for (int r = 0; r < n_robots; ++r) {
      world.SetAllowed(cell->object_body(p), cell->end_effector_body(r), held_part[r] == p);
    }
    bool touches = false;
    if (object_of[p] >= 0) {
      const int node = object_of[p];
      touches = m.rest_check.count(node) > 0;
      // Any object may touch the table top from above (e.g. a moved input that slides along the
      // table into a resting base, or reaches down to the top when mated), never sink into it.
      double lowest = std::numeric_limits<double>::infinity();
      for (int q : tree_.nodes[node].parts) {
        const Iso3 X_WP = X_WA.at(node) * X_AP_[q];
        for (const Vec3& v : hull_P_[q]) lowest = std::min(lowest, (X_WP * v).z());
      }
      touches = touches || std::abs(lowest - project_.table.height) <= options_.table_tolerance_m;
      if (auto it = objects_.find(node); it != objects_.end() && it->second.at_rest_pose) {
        const PoseError e = Difference(it->second.X_WA, X_WA.at(node));
        touches = touches || (e.position_m <= options_.position_tolerance_m &&
                              e.rotation_rad <= options_.rotation_tolerance_rad);
      }
    }
    world.SetAllowed(cell->object_body(p), cell->table_body(), touches);
  }

  ++out_.collision_checks;
  CollisionRequest request;
  request.all_pairs = true;
  request.max_pairs = 64;
  CollisionResult result;
  if (cell->InCollision(&result, request)) {
    std::set<std::pair<int, int>> seen;
    int reported = 0;
    int more = 0;
    const std::vector<ShapePair>& pairs =
        result.pairs.empty() ? std::vector<ShapePair>{result.first} : result.pairs;
    for (const ShapePair& pair : pairs) {
      const auto key = std::minmax(pair.body_a.value, pair.body_b.value);
      if (!seen.insert(key).second) continue;
      if (reported == kMaxCollisionPairsReported) {
        ++more;
        continue;
      }
      ++reported;
      Issue(index, "collision",
            label + Quote(world.body_name(pair.body_a)) + " collides with " +
                Quote(world.body_name(pair.body_b)) + " (" + cell->Describe(pair) + ")");
    }
    if (more > 0) {
      Issue(index, "collision",
            label + "and " + std::to_string(more) + " more colliding pairs of bodies");
    }
  }

  if (n_robots >= 2) {
    DistanceRequest request_d;
    request_d.nearest_points = false;
    request_d.upper_bound_m = options_.min_clearance_m + 1e-3;
    const DistanceResult d = cell->MinRobotClearance(request_d);
    if (d.distance < options_.min_clearance_m) {
      std::string who;
      if (d.has_pair()) {
        who = " between " + Quote(world.body_name(d.pair.body_a)) + " and " +
              Quote(world.body_name(d.pair.body_b));
      }
      Issue(index, "clearance",
            label + "robots come " + Mm(d.distance) + " close" + who + ", less than the " +
                Mm(options_.min_clearance_m) + " clearance");
    }
  }
}

std::map<int, Iso3> Validator::CheckKeyframe(int index, const std::string& label,
                                             const Keyframe& kf, const Moment& m) {
  ++out_.keyframes;
  const bool initial = index < 0;
  const int n_robots = static_cast<int>(robots_.size());

  // The object list: exactly the objects that exist at this moment.
  std::map<int, const PlanObject*> listed;
  for (const PlanObject& o : kf.objects) {
    if (!listed.emplace(o.node, &o).second) {
      Issue(index, "pose", label + "the keyframe lists " + Quote(NodeName(o.node)) + " twice");
    } else if (!objects_.count(o.node)) {
      Issue(index, "pose",
            label + "the keyframe lists " + Quote(NodeName(o.node)) +
                ", which does not exist as an object at this moment");
    }
  }
  std::map<int, Iso3> X_WA;
  for (const auto& [node, state] : objects_) {
    auto it = listed.find(node);
    if (it == listed.end()) {
      Issue(index, "pose",
            label + "the keyframe does not list the object " + Quote(NodeName(node)));
      X_WA[node] = state.X_WA;
      continue;
    }
    const PlanObject& o = *it->second;
    X_WA[node] = o.X_WA;
    if (auto req = m.required.find(node); req != m.required.end()) {
      const PoseError e = Difference(req->second.first, o.X_WA);
      if (e.position_m > options_.position_tolerance_m ||
          e.rotation_rad > options_.rotation_tolerance_rad) {
        Issue(index, "pose",
              label + Quote(NodeName(node)) + " is " + Mm(e.position_m) + " / " +
                  Deg(e.rotation_rad) + " away from " + req->second.second);
      }
    } else if (!m.moving.count(node)) {
      const PoseError e = Difference(state.X_WA, o.X_WA);
      if (e.position_m > options_.position_tolerance_m ||
          e.rotation_rad > options_.rotation_tolerance_rad) {
        Issue(index, "pose",
              label + Quote(NodeName(node)) + " is " + Mm(e.position_m) + " / " +
                  Deg(e.rotation_rad) +
                  (initial ? " away from its initial pose in the project"
                           : " away from where it was, but the action "
                             "may not move it"));
      }
      // Keep the state's pose: small drifts must not add up over the plan.
      X_WA[node] = state.X_WA;
    }
    if (!m.acted.count(node) && o.resting != state.resting) {
      Issue(index, "pose",
            label + Quote(NodeName(node)) + " is marked " + (o.resting ? "resting" : "in the air") +
                ", but it is " + (state.resting ? "resting" : "in the air"));
    }
  }
  for (int node : m.rest_check) {
    if (X_WA.count(node)) CheckRest(index, label, node, X_WA.at(node));
  }

  // Joints: limits; robots that may not move keep their joints.
  for (int r = 0; r < n_robots; ++r) {
    const RobotModel& robot = robots_[r];
    const JointVector& q = kf.q[r];
    if (!WithinLimits(robot.chain, q, 1e-9)) {
      for (int j = 0; j < robot.chain.dof(); ++j) {
        const Joint& joint = robot.chain.joints[j];
        if (q[j] < joint.lower - 1e-9 || q[j] > joint.upper + 1e-9) {
          Issue(index, "joint_limits",
                label + "robot " + Quote(robot.name) + " joint " + Quote(joint.name) + " at " +
                    Num(q[j]) + " is outside [" + Num(joint.lower) + ", " + Num(joint.upper) + "]");
        }
      }
    }
    if (initial) continue;
    const double moved = JointDistanceMax(robot.chain, q, q_[r], false);
    if (moved <= options_.joint_tolerance) continue;
    const int held = holding_[r];
    if (held >= 0) {
      if (!m.moving.count(held)) {
        Issue(index, "joints",
              label + "robot " + Quote(robot.name) + " holds " + Quote(NodeName(held)) +
                  ", which does not move, yet its joints changed by up to " + Num(moved));
      }
      continue;
    }
    const bool grasps_now = std::any_of(m.new_holds.begin(), m.new_holds.end(),
                                        [&](const auto& nh) { return nh.second.robot == r; });
    const bool at_home =
        JointDistanceMax(robot.chain, q, plan_.initial.q[r], false) <= options_.joint_tolerance;
    if (!grasps_now && !may_move_[r] && !at_home) {
      Issue(index, "joints",
            label + "robot " + Quote(robot.name) +
                " is free and does not act, yet its joints changed by up to " + Num(moved) +
                " and it is not at its home configuration");
    }
  }

  // FK: every grasp held at this moment, the new ones included.
  std::vector<std::pair<int, PlanHold>> holds;
  for (const auto& [node, state] : objects_) {
    for (const PlanHold& h : state.holders) holds.emplace_back(node, h);
  }
  holds.insert(holds.end(), m.new_holds.begin(), m.new_holds.end());
  for (const auto& [node, h] : holds) {
    if (!NodeHasPart(node, h.grasp.part)) continue;  // reported as a precondition
    const RobotModel& robot = robots_[h.robot];
    const Iso3 X_WG = X_WA.at(node) * X_AP_[h.grasp.part] * h.grasp.X_PG;
    const Iso3 X_WT = TcpPose(robot.chain, robot.X_WB, kf.q[h.robot], robot.ee.X_FT);
    const PoseError e = Difference(X_WG, X_WT);
    if (e.position_m > options_.position_tolerance_m ||
        e.rotation_rad > options_.rotation_tolerance_rad) {
      const std::string of = node == h.grasp.part ? "" : " of " + Quote(NodeName(node));
      Issue(index, "fk",
            label + "robot " + Quote(robot.name) + ": the TCP is " + Mm(e.position_m) + " / " +
                Deg(e.rotation_rad) + " away from its grasp on " + Quote(PartName(h.grasp.part)) +
                of + " (allowed " + Mm(options_.position_tolerance_m) + " / " +
                Deg(options_.rotation_tolerance_rad) + ")");
    }
  }

  if (options_.check_collisions) CheckCollisions(index, label, kf, m, X_WA, holds);
  return X_WA;
}

void Validator::AddObject(int node, const Iso3& X_WA, const std::vector<PlanHold>& holders,
                          bool on_table, StepConfiguration& config,
                          std::vector<int>& body_of_part) const {
  const Table& t = project_.table;
  for (int p : tree_.nodes[node].parts) {
    const Iso3 X_WP = X_WA * X_AP_[p];
    body_of_part[p] = static_cast<int>(config.bodies.size());
    config.bodies.push_back(
        {PartName(p), check_.parts[p].mass_kg, X_WP * check_.parts[p].mass_properties.com});
    if (!on_table) continue;
    const std::vector<Eigen::Vector2d> polygon = SupportPolygon(p, X_WP);
    if (polygon.empty()) continue;
    WrenchTableSupport support;
    support.body = body_of_part[p];
    support.friction = t.friction;
    for (const Eigen::Vector2d& v : polygon) support.p_WV.emplace_back(v.x(), v.y(), t.height);
    config.tables.push_back(std::move(support));
  }
  // Connections made by the steps inside the object.
  std::vector<int> stack = {node};
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    const AssemblyNode& an = tree_.nodes[n];
    if (an.step < 0) continue;
    const Interface& f = interfaces_[n];
    if (f.step != nullptr && f.moved_part >= 0) {
      WrenchConnection c;
      c.body_a = body_of_part[f.base_part];
      c.body_b = body_of_part[f.moved_part];
      c.X_WC = X_WA * f.X_AC;
      c.limits = f.limits;
      c.name = an.name;
      config.connections.push_back(c);
    }
    for (int input : an.inputs) stack.push_back(input);
  }
  for (const PlanHold& h : holders) {
    if (!NodeHasPart(node, h.grasp.part)) continue;
    const RobotModel& robot = robots_[h.robot];
    config.grippers.push_back(MakeGripper(robot.name, body_of_part[h.grasp.part],
                                          X_WA * X_AP_[h.grasp.part] * h.grasp.X_PG, robot.ee.kind,
                                          robot.limits));
  }
}

void Validator::RunGate(int index, WrenchGate gate, const StepConfiguration& config,
                        std::string what) {
  if (!options_.check_wrench || options_.wrench_mode == MatingWrenchMode::kNone) return;
  WrenchQuery query;
  query.gate = gate;
  query.mode = options_.wrench_mode;
  query.lambda = options_.force_scale;
  ++out_.wrench_checks;
  const std::string name = "wrench_" + std::string(ToString(gate));
  auto check = checker_->Check(config, query);
  if (!check) {
    Issue(index, name, what + ": the wrench check could not run: " + check.error().message);
    return;
  }
  if (!check->feasible) Issue(index, name, what + ": " + check->reason);
  if (index < 0) return;
  if (out_.utilisation.size() <= static_cast<size_t>(index)) out_.utilisation.resize(index + 1);
  for (const SupportLoad& load : check->supports) {
    if (load.kind != SupportKind::kGripper || !std::isfinite(load.utilisation)) continue;
    const std::string& who = config.grippers[static_cast<size_t>(load.index)].name;
    for (size_t r = 0; r < robots_.size(); ++r) {
      if (robots_[r].name != who) continue;
      double& u = out_.utilisation[static_cast<size_t>(index)][static_cast<int>(r)];
      u = std::max(u, load.utilisation);
    }
  }
}

bool Validator::ActionShapeOk(int index, const PlanAction& a) {
  size_t robots = 1, objects = 1;
  switch (a.type) {
    case ActionType::kHandover:
      robots = 2;
      break;
    case ActionType::kAssemble:
      robots = a.robots.empty() ? 1 : a.robots.size();
      objects = 3;
      break;
    default:
      break;
  }
  if (a.robots.size() != robots || a.objects.size() != objects || a.grasps.size() != robots) {
    Issue(index, "precondition",
          std::string(ToString(a.type)) + " is malformed: " + std::to_string(a.robots.size()) +
              " robots, " + std::to_string(a.objects.size()) + " objects and " +
              std::to_string(a.grasps.size()) + " grasps (expected " + std::to_string(robots) +
              ", " + std::to_string(objects) + ", " + std::to_string(robots) +
              "); the replay stops here");
    return false;
  }
  std::set<int> distinct(a.robots.begin(), a.robots.end());
  if (distinct.size() != a.robots.size()) {
    Issue(index, "precondition", "a robot appears twice in the action's robots");
  }
  for (size_t k = 0; k < a.robots.size(); ++k) {
    if (a.grasps[k].robot != a.robots[k]) {
      Issue(index, "precondition",
            "grasp " + std::to_string(k) + " belongs to robot " +
                Quote(RobotName(a.grasps[k].robot)) + ", but the action's robot " +
                std::to_string(k) + " is " + Quote(RobotName(a.robots[k])));
    }
  }
  for (size_t k = 0; k < objects; ++k) {
    const int o = a.objects[k];
    const bool result = a.type == ActionType::kAssemble && k == 2;
    if (!result && !objects_.count(o)) {
      Issue(index, "precondition",
            Quote(NodeName(o)) + " does not exist as an object at this point of the plan (it " +
                (tree_.nodes[o].step >= 0 ? "has not been assembled yet or " : "") +
                "is part of a larger object); the replay stops here");
      return false;
    }
  }
  return true;
}

void Validator::ReplayAction(int i) {
  const PlanAction& a = plan_.actions[i];
  if (!ActionShapeOk(i, a)) return;
  freed_now_.clear();
  const Keyframe& kf = a.keyframe;
  const int o = a.objects[0];
  Moment m;
  m.acted.insert(a.objects.begin(), a.objects.end());
  std::map<int, Iso3> X;

  switch (a.type) {
    case ActionType::kPick: {
      const int r = a.robots[0];
      const PlanHold& g = a.grasps[0];
      ObjectState& obj = objects_[o];
      if (!obj.resting) {
        Issue(i, "precondition", "pick: " + Quote(NodeName(o)) + " is in the air, not resting");
      }
      if (!obj.holders.empty()) {
        Issue(i, "precondition",
              "pick: " + Quote(NodeName(o)) + " is already held by " +
                  Quote(RobotName(obj.holders[0].robot)));
      }
      RequireFree(i, r, "the picking robot");
      if (!NodeHasPart(o, g.grasp.part)) {
        Issue(i, "precondition",
              "the grasp is on " + Quote(PartName(g.grasp.part)) + ", which is not a part of " +
                  Quote(NodeName(o)));
      }
      m.new_holds.emplace_back(o, g);
      X = CheckKeyframe(i, "", kf, m);
      StepConfiguration config;
      std::vector<int> body(project_.parts.size(), -1);
      AddObject(o, X.at(o), {g}, false, config, body);
      RunGate(i, WrenchGate::kTransport, config,
              Quote(RobotName(r)) + " carrying " + Quote(NodeName(o)));
      Detach(r);
      ObjectState& after = objects_[o];
      after.resting = false;
      after.holders = {g};
      holding_[r] = o;
      break;
    }
    case ActionType::kPlace: {
      const int r = a.robots[0];
      ObjectState& obj = objects_[o];
      if (obj.resting) {
        Issue(i, "precondition", "place: " + Quote(NodeName(o)) + " already rests on the table");
      }
      if (obj.holders.size() != 1 || obj.holders[0].robot != r) {
        Issue(i, "precondition",
              "place: " + Quote(RobotName(r)) + " must be the only holder of " +
                  Quote(NodeName(o)) + " (it has " + std::to_string(obj.holders.size()) +
                  " holders)");
      }
      GraspMatches(i, o, a.grasps[0]);
      m.moving.insert(o);
      m.rest_check.insert(o);
      X = CheckKeyframe(i, "", kf, m);
      StepConfiguration config;
      std::vector<int> body(project_.parts.size(), -1);
      AddObject(o, X.at(o), {}, true, config, body);
      RunGate(i, WrenchGate::kRest, config, Quote(NodeName(o)) + " set down on the table");
      if (obj.holders.size() == 1) {
        // Carried down to the table by its holder alone.
        StepConfiguration carried;
        std::vector<int> carried_body(project_.parts.size(), -1);
        AddObject(o, X.at(o), {obj.holders[0]}, false, carried, carried_body);
        RunGate(i, WrenchGate::kTransport, carried,
                Quote(RobotName(r)) + " carrying " + Quote(NodeName(o)) + " down to the table");
      }
      for (const PlanHold& h : objects_[o].holders) {
        holding_[h.robot] = -1;
        freed_now_.insert(h.robot);
      }
      ObjectState& after = objects_[o];
      after.X_WA = X.at(o);
      after.resting = true;
      after.at_rest_pose = true;
      after.holders.clear();
      break;
    }
    case ActionType::kHandover: {
      const int giver = a.robots[0];
      const int receiver = a.robots[1];
      const PlanHold& g2 = a.grasps[1];
      ObjectState& obj = objects_[o];
      if (obj.resting) {
        Issue(i, "precondition", "handover: " + Quote(NodeName(o)) + " rests on the table");
      }
      if (obj.holders.size() != 1 || obj.holders[0].robot != giver) {
        Issue(i, "precondition",
              "handover: the giver " + Quote(RobotName(giver)) + " must be the only holder of " +
                  Quote(NodeName(o)));
      }
      GraspMatches(i, o, a.grasps[0]);
      RequireFree(i, receiver, "the receiver");
      if (!NodeHasPart(o, g2.grasp.part)) {
        Issue(i, "precondition",
              "the receiver's grasp is on " + Quote(PartName(g2.grasp.part)) +
                  ", which is not a part of " + Quote(NodeName(o)));
      }
      m.moving.insert(o);
      m.new_holds.emplace_back(o, g2);
      X = CheckKeyframe(i, "", kf, m);
      StepConfiguration config;
      std::vector<int> body(project_.parts.size(), -1);
      AddObject(o, X.at(o), {g2}, false, config, body);
      RunGate(i, WrenchGate::kTransport, config,
              Quote(RobotName(receiver)) + " carrying " + Quote(NodeName(o)) + " alone");
      const bool moved =
          Difference(objects_[o].X_WA, X.at(o)).position_m > options_.position_tolerance_m;
      for (const PlanHold& h : objects_[o].holders) {
        holding_[h.robot] = -1;
        freed_now_.insert(h.robot);
      }
      Detach(receiver);
      ObjectState& after = objects_[o];
      after.X_WA = X.at(o);
      after.at_rest_pose = after.at_rest_pose && !moved;
      after.holders = {g2};
      holding_[receiver] = o;
      freed_now_.erase(receiver);
      break;
    }
    case ActionType::kAddGrasp: {
      const int r = a.robots[0];
      const PlanHold& g = a.grasps[0];
      ObjectState& obj = objects_[o];
      RequireFree(i, r, "the bracing robot");
      if (!obj.resting && obj.holders.empty()) {
        Issue(i, "precondition",
              "add_grasp: " + Quote(NodeName(o)) + " is neither resting nor held");
      }
      if (!NodeHasPart(o, g.grasp.part)) {
        Issue(i, "precondition",
              "the grasp is on " + Quote(PartName(g.grasp.part)) + ", which is not a part of " +
                  Quote(NodeName(o)));
      }
      if (!obj.resting) m.moving.insert(o);
      m.new_holds.emplace_back(o, g);
      X = CheckKeyframe(i, "", kf, m);
      std::vector<PlanHold> all = objects_[o].holders;
      all.push_back(g);
      StepConfiguration config;
      std::vector<int> body(project_.parts.size(), -1);
      AddObject(o, X.at(o), all, objects_[o].resting, config, body);
      RunGate(i, WrenchGate::kRelease, config,
              Quote(NodeName(o)) + " held still by " + std::to_string(all.size()) + " robots" +
                  (objects_[o].resting ? " and the table" : ""));
      Detach(r);
      ObjectState& after = objects_[o];
      if (!after.resting) {
        after.at_rest_pose = after.at_rest_pose && Difference(after.X_WA, X.at(o)).position_m <=
                                                       options_.position_tolerance_m;
        after.X_WA = X.at(o);
      }
      after.holders.push_back(g);
      holding_[r] = o;
      break;
    }
    case ActionType::kRelease: {
      const int r = a.robots[0];
      ObjectState& obj = objects_[o];
      const bool holds = GraspMatches(i, o, a.grasps[0]) || HoldOf(o, r) != nullptr;
      if (holds && !obj.resting && obj.holders.size() < 2) {
        Issue(i, "precondition",
              "release: " + Quote(NodeName(o)) + " is in the air and " + Quote(RobotName(r)) +
                  " is its only holder: it would fall");
      }
      X = CheckKeyframe(i, "", kf, m);
      std::vector<PlanHold> remaining;
      for (const PlanHold& h : objects_[o].holders) {
        if (h.robot != r) remaining.push_back(h);
      }
      StepConfiguration config;
      std::vector<int> body(project_.parts.size(), -1);
      const bool resting = objects_[o].resting;
      AddObject(o, X.at(o), remaining, resting, config, body);
      if (!remaining.empty()) {
        RunGate(i, WrenchGate::kRelease, config,
                Quote(NodeName(o)) + " held by the remaining " + std::to_string(remaining.size()) +
                    " robot(s)" + (resting ? " and the table" : ""));
      } else if (resting) {
        RunGate(i, WrenchGate::kRest, config, Quote(NodeName(o)) + " left on the table");
      }
      if (holding_[r] == o) {
        Detach(r);
        freed_now_.insert(r);
      }
      break;
    }
    case ActionType::kAssemble: {
      const int M = a.objects[0];
      const int B = a.objects[1];
      if (M == B) {
        Issue(i, "precondition",
              "assemble: the moved and the base input are the same object " + Quote(NodeName(M)) +
                  "; the replay stops here");
        return;
      }
      int S = -1;
      for (size_t n = 0; n < tree_.nodes.size(); ++n) {
        const std::vector<int>& in = tree_.nodes[n].inputs;
        if (in.size() == 2 && ((in[0] == M && in[1] == B) || (in[0] == B && in[1] == M))) {
          S = static_cast<int>(n);
        }
      }
      if (S < 0) {
        Issue(i, "precondition",
              "assemble: " + Quote(NodeName(M)) + " and " + Quote(NodeName(B)) +
                  " are not the two inputs of any assembly step; the replay "
                  "stops here");
        return;
      }
      if (a.objects[2] != S) {
        Issue(i, "precondition",
              "assemble: joining " + Quote(NodeName(M)) + " and " + Quote(NodeName(B)) +
                  " builds " + Quote(NodeName(S)) + ", not " + Quote(NodeName(a.objects[2])));
      }
      const Interface& f = interfaces_[S];
      if (f.moved_node != M) {
        Issue(i, "precondition",
              "assemble: step " + Quote(NodeName(S)) + " moves " + Quote(NodeName(f.moved_node)) +
                  " onto " + Quote(NodeName(f.base_node)) + ", the plan the other way");
      }
      const ObjectState& mo = objects_[M];
      const ObjectState& bo = objects_[B];
      if (mo.resting) {
        Issue(i, "precondition",
              "assemble: the moved input " + Quote(NodeName(M)) +
                  " rests on the table; it must be held in the air");
      }
      if (mo.holders.empty()) {
        Issue(i, "precondition", "assemble: nothing holds the moved input " + Quote(NodeName(M)));
      }
      if (!bo.resting && bo.holders.empty()) {
        Issue(i, "precondition",
              "assemble: the base input " + Quote(NodeName(B)) + " is neither resting nor held");
      }
      std::set<int> expected, named(a.robots.begin(), a.robots.end());
      for (const PlanHold& h : mo.holders) expected.insert(h.robot);
      for (const PlanHold& h : bo.holders) expected.insert(h.robot);
      if (expected != named) {
        Issue(i, "precondition",
              "assemble: the action's robots must be exactly those holding " + Quote(NodeName(M)) +
                  " or " + Quote(NodeName(B)));
      }
      for (const PlanHold& h : a.grasps) {
        if (holding_[h.robot] == M || holding_[h.robot] == B) GraspMatches(i, holding_[h.robot], h);
      }
      const bool base_moves = !bo.resting;
      m.moving.insert(M);
      if (base_moves) m.moving.insert(B);

      // B where the keyframe puts it (the state's pose when it may not move or is not listed).
      Iso3 X_WB = bo.X_WA;
      if (base_moves) {
        for (const PlanObject& po : kf.objects) {
          if (po.node == B) X_WB = po.X_WA;
        }
      }
      if (a.approach) {
        Moment ap = m;
        Iso3 X_WM_ap = X_WB;
        X_WM_ap.translation() -= f.step->mating.approach_m * (X_WB.linear() * f.axis_A);
        ap.required[M] = {X_WM_ap, "its approach pose (" + Mm(f.step->mating.approach_m) +
                                       " back along the insertion axis from " + Quote(NodeName(B)) +
                                       ")"};
        if (base_moves) ap.required[B] = {X_WB, "its pose at the assemble keyframe"};
        // Along the insertion the moved input may slide on the base (touching faces).
        ap.allowed_pairs.emplace_back(M, B);
        CheckKeyframe(i, "approach: ", *a.approach, ap);
      } else {
        Issue(i, "pose", "assemble has no approach keyframe");
      }
      CheckInsertionPath(i, f, X_WB);
      m.allowed_pairs.emplace_back(M, B);
      m.required[M] = {X_WB, "its mating pose on " + Quote(NodeName(B)) + " (X_WM = X_WB)"};
      X = CheckKeyframe(i, "", kf, m);

      StepConfiguration config;
      std::vector<int> body(project_.parts.size(), -1);
      // The moved input rests on the table where it touches it (a part slid along the table
      // into a resting base): its parts that reach the top get their support polygons.
      AddObject(M, X.at(M), objects_[M].holders, true, config, body);
      AddObject(B, X.at(B), objects_[B].holders, objects_[B].resting, config, body);
      if (f.moved_part >= 0 && body[f.moved_part] >= 0 && body[f.base_part] >= 0) {
        config.mating = MatingLoadFromProject(f.step->mating, X.at(B), body[f.moved_part],
                                              body[f.base_part], X.at(B) * f.p_A);
      }
      RunGate(i, WrenchGate::kAssembly, config,
              "mating " + Quote(NodeName(M)) + " onto " + Quote(NodeName(B)));

      ObjectState s;
      s.X_WA = X.at(B);
      s.resting = objects_[B].resting;
      s.at_rest_pose =
          objects_[B].at_rest_pose &&
          Difference(objects_[B].X_WA, X.at(B)).position_m <= options_.position_tolerance_m;
      s.holders = objects_[M].holders;
      s.holders.insert(s.holders.end(), objects_[B].holders.begin(), objects_[B].holders.end());
      objects_.erase(M);
      objects_.erase(B);
      for (const PlanHold& h : s.holders) holding_[h.robot] = S;
      objects_[S] = std::move(s);
      break;
    }
  }

  // Objects the action moved take their keyframe pose (set above); the robots take their joints.
  q_ = kf.q;
  for (size_t r = 0; r < robots_.size(); ++r) may_move_[r] = freed_now_.count(static_cast<int>(r));
  ++out_.actions;
}

void Validator::CheckInitial() {
  // Every part rests at its initial pose; robots at home (the plan's initial joints).
  for (size_t p = 0; p < project_.parts.size(); ++p) {
    ObjectState s;
    s.X_WA = ToIsometry(project_.parts[p].initial_pose) * X_AP_[p].inverse();
    objects_[static_cast<int>(p)] = s;
  }
  q_ = plan_.initial.q;
  holding_.assign(robots_.size(), -1);
  may_move_.assign(robots_.size(), 0);
  Moment m;
  for (const auto& [node, s] : objects_) m.rest_check.insert(node);
  CheckKeyframe(-1, "initial keyframe: ", plan_.initial, m);
}

PlanValidation Validator::Run() {
  CheckNames();
  CheckInitial();
  const int n_actions = static_cast<int>(plan_.actions.size());
  bool stopped = false;
  for (int i = 0; i < n_actions; ++i) {
    const int before = out_.actions;
    ReplayAction(i);
    if (out_.actions == before) {
      stopped = true;
      break;
    }
  }
  if (options_.require_complete && !stopped) {
    const int last = n_actions - 1;
    const int root = tree_.root;
    if (objects_.size() != 1 || !objects_.count(root)) {
      std::string names;
      for (const auto& [node, s] : objects_)
        names += (names.empty() ? "" : ", ") + Quote(NodeName(node));
      Issue(last, "incomplete",
            "the plan ends with " + std::to_string(objects_.size()) + " objects (" + names +
                "), not with the assembly " + Quote(NodeName(root)) + " alone");
    } else if (!objects_.at(root).resting) {
      Issue(last, "incomplete",
            "the plan ends with " + Quote(NodeName(root)) +
                " in the air instead of resting on the table");
    }
    for (size_t r = 0; r < robots_.size(); ++r) {
      if (holding_[r] >= 0) {
        Issue(last, "incomplete",
              "the plan ends with robot " + Quote(robots_[r].name) + " still holding " +
                  Quote(NodeName(holding_[r])));
      }
    }
  }
  out_.valid = out_.issues.empty();
  return std::move(out_);
}

}  // namespace

Result<void> AnnotateUtilisation(const Project& project, const ProjectCheck& check, Plan& plan,
                                 const std::filesystem::path& project_file) {
  PlanValidationOptions options;
  options.check_collisions = false;
  options.wrench_mode = MatingWrenchMode::kFull;
  options.force_scale = plan.stats.force_scale;
  options.require_complete = false;
  auto v = ValidatePlan(project, check, plan, options, project_file);
  if (!v) return std::unexpected(v.error());
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    plan.actions[i].utilisation =
        i < v->utilisation.size() ? v->utilisation[i] : std::map<int, double>{};
  }
  return {};
}

Result<PlanValidation> ValidatePlan(const Project& project, const ProjectCheck& check,
                                    const Plan& plan, const PlanValidationOptions& options,
                                    const std::filesystem::path& project_file) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(options.position_tolerance_m) || !positive(options.rotation_tolerance_rad) ||
      !positive(options.table_tolerance_m) || !(options.joint_tolerance >= 0.0) ||
      !std::isfinite(options.joint_tolerance) || !(options.min_clearance_m >= 0.0) ||
      !std::isfinite(options.min_clearance_m) || !(options.force_scale >= 0.0) ||
      !std::isfinite(options.force_scale)) {
    return Fail(ErrorCode::kInvalidInput,
                "plan validator: tolerances must be positive and finite, the clearance and the "
                "force scale non-negative and finite");
  }
  if (!check.tree) {
    return Fail(ErrorCode::kInvalidInput,
                "plan validator: the project has no usable assembly DAG (run 'wrap validate')");
  }
  if (check.parts.size() != project.parts.size()) {
    return Fail(ErrorCode::kInvalidInput,
                "plan validator: the project check does not match the project's parts");
  }
  for (size_t p = 0; p < project.parts.size(); ++p) {
    if (!check.parts[p].loaded) {
      return Fail(ErrorCode::kInvalidInput, "plan validator: part " + Quote(project.parts[p].name) +
                                                ": mesh '" + project.parts[p].mesh +
                                                "' is not loaded (run 'wrap validate')");
    }
  }
  Validator validator(project, check, plan, options);
  if (auto ok = validator.Setup(project_file); !ok) return std::unexpected(ok.error());
  if (auto ok = validator.CheckInterpretable(); !ok) return std::unexpected(ok.error());
  return validator.Run();
}

}  // namespace wrap
