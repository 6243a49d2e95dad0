// The MJCF writer: the cell (table, robots, grippers, parts) as MuJoCo XML, for drawing and, in
// its physics variant, for `wrap sim` (free parts with their contacts, TCP mocap bodies, welds).
#include "sim/mjcf.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <numbers>
#include <utility>

#include "core/file_io.h"
#include "robot/kinematics.h"

namespace wrap {

namespace fs = std::filesystem;

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
// Shorter capsules and cylinders are drawn as spheres (MuJoCo rejects coincident fromto) [m].
constexpr double kMinSegment = 1e-6;
// Below this enclosed volume a mesh counts as flat: MuJoCo 2.2 rejects it [m^3].
constexpr double kMinMeshVolume = 1e-12;

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

std::string Vec(const Vec3& v) { return Num(v.x()) + " " + Num(v.y()) + " " + Num(v.z()); }

std::string Color(const Rgba& c) {
  return Num(c[0]) + " " + Num(c[1]) + " " + Num(c[2]) + " " + Num(c[3]);
}

std::string Color3(const Rgba& c) { return Num(c[0]) + " " + Num(c[1]) + " " + Num(c[2]); }

// MuJoCo quaternion (w x y z) of a rotation.
std::string Quat(const Mat3& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1.0;
  return Num(q.w()) + " " + Num(q.x()) + " " + Num(q.y()) + " " + Num(q.z());
}

// ` pos="..." quat="..."` of a pose, omitting identity parts.
std::string PoseAttrs(const Iso3& X) {
  std::string s;
  if (!X.translation().isZero(0.0)) s += " pos=\"" + Vec(X.translation()) + "\"";
  if (!X.linear().isIdentity(1e-15)) s += " quat=\"" + Quat(X.linear()) + "\"";
  return s;
}

// Escapes a name for an XML attribute.
std::string Esc(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// True when MuJoCo 2.2 accepts the mesh: some enclosed volume and every directed edge used once
// (it rejects "inconsistent orientation" and "volume too small").
bool MujocoAcceptsMesh(const TriangleMesh& mesh) {
  if (mesh.triangles.size() < 4) return false;
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) edges.emplace_back(t[k], t[(k + 1) % 3]);
  }
  std::sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return false;
  return std::abs(ComputeMassProperties(mesh).volume_m3) > kMinMeshVolume;
}

// Writes the XML of one cell, collecting assets and names on the way.
class Writer {
 public:
  Writer(const CellScene& scene, const SceneState& state, const MjcfOptions& options)
      : scene_(scene), state_(state), options_(options) {}

  Result<MjcfDocument> Run() {
    if (auto ok = CheckState(); !ok) return std::unexpected(ok.error());
    const Aabb bounds = SceneBounds(scene_, state_);
    const Vec3 center = 0.5 * (bounds.min + bounds.max);
    const double extent = std::max(0.5, 0.5 * bounds.size().norm());

    Line("<mujoco model=\"" + Esc(scene_.name.empty() ? "cell" : scene_.name) + "\">");
    ++depth_;
    Line("<compiler angle=\"radian\" inertiafromgeom=\"false\"/>");
    if (options_.physics) {
      // Dense Jacobians: verify/ reads the weld rows of efc_J to measure gripper wrenches.
      // Multi-point convex collision: with one contact per mesh-box pair a flat part rocks
      // and tips over the table's edge instead of resting on its face.
      Line("<option timestep=\"" + Num(options_.timestep_s) +
           "\" gravity=\"0 0 -9.81\" jacobian=\"dense\" cone=\"elliptic\" impratio=\"10\">");
      Line("  <flag multiccd=\"enable\"/>");
      Line("</option>");
      Line("<size njmax=\"6000\" nconmax=\"1500\"/>");
    }
    Line("<statistic center=\"" + Vec(center) + "\" extent=\"" + Num(extent) + "\"/>");
    Visual();
    Defaults();
    MarkAssetBlock();
    Line("<worldbody>");
    ++depth_;
    Lights(center, extent);
    const CameraView& cam = options_.camera;
    const Vec3 fwd = Forward(cam);
    const Vec3 cam_pos = cam.lookat - cam.distance_m * fwd;
    const Vec3 up = Up(cam);
    const Vec3 right = fwd.cross(up);
    Line("<camera name=\"overview\" pos=\"" + Vec(cam_pos) + "\" xyaxes=\"" + Vec(right) + " " +
         Vec(up) + "\" fovy=\"" + Num(options_.fovy_deg) + "\"/>");
    Floor();
    Table();
    for (const SceneMobileBase& b : scene_.mobile_bases) {
      if (auto ok = MobileBaseBody(b); !ok) return std::unexpected(ok.error());
    }
    for (size_t r = 0; r < scene_.robots.size(); ++r) {
      if (auto ok = RobotBodies(static_cast<int>(r)); !ok) return std::unexpected(ok.error());
    }
    for (size_t p = 0; p < scene_.parts.size(); ++p) PartBody(static_cast<int>(p));
    if (options_.physics) TcpBodies();
    --depth_;
    Line("</worldbody>");
    if (options_.physics) {
      Welds();
    } else {
      Keyframe();
    }
    --depth_;
    Line("</mujoco>");
    for (auto& [mesh, name] : part_mesh_names_) {
      doc_.assets.push_back({name + ".msh", EncodeMsh(*mesh)});
    }
    std::sort(doc_.assets.begin(), doc_.assets.end(),
              [](const MjcfAsset& a, const MjcfAsset& b) { return a.name < b.name; });
    doc_.xml = xml_;
    return std::move(doc_);
  }

