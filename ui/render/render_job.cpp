#include "render/render_job.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "render/contact_sheet.h"
#include "render/renderer.h"
#include "render/video.h"
#include "robot/kinematics.h"
#include "sim/mujoco_model.h"
#include "task/plan_state.h"

namespace wrap::render {

namespace fs = std::filesystem;

namespace {

constexpr int kMinSize = 16;
constexpr int kMaxSize = 8192;

Aabb Union(const Aabb& a, const Aabb& b) {
  Aabb u;
  u.min = a.min.cwiseMin(b.min);
  u.max = a.max.cwiseMax(b.max);
  return u;
}

bool PlainFileName(const std::string& name) {
  return !name.empty() && name.find('/') == std::string::npos && name != "." && name != "..";
}

}  // namespace

Result<void> CheckRenderOptions(const RenderJob& job) {
  auto bad = [](const std::string& m) { return Fail(ErrorCode::kInvalidInput, m); };
  if (job.width < kMinSize || job.width > kMaxSize || job.height < kMinSize ||
      job.height > kMaxSize) {
    return bad("--size " + std::to_string(job.width) + "x" + std::to_string(job.height) +
               ": width and height must be between " + std::to_string(kMinSize) + " and " +
               std::to_string(kMaxSize) + " pixels");
  }
  const CameraRequest& c = job.camera;
  if (c.azimuth_deg && !std::isfinite(*c.azimuth_deg)) {
    return bad("--camera: azimuth is not a number");
  }
  if (c.elevation_deg && !(std::abs(*c.elevation_deg) <= 90.0)) {
    return bad("--camera: elevation must be in [-90, 90] degrees");
  }
  if (c.distance_m && !(std::isfinite(*c.distance_m) && *c.distance_m > 0.0)) {
    return bad("--camera: distance must be a positive number of metres");
  }
  if (job.contact_sheet && !PlainFileName(job.sheet_file)) {
    return bad("render: bad contact sheet name '" + job.sheet_file + "'");
  }
  return {};
}

Result<void> CheckRenderJob(const RenderJob& job) {
  if (auto ok = CheckRenderOptions(job); !ok) return ok;
  if (job.shots.empty())
    return Fail(ErrorCode::kInvalidInput, "render: nothing to draw (no shots)");
  for (const Shot& s : job.shots) {
    if (!PlainFileName(s.file_name)) {
      return Fail(ErrorCode::kInvalidInput, "render: bad file name '" + s.file_name + "'");
    }
  }
  return {};
}

Result<void> PrepareOutputDirectory(const fs::path& dir) {
  if (dir.empty()) return Fail(ErrorCode::kIo, "output folder: no path given");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    return Fail(ErrorCode::kIo, "output folder '" + dir.string() +
                                    "' cannot be created: " + (ec ? ec.message() : "not a folder"));
  }
  const fs::path probe = dir / ".wrap_write_probe";
  {
    std::ofstream out(probe);
    if (!out || !(out << "probe") || !out.flush()) {
      return Fail(ErrorCode::kIo,
                  "output folder '" + dir.string() + "' is not writable: " + std::strerror(errno));
    }
  }
  fs::remove(probe, ec);
  return {};
}

