#include "authoring/layout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "model/catalog.h"
#include "task/planner.h"

namespace wrap {

namespace {

constexpr double kUr5eReach_m = 0.85;  // the catalog's UR5e: the layout's reference arm

// A part's footprint at rest: its hull's box in the rest frame T (origin under the COM).
struct Footprint {
  Eigen::Vector2d lo = Eigen::Vector2d::Zero();
  Eigen::Vector2d hi = Eigen::Vector2d::Zero();
};

Footprint FootprintOf(const Subassembly& sub, const Iso3& X_TA) {
  Footprint f;
  f.lo = Eigen::Vector2d::Constant(1e9);
  f.hi = -f.lo;
  for (const Vec3& v : sub.hull.mesh.vertices) {
    const Vec3 t = X_TA * v;
    f.lo = f.lo.cwiseMin(t.head<2>());
    f.hi = f.hi.cwiseMax(t.head<2>());
  }
  return f;
}

Iso3 Yawed(double yaw, const Iso3& X_TA) {
  Iso3 R = Iso3::Identity();
  R.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  return R * X_TA;
}

struct Box2 {
  Eigen::Vector2d lo, hi;
  bool Overlaps(const Box2& o, double gap) const {
    return !(hi.x() + gap <= o.lo.x() || o.hi.x() + gap <= lo.x() || hi.y() + gap <= o.lo.y() ||
             o.hi.y() + gap <= lo.y());
  }
};

// Robots whose horizontal reach covers a point on the table.
int Reaching(const Project& project, const Eigen::Vector2d& p) {
  int n = 0;
  for (const Robot& r : project.robots) {
    const RobotModelInfo* info = FindRobotModel(r.model);
    const double reach = info ? info->reach_m : 0.85;
    n += (RobotBaseInWorld(project, r).translation().head<2>() - p).norm() < 0.9 * reach ? 1 : 0;
  }
  return n;
}

// The table positions tried, nearest the centre first, among those most robots reach.
std::vector<Eigen::Vector2d> Positions(const Project& project, double grid) {
  const Table& t = project.table;
  std::vector<std::pair<double, Eigen::Vector2d>> ranked;
  const Eigen::Vector2d c = t.center_xy.head<2>();
  for (double x = -0.5 * t.size.x(); x <= 0.5 * t.size.x(); x += grid) {
    for (double y = -0.5 * t.size.y(); y <= 0.5 * t.size.y(); y += grid) {
      const Eigen::Vector2d p = c + Eigen::Vector2d(x, y);
      const int robots = std::min(Reaching(project, p), 2);
      ranked.push_back({-10.0 * robots + (p - c).norm(), p});
    }
  }
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Vector2d> out;
  for (const auto& [rank, p] : ranked) out.push_back(p);
  return out;
}

struct Placed {
  int placement = 0;  // index into the part's placement order
  double yaw = 0.0;
  bool edge = false;
};

// A part's placements in the order tried: resting as it stands in the assembly first (its
// grasps for the assembly then need no regrasp), then the others, most stable first.
std::vector<int> PlacementOrder(const Subassembly& sub) {
  std::vector<int> order(sub.placements.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::stable_partition(order.begin(), order.end(), [&](int k) {
    return sub.placements[k].normal_A.dot(-Vec3::UnitZ()) > 0.999;
  });
  return order;
}

// Puts part p (placement and yaw in `how`) at the first free position; false when none fits.
bool PlacePart(Project& project, const Subassembly& sub, int p, const Placed& how,
               const std::vector<Eigen::Vector2d>& positions, std::vector<Box2>& taken,
               double gap, std::string* where) {
  const int k = PlacementOrder(sub)[how.placement];
  const Iso3 X_TA = Yawed(how.yaw, sub.placements[k].X_TA);
  const Footprint f = FootprintOf(sub, X_TA);
  const Table& t = project.table;
  const Eigen::Vector2d lo = t.center_xy.head<2>() - 0.5 * t.size.head<2>();
  const Eigen::Vector2d hi = t.center_xy.head<2>() + 0.5 * t.size.head<2>();
  for (const Eigen::Vector2d& pos : positions) {
    Box2 box{pos + f.lo, pos + f.hi};
    const Eigen::Vector2d mid = 0.5 * (box.lo + box.hi);
    const bool inside = (box.lo.array() >= lo.array() + 0.01).all() &&
                        (box.hi.array() <= hi.array() - 0.01).all();
    // Over the edge: the footprint's centre on the table, a third of the part beyond it.
    const bool at_edge = (mid.array() >= lo.array()).all() && (mid.array() <= hi.array()).all() &&
                         !inside;
    if (how.edge ? !at_edge : !inside) continue;
    if (std::any_of(taken.begin(), taken.end(), [&](const Box2& o) { return box.Overlaps(o, gap); })) {
      continue;
    }
    Iso3 X_WT = Iso3::Identity();
    X_WT.translation() = Vec3(pos.x(), pos.y(), t.height);
    // The part's subassembly frame is the assembly frame: X_WP = X_WA * X_AP (X_AP is the
    // identity for meshes modelled in place, a STEP instance's placement otherwise).
    project.parts[p].initial_pose =
        FromIsometry(X_WT * X_TA * ToIsometry(project.parts[p].assembled_pose));
    taken.push_back(box);
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.3f, %.3f) m, placement %d of %zu", pos.x(), pos.y(),
                  k + 1, sub.placements.size());
    *where = buf;
    if (sub.placements[k].normal_A.dot(-Vec3::UnitZ()) > 0.999) *where += " (as assembled)";
    if (how.yaw != 0.0) *where += ", turned 90 degrees";
    return true;
  }
  return false;
}

}  // namespace