  // The camera frame as MuJoCo's free camera computes it: forward, up and right, never singular.
  static Vec3 Forward(const CameraView& cam) {
    const double az = cam.azimuth_deg * kDegToRad;
    const double el = cam.elevation_deg * kDegToRad;
    return Vec3(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  }
  static Vec3 Up(const CameraView& cam) {
    const double az = cam.azimuth_deg * kDegToRad;
    const double el = cam.elevation_deg * kDegToRad;
    return Vec3(-std::sin(el) * std::cos(az), -std::sin(el) * std::sin(az), std::cos(el));
  }

 private:
  Result<void> CheckState() const {
    if (state_.q.size() != scene_.robots.size() ||
        state_.opening_m.size() != scene_.robots.size() ||
        state_.X_WP.size() != scene_.parts.size()) {
      return Fail(ErrorCode::kInvalidInput,
                  "mjcf: state has " + std::to_string(state_.q.size()) + " robots and " +
                      std::to_string(state_.X_WP.size()) + " parts; the scene has " +
                      std::to_string(scene_.robots.size()) + " and " +
                      std::to_string(scene_.parts.size()));
    }
    for (size_t r = 0; r < scene_.robots.size(); ++r) {
      if (state_.q[r].size() != scene_.robots[r].chain.dof()) {
        return Fail(ErrorCode::kInvalidInput,
                    "mjcf: robot '" + scene_.robots[r].name + "': state has " +
                        std::to_string(state_.q[r].size()) + " joint values, the chain " +
                        std::to_string(scene_.robots[r].chain.dof()));
      }
    }
    return {};
  }

  // The state as keyframe "state" (qpos in the order the joints appear: per robot its chain
  // joints, then its fingers; mocap poses in part order), e.g. for MuJoCo's `simulate`.
  void Keyframe() {
    std::string qpos, mpos, mquat;
    auto add = [](std::string& list, double v) { list += (list.empty() ? "" : " ") + Num(v); };
    for (size_t r = 0; r < scene_.robots.size(); ++r) {
      for (int j = 0; j < state_.q[r].size(); ++j) add(qpos, state_.q[r][j]);
      for (const std::string& finger : doc_.finger_joints[r]) {
        if (!finger.empty()) add(qpos, 0.5 * std::max(0.0, state_.opening_m[r]));
      }
    }
    for (const Iso3& X : state_.X_WP) {
      for (int k = 0; k < 3; ++k) add(mpos, X.translation()[k]);
      mquat += (mquat.empty() ? "" : " ") + Quat(X.linear());
    }
    Line("<keyframe>");
    ++depth_;
    std::string key = "<key name=\"state\"";
    if (!qpos.empty()) key += " qpos=\"" + qpos + "\"";
    if (!mpos.empty()) key += " mpos=\"" + mpos + "\" mquat=\"" + mquat + "\"";
    Line(key + "/>");
    --depth_;
    Line("</keyframe>");
  }

  void Line(const std::string& s) {
    xml_.append(2 * depth_, ' ');
    xml_ += s;
    xml_ += '\n';
  }

  void Visual() {
    const int w = std::max(1, options_.offscreen_width);
    const int h = std::max(1, options_.offscreen_height);
    const CameraView& cam = options_.camera;
    Line("<visual>");
    ++depth_;
    Line("<global offwidth=\"" + std::to_string(w) + "\" offheight=\"" + std::to_string(h) +
         "\" fovy=\"" + Num(options_.fovy_deg) + "\" azimuth=\"" + Num(cam.azimuth_deg) +
         "\" elevation=\"" + Num(cam.elevation_deg) + "\"/>");
    Line("<quality shadowsize=\"" + std::to_string(options_.shadow_map_px) + "\" offsamples=\"" +
         std::to_string(options_.offscreen_samples) + "\"/>");
    // A soft headlight keeps the side away from the key light readable.
    Line(
        "<headlight ambient=\"0.35 0.35 0.35\" diffuse=\"0.25 0.25 0.25\" specular=\"0.08 0.08 "
        "0.08\"/>");
    Line("<map znear=\"0.01\" zfar=\"60\" haze=\"0.25\" shadowclip=\"1.2\" shadowscale=\"0.7\"/>");
    Line("<rgba haze=\"" + Color(options_.style.sky_bottom) + "\"/>");
    --depth_;
    Line("</visual>");
  }

  void Defaults() {
    Line("<default>");
    ++depth_;
    Line("<geom contype=\"0\" conaffinity=\"0\" group=\"0\"/>");
    Line("<joint limited=\"false\" damping=\"1\"/>");
    --depth_;
    Line("</default>");
  }

  // Named material for a colour, shared by every geom of that colour.
  std::string Material(const Rgba& color, double specular = 0.25, double shininess = 0.4) {
    char key[160];
    std::snprintf(key, sizeof key, "%s|%g|%g", Color(color).c_str(), specular, shininess);
    auto [it, inserted] = materials_.try_emplace(key, "mat" + std::to_string(materials_.size()));
    if (inserted) {
      material_xml_.push_back("<material name=\"" + it->second + "\" rgba=\"" + Color(color) +
                              "\" specular=\"" + Num(specular) + "\" shininess=\"" +
                              Num(shininess) + "\"/>");
    }
    return it->second;
  }

  // Materials and meshes are known only once the bodies are written: remember where the asset
  // block goes (BuildCellMjcf inserts AssetBlock() there).
  void MarkAssetBlock() {
    asset_pos_ = xml_.size();
    asset_depth_ = depth_;
  }

  void Lights(const Vec3& center, double extent) {
    // Key light from above, front-left of the default view, casting the shadows; a weaker fill
    // light from the other side without shadows.
    const Vec3 key_dir = Vec3(-0.25, 0.45, -1.0).normalized();
    const Vec3 fill_dir = Vec3(-0.5, -0.3, -0.8).normalized();
    Line("<light name=\"key\" directional=\"true\" pos=\"" + Vec(center - 3.0 * extent * key_dir) +
         "\" dir=\"" + Vec(key_dir) + "\" diffuse=\"0.42 0.42 0.41\" specular=\"0.15 0.15 0.15\"" +
         " castshadow=\"" + (options_.shadows ? "true" : "false") + "\"/>");
    Line("<light name=\"fill\" directional=\"true\" pos=\"" +
         Vec(center - 3.0 * extent * fill_dir) + "\" dir=\"" + Vec(fill_dir) +
         "\" diffuse=\"0.15 0.15 0.16\" specular=\"0 0 0\" castshadow=\"false\"/>");
  }

  void Floor() {
    Line("<geom name=\"floor\" type=\"plane\" size=\"0 0 0.05\" material=\"floor\"" +
         SupportContact() + "/>");
  }

  void Table() {
    const SceneTable& t = scene_.table;
    const Vec3 half = 0.5 * t.size;
    const Vec3 top_center = t.top_center - Vec3(0, 0, half.z());
    Line("<body name=\"table\">");
    ++depth_;
    Line("<geom name=\"table/top\" type=\"box\" pos=\"" + Vec(top_center) + "\" size=\"" +
         Vec(half) + "\" material=\"table\"" + SupportContact() + "/>");
    // Four legs from the floor to the underside, inset from the corners.
    const double underside = t.top_center.z() - t.size.z();
    const double leg = std::min({0.025, 0.1 * half.x(), 0.1 * half.y()});
    const double inset = 2.0 * leg;
    if (underside > 0.02) {
      const std::string legs = Material(options_.style.table_legs, 0.3, 0.5);
      for (int i = 0; i < 4; ++i) {
        const Vec3 p(t.top_center.x() + ((i & 1) ? 1 : -1) * (half.x() - inset),
                     t.top_center.y() + ((i & 2) ? 1 : -1) * (half.y() - inset), 0.5 * underside);
        Line("<geom name=\"table/leg" + std::to_string(i) + "\" type=\"box\" pos=\"" + Vec(p) +
             "\" size=\"" + Num(leg) + " " + Num(leg) + " " + Num(0.5 * underside) +
             "\" material=\"" + legs + "\"/>");
      }
    }
    --depth_;
    Line("</body>");
  }

  // One geom for a shape in the current body's frame; `prefix` names it.
  Result<void> Geom(const Shape& s, const std::string& name, const std::string& material,
                    const Iso3& X_BL = Iso3::Identity()) {
    const std::string head = "<geom name=\"" + Esc(name) + "\" material=\"" + material + "\"";
    switch (s.type) {
      case Shape::Type::kCapsule:
      case Shape::Type::kCylinder:
      case Shape::Type::kSphere: {
        if (!(s.radius > 0.0)) return Bad(name, "radius " + Num(s.radius));
        const Vec3 p0 = X_BL * s.p0;
        const Vec3 p1 = X_BL * s.p1;
        if (s.type == Shape::Type::kSphere || (p1 - p0).norm() < kMinSegment) {
          Line(head + " type=\"sphere\" pos=\"" + Vec(p0) + "\" size=\"" + Num(s.radius) + "\"/>");
        } else {
          const char* type = s.type == Shape::Type::kCapsule ? "capsule" : "cylinder";
          Line(head + " type=\"" + type + "\" fromto=\"" + Vec(p0) + " " + Vec(p1) + "\" size=\"" +
               Num(s.radius) + "\"/>");
        }
        return {};
      }
      case Shape::Type::kBox:
        if (!(s.half_extents.array() > 0.0).all())
          return Bad(name, "half extents " + Vec(s.half_extents));
        Line(head + " type=\"box\"" + PoseAttrs(X_BL * s.X_LS) + " size=\"" + Vec(s.half_extents) +
             "\"/>");
        return {};
      case Shape::Type::kMesh: {
        if (s.mesh.empty()) return Bad(name, "empty mesh");
        if (!MujocoAcceptsMesh(s.mesh)) {
          BoxFallback(s.mesh, X_BL, head, name);
          return {};
        }
        const std::string mesh = "mesh" + std::to_string(mesh_count_++);
        doc_.assets.push_back({mesh + ".msh", EncodeMsh(Transformed(s.mesh, X_BL))});
        mesh_xml_.push_back("<mesh name=\"" + mesh + "\" file=\"" + mesh + ".msh\"/>");
        Line(head + " type=\"mesh\" mesh=\"" + mesh + "\"/>");
        return {};
      }
    }
    return {};
  }

  // A mesh MuJoCo would reject, drawn as its bounding box.
  void BoxFallback(const TriangleMesh& mesh, const Iso3& X, const std::string& head,
                   const std::string& name) {
    const Aabb box = ComputeAabb(Transformed(mesh, X));
    const Vec3 half = (0.5 * box.size()).cwiseMax(Vec3::Constant(5e-4));
    Line(head + " type=\"box\" pos=\"" + Vec(0.5 * (box.min + box.max)) + "\" size=\"" + Vec(half) +
         "\"/>");
    doc_.warnings.push_back("mesh of '" + name +
                            "' is flat or inconsistently oriented; drawn as its bounding box");
  }

  Result<void> Bad(const std::string& name, const std::string& what) const {
    return Fail(ErrorCode::kInvalidInput, "mjcf: shape '" + name + "': degenerate (" + what + ")");
  }

  Result<void> MobileBaseBody(const SceneMobileBase& b) {
    const SceneStyle& st = options_.style;
    Line("<body name=\"base:" + Esc(b.name) + "\"" + PoseAttrs(b.X_WB) + ">");
    ++depth_;
    int k = 0;
    for (const Shape& s : b.model.visual) {
      // Wheels and the lower chassis dark, the rest in the chassis colour.
      const bool dark = s.type != Shape::Type::kBox || s.name.find("lower") != std::string::npos;
      const bool metal = s.name.find("bulkhead") != std::string::npos;
      const std::string mat = dark    ? Material(st.tire, 0.1, 0.2)
                              : metal ? Material(st.pedestal, 0.3, 0.5)
                                      : Material(st.mobile_base, 0.3, 0.5);
      if (auto ok = Geom(s, "base:" + b.name + "/" + std::to_string(k++), mat); !ok) return ok;
    }
    --depth_;
    Line("</body>");
    return {};
  }

  Result<void> RobotBodies(int r) {
    const SceneRobot& robot = scene_.robots[r];
    const SceneStyle& st = options_.style;
    const Rgba accent = st.accents.empty() ? st.robot : st.accents[r % st.accents.size()];
    const std::string accent_mat = Material(accent, 0.35, 0.5);
    const std::string light_mat = Material(st.robot, 0.35, 0.6);
    const std::string dark_mat = Material(st.robot_dark, 0.2, 0.4);
    const std::string prefix = "robot:" + robot.name + "/";
    const Chain& chain = robot.chain;

    if (robot.pedestal_radius_m > 0.0) {
      const Vec3 top = robot.X_WB.translation();
      const Vec3 bottom(top.x(), top.y(), robot.pedestal_bottom_z);
      Line("<geom name=\"" + Esc(prefix + "pedestal") + "\" type=\"cylinder\" fromto=\"" +
           Vec(bottom) + " " + Vec(top) + "\" size=\"" + Num(robot.pedestal_radius_m) +
           "\" material=\"" + Material(st.pedestal, 0.3, 0.5) + "\"/>");
    }

    doc_.robot_joints.emplace_back();
    Line("<body name=\"" + Esc(prefix + "link0") + "\"" + PoseAttrs(robot.X_WB) + ">");
    ++depth_;
    for (size_t l = 0; l < chain.links.size(); ++l) {
      if (l > 0) {
        const Joint& j = chain.joints[l - 1];
        const std::string jname = prefix + "joint" + std::to_string(l);
        Line("<body name=\"" + Esc(prefix + "link" + std::to_string(l)) + "\"" + PoseAttrs(j.X_PJ) +
             ">");
        ++depth_;
        Line("<joint name=\"" + Esc(jname) + "\" type=\"" +
             (j.type == Joint::Type::kRevolute ? "hinge" : "slide") + "\" axis=\"" + Vec(j.axis) +
             "\" ref=\"0\"/>");
        Inertial();
        doc_.robot_joints.back().push_back(jname);
      }
      const std::string& mat = l == 0 ? accent_mat : light_mat;
      int k = 0;
      for (const Shape& s : chain.links[l].visual) {
        auto ok = Geom(s, prefix + "link" + std::to_string(l) + "/" + std::to_string(k++), mat);
        if (!ok) return ok;
      }
    }
    if (auto ok = EndEffectorBody(robot, prefix, accent_mat, dark_mat); !ok) return ok;
    for (size_t l = 1; l < chain.links.size(); ++l) {
      --depth_;
      Line("</body>");
    }
    --depth_;
    Line("</body>");
    return {};
  }

  Result<void> EndEffectorBody(const SceneRobot& robot, const std::string& prefix,
                               const std::string& accent_mat, const std::string& dark_mat) {
    const EndEffector& ee = robot.end_effector;
    Line("<body name=\"" + Esc(prefix + "ee") + "\"" + PoseAttrs(robot.chain.X_LF) + ">");
    ++depth_;
    for (size_t k = 0; k < ee.visual.size(); ++k) {
      const int index = static_cast<int>(k);
      if (index == ee.finger_shapes[0] || index == ee.finger_shapes[1]) continue;
      const Shape& s = ee.visual[k];
      const bool body = s.type == Shape::Type::kBox || s.type == Shape::Type::kMesh;
      auto ok = Geom(s, prefix + "ee/" + std::to_string(k), body ? accent_mat : dark_mat);
      if (!ok) return ok;
    }
    std::array<std::string, 2> fingers;
    if (ee.kind == EndEffectorKind::kTwoFinger && ee.finger_shapes[0] >= 0) {
      // Each finger slides outwards from closed; qpos = half the opening.
      const FingerGeometry& f = ee.fingers;
      const double half_along = f.closing_axis_F.cwiseAbs().dot(f.half_extents);
      const double sides[2] = {+1.0, -1.0};
      for (int k = 0; k < 2; ++k) {
        const std::string name = prefix + (k == 0 ? "finger_pos" : "finger_neg");
        const Vec3 p = f.center_F + sides[k] * half_along * f.closing_axis_F;
        Line("<body name=\"" + Esc(name) + "\" pos=\"" + Vec(p) + "\">");
        ++depth_;
        Line("<joint name=\"" + Esc(name) + "\" type=\"slide\" axis=\"" +
             Vec(sides[k] * f.closing_axis_F) + "\"/>");
        Inertial();
        Line("<geom name=\"" + Esc(name) + "\" type=\"box\" size=\"" + Vec(f.half_extents) +
             "\" material=\"" + dark_mat + "\"/>");
        --depth_;
        Line("</body>");
        fingers[k] = name;
      }
    }
    doc_.finger_joints.push_back(fingers);
    --depth_;
    Line("</body>");
    return {};
  }

  // Physics: the table and floor collide with parts (contype 1 meets a part's conaffinity 1),
  // parts not with each other (contype 2 meets only conaffinity 2).
  std::string SupportContact() const {
    if (!options_.physics) return "";
    return " contype=\"" + std::to_string(kPartConaffinity) + "\" conaffinity=\"" +
           std::to_string(kPartContype) + "\"" + ContactParameters();
  }
  std::string PartContact() const {
    if (!options_.physics) return "";
    return " contype=\"" + std::to_string(kPartContype) + "\" conaffinity=\"" +
           std::to_string(kPartConaffinity) + "\"" + ContactParameters();
  }
  // Friction and stiffness of every part-table contact, on both geoms: MuJoCo averages the two
  // geoms' solref, so a table left at the default 0.02 s made the pair's time constant 12 ms
  // instead of 4 (a 39 g beam pressed with 10 N sank 0.5 mm, then mm, and rolled over). As stiff
  // as the step allows with margin (a softer contact lets heavy parts sink mm deep).
  std::string ContactParameters() const {
    return " friction=\"" + Num(scene_.table.friction) + " 0.005 0.0001\" solref=\"" +
           Num(4.0 * options_.timestep_s) + " 1\"";
  }

  // Physics: spheres of kSupportSphereRadius_m at part p's support points
  // (MjcfOptions::support_points_P), which meet
  // only the table and floor. MuJoCo 2.2 collides a mesh with the table box through libccd (MPR
  // with multiccd) and finds one to four points anywhere on a flat face (under a beam pressed by
  // an insertion, two on its centre line: it rolled over its long edge). Sphere-box contacts are
  // exact and put MuJoCo's friction where the wrench LP has it, at the corners of the support
  // polygon. Not drawn (group 3).
  void SupportSpheres(int p, const std::string& part_name) {
    doc_.support_geoms.emplace_back();
    if (p >= static_cast<int>(options_.support_points_P.size())) return;
    for (const Vec3& v : options_.support_points_P[p]) {
      const std::string name =
          part_name + "/support" + std::to_string(doc_.support_geoms.back().size());
      Line("<geom name=\"" + Esc(name) + "\" type=\"sphere\" size=\"" +
           Num(kSupportSphereRadius_m) + "\" pos=\"" + Vec(v) + "\" group=\"3\" rgba=\"0 0 0 0\"" +
           PartContact() + "/>");
      doc_.support_geoms.back().push_back(name);
    }
  }

  // Physics: a part's mass and inertia about its COM (a small box's when the mesh gives none).
  void PartInertial(const ScenePart& part) {
    const double mass = part.mass_kg > 0.0 ? part.mass_kg : 0.01;
    Mat3 I = part.inertia_com;
    Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (I + I.transpose()));
    if (!(eig.eigenvalues().minCoeff() > 1e-12)) {
      const Vec3 size = ComputeAabb(*part.mesh).size().cwiseMax(Vec3::Constant(1e-3));
      I = Mat3::Zero();
      I(0, 0) = mass * (size.y() * size.y() + size.z() * size.z()) / 12.0;
      I(1, 1) = mass * (size.x() * size.x() + size.z() * size.z()) / 12.0;
      I(2, 2) = mass * (size.x() * size.x() + size.y() * size.y()) / 12.0;
    }
    Line("<inertial pos=\"" + Vec(part.com_P) + "\" mass=\"" + Num(mass) + "\" fullinertia=\"" +
         Num(I(0, 0)) + " " + Num(I(1, 1)) + " " + Num(I(2, 2)) + " " + Num(I(0, 1)) + " " +
         Num(I(0, 2)) + " " + Num(I(1, 2)) + "\"/>");
  }

