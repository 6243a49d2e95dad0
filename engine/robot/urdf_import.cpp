// The one urdfdom adapter: urdfdom's model is read here and nowhere else; its console_bridge
// messages are captured and turned into Error messages.
#include "robot/urdf_import.h"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <vector>

#include "geometry/mesh_import.h"
#include "robot/kinematics.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

// console_bridge has one process-wide output handler: parse one URDF at a time and collect what
// urdfdom reports while doing so.
std::mutex& ParseMutex() {
  static std::mutex m;
  return m;
}

class LogCapture : public console_bridge::OutputHandler {
 public:
  LogCapture() : previous_(console_bridge::getOutputHandler()) {
    console_bridge::useOutputHandler(this);
  }
  ~LogCapture() override { console_bridge::useOutputHandler(previous_); }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;

  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors.push_back(text);
  }
  std::vector<std::string> errors;

 private:
  console_bridge::OutputHandler* previous_;
};

std::string Join(const std::vector<std::string>& items, const char* sep) {
  std::string out;
  for (std::size_t k = 0; k < items.size(); ++k) {
    if (k) out += sep;
    out += items[k];
  }
  return out;
}

Iso3 ToIso3(const urdf::Pose& p) {
  Iso3 X = Iso3::Identity();
  X.translation() = Vec3(p.position.x, p.position.y, p.position.z);
  Eigen::Quaterniond q(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  if (q.norm() > 0.0) X.linear() = q.normalized().toRotationMatrix();
  return X;
}

Vec3 ToVec3(const urdf::Vector3& v) { return Vec3(v.x, v.y, v.z); }

bool IsMovable(const urdf::Joint& j) {
  return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS ||
         j.type == urdf::Joint::PRISMATIC;
}

const char* JointTypeName(const urdf::Joint& j) {
  switch (j.type) {
    case urdf::Joint::REVOLUTE:
      return "revolute";
    case urdf::Joint::CONTINUOUS:
      return "continuous";
    case urdf::Joint::PRISMATIC:
      return "prismatic";
    case urdf::Joint::FLOATING:
      return "floating";
    case urdf::Joint::PLANAR:
      return "planar";
    case urdf::Joint::FIXED:
      return "fixed";
    default:
      return "unknown";
  }
}

// Everything needed while converting one file.
class Importer {
 public:
  Importer(const fs::path& file, const UrdfImportOptions& options)
      : file_(file), dir_(file.parent_path()), options_(options) {}

  Result<Chain> Run(const urdf::ModelInterface& model);

 private:
  std::unexpected<Error> Invalid(const std::string& what) const {
    return Fail(ErrorCode::kInvalidInput, "urdf '" + file_.string() + "': " + what);
  }
  Result<fs::path> ResolveUri(const std::string& uri, const std::string& element) const;
  // Appends the shapes of `link` (its frame at X_CL in chain link C) to `out`.
  Result<void> AddGeometry(const urdf::Link& link, const Iso3& X_CL, Link* out) const;
  Result<Shape> ConvertGeometry(const urdf::Geometry& geometry, const Iso3& X_CG,
                                const std::string& element) const;
  // Folds the fixed side branches of `link` (children not in `on_path`) into chain link `out`.
  Result<void> FoldFixedBranches(const urdf::Link& link, const Iso3& X_CL,
                                 const std::set<const urdf::Link*>& on_path, Link* out) const;
  Result<const urdf::Link*> FindTip(const urdf::Link& root) const;

  fs::path file_;
  fs::path dir_;
  const UrdfImportOptions& options_;
};

Result<fs::path> Importer::ResolveUri(const std::string& uri, const std::string& element) const {
  constexpr std::string_view kPackage = "package://";
  constexpr std::string_view kFile = "file://";
  std::error_code ec;
  if (uri.starts_with(kPackage)) {
    const std::string rest_all = uri.substr(kPackage.size());
    const std::size_t slash = rest_all.find('/');
    const std::string package = rest_all.substr(0, slash);
    const fs::path rest =
        slash == std::string::npos ? fs::path() : fs::path(rest_all.substr(slash + 1));
    if (auto it = options_.package_paths.find(package); it != options_.package_paths.end()) {
      return it->second / rest;
    }
    // A folder named like the package above the URDF, or the package folder inside an ancestor.
    const fs::path start = fs::absolute(dir_.empty() ? fs::path(".") : dir_, ec);
    for (fs::path d = start;; d = d.parent_path()) {
      if (d.filename() == package && fs::exists(d / rest, ec)) return d / rest;
      if (fs::exists(d / package / rest, ec)) return d / package / rest;
      if (d == d.parent_path()) break;
    }
    // Meshes copied next to the URDF with the package's layout.
    for (const fs::path& d : {start, start.parent_path()}) {
      if (fs::exists(d / rest, ec)) return d / rest;
    }
    return Invalid(element + ": mesh '" + uri + "': package '" + package +
                   "' not found (no folder of that name above '" + start.string() +
                   "'); give its folder in UrdfImportOptions::package_paths");
  }
  if (uri.starts_with(kFile)) return fs::path(uri.substr(kFile.size()));
  if (uri.find("://") != std::string::npos) {
    return Invalid(element + ": mesh '" + uri +
                   "': only package://, file:// and plain paths are supported");
  }
  const fs::path p(uri);
  return p.is_absolute() ? p : dir_ / p;
}

Result<Shape> Importer::ConvertGeometry(const urdf::Geometry& geometry, const Iso3& X_CG,
                                        const std::string& element) const {
  Shape s;
  s.name = element;
  switch (geometry.type) {
    case urdf::Geometry::BOX: {
      const Vec3 size = ToVec3(static_cast<const urdf::Box&>(geometry).dim);
      if (!(size.array() > 0.0).all() || !size.allFinite()) {
        return Invalid(element + ": box size must be positive, got (" + std::to_string(size.x()) +
                       ", " + std::to_string(size.y()) + ", " + std::to_string(size.z()) + ")");
      }
      s.type = Shape::Type::kBox;
      s.X_LS = X_CG;
      s.half_extents = 0.5 * size;
      return s;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& c = static_cast<const urdf::Cylinder&>(geometry);
      if (!(c.radius > 0.0) || !(c.length > 0.0) || !std::isfinite(c.radius) ||
          !std::isfinite(c.length)) {
        return Invalid(element + ": cylinder radius and length must be positive, got radius " +
                       std::to_string(c.radius) + " length " + std::to_string(c.length));
      }
      // URDF cylinders lie along the local z, centred at the origin.
      s.type = Shape::Type::kCylinder;
      s.radius = c.radius;
      s.p0 = X_CG * Vec3(0, 0, -0.5 * c.length);
      s.p1 = X_CG * Vec3(0, 0, 0.5 * c.length);
      return s;
    }
    case urdf::Geometry::SPHERE: {
      const auto& sp = static_cast<const urdf::Sphere&>(geometry);
      if (!(sp.radius > 0.0) || !std::isfinite(sp.radius)) {
        return Invalid(element + ": sphere radius must be positive, got " +
                       std::to_string(sp.radius));
      }
      s.type = Shape::Type::kSphere;
      s.radius = sp.radius;
      s.p0 = s.p1 = X_CG.translation();
      return s;
    }
    case urdf::Geometry::MESH: {
      const auto& m = static_cast<const urdf::Mesh&>(geometry);
      const Vec3 scale = ToVec3(m.scale);
      if (!scale.allFinite() || (scale.array() == 0.0).any()) {
        return Invalid(element + ": mesh '" + m.filename + "': scale must be finite and non-zero");
      }
      auto path = ResolveUri(m.filename, element);
      if (!path) return std::unexpected(path.error());
      auto mesh = ImportMesh(*path);
      if (!mesh) {
        return Fail(mesh.error().code,
                    "urdf '" + file_.string() + "': " + element + ": " + mesh.error().message);
      }
      s.type = Shape::Type::kMesh;
      s.mesh = std::move(*mesh);
      for (Vec3& v : s.mesh.vertices) v = X_CG * scale.cwiseProduct(v);
      // A mirroring scale turns the triangles inside out: restore counter-clockwise faces.
      if (scale.prod() < 0.0) {
        for (Eigen::Vector3i& t : s.mesh.triangles) std::swap(t[1], t[2]);
      }
      return s;
    }
  }
  return Invalid(element + ": unknown geometry type");
}

Result<void> Importer::AddGeometry(const urdf::Link& link, const Iso3& X_CL, Link* out) const {
  for (std::size_t k = 0; k < link.collision_array.size(); ++k) {
    const urdf::Collision& c = *link.collision_array[k];
    if (!c.geometry) continue;
    const std::string element = "link '" + link.name + "' collision " +
                                (c.name.empty() ? std::to_string(k) : "'" + c.name + "'");
    auto shape = ConvertGeometry(*c.geometry, X_CL * ToIso3(c.origin), element);
    if (!shape) return std::unexpected(shape.error());
    shape->name = link.name + "/" + (c.name.empty() ? "collision" + std::to_string(k) : c.name);
    out->collision.push_back(std::move(*shape));
  }
  if (!options_.import_visual) return {};
  for (std::size_t k = 0; k < link.visual_array.size(); ++k) {
    const urdf::Visual& v = *link.visual_array[k];
    if (!v.geometry) continue;
    const std::string element = "link '" + link.name + "' visual " +
                                (v.name.empty() ? std::to_string(k) : "'" + v.name + "'");
    auto shape = ConvertGeometry(*v.geometry, X_CL * ToIso3(v.origin), element);
    if (!shape) return std::unexpected(shape.error());
    shape->name = link.name + "/" + (v.name.empty() ? "visual" + std::to_string(k) : v.name);
    out->visual.push_back(std::move(*shape));
  }
  return {};
}

Result<void> Importer::FoldFixedBranches(const urdf::Link& link, const Iso3& X_CL,
                                         const std::set<const urdf::Link*>& on_path,
                                         Link* out) const {
  for (const auto& joint : link.child_joints) {
    if (!joint || joint->type != urdf::Joint::FIXED) continue;
    urdf::LinkConstSharedPtr child = nullptr;
    for (const auto& c : link.child_links) {
      if (c && c->name == joint->child_link_name) child = c;
    }
    if (!child || on_path.count(child.get())) continue;
    const Iso3 X_CK = X_CL * ToIso3(joint->parent_to_joint_origin_transform);
    if (auto r = AddGeometry(*child, X_CK, out); !r) return r;
    if (auto r = FoldFixedBranches(*child, X_CK, on_path, out); !r) return r;
  }
  return {};
}

Result<const urdf::Link*> Importer::FindTip(const urdf::Link& root) const {
  // Leaves below the root with the movable joints on their way down.
  struct Leaf {
    const urdf::Link* link;
    std::vector<const urdf::Joint*> movable;
  };
  std::vector<Leaf> leaves;
  std::vector<std::pair<const urdf::Link*, std::vector<const urdf::Joint*>>> stack;
  stack.push_back({&root, {}});
  while (!stack.empty()) {
    auto [link, movable] = std::move(stack.back());
    stack.pop_back();
    if (link->child_links.empty()) {
      leaves.push_back({link, movable});
      continue;
    }
    for (const auto& child : link->child_links) {
      auto path = movable;
      if (child->parent_joint && child->parent_joint->type != urdf::Joint::FIXED) {
        path.push_back(child->parent_joint.get());
      }
      stack.push_back({child.get(), std::move(path)});
    }
  }
  // A leaf whose movable joints are a proper prefix of another leaf's hangs off that chain.
  auto is_proper_prefix = [](const std::vector<const urdf::Joint*>& a,
                             const std::vector<const urdf::Joint*>& b) {
    return a.size() < b.size() && std::equal(a.begin(), a.end(), b.begin());
  };
  std::vector<std::string> candidates;
  const urdf::Link* tip = nullptr;
  for (const Leaf& l : leaves) {
    const bool dominated = std::any_of(leaves.begin(), leaves.end(), [&](const Leaf& o) {
      return is_proper_prefix(l.movable, o.movable);
    });
    if (dominated) continue;
    candidates.push_back(l.link->name);
    tip = l.link;
  }
  std::sort(candidates.begin(), candidates.end());
  if (candidates.size() != 1) {
    return Invalid(std::to_string(candidates.size()) + " tip links [" + Join(candidates, ", ") +
                   "] below '" + root.name +
                   "' and no tip named: set UrdfImportOptions::tip to one of them");
  }
  return tip;
}

Result<Chain> Importer::Run(const urdf::ModelInterface& model) {
  // urdfdom keeps the last parent of a link with two: a closed loop it does not report.
  std::map<std::string, std::vector<std::string>> parents_of;
  for (const auto& [name, joint] : model.joints_) {
    if (!joint) continue;
    parents_of[joint->child_link_name].push_back(name);
    // urdfdom accepts a joint from a link to itself and leaves that link (and what hangs below
    // it) off the tree from the root without a word (found by fuzzing: tests/fuzz/regressions).
    if (joint->child_link_name == joint->parent_link_name) {
      return Invalid("closed loop: joint '" + name + "' connects link '" + joint->child_link_name +
                     "' to itself; only trees (serial chains) are supported");
    }
  }
  for (const auto& [link, joints] : parents_of) {
    if (joints.size() > 1) {
      return Invalid("closed loop: link '" + link + "' is the child of " +
                     std::to_string(joints.size()) + " joints [" + Join(joints, ", ") +
                     "]; only trees (serial chains) are supported");
    }
  }

  const urdf::Link* root = model.getRoot().get();
  if (!options_.root.empty()) {
    root = model.getLink(options_.root).get();
    if (!root) return Invalid("root link '" + options_.root + "' not found");
  }
  if (!root) return Invalid("no root link");

  const urdf::Link* tip = nullptr;
  if (!options_.tip.empty()) {
    tip = model.getLink(options_.tip).get();
    if (!tip) return Invalid("tip link '" + options_.tip + "' not found");
  } else {
    auto found = FindTip(*root);
    if (!found) return std::unexpected(found.error());
    tip = *found;
  }

  // The path root -> tip, walking up from the tip.
  std::vector<const urdf::Joint*> path;
  std::set<const urdf::Link*> on_path{tip};
  for (const urdf::Link* l = tip; l != root;) {
    const urdf::Joint* j = l->parent_joint.get();
    const urdf::Link* parent = l->getParent().get();
    if (!j || !parent) {
      return Invalid("tip link '" + tip->name + "' is not below root link '" + root->name + "'");
    }
    path.push_back(j);
    on_path.insert(parent);
    l = parent;
  }
  std::reverse(path.begin(), path.end());

  Chain chain;
  chain.name = model.getName();
  chain.links.emplace_back();
  chain.links.back().name = root->name;
  Iso3 X_CL = Iso3::Identity();  // current URDF link in the current chain link's frame
  if (auto r = AddGeometry(*root, X_CL, &chain.links.back()); !r) return std::unexpected(r.error());
  if (auto r = FoldFixedBranches(*root, X_CL, on_path, &chain.links.back()); !r) {
    return std::unexpected(r.error());
  }
  for (const urdf::Joint* j : path) {
    const std::string element = "joint '" + j->name + "'";
    const urdf::Link* child = model.getLink(j->child_link_name).get();
    const Iso3 X_origin = ToIso3(j->parent_to_joint_origin_transform);
    if (j->type == urdf::Joint::FIXED) {
      X_CL = X_CL * X_origin;
    } else if (IsMovable(*j)) {
      if (j->mimic) {
        return Invalid(element + " mimics joint '" + j->mimic->joint_name +
                       "': mimic joints are not supported on the chain");
      }
      Joint joint;
      joint.name = j->name;
      joint.type =
          j->type == urdf::Joint::PRISMATIC ? Joint::Type::kPrismatic : Joint::Type::kRevolute;
      joint.X_PJ = X_CL * X_origin;
      const Vec3 axis = ToVec3(j->axis);
      if (!(axis.norm() > 1e-9) || !axis.allFinite()) {
        return Invalid(element + ": axis must be a non-zero vector");
      }
      joint.axis = axis.normalized();
      joint.max_acceleration = options_.default_max_acceleration;
      joint.max_velocity = options_.default_max_velocity;
      if (j->type == urdf::Joint::CONTINUOUS) {
        joint.lower = -options_.continuous_range_rad;
        joint.upper = options_.continuous_range_rad;
      } else {
        if (!j->limits) return Invalid(element + ": no <limit> element");
        joint.lower = j->limits->lower;
        joint.upper = j->limits->upper;
        if (!(joint.lower <= joint.upper) || !std::isfinite(joint.lower) ||
            !std::isfinite(joint.upper)) {
          return Invalid(element + ": limit lower " + std::to_string(joint.lower) +
                         " is above upper " + std::to_string(joint.upper));
        }
      }
      if (j->limits) {
        if (j->limits->velocity > 0.0) joint.max_velocity = j->limits->velocity;
        joint.max_effort = std::max(0.0, j->limits->effort);
      }
      chain.joints.push_back(joint);
      chain.links.emplace_back();
      chain.links.back().name = child->name;
      X_CL = Iso3::Identity();
    } else {
      return Invalid(element + " is " + JointTypeName(*j) +
                     ": only revolute, continuous, prismatic and fixed joints are supported");
    }
    if (auto r = AddGeometry(*child, X_CL, &chain.links.back()); !r) {
      return std::unexpected(r.error());
    }
    if (auto r = FoldFixedBranches(*child, X_CL, on_path, &chain.links.back()); !r) {
      return std::unexpected(r.error());
    }
  }
  if (chain.joints.empty()) {
    return Invalid("no revolute, continuous or prismatic joint between root link '" + root->name +
                   "' and tip link '" + tip->name + "'");
  }
  if (chain.dof() > kMaxDof) {
    return Invalid("the chain from root link '" + root->name + "' to tip link '" + tip->name +
                   "' has " + std::to_string(chain.dof()) + " movable joints; at most " +
                   std::to_string(kMaxDof) + " are supported");
  }
  chain.X_LF = X_CL;
  return chain;
}

}  // namespace

