#include "model/validate.h"

#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include "geometry/mesh_file.h"
#include "geometry/step_cache.h"
#include "model/catalog.h"
#include "model/paths.h"
#include "model/project_io.h"

namespace wrap {

namespace fs = std::filesystem;

namespace {

// Thresholds of the plausibility warnings.
constexpr double kMaxPartSize_m = 5.0;      // Larger: probably mm read as m.
constexpr double kMinPartSize_m = 0.001;    // Smaller: probably m read as mm.
constexpr double kRestTolerance_m = 0.002;  // Lowest point this close to the table top rests.
constexpr int kMinReachingRobots = 2;       // Handovers and bracing need two robots.

std::string Num(double v) {
  std::ostringstream ss;
  ss.precision(6);
  ss << v;
  return ss.str();
}

std::string Quote(const std::string& s) { return "'" + s + "'"; }

class Checker {
 public:
  Checker(const Project& project, const fs::path& file, ProjectCheck& out)
      : p_(project), file_path_(file), file_(file.string()), out_(out) {}

  void Error(const std::string& path, const std::string& msg) {
    out_.diagnostics.Error(file_, path, msg);
  }
  void Warning(const std::string& path, const std::string& msg) {
    out_.diagnostics.Warning(file_, path, msg);
  }

  bool Finite(double v, const std::string& path) {
    if (std::isfinite(v)) return true;
    Error(path, "must be a finite number, found " + Num(v));
    return false;
  }
  void Positive(double v, const std::string& path) {
    if (Finite(v, path) && v <= 0.0) Error(path, "must be positive, found " + Num(v));
  }
  void NonNegative(double v, const std::string& path) {
    if (Finite(v, path) && v < 0.0) Error(path, "must not be negative, found " + Num(v));
  }
  void FiniteVec(const Vec3& v, const std::string& path) {
    for (int i = 0; i < 3; ++i) Finite(v[i], path + "[" + std::to_string(i) + "]");
  }
  void PositiveVec(const Vec3& v, const std::string& path) {
    for (int i = 0; i < 3; ++i) Positive(v[i], path + "[" + std::to_string(i) + "]");
  }
  void NonNegativeVec(const Vec3& v, const std::string& path) {
    for (int i = 0; i < 3; ++i) NonNegative(v[i], path + "[" + std::to_string(i) + "]");
  }
  void PoseOk(const Pose& pose, const std::string& path) {
    FiniteVec(pose.xyz, path + ".xyz");
    FiniteVec(pose.rpy, path + ".rpy");
  }
  void WrenchBoxOk(const WrenchBox& b, const std::string& path) {
    NonNegativeVec(b.force_N, path + ".force_N");
    NonNegativeVec(b.torque_Nm, path + ".torque_Nm");
  }
  void WrenchLimitsOk(const WrenchLimits& w, const std::string& path) {
    WrenchBoxOk(w.two_finger, path + ".two_finger");
    WrenchBoxOk(w.vacuum_assembly, path + ".vacuum_assembly");
    WrenchBoxOk(w.vacuum_transport, path + ".vacuum_transport");
  }

  void Run(const ValidationOptions& options) {
    CheckTable();
    Positive(p_.geometry.contact_m, "geometry.contact_m");
    NonNegative(p_.geometry.touch_depth_m, "geometry.touch_depth_m");
    CheckTessellation();
    CheckNames();
    out_.parts.assign(p_.parts.size(), PartGeometry{});
    if (p_.parts.empty()) Error("parts", "the project needs at least one part");
    for (size_t i = 0; i < p_.parts.size(); ++i) CheckPart(static_cast<int>(i), options);
    CheckSteps();
    WrenchBoxOk(p_.connection_limits, "connection_limits");
    WrenchLimitsOk(p_.wrench_limits, "wrench_limits");
    CheckBases();
    CheckRobots();
    CheckReach();
    if (!(p_.planner.time_limit_s > 0.0) || !std::isfinite(p_.planner.time_limit_s)) {
      Error("planner.time_limit_s",
            "must be a positive finite number of seconds, found " + Num(p_.planner.time_limit_s));
    }
  }

