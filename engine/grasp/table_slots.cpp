#include "grasp/table_slots.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "grasp/detail/parallel.h"
#include "model/catalog.h"
#include "model/validate.h"
#include "robot/catalog.h"
#include "robot/ik.h"
#include "robot/project_chain.h"

namespace wrap {

namespace {

// A robot as the slot search needs it.
struct ReachRobot {
  Chain chain;
  Iso3 X_WB = Iso3::Identity();
  Iso3 X_FT = Iso3::Identity();
  std::optional<UrAnalyticIk> ur;
  double reach_m = std::numeric_limits<double>::infinity();  // horizontal pre-filter
};

Result<ReachRobot> LoadReachRobot(const Project& project, const std::filesystem::path& file,
                                  const Robot& robot) {
  ReachRobot out;
  auto chain = LoadProjectChain(project, robot, file, false);
  if (!chain) return std::unexpected(chain.error());
  out.chain = std::move(*chain);
  if (const RobotModelInfo* info = robot.model.empty() ? nullptr : FindRobotModel(robot.model)) {
    out.reach_m = info->reach_m + 0.05;  // the catalog's flange reach, plus a little slack
  }
  auto ee = LoadEndEffector(robot.end_effector);
  if (!ee) return std::unexpected(ee.error());
  out.X_FT = ee->X_FT;
  out.X_WB = RobotBaseInWorld(project, robot);
  if (auto ur = UrAnalyticIk::FromChain(out.chain)) out.ur = *ur;
  return out;
}

}  // namespace

Iso3 PlacementPose(const TableSlot& slot, double yaw_rad, const StablePlacement& placement) {
  Iso3 X_WT = Iso3::Identity();
  X_WT.linear() = Eigen::AngleAxisd(yaw_rad, Vec3::UnitZ()).toRotationMatrix();
  X_WT.translation() = slot.p_W;
  return X_WT * placement.X_TA;
}

Result<TableSlots> ComputeTableSlots(const Project& project,
                                     const std::filesystem::path& project_file,
                                     const TableSlotOptions& options, std::uint64_t seed,
                                     RunContext& ctx) {
  TableSlots out;
  for (int k = 0; k < std::max(1, options.yaws); ++k) {
    out.yaws_rad.push_back(2.0 * std::numbers::pi * k / std::max(1, options.yaws));
  }
  if (options.num_slots <= 0 || project.robots.empty()) return out;
  if (!(options.grid_step_m > 0.0)) {
    return Fail(ErrorCode::kInvalidInput, "table slots: grid step must be positive");
  }
  std::vector<ReachRobot> robots;
  for (const Robot& r : project.robots) {
    auto loaded = LoadReachRobot(project, project_file, r);
    if (!loaded) {
      return Fail(loaded.error().code,
                  "table slots: robot '" + r.name + "': " + loaded.error().message);
    }
    robots.push_back(std::move(*loaded));
  }

  // Candidate grid over the table top, centred, less the edge margin and the robots' bases.
  const Table& t = project.table;
  const double half_x = 0.5 * t.size.x() - options.edge_margin_m;
  const double half_y = 0.5 * t.size.y() - options.edge_margin_m;
  const int nx = half_x > 0 ? static_cast<int>(std::floor(half_x / options.grid_step_m)) : -1;
  const int ny = half_y > 0 ? static_cast<int>(std::floor(half_y / options.grid_step_m)) : -1;
  std::vector<Vec3> candidates;
  for (int i = -nx; i <= nx; ++i) {
    for (int j = -ny; j <= ny; ++j) {
      const Vec3 p(t.center_xy.x() + i * options.grid_step_m,
                   t.center_xy.y() + j * options.grid_step_m, t.height);
      bool clear = true;
      for (const ReachRobot& r : robots) {
        clear = clear && (p - r.X_WB.translation()).head<2>().norm() >= options.base_clearance_m;
      }
      if (clear) candidates.push_back(p);
    }
  }
  out.candidates = static_cast<int>(candidates.size());

  // reach[r][c]: robot r reaches candidate c from above. One task per robot, own generator.
  const int nr = static_cast<int>(robots.size());
  const int nc = static_cast<int>(candidates.size());
  std::vector<std::vector<char>> reach(nr, std::vector<char>(nc, 0));
  detail::ParallelFor(nr, options.parallel, [&](int r) {
    const ReachRobot& robot = robots[r];
    std::mt19937_64 rng(seed ^ (0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(r + 1)));
    NumericIkOptions ik;
    std::optional<JointVector> warm;
    const Iso3 X_BW = robot.X_WB.inverse();
    for (int c = 0; c < nc; ++c) {
      if (ctx.ShouldStop()) return;
      const Vec3& p = candidates[c];
      if ((p - robot.X_WB.translation()).head<2>().norm() > robot.reach_m) continue;
      const int yaws = std::max(1, options.probe_yaws);
      for (int k = 0; k < yaws && !reach[r][c]; ++k) {
        Iso3 X_WT = Iso3::Identity();
        X_WT.linear() = (Eigen::AngleAxisd(2.0 * std::numbers::pi * k / yaws, Vec3::UnitZ()) *
                         Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()))
                            .toRotationMatrix();
        X_WT.translation() = p + Vec3(0, 0, options.probe_height_m);
        const Iso3 X_BT = X_BW * X_WT;
        if (robot.ur) {
          reach[r][c] = robot.ur->SolveTcp(X_BT, robot.X_FT).count > 0;
          continue;
        }
        NumericIkRequest request;
        request.X_BT = X_BT;
        request.X_FT = robot.X_FT;
        if (warm) request.seeds.push_back(*warm);
        // Random restarts for the first yaw only; the other yaws start from the last solution
        // (neighbouring grid points): an unreachable point then costs a few hundred iterations.
        ik.restarts = k == 0 || !warm ? options.numeric_ik_restarts : 0;
        if (auto sol = SolveNumericIk(robot.chain, request, rng, ik)) {
          reach[r][c] = 1;
          warm = sol->q;
        }
      }
    }
  });
  if (ctx.ShouldStop()) {
    return Fail(ctx.cancelled() ? ErrorCode::kCancelled : ErrorCode::kTimeout,
                "table slots: stopped during the reachability search");
  }