Result<RenderReport> RunRenderJob(const CellScene& scene, const RenderJob& job) {
  if (auto ok = CheckRenderJob(job); !ok) return std::unexpected(ok.error());
  if (!job.video.empty()) {
    if (auto ok = CheckVideoEncoder(); !ok) return std::unexpected(ok.error());
  }
  if (auto ok = PrepareOutputDirectory(job.out_dir); !ok) return std::unexpected(ok.error());

  RenderReport report;
  MjcfOptions mjcf;
  mjcf.offscreen_width = job.width;
  mjcf.offscreen_height = job.height;
  mjcf.shadows = job.shadows;

  // One camera for every shot, framing all of them.
  Aabb bounds = SceneBounds(scene, job.shots.front().state);
  for (const Shot& s : job.shots) bounds = Union(bounds, SceneBounds(scene, s.state));
  const double aspect = double(job.width) / double(job.height);
  CameraView camera =
      FrameBox(bounds, job.camera.azimuth_deg.value_or(kDefaultAzimuthDeg),
               job.camera.elevation_deg.value_or(kDefaultElevationDeg), mjcf.fovy_deg, aspect);
  if (job.camera.distance_m) camera.distance_m = *job.camera.distance_m;
  mjcf.camera = camera;
  report.camera = camera;

  auto doc = BuildCellMjcf(scene, job.shots.front().state, mjcf);
  if (!doc) return std::unexpected(doc.error());
  report.warnings = doc->warnings;
  auto model = CellModel::Compile(*doc);
  if (!model) return std::unexpected(model.error());

  RendererOptions ro;
  ro.width = job.width;
  ro.height = job.height;
  ro.backend = job.backend;
  ro.shadows = job.shadows;
  auto renderer = OffscreenRenderer::Create(*model, ro);
  if (!renderer) return std::unexpected(renderer.error());
  OffscreenRenderer& r = **renderer;
  report.gl = r.gl_description();

  // The sheet's layout first: it keeps only the shrunk snapshots, not every full frame.
  const int caption_h = r.text_height() * 2;
  const int title_h = job.title.empty() ? 0 : r.text_height(true) * 2;
  const SheetLayout layout = PlanContactSheet(static_cast<int>(job.shots.size()), job.width,
                                              job.height, caption_h, title_h);
  std::vector<Image> cells;
  std::vector<fs::path> files;
  double total_ms = 0.0;
  for (const Shot& shot : job.shots) {
    const auto start = std::chrono::steady_clock::now();
    auto image = r.Render(shot.state, camera);
    if (!image) return std::unexpected(image.error());
    total_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const fs::path file = job.out_dir / shot.file_name;
    if (auto ok = WritePng(*image, file); !ok) return std::unexpected(ok.error());
    report.written.push_back(file);
    files.push_back(file);
    if (job.contact_sheet) cells.push_back(Downscale(*image, layout.shrink));
  }
  report.mean_frame_ms = total_ms / double(job.shots.size());

  if (job.contact_sheet) {
    std::vector<Image> captions;
    for (const Shot& shot : job.shots) {
      auto caption = r.RenderText(shot.caption, layout.cell_width, caption_h);
      if (!caption) return std::unexpected(caption.error());
      captions.push_back(std::move(*caption));
    }
    Image title;
    if (!job.title.empty()) {
      auto t = r.RenderText(job.title, std::min(layout.width, job.width), title_h, true);
      if (!t) return std::unexpected(t.error());
      title = std::move(*t);
    }
    const fs::path file = job.out_dir / job.sheet_file;
    if (auto ok = WritePng(ComposeContactSheet(layout, cells, captions, title), file); !ok) {
      return std::unexpected(ok.error());
    }
    report.written.push_back(file);
  }

  if (!job.video.empty()) {
    std::vector<double> durations;
    for (const Shot& s : job.shots) durations.push_back(s.duration_s);
    if (auto ok = EncodeVideo(files, durations, job.video); !ok) return std::unexpected(ok.error());
    report.written.push_back(job.video);
  }
  for (std::string& w : TakeMujocoWarnings()) report.warnings.push_back("MuJoCo: " + w);
  return report;
}

Result<std::vector<Shot>> StillShots(const CellScene& scene, const StillShotOptions& options) {
  std::vector<Shot> shots;
  if (options.initial) shots.push_back({InitialState(scene), "initial scene", "initial.png"});
  if (options.goal) {
    auto goal = GoalState(scene);
    if (!goal) return std::unexpected(goal.error());
    shots.push_back({std::move(*goal), "assembled goal", "goal.png"});
  }
  if (options.explode != 0.0) {
    auto exploded = GoalState(scene, GoalOptions{options.explode});
    if (!exploded) return std::unexpected(exploded.error());
    char caption[64];
    std::snprintf(caption, sizeof caption, "goal, exploded x%.2g", options.explode);
    shots.push_back({std::move(*exploded), caption, "goal_exploded.png"});
  }
  if (shots.empty()) return Fail(ErrorCode::kInvalidInput, "render: no shot selected");
  return shots;
}