 private:
  void CheckTessellation() {
    const StepTessellation& t = p_.tessellation;
    if (!(t.linear_deflection_m >= 1e-7 && t.linear_deflection_m <= 0.1)) {
      Error("tessellation.linear_deflection_m",
            "must be between 1e-7 and 0.1 m, found " + Num(t.linear_deflection_m));
      tessellation_ok_ = false;
    }
    const double degrees = t.angular_deflection_rad * 180.0 / std::numbers::pi;
    if (!(t.angular_deflection_rad >= 1e-3 && t.angular_deflection_rad <= std::numbers::pi / 2)) {
      Error("tessellation.angular_deflection_deg",
            "must be between 0.06 and 90 degrees, found " + Num(degrees));
      tessellation_ok_ = false;
    }
  }

  void CheckTable() {
    PositiveVec(p_.table.size, "table.size");
    Finite(p_.table.center_xy.x(), "table.center_xy[0]");
    Finite(p_.table.center_xy.y(), "table.center_xy[1]");
    Finite(p_.table.height, "table.height");
    Positive(p_.table.friction, "table.friction");
    if (std::isfinite(p_.table.friction) && p_.table.friction > 2.0) {
      Warning("table.friction", "friction coefficient " + Num(p_.table.friction) +
                                    " is unusually high (PLA on wood is about 0.4)");
    }
  }

  void CheckNames() {
    std::map<std::string, std::string> seen;  // name -> JSON path of first use
    auto claim = [&](const std::string& name, const std::string& path, const char* what) {
      if (name.empty()) {
        Error(path, std::string("a ") + what + " needs a non-empty name");
        return;
      }
      auto [it, fresh] = seen.emplace(name, path);
      if (!fresh) {
        Error(path, "name " + Quote(name) + " is already used at " + it->second +
                        " (part and step names share one namespace)");
      }
    };
    for (size_t i = 0; i < p_.parts.size(); ++i) {
      claim(p_.parts[i].name, "parts[" + std::to_string(i) + "].name", "part");
    }
    for (size_t i = 0; i < p_.steps.size(); ++i) {
      claim(p_.steps[i].name, "steps[" + std::to_string(i) + "].name", "step");
    }
    std::map<std::string, std::string> robots;
    for (size_t i = 0; i < p_.robots.size(); ++i) {
      const std::string path = "robots[" + std::to_string(i) + "].name";
      if (p_.robots[i].name.empty()) {
        Error(path, "a robot needs a non-empty name");
        continue;
      }
      auto [it, fresh] = robots.emplace(p_.robots[i].name, path);
      if (!fresh)
        Error(path, "robot name " + Quote(p_.robots[i].name) + " is already used at " + it->second);
    }
    std::map<std::string, std::string> bases;
    for (size_t i = 0; i < p_.mobile_bases.size(); ++i) {
      const std::string path = "mobile_bases[" + std::to_string(i) + "].name";
      auto [it, fresh] = bases.emplace(p_.mobile_bases[i].name, path);
      if (!fresh)
        Error(path, "mobile base name " + Quote(p_.mobile_bases[i].name) + " is already used at " +
                        it->second);
    }
  }