  // Eligible candidates: reached by min_robots, else by as many as any candidate is.
  std::vector<int> count(nc, 0);
  int best = 0;
  for (int c = 0; c < nc; ++c) {
    for (int r = 0; r < nr; ++r) count[c] += reach[r][c];
    best = std::max(best, count[c]);
  }
  const int need = std::max(1, std::min(options.min_robots, best));
  std::vector<int> eligible;
  for (int c = 0; c < nc; ++c) {
    if (count[c] >= need) eligible.push_back(c);
  }
  out.reachable = static_cast<int>(eligible.size());
  if (eligible.empty()) return out;

  // Farthest-point selection from the best-reached candidate nearest the table centre.
  const Vec3 centre(t.center_xy.x(), t.center_xy.y(), t.height);
  int first = eligible[0];
  for (int c : eligible) {
    const double dc = (candidates[c] - centre).norm(), df = (candidates[first] - centre).norm();
    if (count[c] > count[first] || (count[c] == count[first] && dc < df - 1e-12)) first = c;
  }
  std::vector<double> min_dist(nc, std::numeric_limits<double>::infinity());
  std::vector<char> taken(nc, 0);
  int next = first;
  while (next >= 0 && static_cast<int>(out.slots.size()) < options.num_slots) {
    taken[next] = 1;
    TableSlot slot;
    slot.p_W = candidates[next];
    for (int r = 0; r < nr; ++r) {
      if (reach[r][next]) slot.robots.push_back(r);
    }
    out.slots.push_back(std::move(slot));
    for (int c : eligible) {
      min_dist[c] = std::min(min_dist[c], (candidates[c] - candidates[next]).norm());
    }
    next = -1;
    for (int c : eligible) {
      if (taken[c]) continue;
      if (next < 0 || min_dist[c] > min_dist[next] + 1e-12 ||
          (std::abs(min_dist[c] - min_dist[next]) <= 1e-12 && count[c] > count[next])) {
        next = c;
      }
    }
  }
  return out;
}

}  // namespace wrap