Result<std::vector<double>> FrameTimes(double duration_s, int frames,
                                       const std::vector<double>& at_s) {
  if (!std::isfinite(duration_s) || duration_s < 0.0) {
    return Fail(ErrorCode::kInvalidInput, "timeline duration must be a finite number >= 0");
  }
  if (!at_s.empty()) {
    for (double t : at_s) {
      if (!std::isfinite(t) || t < 0.0 || t > duration_s + 1e-9) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "--at: time %g s is outside the timeline [0, %g] s", t,
                      duration_s);
        return Fail(ErrorCode::kInvalidInput, buf);
      }
    }
    return at_s;
  }
  if (frames < 1) {
    return Fail(ErrorCode::kInvalidInput,
                "--frames " + std::to_string(frames) + ": need at least 1 frame");
  }
  std::vector<double> times;
  for (int i = 0; i < frames; ++i) {
    times.push_back(frames == 1 ? 0.0 : duration_s * double(i) / double(frames - 1));
  }
  return times;
}

namespace {

// The keyframe of a timeline entry.
const Keyframe& KeyframeOf(const Plan& plan, const PlanTimelineEntry& e) {
  if (e.action < 0) return plan.initial;
  const PlanAction& a = plan.actions[e.action];
  return e.approach && a.approach ? *a.approach : a.keyframe;
}

std::string EntryName(const PlanTimelineEntry& e) {
  if (e.action < 0) return "initial";
  return "actions[" + std::to_string(e.action) + "]." + (e.approach ? "approach" : "keyframe");
}

// A keyframe as a scene state, with the robots' finger openings given.
Result<SceneState> KeyframeState(const CellScene& scene, const AssemblyTree& tree,
                                 const Keyframe& k, const std::string& where,
                                 std::vector<double> opening_m) {
  auto bad = [&](const std::string& m) {
    return Fail(ErrorCode::kInvalidInput, "plan: " + where + ": " + m);
  };
  if (k.q.size() != scene.robots.size()) {
    return bad("joint values of " + std::to_string(k.q.size()) + " robots, the cell has " +
               std::to_string(scene.robots.size()));
  }
  SceneState state;
  for (size_t r = 0; r < k.q.size(); ++r) {
    const SceneRobot& robot = scene.robots[r];
    if (k.q[r].size() != robot.chain.dof()) {
      return bad("robot '" + robot.name + "' has " + std::to_string(robot.chain.dof()) +
                 " joints, the keyframe gives " + std::to_string(k.q[r].size()) + " values");
    }
    state.q.push_back(k.q[r]);
  }
  state.opening_m = std::move(opening_m);
  state.X_WP.assign(scene.parts.size(), Iso3::Identity());
  std::vector<bool> placed(scene.parts.size(), false);
  for (const PlanObject& o : k.objects) {
    if (o.node < 0 || o.node >= static_cast<int>(tree.nodes.size())) {
      return bad("object node " + std::to_string(o.node) + " is not in the assembly");
    }
    for (int p : tree.nodes[o.node].parts) {
      if (p < 0 || p >= static_cast<int>(scene.parts.size()) || placed[p]) {
        return bad("part " + (p >= 0 && p < int(scene.parts.size())
                                  ? "'" + scene.parts[p].name + "' is in two objects"
                                  : std::to_string(p) + " is not in the cell"));
      }
      placed[p] = true;
      state.X_WP[p] = o.X_WA * scene.parts[p].X_AP;
    }
  }
  for (size_t p = 0; p < placed.size(); ++p) {
    if (!placed[p]) return bad("part '" + scene.parts[p].name + "' is in no object");
  }
  return state;
}

}  // namespace