  // Physics: one mocap body per robot at its TCP, which the simulation drives and welds to.
  void TcpBodies() {
    for (size_t r = 0; r < scene_.robots.size(); ++r) {
      const SceneRobot& robot = scene_.robots[r];
      const Iso3 X_WT = TcpPose(robot.chain, robot.X_WB, state_.q[r], robot.end_effector.X_FT);
      const std::string name = "tcp:" + robot.name;
      Line("<body name=\"" + Esc(name) + "\" mocap=\"true\"" + PoseAttrs(X_WT) + "/>");
      doc_.tcp_bodies.push_back(name);
    }
  }

  // Physics: inactive welds, TCP to part and part to part, stiff as the step allows (MuJoCo
  // clamps the time constant to twice the step).
  void Welds() {
    const std::string solref = " solref=\"" + Num(2.0 * options_.timestep_s) + " 1\"";
    const size_t np = scene_.parts.size();
    Line("<equality>");
    ++depth_;
    doc_.grip_welds.assign(scene_.robots.size(), std::vector<std::string>(np));
    for (size_t r = 0; r < scene_.robots.size(); ++r) {
      for (size_t p = 0; p < np; ++p) {
        const std::string name = "grip/" + std::to_string(r) + "/" + std::to_string(p);
        Line("<weld name=\"" + name + "\" body1=\"" + Esc(doc_.tcp_bodies[r]) + "\" body2=\"" +
             Esc(doc_.part_bodies[p]) + "\" active=\"false\"" + solref + "/>");
        doc_.grip_welds[r][p] = name;
      }
    }
    doc_.join_welds.assign(np, std::vector<std::string>(np));
    for (size_t p = 0; p < np; ++p) {
      for (size_t q = p + 1; q < np; ++q) {
        const std::string name = "join/" + std::to_string(p) + "/" + std::to_string(q);
        Line("<weld name=\"" + name + "\" body1=\"" + Esc(doc_.part_bodies[p]) + "\" body2=\"" +
             Esc(doc_.part_bodies[q]) + "\" active=\"false\"" + solref + "/>");
        doc_.join_welds[p][q] = name;
      }
    }
    --depth_;
    Line("</equality>");
  }