  void CheckPart(int i, const ValidationOptions& options) {
    const Part& part = p_.parts[i];
    const std::string path = "parts[" + std::to_string(i) + "]";
    Positive(part.scale, path + ".scale");
    if (part.mass_kg) Positive(*part.mass_kg, path + ".mass_kg");
    Positive(part.density_kg_m3, path + ".density_kg_m3");
    PoseOk(part.assembled_pose, path + ".assembled_pose");
    PoseOk(part.initial_pose, path + ".initial_pose");
    for (int c = 0; c < 4; ++c) {
      const double v = part.color[c];
      if (!(v >= 0.0 && v <= 1.0)) {
        Error(path + ".color[" + std::to_string(c) + "]",
              "colour channels are in [0, 1], found " + Num(v));
      }
    }
    if (part.mesh.empty()) {
      Error(path + ".mesh", "no mesh file given");
      return;
    }
    auto resolved = ResolveProjectPath(p_, file_path_, part.mesh);
    if (!resolved) {
      Error(path + ".mesh", resolved.error().message);
      return;
    }
    PartGeometry& geo = out_.parts[i];
    geo.resolved = resolved->path;
    std::error_code ec;
    if (!fs::exists(resolved->path, ec)) {
      std::string msg =
          "file " + Quote(part.mesh) + " not found (resolved to " + resolved->path.string();
      if (!resolved->explanation.empty()) msg += "; " + resolved->explanation;
      msg += ")";
      if (!resolved->hint.empty()) msg += "; " + resolved->hint;
      Error(path + ".mesh", msg);
      return;
    }
    const bool step = LooksLikeStep(resolved->path);
    if (!part.solid.empty() && !step) {
      Error(path + ".solid", "names a solid of a STEP file, but " + Quote(part.mesh) +
                                 " is not one; remove 'solid' or use a .step/.stp mesh");
      return;
    }
    if (step && std::isfinite(part.scale) && part.scale != 1.0) {
      Warning(path + ".scale", "STEP files come in metres from their own unit; scale " +
                                   Num(part.scale) + " resizes the part (1 keeps it as designed)");
    }
    if (!options.load_meshes || !(part.scale > 0.0) || !std::isfinite(part.scale)) return;
    if (step && !tessellation_ok_) return;  // reported at "tessellation"
    MeshFileOptions mo;
    mo.scale = part.scale;
    mo.solid = part.solid;
    mo.tessellation = p_.tessellation;
    if (!file_path_.empty()) mo.cache_dir = StepCacheDirFor(file_path_);
    auto mesh = LoadMeshFile(resolved->path, mo);
    if (!mesh) {
      Error(path + ".mesh", "cannot read mesh " + Quote(part.mesh) + ": " + mesh.error().message);
      return;
    }
    for (const std::string& w : mesh->warnings) {
      Warning(path + ".mesh", Quote(part.mesh) + ": " + w);
    }
    geo.mesh = std::move(mesh->mesh);
    geo.topology = AnalyzeTopology(geo.mesh);
    geo.aabb = ComputeAabb(geo.mesh);
    const Vec3 size = geo.aabb.size();
    const int tri = static_cast<int>(geo.mesh.triangles.size());
    if (geo.topology.degenerate_triangles == tri || size.minCoeff() <= 0.0) {
      Error(path + ".mesh",
            "mesh " + Quote(part.mesh) +
                " is degenerate (all triangles have zero area or it is flat: " + "size " +
                Num(size.x()) + " x " + Num(size.y()) + " x " + Num(size.z()) + " m)");
      return;
    }
    geo.loaded = true;
    geo.mass_properties = ComputeMassProperties(geo.mesh);
    if (!geo.topology.closed()) {
      Warning(path + ".mesh", "mesh " + Quote(part.mesh) + " is not closed (" +
                                  std::to_string(geo.topology.boundary_edges) +
                                  " boundary edges, " +
                                  std::to_string(geo.topology.non_manifold_edges) +
                                  " non-manifold edges): volume, mass and hull may be wrong");
    } else if (geo.mass_properties.volume_m3 <= 0.0) {
      Warning(path + ".mesh", "mesh " + Quote(part.mesh) +
                                  " encloses a negative volume: its triangles face inward");
    }
    if (geo.topology.degenerate_triangles > 0) {
      Warning(path + ".mesh", std::to_string(geo.topology.degenerate_triangles) +
                                  " degenerate (zero-area) triangles in " + Quote(part.mesh));
    }
    const double largest = size.maxCoeff();
    if (largest > kMaxPartSize_m) {
      Warning(path + ".scale", "part is " + Num(largest) +
                                   " m across (larger than 5 m): probably a unit mistake; "
                                   "check 'scale' (0.001 for mm, 0.01 for cm)");
    } else if (largest < kMinPartSize_m) {
      Warning(path + ".scale", "part is " + Num(largest) +
                                   " m across (smaller than 1 mm): probably a unit mistake; "
                                   "check 'scale' (1 for m, 0.001 for mm)");
    }
    if (part.mass_kg) {
      geo.mass_kg = *part.mass_kg;
    } else {
      geo.mass_kg = part.density_kg_m3 * std::abs(geo.mass_properties.volume_m3);
      if (!geo.topology.closed()) {
        Warning(path + ".mass_kg", "mass estimated from an open mesh; give 'mass_kg'");
      }
    }
    CheckRestingOnTable(i, geo);
  }

