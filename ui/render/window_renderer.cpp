#include "render/window_renderer.h"

#include <mujoco/mujoco.h>

#include <algorithm>

#include "robot/robot_check.h"
#include "sim/mjcf.h"
#include "sim/mujoco_model.h"

namespace wrap::render {

namespace {
constexpr int kExtraGeoms = 600;  // arrows, markers, lines, dots added after mjv_updateScene
constexpr int kFineSamples = 4;  // multisampling of fine drawing
}  // namespace

struct ViewportRenderer::Impl {
  ProjectCheck check;
  CellScene scene;
  std::unique_ptr<CellModel> model;
  std::unique_ptr<mjData, void (*)(mjData*)> data{nullptr, mj_deleteData};
  std::vector<int> part_body;  // body id per part
  std::vector<int> body_robot;  // per body: the robot whose end effector it belongs to, or -1
  std::vector<int> body_arm;    // per body: the robot it belongs to (links, gripper), or -1
  int table_body = -1;          // the table's body
  mjvScene mjscene;
  mjvOption option;
  mjvCamera camera;
  mjrContext context;
  bool scene_made = false;
  bool context_made = false;
  int last_w = 1, last_h = 1;
  // The GL context's offscreen buffer: its size and multisampling.
  int ctx_w = 0, ctx_h = 0, ctx_samples = -1;