  void Inertial() { Line("<inertial pos=\"0 0 0\" mass=\"0.1\" diaginertia=\"1e-4 1e-4 1e-4\"/>"); }

  // A part: a mocap body with its mesh (shared between parts made from one file), or the mesh's
  // box when MuJoCo would reject the mesh.
  void PartBody(int p) {
    const ScenePart& part = scene_.parts[p];
    const std::string name = "part:" + part.name;
    const std::string head = "<geom name=\"" + Esc(name) + "\" material=\"" +
                             Material(part.color, 0.3, 0.45) + "\"" + PartContact();
    if (options_.physics) {
      Line("<body name=\"" + Esc(name) + "\"" + PoseAttrs(state_.X_WP[p]) + ">");
      ++depth_;
      Line("<joint name=\"" + Esc(name) + "\" type=\"free\" damping=\"0\"/>");
      PartInertial(part);
    } else {
      Line("<body name=\"" + Esc(name) + "\" mocap=\"true\"" + PoseAttrs(state_.X_WP[p]) + ">");
      ++depth_;
    }
    auto [accepted, fresh] = part_mesh_ok_.try_emplace(part.mesh.get(), false);
    if (fresh) accepted->second = MujocoAcceptsMesh(*part.mesh);
    if (accepted->second) {
      auto [it, inserted] = part_mesh_names_.try_emplace(
          part.mesh.get(), "part_mesh" + std::to_string(part_mesh_names_.size()));
      if (inserted) {
        mesh_xml_.push_back("<mesh name=\"" + it->second + "\" file=\"" + it->second + ".msh\"/>");
      }
      Line(head + " type=\"mesh\" mesh=\"" + it->second + "\"/>");
    } else {
      BoxFallback(*part.mesh, Iso3::Identity(), head, name);
    }
    if (options_.physics) SupportSpheres(p, name);
    --depth_;
    Line("</body>");
    doc_.part_bodies.push_back(name);
  }

