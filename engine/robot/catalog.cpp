#include "robot/catalog.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <span>
#include <utility>

#include "robot/detail/embedded_assets.h"
#include "robot/kinematics.h"

namespace wrap {

namespace {

using json = nlohmann::json;

constexpr std::string_view kRobotSchema = "wrap.robot_model/1";
constexpr std::string_view kEndEffectorSchema = "wrap.end_effector/1";
constexpr std::string_view kMobileBaseSchema = "wrap.mobile_base/1";

// A problem at a JSON path; thrown inside the parsers and turned into an Error at their entry.
struct ParseError {
  std::string path;
  std::string message;
};

std::string Join(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string Index(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

const json& Member(const json& object, std::string_view key, const std::string& path) {
  if (!object.is_object()) throw ParseError{path, "expected an object"};
  const auto it = object.find(key);
  if (it == object.end()) throw ParseError{Join(path, key), "missing"};
  return *it;
}

bool Has(const json& object, std::string_view key) {
  return object.is_object() && object.contains(key);
}

double AsNumber(const json& value, const std::string& path) {
  if (!value.is_number()) throw ParseError{path, "expected a number"};
  const double x = value.get<double>();
  if (!std::isfinite(x)) throw ParseError{path, "expected a finite number"};
  return x;
}

double Number(const json& object, std::string_view key, const std::string& path) {
  return AsNumber(Member(object, key, path), Join(path, key));
}

double NumberOr(const json& object, std::string_view key, const std::string& path,
                double fallback) {
  return Has(object, key) ? Number(object, key, path) : fallback;
}

double Positive(const json& object, std::string_view key, const std::string& path) {
  const double x = Number(object, key, path);
  if (x <= 0.0) throw ParseError{Join(path, key), "expected a positive number"};
  return x;
}

double NonNegative(const json& object, std::string_view key, const std::string& path) {
  const double x = Number(object, key, path);
  if (x < 0.0) throw ParseError{Join(path, key), "expected a number >= 0"};
  return x;
}

std::string String(const json& object, std::string_view key, const std::string& path) {
  const json& value = Member(object, key, path);
  if (!value.is_string()) throw ParseError{Join(path, key), "expected a string"};
  return value.get<std::string>();
}

std::string StringOr(const json& object, std::string_view key, const std::string& path,
                     std::string fallback) {
  return Has(object, key) ? String(object, key, path) : std::move(fallback);
}

Vec3 Vector3(const json& object, std::string_view key, const std::string& path) {
  const json& value = Member(object, key, path);
  const std::string at = Join(path, key);
  if (!value.is_array() || value.size() != 3) throw ParseError{at, "expected [x, y, z]"};
  return Vec3(AsNumber(value[0], Index(at, 0)), AsNumber(value[1], Index(at, 1)),
              AsNumber(value[2], Index(at, 2)));
}

Vec3 NonNegativeVector3(const json& object, std::string_view key, const std::string& path) {
  const Vec3 v = Vector3(object, key, path);
  if ((v.array() < 0.0).any()) throw ParseError{Join(path, key), "expected entries >= 0"};
  return v;
}

const json& Array(const json& object, std::string_view key, const std::string& path) {
  const json& value = Member(object, key, path);
  if (!value.is_array()) throw ParseError{Join(path, key), "expected an array"};
  return value;
}

// {"xyz": [...], "rpy": [...]} (each optional, zero by default) as an isometry.
Iso3 Origin(const json& object, const std::string& path) {
  Pose pose;
  if (Has(object, "xyz")) pose.xyz = Vector3(object, "xyz", path);
  if (Has(object, "rpy")) pose.rpy = Vector3(object, "rpy", path);
  return ToIsometry(pose);
}

Mat3 RotX(double angle) { return Eigen::AngleAxisd(angle, Vec3::UnitX()).toRotationMatrix(); }
Mat3 RotZ(double angle) { return Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix(); }

Shape ParseShape(const json& j, const std::string& path) {
  Shape shape;
  shape.name = StringOr(j, "name", path, path);
  const std::string type = String(j, "type", path);
  if (type == "capsule" || type == "cylinder") {
    shape.type = type == "capsule" ? Shape::Type::kCapsule : Shape::Type::kCylinder;
    shape.radius = Positive(j, "radius", path);
    shape.p0 = Vector3(j, "p0", path);
    shape.p1 = Vector3(j, "p1", path);
    if (shape.type == Shape::Type::kCylinder && (shape.p1 - shape.p0).norm() <= 0.0) {
      throw ParseError{path, "a cylinder needs p0 != p1"};
    }
  } else if (type == "sphere") {
    shape.type = Shape::Type::kSphere;
    shape.radius = Positive(j, "radius", path);
    shape.p0 = shape.p1 = Vector3(j, "center", path);
  } else if (type == "box") {
    shape.type = Shape::Type::kBox;
    Pose pose;
    pose.xyz = Vector3(j, "center", path);
    if (Has(j, "rpy")) pose.rpy = Vector3(j, "rpy", path);
    shape.X_LS = ToIsometry(pose);
    shape.half_extents = Vector3(j, "half_extents", path);
    if ((shape.half_extents.array() <= 0.0).any()) {
      throw ParseError{Join(path, "half_extents"), "expected positive half extents"};
    }
  } else {
    throw ParseError{Join(path, "type"),
                     "unknown shape type '" + type + "' (capsule, cylinder, sphere, box)"};
  }
  return shape;
}

std::vector<Shape> ParseShapes(const json& object, std::string_view key, const std::string& path) {
  std::vector<Shape> shapes;
  if (!Has(object, key)) return shapes;
  const json& list = Array(object, key, path);
  const std::string at = Join(path, key);
  for (std::size_t i = 0; i < list.size(); ++i) shapes.push_back(ParseShape(list[i], Index(at, i)));
  return shapes;
}

// Re-expresses a shape given in frame A in frame B, with X_BA the pose of A in B.
Shape Transformed(Shape shape, const Iso3& X_BA) {
  shape.p0 = X_BA * shape.p0;
  shape.p1 = X_BA * shape.p1;
  shape.X_LS = X_BA * shape.X_LS;
  for (Vec3& v : shape.mesh.vertices) v = X_BA * v;
  return shape;
}

template <typename T>
Result<T> Guarded(std::string_view json_text, std::string_view origin, std::string_view schema,
                  T (*parse)(const json&)) {
  try {
    const json root = json::parse(json_text);
    const std::string found = String(root, "schema", "");
    if (found != schema) {
      throw ParseError{"schema", "expected '" + std::string(schema) + "', found '" + found + "'"};
    }
    return parse(root);
  } catch (const ParseError& e) {
    return Fail(ErrorCode::kInvalidInput,
                "robot catalog: " + std::string(origin) + ": " + e.path + ": " + e.message);
  } catch (const json::exception& e) {
    return Fail(ErrorCode::kInvalidInput,
                "robot catalog: " + std::string(origin) + ": not valid JSON: " + e.what());
  }
}

// One joint's limits: {"lower", "upper", "velocity", "acceleration", "effort"}.
void ParseLimits(const json& j, const std::string& path, Joint& joint) {
  const json& limits = Member(j, "limits", path);
  const std::string at = Join(path, "limits");
  joint.lower = Number(limits, "lower", at);
  joint.upper = Number(limits, "upper", at);
  if (joint.lower > joint.upper) throw ParseError{at, "lower limit above upper limit"};
  joint.max_velocity = Positive(limits, "velocity", at);
  joint.max_acceleration = Positive(limits, "acceleration", at);
  joint.max_effort = Has(limits, "effort") ? NonNegative(limits, "effort", at) : 0.0;
}

Chain ParseChain(const json& root) {
  Chain chain;
  chain.name = String(root, "name", "");
  const std::string kinematics = String(root, "kinematics", "");
  const bool dh = kinematics == "dh";
  if (!dh && kinematics != "urdf") {
    throw ParseError{"kinematics", "expected 'dh' or 'urdf', found '" + kinematics + "'"};
  }
  const json& joints = Array(root, "joints", "");
  if (joints.empty() || joints.size() > static_cast<std::size_t>(kMaxDof)) {
    throw ParseError{"joints", "expected 1 to " + std::to_string(kMaxDof) + " joints"};
  }
  // DH: link i's frame is DH frame i-1 turned by q_i, and DH frame i is link i's frame times
  // C_i = Tz(d_i) Tx(a_i) Rx(alpha_i). So joint i sits at C_{i-1} Rz(theta_offset_i) in link i-1.
  std::vector<Iso3> C(joints.size() + 1, Iso3::Identity());  // C[i + 1] for joint i.
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const json& j = joints[i];
    const std::string path = Index("joints", i);
    Joint joint;
    joint.name = String(j, "name", path);
    const std::string type = StringOr(j, "type", path, "revolute");
    if (type == "prismatic") {
      joint.type = Joint::Type::kPrismatic;
    } else if (type != "revolute") {
      throw ParseError{Join(path, "type"), "expected 'revolute' or 'prismatic'"};
    }
    if (dh) {
      const json& row = Member(j, "dh", path);
      const std::string at = Join(path, "dh");
      Iso3 X = Iso3::Identity();
      X.translation() = Vec3(Number(row, "a", at), 0.0, Number(row, "d", at));
      X.linear() = RotX(Number(row, "alpha", at));
      C[i + 1] = X;
      joint.X_PJ = C[i];
      joint.X_PJ.linear() = joint.X_PJ.linear() * RotZ(NumberOr(row, "theta_offset", at, 0.0));
      joint.axis = Vec3::UnitZ();
    } else {
      joint.X_PJ = Origin(Member(j, "origin", path), Join(path, "origin"));
      const Vec3 axis = Vector3(j, "axis", path);
      if (axis.norm() < 1e-9) throw ParseError{Join(path, "axis"), "expected a non-zero axis"};
      joint.axis = axis.normalized();
    }
    ParseLimits(j, path, joint);
    chain.joints.push_back(std::move(joint));
  }
  const json& links = Array(root, "links", "");
  if (links.size() != joints.size() + 1) {
    throw ParseError{"links", "expected " + std::to_string(joints.size() + 1) +
                                  " links (one per joint plus the base)"};
  }
  for (std::size_t i = 0; i < links.size(); ++i) {
    const json& l = links[i];
    const std::string path = Index("links", i);
    Link link;
    link.name = String(l, "name", path);
    const std::string frame = StringOr(l, "frame", path, "link");
    if (frame != "link" && !(frame == "dh" && dh)) {
      throw ParseError{Join(path, "frame"), dh ? "expected 'dh' or 'link'" : "expected 'link'"};
    }
    const Iso3 X_LA = frame == "dh" ? C[i] : Iso3::Identity();
    for (Shape& s : ParseShapes(l, "collision", path)) {
      link.collision.push_back(Transformed(std::move(s), X_LA));
    }
    if (Has(l, "visual")) {
      for (Shape& s : ParseShapes(l, "visual", path)) {
        link.visual.push_back(Transformed(std::move(s), X_LA));
      }
    } else {
      link.visual = link.collision;
    }
    chain.links.push_back(std::move(link));
  }
  const json& flange = Member(root, "flange", "");
  const std::string frame = StringOr(flange, "frame", "flange", "link");
  if (frame != "link" && !(frame == "dh" && dh)) throw ParseError{"flange.frame", "bad frame"};
  chain.X_LF = (frame == "dh" ? C.back() : Iso3::Identity()) * Origin(flange, "flange");
  return chain;
}

WrenchBox ParseWrenchBox(const json& object, std::string_view key, const std::string& path) {
  const json& j = Member(object, key, path);
  const std::string at = Join(path, key);
  return WrenchBox{NonNegativeVector3(j, "force_N", at), NonNegativeVector3(j, "torque_Nm", at)};
}

Shape FingerBox(const FingerGeometry& fingers, double opening_m, double side,
                const std::string& name) {
  Shape box;
  box.type = Shape::Type::kBox;
  box.name = name;
  box.half_extents = fingers.half_extents;
  const double half_along_axis = fingers.closing_axis_F.cwiseAbs().dot(fingers.half_extents);
  box.X_LS = Iso3::Identity();
  box.X_LS.translation() =
      fingers.center_F + side * (0.5 * opening_m + half_along_axis) * fingers.closing_axis_F;
  return box;
}

EndEffector ParseEndEffectorRoot(const json& root) {
  EndEffector ee;
  ee.name = String(root, "name", "");
  ee.title = StringOr(root, "title", "", ee.name);
  const std::string kind = String(root, "kind", "");
  if (kind == "two-finger") {
    ee.kind = EndEffectorKind::kTwoFinger;
  } else if (kind == "vacuum") {
    ee.kind = EndEffectorKind::kVacuum;
  } else {
    throw ParseError{"kind", "expected 'two-finger' or 'vacuum', found '" + kind + "'"};
  }
  ee.X_FT = Origin(Member(root, "tcp", ""), "tcp");
  ee.mass_kg = Has(root, "mass_kg") ? NonNegative(root, "mass_kg", "") : 0.0;
  ee.collision = ParseShapes(root, "collision", "");
  if (ee.kind == EndEffectorKind::kTwoFinger) {
    ee.stroke_m = Positive(root, "stroke_m", "");
    const json& pad = Member(root, "pad", "");
    ee.pad_width_m = Positive(pad, "width_m", "pad");
    ee.pad_length_m = Positive(pad, "length_m", "pad");
    ee.pad_center_F = Vector3(pad, "center", "pad");
    const json& fingers = Member(root, "fingers", "");
    const Vec3 axis = Vector3(fingers, "closing_axis", "fingers");
    if (axis.norm() < 1e-9) throw ParseError{"fingers.closing_axis", "expected a non-zero axis"};
    ee.fingers.closing_axis_F = axis.normalized();
    ee.fingers.center_F = Vector3(fingers, "center", "fingers");
    ee.fingers.half_extents = Vector3(fingers, "half_extents", "fingers");
    if ((ee.fingers.half_extents.array() <= 0.0).any()) {
      throw ParseError{"fingers.half_extents", "expected positive half extents"};
    }
    ee.finger_shapes = {static_cast<int>(ee.collision.size()),
                        static_cast<int>(ee.collision.size()) + 1};
    ee.collision.push_back(FingerBox(ee.fingers, ee.stroke_m, +1.0, ee.name + "/finger_pos"));
    ee.collision.push_back(FingerBox(ee.fingers, ee.stroke_m, -1.0, ee.name + "/finger_neg"));
  } else {
    ee.cup_diameter_m = Positive(Member(root, "cup", ""), "diameter_m", "cup");
  }
  ee.visual = ee.collision;
  const json& limits = Member(root, "wrench_limits", "");
  ee.wrench_assembly = ParseWrenchBox(limits, "assembly", "wrench_limits");
  ee.wrench_transport = ParseWrenchBox(limits, "transport", "wrench_limits");
  return ee;
}

MobileBaseModel ParseMobileBaseRoot(const json& root) {
  MobileBaseModel base;
  base.name = String(root, "name", "");
  base.title = StringOr(root, "title", "", base.name);
  base.base_height_m = NonNegative(root, "base_height_m", "");
  base.mass_kg = Has(root, "mass_kg") ? NonNegative(root, "mass_kg", "") : 0.0;
  // The file gives shapes and mounts in the URDF's base_link; the model uses the floor frame
  // under it, like a project's mobile-base pose.
  Iso3 X_BL = Iso3::Identity();
  X_BL.translation().z() = base.base_height_m;
  for (Shape& s : ParseShapes(root, "collision", "")) {
    base.collision.push_back(Transformed(std::move(s), X_BL));
  }
  base.visual = base.collision;
  // Mounts are given in the bulkhead frame, as in the URDF.
  const Iso3 X_LH =
      Has(root, "bulkhead") ? Origin(root.at("bulkhead"), "bulkhead") : Iso3::Identity();
  const json& mounts = Array(root, "mounts", "");
  for (std::size_t i = 0; i < mounts.size(); ++i) {
    const std::string path = Index("mounts", i);
    base.mounts.push_back({String(mounts[i], "name", path), X_BL * X_LH * Origin(mounts[i], path)});
  }
  base.arm_model = StringOr(root, "arm_model", "", "");
  base.end_effector = StringOr(root, "end_effector", "", "");
  base.tool_coupling_m = NumberOr(root, "tool_coupling_m", "", 0.0);
  return base;
}

// The schema of every embedded asset, read once.
struct AssetIndex {
  std::vector<std::pair<const detail::EmbeddedAsset*, std::string>> entries;
};

const AssetIndex& AssetTable() {
  static const AssetIndex index = [] {
    AssetIndex out;
    for (const detail::EmbeddedAsset& asset : detail::EmbeddedRobotAssets()) {
      std::string schema;
      try {
        const json root = json::parse(asset.text);
        if (root.is_object() && root.contains("schema") && root["schema"].is_string()) {
          schema = root["schema"].get<std::string>();
        }
      } catch (const json::exception&) {
        // Reported by the parser with its path when the asset is loaded.
      }
      out.entries.emplace_back(&asset, std::move(schema));
    }
    return out;
  }();
  return index;
}

std::vector<std::string> NamesOfSchema(std::string_view schema) {
  std::vector<std::string> names;
  for (const auto& [asset, found] : AssetTable().entries) {
    if (found == schema) names.emplace_back(asset->name);
  }
  return names;
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

template <typename T>
Result<T> LoadByName(std::string_view name, std::string_view schema, std::string_view what,
                     T (*parse)(const json&)) {
  for (const auto& [asset, found] : AssetTable().entries) {
    if (asset->name == name && found == schema) {
      return Guarded<T>(asset->text, asset->file, schema, parse);
    }
  }
  return Fail(ErrorCode::kInvalidInput, "robot catalog: unknown " + std::string(what) + " '" +
                                            std::string(name) +
                                            "'; known: " + JoinNames(NamesOfSchema(schema)));
}

}  // namespace

Result<Chain> ParseRobotModel(std::string_view json_text, std::string_view origin) {
  return Guarded<Chain>(json_text, origin, kRobotSchema, &ParseChain);
}

Result<EndEffector> ParseEndEffector(std::string_view json_text, std::string_view origin) {
  return Guarded<EndEffector>(json_text, origin, kEndEffectorSchema, &ParseEndEffectorRoot);
}

Result<MobileBaseModel> ParseMobileBase(std::string_view json_text, std::string_view origin) {
  return Guarded<MobileBaseModel>(json_text, origin, kMobileBaseSchema, &ParseMobileBaseRoot);
}

Result<Chain> LoadRobotModel(std::string_view name) {
  return LoadByName<Chain>(name, kRobotSchema, "robot model", &ParseChain);
}

Result<EndEffector> LoadEndEffector(std::string_view name) {
  return LoadByName<EndEffector>(name, kEndEffectorSchema, "end effector", &ParseEndEffectorRoot);
}

Result<MobileBaseModel> LoadMobileBase(std::string_view name) {
  return LoadByName<MobileBaseModel>(name, kMobileBaseSchema, "mobile base", &ParseMobileBaseRoot);
}

std::vector<std::string> CatalogRobotModelNames() { return NamesOfSchema(kRobotSchema); }
std::vector<std::string> CatalogEndEffectorNames() { return NamesOfSchema(kEndEffectorSchema); }
std::vector<std::string> CatalogMobileBaseNames() { return NamesOfSchema(kMobileBaseSchema); }

std::vector<Shape> EndEffectorShapesAt(const EndEffector& ee, double opening_m) {
  std::vector<Shape> shapes = ee.collision;
  if (ee.kind != EndEffectorKind::kTwoFinger) return shapes;
  const double opening = std::clamp(opening_m, 0.0, ee.stroke_m);
  const double sides[2] = {+1.0, -1.0};
  for (int k = 0; k < 2; ++k) {
    const int index = ee.finger_shapes[k];
    if (index < 0 || index >= static_cast<int>(shapes.size())) continue;
    shapes[index] = FingerBox(ee.fingers, opening, sides[k], shapes[index].name);
  }
  return shapes;
}

}  // namespace wrap
