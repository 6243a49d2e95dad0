#include "motion/scene.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "robot/kinematics.h"

namespace wrap {

namespace {
// The grasp sampler's clearance on each side of a two-finger grasp (as the planner and the
// validator open the fingers) [m].
constexpr double kFingerClearanceM = 1e-3;
}  // namespace

double GraspOpening(const TaskRobot& robot, const PlanGrasp& grasp) {
  if (robot.end_effector.kind != EndEffectorKind::kTwoFinger) return -1.0;
  return grasp.width_m + 2.0 * kFingerClearanceM;
}

Result<MotionScene> MotionScene::Build(const TaskWorld& world) {
  MotionScene scene;
  scene.world_ = &world;
  scene.frames_.resize(world.robots.size());
  for (size_t r = 0; r < world.robots.size(); ++r) {
    scene.frames_[r].resize(world.robots[r].chain.links.size());
  }
  scene.object_of_part_.assign(world.num_parts, -1);
  // The fully open cell first: it is the one most segments use, and it reports a bad cell early.
  std::vector<double> open(world.robots.size(), -1.0);
  PlanState empty;
  empty.held.assign(world.robots.size(), -1);
  empty.grasp.resize(world.robots.size());
  std::vector<JointVector> home;
  for (const TaskRobot& r : world.robots) home.push_back(r.home);
  if (auto ok = scene.Set(empty, open, home); !ok) return std::unexpected(ok.error());
  return scene;
}

Result<void> MotionScene::Set(const PlanState& state, std::span<const double> openings,
                              std::span<const JointVector> q,
                              const std::vector<std::pair<int, int>>& mating,
                              const std::vector<int>& table_ok,
                              const std::vector<std::pair<int, int>>& gripper_ok) {
  const TaskWorld& w = *world_;
  const int n_robots = static_cast<int>(w.robots.size());
  std::vector<long long> key;
  for (double o : openings) key.push_back(o < 0.0 ? -1 : std::llround(o * 1e5));
  auto it = cells_.find(key);
  if (it == cells_.end()) {
    CellDef def = w.cell_def;
    // The task world's cell leaves the fingers out (the task planner moves them as bodies of
    // their own): here they are part of the gripper, fully open or at the opening.
    for (int r = 0; r < n_robots; ++r) {
      const EndEffector& ee = w.robots[r].end_effector;
      def.robots[r].end_effector.collision =
          openings[r] >= 0.0 ? EndEffectorShapesAt(ee, openings[r]) : ee.collision;
    }
    CellOptions options;
    options.objects_touch_table = false;  // decided per state below
    auto cell = Cell::Build(def, options);
    if (!cell) {
      return Fail(ErrorCode::kInvalidInput,
                  "the motion planner's collision cell does not build: " + cell.error().message);
    }
    it = cells_.emplace(key, std::move(*cell)).first;
  }
  cell_ = &it->second;
  Cell& cell = *cell_;
  CollisionWorld& cw = cell.world();

  // Detach everything, then attach what is held.
  for (int p = 0; p < w.num_parts; ++p) {
    for (int r = 0; r < n_robots; ++r) cell.Detach(p, r);
  }
  std::fill(object_of_part_.begin(), object_of_part_.end(), -1);
  for (const auto& [node, o] : state.objects) {
    for (int p : w.tree->nodes[node].parts) {
      object_of_part_[p] = node;
      cell.SetObjectPose(p, o.X_WA * w.X_AP[p]);
    }
  }
  for (int r = 0; r < n_robots; ++r) {
    const JointVector& qr = q[r];
    ForwardKinematics(w.robots[r].chain, w.robots[r].X_WB, qr, frames_[r]);
    cell.SetConfiguration(r, std::span<const double>(qr.data(), qr.size()), frames_[r]);
  }
  auto allowed_nodes = [&](int a, int b) {
    if (a == b) return true;
    return std::any_of(mating.begin(), mating.end(), [&](const auto& pr) {
      return (pr.first == a && pr.second == b) || (pr.first == b && pr.second == a);
    });
  };
  for (int p = 0; p < w.num_parts; ++p) {
    const int node = object_of_part_[p];
    cell.SetObjectEnabled(p, node >= 0);
    for (int s = p + 1; s < w.num_parts; ++s) {
      cell.SetObjectPairAllowed(
          p, s, node >= 0 && object_of_part_[s] >= 0 && allowed_nodes(node, object_of_part_[s]));
    }
    bool table = false;
    if (node >= 0) {
      table = state.objects.at(node).resting ||
              std::find(table_ok.begin(), table_ok.end(), node) != table_ok.end();
    }
    cw.SetAllowed(cell.object_body(p), cell.table_body(), table);
    for (int r = 0; r < n_robots; ++r) {
      const bool ok = std::any_of(gripper_ok.begin(), gripper_ok.end(), [&](const auto& pr) {
        return pr.first == r && pr.second == node;
      });
      cw.SetAllowed(cell.object_body(p), cell.end_effector_body(r), ok);
    }
  }
  // Held objects follow their first holder, at the grasp (exact, not the IK's residual).
  for (const auto& [node, o] : state.objects) {
    const std::vector<int> holders = state.Holders(node);
    for (size_t k = 0; k < holders.size(); ++k) {
      const int r = holders[k];
      const PlanGrasp& g = state.grasp[r];
      const Iso3 X_AT = w.X_AP[g.part] * g.X_PG;
      for (int p : w.tree->nodes[node].parts) {
        if (k == 0) {
          cell.Attach(p, r, X_AT.inverse() * w.X_AP[p]);
        } else {
          cell.Attach(p, r);
        }
      }
    }
  }
  for (int r = 0; r < n_robots; ++r) SetRobot(r, q[r]);
  return {};
}

void MotionScene::SetRobot(int robot, const JointVector& q) {
  const TaskRobot& r = world_->robots[robot];
  ForwardKinematics(r.chain, r.X_WB, q, frames_[robot]);
  cell_->SetConfiguration(robot, std::span<const double>(q.data(), q.size()), frames_[robot]);
}

bool MotionScene::Collides(std::span<const int> robots, double margin_m) {
  CollisionRequest request;
  request.margin_m = margin_m;
  if (!robots.empty()) {
    request.group_mask = std::uint64_t{1} << kCellObjectGroup;
    for (int r : robots) {
      request.group_mask |= std::uint64_t{1} << CellLinkGroup(r);
      request.group_mask |= std::uint64_t{1} << CellEndEffectorGroup(r);
    }
  }
  return cell_->InCollision(nullptr, request);
}

void MotionScene::AppendBoxes(int robot, std::vector<Aabb>& out) {
  CollisionWorld& cw = cell_->world();
  const int links = static_cast<int>(world_->robots[robot].chain.links.size());
  for (int i = 1; i < links; ++i) out.push_back(cw.body_aabb(cell_->link_body(robot, i)));
  out.push_back(cw.body_aabb(cell_->end_effector_body(robot)));
  for (int p = 0; p < world_->num_parts; ++p) {
    if (object_of_part_[p] >= 0 && cell_->carrier(p) == robot) {
      out.push_back(cw.body_aabb(cell_->object_body(p)));
    }
  }
}

void MotionScene::AppendObjectBoxes(int node, std::vector<Aabb>& out) {
  CollisionWorld& cw = cell_->world();
  for (int p : world_->tree->nodes[node].parts) {
    if (object_of_part_[p] == node) out.push_back(cw.body_aabb(cell_->object_body(p)));
  }
}

}  // namespace wrap