 public:
  // The asset block: textures, materials and meshes, inserted after the bodies are written.
  std::string AssetBlock() const {
    const SceneStyle& st = options_.style;
    std::string s;
    const std::string pad(2 * asset_depth_, ' ');
    auto add = [&](int extra, const std::string& line) {
      s += pad;
      s.append(2 * extra, ' ');
      s += line;
      s += '\n';
    };
    add(0, "<asset>");
    add(1, "<texture name=\"sky\" type=\"skybox\" builtin=\"gradient\" rgb1=\"" +
               Color3(st.sky_top) + "\" rgb2=\"" + Color3(st.sky_bottom) +
               "\" width=\"256\" height=\"256\"/>");
    // A faint 0.5 m grid on the floor.
    const Rgba& f = st.floor;
    const Rgba grid = {f[0] * 0.94, f[1] * 0.94, f[2] * 0.94, 1.0};
    add(1, "<texture name=\"floor\" type=\"2d\" builtin=\"checker\" rgb1=\"" + Color3(f) +
               "\" rgb2=\"" + Color3(f) + "\" mark=\"edge\" markrgb=\"" + Color3(grid) +
               "\" width=\"512\" height=\"512\"/>");
    add(1,
        "<material name=\"floor\" texture=\"floor\" texrepeat=\"2 2\" texuniform=\"true\" "
        "specular=\"0\" shininess=\"0\" reflectance=\"0\"/>");
    // A subtle grain on the table top: random specks a shade darker than the wood.
    const Rgba& t = st.table;
    const Rgba speck = {t[0] * 0.955, t[1] * 0.955, t[2] * 0.955, 1.0};
    add(1, "<texture name=\"table\" type=\"2d\" builtin=\"flat\" rgb1=\"" + Color3(t) +
               "\" mark=\"random\" random=\"0.08\" markrgb=\"" + Color3(speck) +
               "\" width=\"512\" height=\"512\"/>");
    add(1,
        "<material name=\"table\" texture=\"table\" texrepeat=\"1 1\" texuniform=\"true\" "
        "specular=\"0.08\" shininess=\"0.2\"/>");
    for (const std::string& m : material_xml_) add(1, m);
    for (const std::string& m : mesh_xml_) add(1, m);
    add(0, "</asset>");
    return s;
  }