  ~Impl() { Free(); }
  /// (Re)makes MuJoCo's GL context with an offscreen buffer of at least w x h pixels and
  /// `samples` multisampling. mjr_makeContext reads these from the model's visual settings;
  /// a shallow copy of the model carries ours (it only reads, and keeps no pointer).
  void MakeContext(int w, int h, int samples) {
    if (context_made) mjr_freeContext(&context);
    context_made = false;
    mjModel copy = *model->model();
    copy.vis.global.offwidth = w;
    copy.vis.global.offheight = h;
    copy.vis.quality.offsamples = samples;
    mjr_defaultContext(&context);
    mjr_makeContext(&copy, &context, mjFONTSCALE_100);
    context_made = true;
    ctx_w = w;
    ctx_h = h;
    ctx_samples = samples;
  }
  void Free() {
    if (context_made) mjr_freeContext(&context);
    if (scene_made) mjv_freeScene(&mjscene);
    context_made = scene_made = false;
  }
};

// Lines (thin capsules) and dots (balls) appended to the scene as decor.
static void AddLinesAndDots(const std::vector<SceneLine>& lines, const std::vector<SceneDot>& dots,
                     mjvScene& scene) {
  auto rgba_of = [](const Rgba& c, float out[4]) {
    for (int i = 0; i < 4; ++i) out[i] = static_cast<float>(c[i]);
  };
  for (const SceneLine& line : lines) {
    if (scene.ngeom >= scene.maxgeom) return;
    if ((line.to_W - line.from_W).norm() < 1e-6) continue;
    mjvGeom* geom = scene.geoms + scene.ngeom;
    float rgba[4];
    rgba_of(line.color, rgba);
    mjv_initGeom(geom, mjGEOM_CAPSULE, nullptr, nullptr, nullptr, rgba);
    mjv_makeConnector(geom, mjGEOM_CAPSULE, line.width_m, line.from_W.x(), line.from_W.y(),
                      line.from_W.z(), line.to_W.x(), line.to_W.y(), line.to_W.z());
    geom->category = mjCAT_DECOR;
    geom->emission = 0.5f;
    scene.ngeom++;
  }
  for (const SceneDot& dot : dots) {
    if (scene.ngeom >= scene.maxgeom) return;
    mjvGeom* geom = scene.geoms + scene.ngeom;
    float rgba[4];
    rgba_of(dot.color, rgba);
    const mjtNum size[3] = {dot.radius_m, dot.radius_m, dot.radius_m};
    const mjtNum pos[3] = {dot.at_W.x(), dot.at_W.y(), dot.at_W.z()};
    mjv_initGeom(geom, mjGEOM_SPHERE, size, pos, nullptr, rgba);
    geom->category = mjCAT_DECOR;
    geom->emission = 0.5f;
    scene.ngeom++;
  }
}

ViewportRenderer::ViewportRenderer() = default;
ViewportRenderer::~ViewportRenderer() = default;

bool ViewportRenderer::ready() const { return impl_ && impl_->model; }
const CellScene& ViewportRenderer::scene() const { return impl_->scene; }
const ProjectCheck& ViewportRenderer::check() const { return impl_->check; }

Result<void> ViewportRenderer::Build(const Project& project, const std::filesystem::path& file) {
  InstallMujocoHandlers();
  auto next = std::make_unique<Impl>();
  next->check = ValidateProject(project, file);
  auto scene = BuildCellScene(project, next->check, file);
  if (!scene) return std::unexpected(scene.error());
  next->scene = std::move(*scene);
  const SceneState state = InitialState(next->scene);
  MjcfOptions options;
  options.shadows = true;
  options.shadow_map_px = 1024;  // software GL: keep the frame rate up
  auto doc = BuildCellMjcf(next->scene, state, options);
  if (!doc) return std::unexpected(doc.error());
  auto compiled = CellModel::Compile(*doc);
  if (!compiled) return std::unexpected(compiled.error());
  next->model = std::make_unique<CellModel>(std::move(*compiled));
  const mjModel* m = next->model->model();
  for (const std::string& body : doc->part_bodies) {
    next->part_body.push_back(mj_name2id(m, mjOBJ_BODY, body.c_str()));
  }
  // Every body of robot r: named "robot:NAME/..." or below its link0.
  next->body_arm.assign(m->nbody, -1);
  for (size_t r = 0; r < next->scene.robots.size(); ++r) {
    const std::string prefix = "robot:" + next->scene.robots[r].name + "/";
    for (int b = 1; b < m->nbody; ++b) {
      const char* name = mj_id2name(m, mjOBJ_BODY, b);
      if (name && std::string(name).starts_with(prefix)) next->body_arm[b] = static_cast<int>(r);
    }
  }
  for (int b = 1; b < m->nbody; ++b) {
    if (next->body_arm[b] < 0 && next->body_arm[m->body_parentid[b]] >= 0) {
      next->body_arm[b] = next->body_arm[m->body_parentid[b]];
    }
  }
  next->table_body = mj_name2id(m, mjOBJ_BODY, "table");
  // The end effector of robot r: the body "robot:NAME/ee" and everything below it (fingers).
  next->body_robot.assign(m->nbody, -1);
  for (size_t r = 0; r < next->scene.robots.size(); ++r) {
    const std::string ee = "robot:" + next->scene.robots[r].name + "/ee";
    const int root = mj_name2id(m, mjOBJ_BODY, ee.c_str());
    if (root < 0) continue;
    for (int b = 1; b < m->nbody; ++b) {
      for (int a = b; a > 0; a = m->body_parentid[a]) {
        if (a == root) {
          next->body_robot[b] = static_cast<int>(r);
          break;
        }
      }
    }
  }
  Impl* n = next.get();
  auto made = RunGuarded("making the viewport's GL context", [&] {
    n->data = next->model->MakeData();
    mjv_defaultOption(&n->option);
    mjv_defaultScene(&n->mjscene);
    mjv_makeScene(m, &n->mjscene, m->ngeom + kExtraGeoms);
    n->scene_made = true;
    n->MakeContext(std::max(640, impl_ ? impl_->ctx_w : 0), std::max(480, impl_ ? impl_->ctx_h : 0),
                   quality_ == DrawQuality::kFine ? kFineSamples : 0);
    mjr_setBuffer(mjFB_WINDOW, &n->context);
    mjv_defaultFreeCamera(m, &n->camera);
  });
  if (!made) return made;
  if (!n->data) return Fail(ErrorCode::kInternal, "MuJoCo could not allocate its data");
  n->mjscene.flags[mjRND_SHADOW] = 1;
  n->mjscene.flags[mjRND_REFLECTION] = 0;
  n->mjscene.flags[mjRND_SKYBOX] = 1;
  if (auto applied = n->model->Apply(state, n->data.get()); !applied) return applied;
  // Keep the camera the user had when the cell is rebuilt after an edit.
  const bool keep_camera = ready();
  const mjvCamera old_camera = keep_camera ? impl_->camera : n->camera;
  impl_ = std::move(next);
  if (keep_camera) {
    impl_->camera = old_camera;
  } else {
    ResetCamera();
  }
  return {};
}

void ViewportRenderer::Clear() { impl_.reset(); }

Result<void> ViewportRenderer::SetState(const SceneState& state) {
  if (!ready()) return Fail(ErrorCode::kInternal, "viewport: no cell");
  return impl_->model->Apply(state, impl_->data.get());
}

void ViewportRenderer::ResetCamera() {
  if (!ready()) return;
  const CameraView view =
      FrameBox(SceneBounds(impl_->scene, InitialState(impl_->scene)), 105.0, -35.0, 40.0, 1.4, 1.0);
  impl_->camera.type = mjCAMERA_FREE;
  for (int i = 0; i < 3; ++i) impl_->camera.lookat[i] = view.lookat[i];
  impl_->camera.azimuth = view.azimuth_deg;
  impl_->camera.elevation = view.elevation_deg;
  impl_->camera.distance = view.distance_m;
}

void ViewportRenderer::FrameBounds(const Aabb& bounds) {
  if (!ready()) return;
  const CameraView view = FrameBox(bounds, 105.0, -35.0, 40.0, 1.4, 1.6);
  impl_->camera.type = mjCAMERA_FREE;
  for (int i = 0; i < 3; ++i) impl_->camera.lookat[i] = view.lookat[i];
  impl_->camera.azimuth = view.azimuth_deg;
  impl_->camera.elevation = view.elevation_deg;
  impl_->camera.distance = view.distance_m;
}

CameraView ViewportRenderer::camera() const {
  CameraView view;
  if (!ready()) return view;
  const mjvCamera& c = impl_->camera;
  view.lookat = Vec3(c.lookat[0], c.lookat[1], c.lookat[2]);
  view.azimuth_deg = c.azimuth;
  view.elevation_deg = c.elevation;
  view.distance_m = c.distance;
  return view;
}

double ViewportRenderer::fovy_deg() const {
  return ready() ? impl_->model->model()->vis.global.fovy : 45.0;
}

void ViewportRenderer::Orbit(double dx, double dy) {
  if (!ready()) return;
  mjv_moveCamera(impl_->model->model(), mjMOUSE_ROTATE_V, dx, dy, &impl_->mjscene, &impl_->camera);
}

void ViewportRenderer::Pan(double dx, double dy) {
  if (!ready()) return;
  mjv_moveCamera(impl_->model->model(), mjMOUSE_MOVE_V, dx, dy, &impl_->mjscene, &impl_->camera);
}

void ViewportRenderer::Zoom(double d) {
  if (!ready()) return;
  mjv_moveCamera(impl_->model->model(), mjMOUSE_ZOOM, 0.0, d, &impl_->mjscene, &impl_->camera);
}

void ViewportRenderer::Draw(int x, int y, int width, int height) {
  if (!ready() || width <= 0 || height <= 0) return;
  Impl& s = *impl_;
  s.last_w = width;
  s.last_h = height;
  const mjModel* m = s.model->model();
  (void)RunGuarded("drawing the viewport", [&] {
    // The offscreen buffer grows (in steps, so a dragged window edge does not remake it every
    // frame) and its multisampling follows the quality.
    const bool fine = quality_ == DrawQuality::kFine;
    const int samples = fine ? kFineSamples : 0;
    if (width > s.ctx_w || height > s.ctx_h || samples != s.ctx_samples) {
      auto grow = [](int need, int have) { return need > have ? (need + 255) / 256 * 256 : have; };
      s.MakeContext(grow(width, s.ctx_w), grow(height, s.ctx_h), samples);
    }
    s.mjscene.flags[mjRND_SHADOW] = fine ? 1 : 0;
    s.mjscene.flags[mjRND_SKYBOX] = fine ? 1 : 0;
    s.mjscene.flags[mjRND_HAZE] = fine ? 1 : 0;
    mjv_updateScene(m, s.data.get(), &s.option, nullptr, &s.camera, mjCAT_ALL, &s.mjscene);
    // End effectors tinted (e.g. by their wrench utilisation).
    for (int g = 0; g < s.mjscene.ngeom && !tints_.empty(); ++g) {
      mjvGeom& geom = s.mjscene.geoms[g];
      if (geom.objtype != mjOBJ_GEOM || geom.objid < 0) continue;
      const int robot = s.body_robot[m->geom_bodyid[geom.objid]];
      if (robot < 0 || robot >= static_cast<int>(tints_.size()) || !tints_[robot]) continue;
      const Rgba& tint = *tints_[robot];
      for (int c = 0; c < 3; ++c) {
        geom.rgba[c] = static_cast<float>(0.2 * geom.rgba[c] + 0.8 * tint[c]);
      }
      geom.emission = 0.4f;
    }
    // Highlight the selected part: every geom of its body glows.
    if (selected_part_ >= 0 && selected_part_ < static_cast<int>(s.part_body.size())) {
      const int body = s.part_body[selected_part_];
      for (int g = 0; g < s.mjscene.ngeom; ++g) {
        mjvGeom& geom = s.mjscene.geoms[g];
        if (geom.objtype == mjOBJ_GEOM && geom.objid >= 0 && m->geom_bodyid[geom.objid] == body) {
          // Towards amber, and glowing: visible on any part colour.
          const float amber[3] = {1.0f, 0.78f, 0.15f};
          for (int c = 0; c < 3; ++c) geom.rgba[c] = 0.4f * geom.rgba[c] + 0.6f * amber[c];
          geom.emission = 0.35f;
        }
      }
    }
    // Highlights: whole robots (links, gripper, pedestal), parts, the table.
    for (int g = 0; g < s.mjscene.ngeom && !highlights_.empty(); ++g) {
      mjvGeom& geom = s.mjscene.geoms[g];
      if (geom.objtype != mjOBJ_GEOM || geom.objid < 0) continue;
      const int body = m->geom_bodyid[geom.objid];
      const char* gname = mj_id2name(m, mjOBJ_GEOM, geom.objid);
      for (const SceneHighlight& h : highlights_) {
        bool hit = false;
        switch (h.kind) {
          case SceneHighlight::Kind::kRobot:
            hit = s.body_arm[body] == h.index ||
                  (gname && h.index >= 0 && h.index < static_cast<int>(s.scene.robots.size()) &&
                   std::string(gname).starts_with("robot:" + s.scene.robots[h.index].name + "/"));
            break;
          case SceneHighlight::Kind::kPart:
            hit = h.index >= 0 && h.index < static_cast<int>(s.part_body.size()) &&
                  s.part_body[h.index] == body;
            break;
          case SceneHighlight::Kind::kTable:
            hit = body == s.table_body;
            break;
        }
        if (!hit) continue;
        for (int c = 0; c < 3; ++c) {
          geom.rgba[c] = static_cast<float>(0.3 * geom.rgba[c] + 0.7 * h.color[c]);
        }
        geom.emission = 0.45f;
      }
    }
    for (const SceneArrow& arrow : arrows_) {
      if (s.mjscene.ngeom >= s.mjscene.maxgeom) break;
      mjvGeom* geom = s.mjscene.geoms + s.mjscene.ngeom;
      const float rgba[4] = {static_cast<float>(arrow.color[0]), static_cast<float>(arrow.color[1]),
                             static_cast<float>(arrow.color[2]),
                             static_cast<float>(arrow.color[3])};
      mjv_initGeom(geom, mjGEOM_ARROW, nullptr, nullptr, nullptr, rgba);
      mjv_makeConnector(geom, mjGEOM_ARROW, arrow.width_m, arrow.from_W.x(), arrow.from_W.y(),
                        arrow.from_W.z(), arrow.to_W.x(), arrow.to_W.y(), arrow.to_W.z());
      geom->category = mjCAT_DECOR;
      s.mjscene.ngeom++;
    }
    for (const SceneMarker& marker : markers_) {
      if (s.mjscene.ngeom >= s.mjscene.maxgeom) break;
      mjvGeom* geom = s.mjscene.geoms + s.mjscene.ngeom;
      const float rgba[4] = {
          static_cast<float>(marker.color[0]), static_cast<float>(marker.color[1]),
          static_cast<float>(marker.color[2]), static_cast<float>(marker.color[3])};
      const mjtNum size[3] = {marker.radius_m, marker.radius_m, 0.001};
      const mjtNum pos[3] = {marker.at_W.x(), marker.at_W.y(), marker.at_W.z()};
      mjv_initGeom(geom, mjGEOM_CYLINDER, size, pos, nullptr, rgba);
      geom->category = mjCAT_DECOR;
      s.mjscene.ngeom++;
    }
    AddLinesAndDots(lines_, dots_, s.mjscene);
    // Drawn offscreen, then copied into the window's rectangle (resolving the multisampling).
    mjr_setBuffer(mjFB_OFFSCREEN, &s.context);
    const mjrRect off{0, 0, width, height};
    mjr_render(off, &s.mjscene, &s.context);
    mjr_blitBuffer(off, mjrRect{x, y, width, height}, 1, 0, &s.context);
    mjr_setBuffer(mjFB_WINDOW, &s.context);
  });
}

int ViewportRenderer::Pick(double rel_x, double rel_y) const {
  if (!ready()) return -1;
  const Impl& s = *impl_;
  mjtNum point[3];
  int geom = -1, skin = -1;
  const int body = mjv_select(s.model->model(), s.data.get(), &s.option,
                              static_cast<mjtNum>(s.last_w) / std::max(1, s.last_h), rel_x, rel_y,
                              &s.mjscene, point, &geom, &skin);
  if (body < 0) return -1;
  auto it = std::find(s.part_body.begin(), s.part_body.end(), body);
  return it == s.part_body.end() ? -1 : static_cast<int>(it - s.part_body.begin());
}

}  // namespace wrap::render