std::vector<PlanTimelineEntry> PlanTimeline(const Plan& plan) {
  std::vector<PlanTimelineEntry> timeline = {{-1, false}};
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    if (plan.actions[i].approach) timeline.push_back({static_cast<int>(i), true});
    timeline.push_back({static_cast<int>(i), false});
  }
  return timeline;
}

Result<std::vector<SceneState>> PlanStates(const CellScene& scene, const AssemblyTree& tree,
                                           const Plan& plan) {
  const int n_robots = static_cast<int>(scene.robots.size());
  // Fingers closed to the grasp's width on what a robot holds, else fully open.
  auto openings = [&](const PlanState& s) {
    std::vector<double> opening(n_robots);
    for (int r = 0; r < n_robots; ++r) {
      const double stroke = scene.robots[r].end_effector.stroke_m;
      opening[r] = s.held[r] >= 0 ? std::clamp(s.grasp[r].width_m, 0.0, stroke) : stroke;
    }
    return opening;
  };
  // Who holds what, replayed action by action (task/plan_state.h): from an action's approach
  // through its keyframe its grasps are closed; after the keyframe its grippers let go.
  PlanState before = InitialPlanState(plan.initial, n_robots);
  std::vector<SceneState> states;
  for (const PlanTimelineEntry& e : PlanTimeline(plan)) {
    const PlanState at = e.action >= 0 ? StateAtKeyframe(before, plan.actions[e.action]) : before;
    auto state = KeyframeState(scene, tree, KeyframeOf(plan, e), EntryName(e), openings(at));
    if (!state) return std::unexpected(state.error());
    states.push_back(std::move(*state));
    if (e.action >= 0 && !e.approach) before = ApplyAction(before, plan.actions[e.action]);
  }
  return states;
}

Result<SceneState> MotionState(const CellScene& scene, const AssemblyTree& tree, const Plan& plan,
                               double t) {
  const size_t n_robots = scene.robots.size();
  if (plan.trajectories.size() != n_robots) {
    return Fail(ErrorCode::kInvalidInput, "plan: it has no trajectories for the cell's " +
                                              std::to_string(n_robots) + " robots");
  }
  SceneState state;
  std::vector<Iso3> X_WT(n_robots);
  for (size_t r = 0; r < n_robots; ++r) {
    const SceneRobot& robot = scene.robots[r];
    const RobotTrajectory& tr = plan.trajectories[r];
    if (tr.knots.empty() || tr.knots.front().q.size() != robot.chain.dof()) {
      return Fail(ErrorCode::kInvalidInput,
                  "plan: the trajectory of robot '" + robot.name + "' does not fit its joints");
    }
    state.q.push_back(SampleTrajectory(tr, t));
    const double o = OpeningAt(tr, t);
    const double stroke = robot.end_effector.stroke_m;
    state.opening_m.push_back(o < 0.0 ? stroke : std::clamp(o, 0.0, stroke));
    X_WT[r] = TcpPose(robot.chain, robot.X_WB, state.q.back(), robot.end_effector.X_FT);
  }
  // Objects: replay the actions whose moments have passed (in time order).
  std::vector<int> order(plan.actions.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return plan.actions[a].end_s < plan.actions[b].end_s; });
  PlanState s = InitialPlanState(plan.initial, static_cast<int>(n_robots));
  for (int i : order) {
    if (plan.actions[i].end_s > t) break;
    s = ApplyAction(s, plan.actions[i]);
  }
  // Where an object is now: carried by its first holder, else where the plan left it.
  auto pose_now = [&](int node, const PlanObject& o) {
    const std::vector<int> holders = s.Holders(node);
    if (holders.empty()) return o.X_WA;
    const PlanGrasp& g = s.grasp[holders.front()];
    return X_WT[holders.front()] * (scene.parts[g.part].X_AP * g.X_PG).inverse();
  };
  state.X_WP.assign(scene.parts.size(), Iso3::Identity());
  for (const auto& [n, o] : s.objects) {
    if (n < 0 || n >= static_cast<int>(tree.nodes.size())) {
      return Fail(ErrorCode::kInvalidInput,
                  "plan: object node " + std::to_string(n) + " is not in the assembly");
    }
    const Iso3 X_WA = pose_now(n, o);
    for (int p : tree.nodes[n].parts) state.X_WP[p] = X_WA * scene.parts[p].X_AP;
  }
  return state;
}