  size_t asset_pos() const { return asset_pos_; }

 private:
  const CellScene& scene_;
  const SceneState& state_;
  const MjcfOptions& options_;
  MjcfDocument doc_;
  std::string xml_;
  int depth_ = 0;
  size_t asset_pos_ = 0;
  int asset_depth_ = 0;
  int mesh_count_ = 0;
  std::map<std::string, std::string> materials_;
  std::vector<std::string> material_xml_;
  std::vector<std::string> mesh_xml_;
  std::map<const TriangleMesh*, std::string> part_mesh_names_;
  std::map<const TriangleMesh*, bool> part_mesh_ok_;
};

}  // namespace

CameraView FrameBox(const Aabb& bounds, double azimuth_deg, double elevation_deg, double fovy_deg,
                    double aspect, double margin) {
  CameraView view;
  view.azimuth_deg = azimuth_deg;
  view.elevation_deg = elevation_deg;
  view.lookat = 0.5 * (bounds.min + bounds.max);
  const Vec3 fwd = Writer::Forward(view);
  const Vec3 up = Writer::Up(view);
  const Vec3 right = fwd.cross(up);
  const double tan_v = std::tan(0.5 * std::clamp(fovy_deg, 1.0, 170.0) * kDegToRad);
  const double tan_h = tan_v * std::max(aspect, 1e-3);
  std::array<Vec3, 8> corners;
  for (int i = 0; i < 8; ++i) {
    corners[i] =
        Vec3((i & 1) ? bounds.max.x() : bounds.min.x(), (i & 2) ? bounds.max.y() : bounds.min.y(),
             (i & 4) ? bounds.max.z() : bounds.min.z());
  }
  // Distance at which every corner is inside the frustum.
  auto fit = [&](const Vec3& lookat) {
    double d = 1e-3;
    for (const Vec3& c : corners) {
      const Vec3 o = c - lookat;
      d = std::max(d, std::abs(o.dot(right)) / tan_h - o.dot(fwd));
      d = std::max(d, std::abs(o.dot(up)) / tan_v - o.dot(fwd));
    }
    return d;
  };
  // Centre the corners' projection on screen: shift the look-at point by the middle of their
  // screen extents, a few times (perspective makes it a fixed point, not a formula).
  double d = fit(view.lookat);
  for (int iter = 0; iter < 4; ++iter) {
    double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
    for (const Vec3& c : corners) {
      const Vec3 o = c - view.lookat;
      const double depth = o.dot(fwd) + d;
      umin = std::min(umin, o.dot(right) / depth);
      umax = std::max(umax, o.dot(right) / depth);
      vmin = std::min(vmin, o.dot(up) / depth);
      vmax = std::max(vmax, o.dot(up) / depth);
    }
    view.lookat += d * (0.5 * (umin + umax) * right + 0.5 * (vmin + vmax) * up);
    d = fit(view.lookat);
  }
  view.distance_m = d * margin;
  return view;
}

