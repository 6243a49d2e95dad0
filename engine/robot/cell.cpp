#include "robot/cell.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <set>
#include <source_location>
#include <sstream>

namespace wrap {
namespace {

// An always-on assert for bugs (bad indices): file, line, what failed.
[[noreturn]] void CellBug(const char* what,
                          const std::source_location& loc = std::source_location::current()) {
  std::fprintf(stderr, "%s:%u: cell: %s\n", loc.file_name(), static_cast<unsigned>(loc.line()),
               what);
  std::abort();
}

}  // namespace

Result<Cell> Cell::Build(const CellDef& def, const CellOptions& options) {
  Cell cell;
  const int n_robots = static_cast<int>(def.robots.size());
  if (n_robots > kMaxCellRobots) {
    return Fail(ErrorCode::kInvalidInput, "cell: " + std::to_string(n_robots) +
                                              " robots, at most " + std::to_string(kMaxCellRobots) +
                                              " supported");
  }
  std::set<std::string> names;
  for (const CellRobot& r : def.robots) {
    if (!names.insert(r.name).second) {
      return Fail(ErrorCode::kInvalidInput, "cell: robot name '" + r.name + "' used twice");
    }
  }
  names.clear();
  for (const CellObject& o : def.objects) {
    if (!names.insert(o.name).second) {
      return Fail(ErrorCode::kInvalidInput, "cell: object name '" + o.name + "' used twice");
    }
  }

  // Robots: links 0..dof, then the end effector.
  for (int r = 0; r < n_robots; ++r) {
    const CellRobot& def_r = def.robots[r];
    const Chain& chain = def_r.chain;
    if (chain.links.size() != chain.joints.size() + 1) {
      return Fail(ErrorCode::kInvalidInput,
                  "cell: robot '" + def_r.name + "': chain '" + chain.name + "' has " +
                      std::to_string(chain.links.size()) + " links for " +
                      std::to_string(chain.joints.size()) + " joints, expected joints + 1");
    }
    RobotState rs;
    rs.name = def_r.name;
    rs.dof = chain.dof();
    rs.X_WB = def_r.X_WB;
    rs.X_LF = chain.X_LF;
    rs.X_FT = def_r.end_effector.X_FT;
    rs.first_body = cell.world_.num_bodies();
    rs.q.assign(rs.dof, 0.0);
    rs.X_WL.assign(chain.links.size(), def_r.X_WB);
    rs.X_WF = def_r.X_WB * chain.X_LF;
    rs.X_WT = rs.X_WF * rs.X_FT;
    for (const Link& link : chain.links) {
      BodyDef body{def_r.name + "/" + link.name, CellLinkGroup(r), link.collision, def_r.X_WB};
      auto id = cell.world_.AddBody(body);
      if (!id) return Fail(ErrorCode::kInvalidInput, "cell: robot " + id.error().message);
    }
    BodyDef ee{def_r.name + "/" +
                   (def_r.end_effector.name.empty() ? std::string("end_effector")
                                                    : def_r.end_effector.name),
               CellEndEffectorGroup(r), def_r.end_effector.collision, rs.X_WF};
    auto id = cell.world_.AddBody(ee);
    if (!id) return Fail(ErrorCode::kInvalidInput, "cell: end effector " + id.error().message);
    cell.robots_.push_back(std::move(rs));
  }

  for (const CellObject& def_o : def.objects) {
    if (def_o.mesh.empty()) {
      return Fail(ErrorCode::kInvalidInput,
                  "cell: object '" + def_o.name + "': the mesh has no triangles");
    }
    Shape shape;
    shape.type = Shape::Type::kMesh;
    shape.mesh = def_o.mesh;
    shape.name = def_o.name;
    auto id = cell.world_.AddBody(BodyDef{def_o.name, kCellObjectGroup, {shape}, def_o.X_WO});
    if (!id) return Fail(ErrorCode::kInvalidInput, "cell: object " + id.error().message);
    ObjectState os;
    os.name = def_o.name;
    os.body = *id;
    os.X_WO = def_o.X_WO;
    os.holders.reserve(4);
    cell.objects_.push_back(std::move(os));
  }

  if (def.table.present) {
    if (!(def.table.size.array() > 0.0).all()) {
      return Fail(ErrorCode::kInvalidInput, "cell: table: size must be positive on every axis");
    }
    Shape top;
    top.type = Shape::Type::kBox;
    top.name = "table";
    top.half_extents = 0.5 * def.table.size;
    top.X_LS.translation() = def.table.top_center - Vec3(0, 0, 0.5 * def.table.size.z());
    auto id = cell.world_.AddBody(BodyDef{"table", kCellTableGroup, {top}, Iso3::Identity()});
    if (!id) return Fail(ErrorCode::kInvalidInput, "cell: " + id.error().message);
    cell.table_body_ = *id;
  }

  // Default filters.
  for (int r = 0; r < n_robots; ++r) {
    const int n_bodies = cell.robots_[r].dof + 2;  // links and the end effector
    for (int i = 0; i < n_bodies; ++i) {
      for (int j = i + 1; j < n_bodies && j - i <= options.adjacent_link_gap; ++j) {
        cell.world_.SetAllowed(BodyId{cell.robots_[r].first_body + i},
                               BodyId{cell.robots_[r].first_body + j}, true);
      }
    }
    if (options.base_touches_table && cell.table_body_.valid()) {
      cell.world_.SetAllowed(cell.link_body(r, 0), cell.table_body_, true);
    }
  }
  if (options.objects_touch_table && def.table.present) {
    cell.world_.SetGroupPairAllowed(kCellObjectGroup, kCellTableGroup, true);
  }
  // Contacts within one robot at its reference configuration.
  for (int r = 0; r < n_robots; ++r) {
    const std::vector<Iso3>& frames = def.robots[r].reference_link_frames;
    if (frames.empty()) continue;
    if (frames.size() < def.robots[r].chain.links.size()) {
      return Fail(ErrorCode::kInvalidInput,
                  "cell: robot '" + def.robots[r].name + "': " + std::to_string(frames.size()) +
                      " reference link frames for " +
                      std::to_string(def.robots[r].chain.links.size()) + " links");
    }
    cell.SetConfiguration(r, {}, frames);
    CollisionRequest request;
    request.all_pairs = true;
    request.max_pairs = std::numeric_limits<int>::max();
    request.group_mask =
        (std::uint64_t{1} << CellLinkGroup(r)) | (std::uint64_t{1} << CellEndEffectorGroup(r));
    CollisionResult contacts;
    cell.world_.AnyCollision(request, &contacts);
    for (const ShapePair& p : contacts.pairs) {
      if (cell.robot_of(p.body_a) == r && cell.robot_of(p.body_b) == r) {
        cell.world_.SetAllowed(p.body_a, p.body_b, true);
      }
    }
    cell.SetConfiguration(r, {}, std::vector<Iso3>(frames.size(), def.robots[r].X_WB));
  }

  for (int r = 0; r < n_robots; ++r) {
    for (int s = r + 1; s < n_robots; ++s) {
      cell.robot_pairs_.Add(CellLinkGroup(r), CellLinkGroup(s));
      if (options.clearance_includes_end_effectors) {
        cell.robot_pairs_.Add(CellLinkGroup(r), CellEndEffectorGroup(s));
        cell.robot_pairs_.Add(CellEndEffectorGroup(r), CellLinkGroup(s));
        cell.robot_pairs_.Add(CellEndEffectorGroup(r), CellEndEffectorGroup(s));
      }
    }
  }
  return cell;
}

void Cell::SetConfiguration(int robot, std::span<const double> q, std::span<const Iso3> X_WL) {
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  RobotState& rs = robots_[robot];
  if (X_WL.size() < rs.X_WL.size()) CellBug("SetConfiguration: fewer link frames than links");
  const std::size_t nq = std::min(q.size(), rs.q.size());
  std::copy_n(q.begin(), nq, rs.q.begin());
  for (std::size_t i = 0; i < rs.X_WL.size(); ++i) {
    rs.X_WL[i] = X_WL[i];
    world_.SetPose(BodyId{rs.first_body + static_cast<int>(i)}, rs.X_WL[i]);
  }
  rs.X_WF = rs.X_WL.back() * rs.X_LF;
  rs.X_WT = rs.X_WF * rs.X_FT;
  world_.SetPose(BodyId{rs.first_body + rs.dof + 1}, rs.X_WF);
  for (ObjectState& o : objects_) {
    if (!o.holders.empty() && o.holders.front() == robot) MoveObject(o, rs.X_WT * o.X_TO);
  }
}

void Cell::MoveObject(ObjectState& o, const Iso3& X_WO) {
  o.X_WO = X_WO;
  world_.SetPose(o.body, X_WO);
}

void Cell::SetObjectPose(int object, const Iso3& X_WO) {
  if (object < 0 || object >= num_objects()) CellBug("object index out of range");
  ObjectState& o = objects_[object];
  if (!o.holders.empty()) o.X_TO = robots_[o.holders.front()].X_WT.inverse() * X_WO;
  MoveObject(o, X_WO);
}

const Iso3& Cell::object_pose(int object) const {
  if (object < 0 || object >= num_objects()) CellBug("object index out of range");
  return objects_[object].X_WO;
}

void Cell::SetObjectEnabled(int object, bool enabled) {
  world_.SetEnabled(object_body(object), enabled);
}

void Cell::Attach(int object, int robot) {
  if (object < 0 || object >= num_objects()) CellBug("object index out of range");
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  Attach(object, robot, robots_[robot].X_WT.inverse() * objects_[object].X_WO);
}

void Cell::Attach(int object, int robot, const Iso3& X_TO) {
  if (object < 0 || object >= num_objects()) CellBug("object index out of range");
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  ObjectState& o = objects_[object];
  if (std::find(o.holders.begin(), o.holders.end(), robot) == o.holders.end()) {
    o.holders.push_back(robot);
  }
  world_.SetAllowed(o.body, end_effector_body(robot), true);
  if (o.holders.front() == robot) {
    o.X_TO = X_TO;
    MoveObject(o, robots_[robot].X_WT * X_TO);
  }
}

void Cell::Detach(int object, int robot) {
  if (object < 0 || object >= num_objects()) CellBug("object index out of range");
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  ObjectState& o = objects_[object];
  auto it = std::find(o.holders.begin(), o.holders.end(), robot);
  if (it == o.holders.end()) return;
  o.holders.erase(it);
  world_.SetAllowed(o.body, end_effector_body(robot), false);
  if (!o.holders.empty()) o.X_TO = robots_[o.holders.front()].X_WT.inverse() * o.X_WO;
}

int Cell::carrier(int object) const {
  if (object < 0 || object >= num_objects()) CellBug("object index out of range");
  return objects_[object].holders.empty() ? -1 : objects_[object].holders.front();
}

void Cell::SetObjectPairAllowed(int object_a, int object_b, bool allowed) {
  world_.SetAllowed(object_body(object_a), object_body(object_b), allowed);
}

bool Cell::InCollision(CollisionResult* result, const CollisionRequest& request) {
  return world_.AnyCollision(request, result);
}

DistanceResult Cell::MinRobotClearance(const DistanceRequest& request) {
  return world_.MinDistance(robot_pairs_, request);
}

const Iso3& Cell::X_WB(int robot) const {
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  return robots_[robot].X_WB;
}

const Iso3& Cell::X_WT(int robot) const {
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  return robots_[robot].X_WT;
}

const Iso3& Cell::X_WF(int robot) const {
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  return robots_[robot].X_WF;
}

const Iso3& Cell::X_WL(int robot, int link) const {
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  const RobotState& rs = robots_[robot];
  if (link < 0 || link > rs.dof) CellBug("link index out of range");
  return rs.X_WL[link];
}

BodyId Cell::link_body(int robot, int link) const {
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  const RobotState& rs = robots_[robot];
  if (link < 0 || link > rs.dof) CellBug("link index out of range");
  return BodyId{rs.first_body + link};
}

BodyId Cell::end_effector_body(int robot) const {
  if (robot < 0 || robot >= num_robots()) CellBug("robot index out of range");
  return BodyId{robots_[robot].first_body + robots_[robot].dof + 1};
}

BodyId Cell::object_body(int object) const {
  if (object < 0 || object >= num_objects()) CellBug("object index out of range");
  return objects_[object].body;
}

int Cell::robot_of(BodyId body) const {
  for (int r = 0; r < num_robots(); ++r) {
    const RobotState& rs = robots_[r];
    if (body.value >= rs.first_body && body.value <= rs.first_body + rs.dof + 1) return r;
  }
  return -1;
}

std::string Cell::Describe(const ShapePair& pair) const {
  std::ostringstream os;
  os << world_.Describe(pair);
  int last = -1;
  for (BodyId b : {pair.body_a, pair.body_b}) {
    const int r = b.valid() ? robot_of(b) : -1;
    if (r < 0 || r == last) continue;
    last = r;
    os << "; robot '" << robots_[r].name << "' q=[";
    for (std::size_t k = 0; k < robots_[r].q.size(); ++k) {
      char buf[32];
      std::snprintf(buf, sizeof(buf), "%s%.9g", k ? ", " : "", robots_[r].q[k]);
      os << buf;
    }
    os << "]";
  }
  return os.str();
}

}  // namespace wrap