Result<Chain> ImportUrdf(const std::filesystem::path& file, const UrdfImportOptions& options) {
  std::error_code ec;
  if (!fs::exists(file, ec)) {
    return Fail(ErrorCode::kIo, "urdf '" + file.string() + "': file not found");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) return Fail(ErrorCode::kIo, "urdf '" + file.string() + "': cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return Fail(ErrorCode::kIo, "urdf '" + file.string() + "': read error");

  urdf::ModelInterfaceSharedPtr model;
  std::vector<std::string> errors;
  {
    std::lock_guard<std::mutex> lock(ParseMutex());
    LogCapture capture;
    try {
      model = urdf::parseURDF(text.str());
    } catch (const std::exception& e) {
      capture.errors.push_back(e.what());
      model.reset();
    }
    errors = std::move(capture.errors);
  }
  // urdfdom also drops elements it cannot read (an unknown geometry, a bad number) and carries on:
  // that is an error here too, or a link would silently lose its collision shapes.
  if (!model || !errors.empty()) {
    return Fail(
        ErrorCode::kInvalidInput,
        "urdf '" + file.string() + "': urdfdom: " +
            (errors.empty() ? std::string("could not parse the file") : Join(errors, "; ")));
  }
  // urdfdom links hold their children by shared_ptr, so a link that is its own child (a joint
  // from a link to itself) would keep the model alive forever: cut those references when done.
  struct BreakCycles {
    urdf::ModelInterface& model;
    ~BreakCycles() {
      for (auto& [name, link] : model.links_) {
        if (link) link->child_links.clear();
      }
    }
  } break_cycles{*model};
  Importer importer(file, options);
  try {
    return importer.Run(*model);
  } catch (const std::exception& e) {
    return Fail(ErrorCode::kInternal, "urdf '" + file.string() + "': " + e.what());
  }
}

}  // namespace wrap