Result<MjcfDocument> BuildCellMjcf(const CellScene& scene, const SceneState& state,
                                   const MjcfOptions& options) {
  Writer writer(scene, state, options);
  auto doc = writer.Run();
  if (!doc) return doc;
  doc->xml.insert(writer.asset_pos(), writer.AssetBlock());
  return doc;
}

Result<void> WriteMjcf(const MjcfDocument& doc, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    return Fail(ErrorCode::kIo, "cannot create folder '" + dir.string() + "': " + ec.message());
  if (auto ok = WriteFileAtomic(dir / "cell.xml", doc.xml); !ok) return ok;
  for (const MjcfAsset& a : doc.assets) {
    if (auto ok = WriteFileAtomic(dir / a.name, a.bytes); !ok) return ok;
  }
  return {};
}

std::string EncodeMsh(const TriangleMesh& mesh) {
  std::string out;
  auto put = [&out](const void* p, size_t n) { out.append(static_cast<const char*>(p), n); };
  const std::int32_t counts[4] = {static_cast<std::int32_t>(mesh.vertices.size()), 0, 0,
                                  static_cast<std::int32_t>(mesh.triangles.size())};
  out.reserve(16 + 12 * mesh.vertices.size() + 12 * mesh.triangles.size());
  put(counts, sizeof counts);
  for (const Vec3& v : mesh.vertices) {
    const float f[3] = {static_cast<float>(v.x()), static_cast<float>(v.y()),
                        static_cast<float>(v.z())};
    put(f, sizeof f);
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const std::int32_t i[3] = {t[0], t[1], t[2]};
    put(i, sizeof i);
  }
  return out;
}

}  // namespace wrap
