// The window's counterpart of ui/render's OffscreenRenderer: the cell compiled by the same MJCF
// builder (sim/), drawn by MuJoCo's mjv/mjr into a rectangle of the GUI window's GL context
// (mjFB_WINDOW), with a free camera the mouse moves and picking of parts. It runs on the GUI
// thread, whose context must be current.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/result.h"
#include "model/project.h"
#include "model/validate.h"
#include "sim/mjcf.h"
#include "sim/scene.h"

namespace wrap::render {

/// An arrow drawn into the scene (e.g. the insertion axis of the selected step).
struct SceneArrow {
  Vec3 from_W = Vec3::Zero();           ///< Tail, world [m].
  Vec3 to_W = Vec3::Zero();             ///< Head, world [m].
  Rgba color = {0.95, 0.2, 0.15, 1.0};  ///< Colour.
  double width_m = 0.012;               ///< Shaft width [m].
};

/// A flat disc lying on the table (e.g. where the plan sets an object down).
struct SceneMarker {
  Vec3 at_W = Vec3::Zero();           ///< Centre, world [m].
  double radius_m = 0.03;             ///< [m].
  Rgba color = {0.1, 0.6, 0.9, 0.6};  ///< Colour (translucent).
};

/// A thin straight segment (an insertion's swept outline, a contact between two parts).
struct SceneLine {
  Vec3 from_W = Vec3::Zero();           ///< One end, world [m].
  Vec3 to_W = Vec3::Zero();             ///< The other end, world [m].
  Rgba color = {0.2, 0.85, 0.3, 1.0};   ///< Colour.
  double width_m = 0.0015;              ///< Thickness [m].
};

/// A small ball (e.g. the centre of a contact).
struct SceneDot {
  Vec3 at_W = Vec3::Zero();            ///< Centre, world [m].
  double radius_m = 0.005;             ///< [m].
  Rgba color = {1.0, 0.85, 0.1, 1.0};  ///< Colour.
};

/// Something of the scene drawn in a colour (e.g. the robot that could not reach, the bodies
/// that collided), glowing so it shows on any colour.
struct SceneHighlight {
  enum class Kind { kPart, kRobot, kTable };
  Kind kind = Kind::kPart;              ///< What it is.
  int index = -1;                       ///< Part or robot index in the scene; unused for the table.
  Rgba color = {0.95, 0.15, 0.1, 1.0};  ///< Colour it is tinted towards.
};

/// How the viewport draws: antialiased with shadows, or plain (several times faster under
/// software GL: no multisampling, no shadow pass).
enum class DrawQuality { kFine, kFast };

/// The cell of the document, compiled and drawn in the viewport.
class ViewportRenderer {
 public:
  ViewportRenderer();
  ~ViewportRenderer();
  ViewportRenderer(const ViewportRenderer&) = delete;
  ViewportRenderer& operator=(const ViewportRenderer&) = delete;

  /// Validates `project` (meshes loaded), builds its scene and MJCF, compiles it and makes
  /// MuJoCo's GL resources. On failure the previous cell stays and the error says why.
  Result<void> Build(const Project& project, const std::filesystem::path& project_file);
  /// True once a cell is built.
  bool ready() const;
  /// The scene and DAG of the cell drawn (valid while ready()).
  const CellScene& scene() const;
  const ProjectCheck& check() const;

  /// Shows `state` (robots, fingers, parts) from the next Draw on.
  Result<void> SetState(const SceneState& state);
  /// Draws into the window rectangle (x, y from the bottom-left, GL convention) [px]. The cell
  /// is drawn into MuJoCo's offscreen buffer (multisampled when fine) and copied to the window,
  /// whose own framebuffer is single-sampled; the offscreen buffer grows with the viewport.
  void Draw(int x, int y, int width, int height);
  /// Fine (default) or fast drawing from the next Draw on.
  void set_quality(DrawQuality quality) { quality_ = quality; }
  DrawQuality quality() const { return quality_; }

  /// Part under the point (rel_x, rel_y) in [0, 1] of the last drawn rectangle (origin
  /// bottom-left), or -1.
  int Pick(double rel_x, double rel_y) const;
  /// Highlights a part (index into the scene's parts; -1: none).
  void set_selected_part(int part) { selected_part_ = part; }
  /// Arrows drawn into the scene (insertion axis, grasps).
  void set_arrows(std::vector<SceneArrow> arrows) { arrows_ = std::move(arrows); }
  /// Discs drawn on the table (placements).
  void set_markers(std::vector<SceneMarker> markers) { markers_ = std::move(markers); }
  /// Segments and balls drawn into the scene (decor, never picked).
  void set_lines(std::vector<SceneLine> lines) { lines_ = std::move(lines); }
  void set_dots(std::vector<SceneDot> dots) { dots_ = std::move(dots); }
  /// Per robot (scene order), a colour the robot's end effector (gripper body, fingers, cup) is
  /// tinted with, e.g. its wrench utilisation during playback; absent or nullopt: its own colours.
  void set_gripper_tints(std::vector<std::optional<Rgba>> tints) { tints_ = std::move(tints); }
  /// Whole robots, parts or the table tinted (drawn after the gripper tints and the selection).
  void set_highlights(std::vector<SceneHighlight> highlights) {
    highlights_ = std::move(highlights);
  }
  /// Forgets the cell (an empty project that cannot be drawn): nothing is drawn until the next
  /// Build succeeds.
  void Clear();

  /// Mouse camera moves, in fractions of the viewport height.
  void Orbit(double dx, double dy);
  void Pan(double dx, double dy);
  void Zoom(double d);
  /// Frames the whole cell from the default direction.
  void ResetCamera();
  /// Frames `bounds` (world) tightly from the default direction (e.g. the assembled view).
  void FrameBounds(const Aabb& bounds);
  /// The camera as it stands (azimuth, elevation [deg], distance [m], look-at point).
  CameraView camera() const;
  /// The free camera's vertical field of view [deg] (45 before any cell).
  double fovy_deg() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int selected_part_ = -1;
  std::vector<SceneArrow> arrows_;
  std::vector<SceneMarker> markers_;
  std::vector<SceneLine> lines_;
  std::vector<SceneDot> dots_;
  std::vector<std::optional<Rgba>> tints_;
  std::vector<SceneHighlight> highlights_;
  DrawQuality quality_ = DrawQuality::kFine;
};

}  // namespace wrap::render