  void CheckRestingOnTable(int i, const PartGeometry& geo) {
    const Part& part = p_.parts[i];
    const std::string path = "parts[" + std::to_string(i) + "].initial_pose";
    const Iso3 X_WP = ToIsometry(part.initial_pose);
    double zmin = std::numeric_limits<double>::infinity();
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
    for (const Vec3& v : geo.mesh.vertices) {
      const Vec3 w = X_WP * v;
      zmin = std::min(zmin, w.z());
      lo = lo.cwiseMin(w);
      hi = hi.cwiseMax(w);
    }
    const double gap = zmin - p_.table.height;
    if (gap < -kRestTolerance_m) {
      Warning(path, "part " + Quote(part.name) + " reaches " + Num(-gap * 1000.0) +
                        " mm below the table top (z = " + Num(p_.table.height) + " m)");
    } else if (gap > kRestTolerance_m) {
      Warning(path, "part " + Quote(part.name) + " floats " + Num(gap * 1000.0) +
                        " mm above the table top (z = " + Num(p_.table.height) + " m)");
    }
    const Vec3 half = 0.5 * p_.table.size;
    const Vec3& c = p_.table.center_xy;
    // Overhanging a little is fine (and lets a two-finger gripper take a flat part by its
    // edge); a part whose footprint centre is beyond the edge cannot rest there.
    const Vec3 mid = 0.5 * (lo + hi);
    if (std::abs(mid.x() - c.x()) > half.x() || std::abs(mid.y() - c.y()) > half.y()) {
      Warning(path, "part " + Quote(part.name) + " sticks out over the edge of the table "
                                                 "(its footprint's centre is beyond it)");
    }
  }

  void CheckSteps() {
    AssemblyTree tree;
    if (BuildAssemblyTree(p_, file_, out_.diagnostics, tree)) out_.tree = std::move(tree);
    for (size_t s = 0; s < p_.steps.size(); ++s) {
      const Step& step = p_.steps[s];
      const Mating& m = step.mating;
      const std::string path = "steps[" + std::to_string(s) + "].mating";
      auto is_input = [&](const std::string& n) {
        for (const std::string& in : step.inputs) {
          if (in == n) return true;
        }
        return false;
      };
      if (!m.moved.empty() && !is_input(m.moved)) {
        Error(path + ".moved", Quote(m.moved) + " is not an input of step " + Quote(step.name));
      }
      if (!m.base.empty() && !is_input(m.base)) {
        Error(path + ".base", Quote(m.base) + " is not an input of step " + Quote(step.name));
      }
      if (!m.moved.empty() && m.moved == m.base) {
        Error(path + ".base", "the base and the moved input must differ");
      }
      FiniteVec(m.axis, path + ".axis");
      if (m.axis.allFinite() && m.axis.norm() < 1e-9) {
        Error(path + ".axis", "the insertion axis must not be zero");
      }
      NonNegative(m.force_N, path + ".force_N");
      Finite(m.torque_Nm, path + ".torque_Nm");
      NonNegative(m.transverse_fraction, path + ".transverse_fraction");
      NonNegative(m.offset_m, path + ".offset_m");
      NonNegative(m.approach_m, path + ".approach_m");
      NonNegative(m.interference_travel_m, path + ".interference_travel_m");
      NonNegative(m.interference_depth_m, path + ".interference_depth_m");
      for (size_t k = 0; k < m.final_poses.size(); ++k) {
        PoseOk(m.final_poses[k], path + ".final_poses[" + std::to_string(k) + "]");
      }
      if (m.connection_limits) WrenchBoxOk(*m.connection_limits, path + ".connection_limits");
    }
  }

  void CheckBases() {
    for (size_t i = 0; i < p_.mobile_bases.size(); ++i) {
      const MobileBase& b = p_.mobile_bases[i];
      const std::string path = "mobile_bases[" + std::to_string(i) + "]";
      if (!FindMobileBasePreset(b.model)) {
        Error(path + ".model", "unknown mobile base " + Quote(b.model) +
                                   " (known: " + MobileBasePresetNames() + ")");
      }
      PoseOk(b.pose, path + ".pose");
    }
  }

