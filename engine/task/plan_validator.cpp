// The independent plan validator's front door: ValidatePlan and AnnotateUtilisation, the checks
// of the plan's names and indices, and the validator's own model of the project. It shares no
// code with the search (engine/task/world.h and friends): the robots, the part geometry, the step
// interfaces, the collision cells and the wrench configurations are built here again from the
// project, so a mistake in the planner's model is not repeated here. The keyframe checks are in
// plan_validator_keyframe.cpp, the replay of the actions in plan_validator_replay.cpp. See
// plan_validator.h for what is checked and task/plan.h for the contract.
#include "task/plan_validator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "geometry/convex_hull.h"
#include "robot/home.h"
#include "task/plan_validator_internal.h"

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

namespace plan_validator_internal {

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

PoseError Difference(const Iso3& a, const Iso3& b) {
  PoseError e;
  e.position_m = (a.translation() - b.translation()).norm();
  const Mat3 R = a.linear().transpose() * b.linear();
  e.rotation_rad = std::acos(std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0));
  return e;
}

namespace {

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

}  // namespace

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
  SetupParts();
  SetupInterfaces();
  checker_.emplace(WrenchOptions{});
  geometry_.emplace(AssemblyGeometry::FromProject(project_, check_));
  return {};
}

// Parts: assembled poses, hull vertices (table supports, lowest points), boxes in A.
void Validator::SetupParts() {
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
}

// Step interfaces: the pair of parts, one per input, whose boxes (grown by 1 mm) overlap most.
void Validator::SetupInterfaces() {
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

}  // namespace plan_validator_internal

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
      return Fail(ErrorCode::kInvalidInput,
                  "plan validator: part " + plan_validator_internal::Quote(project.parts[p].name) +
                      ": mesh '" + project.parts[p].mesh + "' is not loaded (run 'wrap validate')");
    }
  }
  plan_validator_internal::Validator validator(project, check, plan, options);
  if (auto ok = validator.Setup(project_file); !ok) return std::unexpected(ok.error());
  if (auto ok = validator.CheckInterpretable(); !ok) return std::unexpected(ok.error());
  return validator.Run();
}

}  // namespace wrap