Result<std::vector<Shot>> PlanShots(const CellScene& scene, const AssemblyTree& tree,
                                    const Plan& plan, const PlanShotOptions& options) {
  if (!plan.trajectories.empty() && options.at.empty() && options.frames > 0) {
    // With motion: frames evenly in time.
    auto times = FrameTimes(plan.stats.makespan_s, options.frames, {});
    if (!times) return std::unexpected(times.error());
    std::vector<Shot> shots;
    for (size_t f = 0; f < times->size(); ++f) {
      const double t = (*times)[f];
      auto state = MotionState(scene, tree, plan, t);
      if (!state) return std::unexpected(state.error());
      // Caption: the action under way (the first whose moment is still ahead).
      std::string doing = "done";
      for (const PlanAction& a : plan.actions) {
        if (a.end_s >= t) {
          doing = DescribeAction(plan, a);
          break;
        }
      }
      char head[48];
      std::snprintf(head, sizeof head, "t = %.1f s: ", t);
      char name[32];
      std::snprintf(name, sizeof name, "frame_%03zu.png", f);
      shots.push_back({std::move(*state), head + doing, name});
    }
    return shots;
  }
  auto states = PlanStates(scene, tree, plan);
  if (!states) return std::unexpected(states.error());
  const std::vector<PlanTimelineEntry> timeline = PlanTimeline(plan);
  const int last = static_cast<int>(timeline.size()) - 1;

  auto caption = [&](int k) {
    const PlanTimelineEntry& e = timeline[k];
    std::string words = std::to_string(k) + ": ";
    if (e.action < 0) return words + "initial scene";
    const PlanAction& a = plan.actions[e.action];
    return words + (e.approach ? "approach: " : "") + DescribeAction(plan, a);
  };
  auto file_name = [&](int k) {
    const PlanTimelineEntry& e = timeline[k];
    std::string type = "initial";
    if (e.action >= 0) {
      type = std::string(ToString(plan.actions[e.action].type)) + (e.approach ? "_approach" : "");
    }
    char name[64];
    std::snprintf(name, sizeof name, "plan_%03d_%s.png", k, type.c_str());
    return std::string(name);
  };

  std::vector<Shot> shots;
  if (options.at.empty() && options.frames < 0) {
    for (int k = 0; k <= last; ++k) shots.push_back({(*states)[k], caption(k), file_name(k)});
    return shots;
  }
  // Keyframe indices as times: --at names keyframes, --frames spreads over them.
  std::vector<double> times;
  if (!options.at.empty()) {
    for (double t : options.at) {
      if (!(t >= 0.0 && t <= last && t == std::floor(t))) {
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "--at: %g is not a keyframe index of the plan (with --plan, --at takes "
                      "whole numbers from 0, the initial keyframe, to %d)",
                      t, last);
        return Fail(ErrorCode::kInvalidInput, buf);
      }
    }
    times = options.at;
  } else {
    auto even = FrameTimes(double(last), options.frames, {});
    if (!even) return std::unexpected(even.error());
    times = std::move(*even);
  }
  for (size_t f = 0; f < times.size(); ++f) {
    const int k = std::clamp(static_cast<int>(std::lround(times[f])), 0, last);
    char name[32];
    std::snprintf(name, sizeof name, "frame_%03zu.png", f);
    shots.push_back({(*states)[k], caption(k), name});
  }
  return shots;
}

}  // namespace wrap::render
