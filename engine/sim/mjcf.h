// The MJCF of a cell: MuJoCo's XML model of the table, the robots (bodies with hinge and slide
// joints, so one compiled model serves every frame of an animation), mobile bases and the parts
// as mocap bodies, with the lights, textures and colours of a paper figure. Text only: compiling
// it is sim/mujoco_model.h's job, drawing it ui/render's.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "core/result.h"
#include "geometry/mesh.h"
#include "model/project.h"
#include "sim/scene.h"

namespace wrap {

/// Colours of a drawn cell: neutral robots with one accent colour each, parts in their project
/// colours, a light table on a light floor.
struct SceneStyle {
  Rgba robot = {0.80, 0.81, 0.82, 1.0};       ///< Arm links (links 1..n).
  Rgba robot_dark = {0.20, 0.21, 0.23, 1.0};  ///< Fingers, suction cups, tool cylinders.
  /// Accent per robot (robot i takes accents[i % size]): its base link and end-effector body.
  std::vector<Rgba> accents = {{0.16, 0.33, 0.60, 1.0}, {0.70, 0.20, 0.18, 1.0},
                               {0.15, 0.50, 0.32, 1.0}, {0.45, 0.28, 0.60, 1.0},
                               {0.10, 0.50, 0.55, 1.0}, {0.60, 0.42, 0.12, 1.0}};
  Rgba pedestal = {0.52, 0.53, 0.55, 1.0};     ///< Robot pedestals.
  Rgba table = {0.86, 0.80, 0.71, 1.0};        ///< Table top (a subtle grain on top of it).
  Rgba table_legs = {0.42, 0.43, 0.45, 1.0};   ///< Table legs.
  Rgba floor = {0.93, 0.93, 0.92, 1.0};        ///< Floor (a faint grid on top of it).
  Rgba mobile_base = {0.96, 0.76, 0.10, 1.0};  ///< Mobile-base chassis (Husky yellow).
  Rgba tire = {0.12, 0.12, 0.13, 1.0};         ///< Wheels and the base's lower chassis.
  Rgba sky_top = {0.93, 0.95, 0.98, 1.0};      ///< Background gradient, top.
  Rgba sky_bottom = {1.0, 1.0, 1.0, 1.0};      ///< Background gradient, horizon.
};

/// A free camera in MuJoCo's convention: it looks at `lookat` from `distance_m` away, turned by
/// `azimuth_deg` about world z (0: looking along +x, 90: along +y) and tilted by
/// `elevation_deg` (negative: looking down).
struct CameraView {
  Vec3 lookat = Vec3(0.0, 0.0, 0.8);  ///< Point looked at, world [m].
  double azimuth_deg = 105.0;         ///< [deg].
  double elevation_deg = -40.0;       ///< [deg], in [-90, 90].
  double distance_m = 3.0;            ///< From the camera to `lookat` [m], > 0.
};

/// The camera at `azimuth_deg`, `elevation_deg` that frames `bounds` tightly: the box's corners
/// fill the view of vertical field of view `fovy_deg` and width/height `aspect`, times `margin`
/// (1.05: 5% spare), with the box centred on screen.
CameraView FrameBox(const Aabb& bounds, double azimuth_deg, double elevation_deg, double fovy_deg,
                    double aspect, double margin = 1.05);

/// Options of BuildCellMjcf.
struct MjcfOptions {
  int offscreen_width = 640;   ///< Largest offscreen image the model can be drawn at [px].
  int offscreen_height = 480;  ///< [px].
  int offscreen_samples = 4;   ///< Multisampling of the offscreen buffer (antialiasing).
  double fovy_deg = 40.0;      ///< Vertical field of view of the free camera [deg].
  CameraView camera;           ///< Written as the default free camera and as camera "overview".
  bool shadows = true;         ///< The key light casts shadows.
  int shadow_map_px = 2048;    ///< Side of the shadow map [px]: sharper shadows cost time on
                               ///< software GL (4096 is ~3x slower than 2048 on llvmpipe).
  SceneStyle style;            ///< Colours.
  /// The physics variant (`wrap sim`, verify/): every part gets a free joint, its mass and
  /// inertia, and contacts with the table and floor (not with other parts: MuJoCo collides
  /// meshes as convex hulls, which would jam every peg in its hole); every robot gets a mocap
  /// body "tcp:NAME" at its TCP; inactive weld constraints "grip/R/P" (TCP of robot R to part P)
  /// and "join/P/Q" (part P to part Q, P < Q) are declared for a simulation to switch on and
  /// off; no keyframe. Default false: the drawing model (visual geoms only, parts mocap).
  bool physics = false;
  double timestep_s = 0.001;  ///< Physics: integration step [s]; welds are as stiff as it allows.
  /// Physics: per part (scene order; missing or empty: none), centres in its frame P [m] of
  /// spheres of kSupportSphereRadius_m that carry it on the table: they meet only the table and
  /// floor, so MuJoCo's contacts of a resting part lie at the corners of its support polygon,
  /// where the wrench LP has them (verify/ passes the hull vertices the plan rests each part on,
  /// each raised by the radius along the table's normal, so that the sphere touches where the
  /// vertex does).
  std::vector<std::vector<Vec3>> support_points_P;
};

/// Radius of the spheres at MjcfOptions::support_points_P [m]: small against any part.
inline constexpr double kSupportSphereRadius_m = 5e-4;
/// Physics: the contact bits of a part's geoms (contype, conaffinity), and of the table's and
/// floor's (the other way round): parts meet the table and floor, not each other.
inline constexpr int kPartContype = 2;
inline constexpr int kPartConaffinity = 1;

/// A file the XML refers to: a mesh in MuJoCo's binary MSH format.
struct MjcfAsset {
  std::string name;   ///< File name, e.g. "mesh3.msh".
  std::string bytes;  ///< Contents.
};

/// An MJCF model of a cell and the names that map a SceneState onto it.
struct MjcfDocument {
  std::string xml;                ///< The model (file "cell.xml" beside its assets).
  std::vector<MjcfAsset> assets;  ///< Meshes the model refers to.
  /// Per robot, the names of its joints, base to tip (one per chain joint).
  std::vector<std::vector<std::string>> robot_joints;
  /// Per robot, the slide joints of the two fingers (qpos = half the opening); empty strings for
  /// a gripper without fingers.
  std::vector<std::array<std::string, 2>> finger_joints;
  std::vector<std::string> part_bodies;  ///< Per part, the name of its mocap body (physics:
                                         ///< its free body).
  std::vector<std::string> tcp_bodies;   ///< Physics: per robot its TCP mocap body; else empty.
  /// Physics: grip_welds[r][p] names the weld of robot r's TCP to part p; else empty.
  std::vector<std::vector<std::string>> grip_welds;
  /// Physics: join_welds[p][q] (p < q) names the weld of part p to part q; else empty.
  std::vector<std::vector<std::string>> join_welds;
  /// Physics: per part, the names of its support spheres (MjcfOptions::support_points_P, same
  /// order), whose contact bits a simulation may switch; else empty.
  std::vector<std::vector<std::string>> support_geoms;
  std::vector<std::string> warnings;  ///< Shapes drawn approximately, e.g. a flat mesh.
};

/// Builds the MJCF of `scene`. Joints are zero at the model's reference configuration (qpos0,
/// the chains' zero pose, fingers closed); the parts' mocap bodies stand at their poses in
/// `state`, and `state` is also keyframe "state" (load it in MuJoCo's `simulate`; renderers
/// apply states through CellModel::Apply). Camera "overview" is `options.camera`. Every geom is
/// visual only (contype = conaffinity = 0). Meshes MuJoCo 2.2 would reject (flat, inconsistently
/// oriented) are drawn as their bounding box, with a warning. Fails with kInvalidInput when the
/// state does not match the scene (sizes) or a shape is degenerate (non-positive size).
Result<MjcfDocument> BuildCellMjcf(const CellScene& scene, const SceneState& state,
                                   const MjcfOptions& options = {});

/// Writes `cell.xml` and the assets into `dir` (created if missing), e.g. to open the cell in
/// MuJoCo's `simulate`. Fails with kIo naming the file.
Result<void> WriteMjcf(const MjcfDocument& doc, const std::filesystem::path& dir);

/// A mesh as MuJoCo's binary MSH file: four int32 counts (vertices, normals, texture
/// coordinates, faces), then float32 vertex coordinates and int32 vertex indices.
std::string EncodeMsh(const TriangleMesh& mesh);

}  // namespace wrap