Result<LayoutReport> LayOutParts(Project& project, const ProjectCheck& check,
                                 const std::filesystem::path& project_file,
                                 const LayoutOptions& options) {
  LayoutReport report;
  PreprocessOptions pre_options;
  pre_options.project_file = project_file;
  RunContext ctx(project.planner.seed);
  auto pre = Preprocess(project, check, pre_options, ctx);
  if (!pre) return std::unexpected(pre.error());
  const int n = static_cast<int>(project.parts.size());
  std::vector<int> todo = options.parts;
  if (todo.empty()) {
    todo.resize(n);
    for (int p = 0; p < n; ++p) todo[p] = p;
  }
  // Largest footprint first: the big parts get the central places.
  auto area = [&](int p) {
    const Subassembly& sub = pre->subassemblies[p];
    if (sub.placements.empty()) return 0.0;
    const Footprint f = FootprintOf(sub, sub.placements[0].X_TA);
    return (f.hi - f.lo).prod();
  };
  std::stable_sort(todo.begin(), todo.end(), [&](int a, int b) { return area(a) > area(b); });
  const std::vector<Eigen::Vector2d> positions = Positions(project, options.grid_m);
  std::vector<Placed> how(n);
  std::vector<int> pending = todo;
  for (int round = 0; round <= options.rounds && !pending.empty(); ++round) {
    std::vector<Box2> taken;
    // Parts that stay put keep their places.
    for (int p = 0; p < n; ++p) {
      if (std::find(todo.begin(), todo.end(), p) != todo.end()) continue;
      const Subassembly& sub = pre->subassemblies[p];
      Box2 b{Eigen::Vector2d::Constant(1e9), Eigen::Vector2d::Constant(-1e9)};
      const Iso3 X_WA = ToIsometry(project.parts[p].initial_pose) *
                        ToIsometry(project.parts[p].assembled_pose).inverse();
      for (const Vec3& v : sub.hull.mesh.vertices) {
        const Vec3 w = X_WA * v;
        b.lo = b.lo.cwiseMin(w.head<2>());
        b.hi = b.hi.cwiseMax(w.head<2>());
      }
      taken.push_back(b);
    }
    for (int p : todo) {
      const Subassembly& sub = pre->subassemblies[p];
      if (sub.placements.empty()) {
        return Fail(ErrorCode::kInvalidInput,
                    "part '" + project.parts[p].name + "' has no stable placement on a table");
      }
      std::string where;
      if (!PlacePart(project, sub, p, how[p], positions, taken, options.gap_m, &where)) {
        return Fail(ErrorCode::kInvalidInput, "the parts do not fit on the " +
                                                  std::to_string(project.table.size.x()) + " x " +
                                                  std::to_string(project.table.size.y()) +
                                                  " m table ('" + project.parts[p].name + "')");
      }
      if (round == 0 || std::find(pending.begin(), pending.end(), p) != pending.end()) {
        report.decisions.push_back("'" + project.parts[p].name + "' starts at " + where +
                                   (how[p].edge ? ", over the table's edge" : ""));
      }
    }
    auto fresh = Preprocess(project, check, pre_options, ctx);
    if (!fresh) return std::unexpected(fresh.error());
    TaskPlannerOptions task;
    task.project_file = project_file;
    auto unpickable = UnpickableAtStart(project, check, *fresh, task);
    if (!unpickable) return std::unexpected(unpickable.error());
    pending.clear();
    for (const UnpickablePart& u : *unpickable) {
      if (std::find(todo.begin(), todo.end(), u.part) == todo.end()) continue;
      pending.push_back(u.part);
      Placed& h = how[u.part];
      const int placements = static_cast<int>(pre->subassemblies[u.part].placements.size());
      report.decisions.push_back(u.why + "; trying another placement");
      if (h.yaw == 0.0) {
        h.yaw = 0.5 * std::numbers::pi;
      } else if (h.placement + 1 < placements) {
        h = Placed{h.placement + 1, 0.0, false};
      } else {
        h = Placed{0, 0.0, true};
      }
    }
  }
  for (int p : pending) report.unpickable.push_back(p);
  for (int p : todo) {
    if (how[p].edge) report.overhanging.push_back(p);
  }
  return report;
}

Table TableFor(const std::string& model) {
  const RobotModelInfo* info = FindRobotModel(model);
  const double scale = (info ? info->reach_m : kUr5eReach_m) / kUr5eReach_m;
  Table t;
  t.size = Vec3(1.2 * scale, 1.0 * scale, 0.05);
  return t;
}

std::vector<Robot> RobotsAroundTable(const Table& table, int count, const std::string& model,
                                     const std::string& end_effector) {
  std::vector<Robot> out;
  // The corners of a rectangle that scales with the arm's reach (a UR5e's: 0.9 x 0.7 m).
  const RobotModelInfo* info = FindRobotModel(model);
  const double scale = (info ? info->reach_m : kUr5eReach_m) / kUr5eReach_m;
  const double ax = 0.45 * scale * std::sqrt(2.0), ay = 0.35 * scale * std::sqrt(2.0);
  for (int k = 0; k < count; ++k) {
    const double angle = std::numbers::pi / 4 + 2.0 * std::numbers::pi * k / count;
    const double x = table.center_xy.x() + ax * std::cos(angle);
    const double y = table.center_xy.y() + ay * std::sin(angle);
    Robot r;
    r.name = model + "_" + std::string(1, static_cast<char>('a' + k % 26)) +
             (k >= 26 ? std::to_string(k / 26) : "");
    r.model = model;
    r.end_effector = end_effector;
    r.base_pose.xyz = Vec3(x, y, table.height);
    r.base_pose.rpy = Vec3(0.0, 0.0, std::atan2(table.center_xy.y() - y, table.center_xy.x() - x));
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace wrap