  void CheckRobots() {
    if (p_.robots.empty()) Error("robots", "the project needs at least one robot");
    for (size_t i = 0; i < p_.robots.size(); ++i) {
      const Robot& r = p_.robots[i];
      const std::string path = "robots[" + std::to_string(i) + "]";
      if (r.model.empty() == r.urdf.empty()) {
        Error(path, "give exactly one of 'model' (a catalog arm: " + RobotModelNames() +
                        ") and 'urdf' (a URDF file)");
      } else if (!r.model.empty() && !FindRobotModel(r.model)) {
        Error(path + ".model",
              "unknown robot model " + Quote(r.model) + " (known: " + RobotModelNames() + ")");
      } else if (!r.urdf.empty()) {
        auto resolved = ResolveProjectPath(p_, file_path_, r.urdf);
        std::error_code ec;
        if (!resolved) {
          Error(path + ".urdf", resolved.error().message);
        } else if (!fs::is_regular_file(resolved->path, ec)) {
          Error(path + ".urdf", "file " + Quote(r.urdf) + " not found (resolved to " +
                                    resolved->path.string() + ")");
        }
      }
      if (!FindEndEffector(r.end_effector)) {
        Error(path + ".end_effector", "unknown end effector " + Quote(r.end_effector) +
                                          " (known: " + EndEffectorNames() + ")");
      }
      if (!r.mounted_on.empty()) {
        const MobileBase* base = nullptr;
        for (const MobileBase& b : p_.mobile_bases) {
          if (b.name == r.mounted_on) base = &b;
        }
        if (!base) {
          Error(path + ".mounted_on", "no mobile base named " + Quote(r.mounted_on));
        } else if (const MobileBaseInfo* info = FindMobileBasePreset(base->model)) {
          bool found = false;
          std::string names;
          for (const MountInfo& m : info->mounts) {
            found = found || m.name == r.mount;
            names += (names.empty() ? "" : ", ") + m.name;
          }
          if (!found) {
            Error(path + ".mount", "base " + Quote(base->name) + " (" + base->model +
                                       ") has no mount " + Quote(r.mount) + " (known: " + names +
                                       ")");
          }
        }
      } else if (!r.mount.empty()) {
        Warning(path + ".mount", "'mount' is ignored without 'mounted_on'");
      }
      PoseOk(r.base_pose, path + ".base_pose");
      if (r.wrench_limits) WrenchLimitsOk(*r.wrench_limits, path + ".wrench_limits");
    }
  }

  // Every part must start within reach of two robots (rough test: horizontal distance from the
  // robot base to the part's origin below the arm's reach); exact IK comes with the robot stage.
  void CheckReach() {
    std::vector<std::pair<Vec3, double>> arms;  // base position, reach
    for (const Robot& r : p_.robots) {
      const RobotModelInfo* info = FindRobotModel(r.model);
      if (!info) continue;
      arms.emplace_back(RobotBaseInWorld(p_, r).translation(), info->reach_m);
    }
    if (arms.size() < static_cast<size_t>(kMinReachingRobots) || arms.size() != p_.robots.size()) {
      return;
    }
    for (size_t i = 0; i < p_.parts.size(); ++i) {
      const Vec3 c = ToIsometry(p_.parts[i].initial_pose).translation();
      int reaching = 0;
      for (const auto& [base, reach] : arms) {
        reaching += (c - base).head<2>().norm() < reach ? 1 : 0;
      }
      if (reaching < kMinReachingRobots) {
        Warning("parts[" + std::to_string(i) + "].initial_pose",
                "part " + Quote(p_.parts[i].name) + " starts within reach of " +
                    std::to_string(reaching) + " robot(s); handovers and bracing need " +
                    std::to_string(kMinReachingRobots));
      }
    }
  }

  const Project& p_;
  const fs::path& file_path_;
  const std::string file_;
  ProjectCheck& out_;
  bool tessellation_ok_ = true;  // STEP meshes are read only with valid deflections
};

}  // namespace

Iso3 RobotBaseInWorld(const Project& project, const Robot& robot) {
  const Iso3 X_MR = ToIsometry(robot.base_pose);
  if (robot.mounted_on.empty()) return X_MR;
  for (const MobileBase& b : project.mobile_bases) {
    if (b.name != robot.mounted_on) continue;
    Iso3 X_WB = ToIsometry(b.pose);
    if (const MobileBaseInfo* info = FindMobileBasePreset(b.model)) {
      for (const MountInfo& m : info->mounts) {
        if (m.name == robot.mount) return X_WB * ToIsometry(m.X_BM) * X_MR;
      }
    }
    return X_WB * X_MR;
  }
  return X_MR;
}

ProjectCheck ValidateProject(const Project& project, const fs::path& project_file,
                             const ValidationOptions& options) {
  ProjectCheck out;
  Checker(project, project_file, out).Run(options);
  return out;
}

LoadedProject LoadProject(const fs::path& path, const ValidationOptions& options) {
  LoadedProject out;
  ProjectParse parse = ReadProjectFile(path);
  out.check.diagnostics = parse.diagnostics;
  if (!parse.project) return out;
  ProjectCheck check = ValidateProject(*parse.project, path, options);
  out.check.diagnostics.Append(check.diagnostics);
  out.check.parts = std::move(check.parts);
  out.check.tree = std::move(check.tree);
  out.project = std::move(parse.project);
  return out;
}

}  // namespace wrap
