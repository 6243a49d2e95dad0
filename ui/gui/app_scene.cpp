// What the viewport shows: the document's cell (rebuilt after every change of the document), the
// plan at the timeline's time while the plan is current, or the failure case the Problems panel
// shows ("Show": the cell as the failing check saw it, the robot, the object and the bodies that
// collided highlighted, the grasp that was tried drawn as an arrow).
#include <imgui.h>

#include <algorithm>

#include "gui/app_impl.h"
#include "render/render_job.h"

namespace wrap::gui {

namespace {

constexpr Rgba kBlame = {0.95, 0.12, 0.1, 1.0};  // a robot that could not, bodies that collided
constexpr Rgba kObject = {1.0, 0.72, 0.1, 1.0};  // the object that was tried
constexpr Rgba kGrasp = {0.95, 0.3, 0.9, 1.0};   // the grasp that was tried

int IndexOf(const std::vector<std::string>& names, const std::string& name) {
  auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

}  // namespace

void App::UpdateViewport() {
  if (s_.viewport_revision != s_.doc.revision()) {
    // Parts' initial poses need no new cell (DocumentState draws them as the document has
    // them); anything else does: at once, or every 0.3 s while a field or handle is dragged (a
    // robot's base moved with the gizmo follows the mouse).
    Project key = s_.doc.project();
    for (Part& part : key.parts) part.initial_pose = Pose{};
    const bool same_cell = built_key_ && *built_key_ == key && s_.viewport.ready() &&
                           built_file_ == s_.doc.ResolvePath();
    if (same_cell) {
      s_.viewport_revision = s_.doc.revision();
    } else if (!ImGui::IsAnyItemActive() || win_.time() - last_build_ > 0.3) {
      s_.viewport_revision = s_.doc.revision();
      last_build_ = win_.time();
      auto built = s_.viewport.Build(s_.doc.project(), s_.doc.ResolvePath());
      s_.viewport_error = built ? "" : built.error().message;
      // A cell that cannot be built is not drawn: the old one would be a stale picture.
      if (!built) {
        s_.viewport.Clear();
        built_key_.reset();
      } else {
        built_key_ = std::move(key);
        built_file_ = s_.doc.ResolvePath();
        if (s_.frame_next_cell) s_.viewport.ResetCamera();
        s_.frame_next_cell = false;
      }
      plan_states_.clear();
    }
  }
  if (!s_.viewport.ready()) return;
  const CellScene& scene = s_.viewport.scene();
  std::vector<SceneArrow> arrows;
  std::vector<SceneMarker> markers;
  std::vector<SceneHighlight> highlights;
  SceneState state;
  const bool failure = FailureState(state, arrows, highlights);
  if (!failure) state = CurrentState();
  std::vector<render::SceneLine> lines;
  std::vector<render::SceneDot> dots;
  const bool assembled = !failure && (s_.show_assembled || s_.show_contacts);
  if (assembled) {
    AssembledView(state, lines, dots);
  } else {
    assembled_framed_ = false;
  }
  (void)s_.viewport.SetState(state);
  int selected = -1;
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    if (scene.parts[i].name == s_.selection.part) selected = static_cast<int>(i);
  }
  s_.viewport.set_selected_part(selected);
  if (!failure && !assembled) {
    if (auto arrow = StepArrow()) arrows.push_back(*arrow);
    PlanMarks(state, selected, arrows, markers);
  }
  s_.viewport.set_lines(std::move(lines));
  s_.viewport.set_dots(std::move(dots));
  s_.viewport.set_arrows(std::move(arrows));
  s_.viewport.set_markers(std::move(markers));
  s_.viewport.set_highlights(std::move(highlights));
  s_.viewport.set_gripper_tints(failure ? std::vector<std::optional<Rgba>>{} : GripperTints(scene));
}

bool App::FailureState(SceneState& state, std::vector<SceneArrow>& arrows,
                       std::vector<SceneHighlight>& highlights) {
  if (s_.showing_case < 0 || !s_.run_failure || !s_.run_failure->failure) return false;
  const RunFailure& rf = *s_.run_failure;
  const PlanFailure& f = *rf.failure;
  if (s_.showing_case >= static_cast<int>(f.cases.size())) return false;
  const FailureCase& c = f.cases[s_.showing_case];
  const CellScene& scene = s_.viewport.scene();
  const Project& planned = *rf.project;
  // The cell as the failing check saw it, by name (the document may have changed since).
  state = DocumentState();
  const FailureScene& fs = c.scene.X_WP.empty() && c.scene.q.empty() ? f.start : c.scene;
  for (size_t r = 0; r < scene.robots.size(); ++r) {
    for (size_t k = 0; k < planned.robots.size() && k < fs.q.size(); ++k) {
      if (planned.robots[k].name == scene.robots[r].name && fs.q[k].size() == state.q[r].size()) {
        state.q[r] = fs.q[k];
      }
    }
  }
  std::vector<std::string> part_names;
  for (const ScenePart& p : scene.parts) part_names.push_back(p.name);
  for (size_t k = 0; k < planned.parts.size() && k < fs.X_WP.size(); ++k) {
    const int i = IndexOf(part_names, planned.parts[k].name);
    if (i >= 0) state.X_WP[i] = fs.X_WP[k];
  }
  // What to highlight: the robot, the object, the bodies that collided.
  auto robot_index = [&](const std::string& name) {
    for (size_t r = 0; r < scene.robots.size(); ++r) {
      if (scene.robots[r].name == name) return static_cast<int>(r);
    }
    return -1;
  };
  // The robot of the check; for a motion segment, every robot it moves.
  std::vector<int> blamed = f.stage == "motion" ? f.robots : std::vector<int>{};
  if (c.robot >= 0) blamed.push_back(c.robot);
  for (int k : blamed) {
    if (k < 0 || k >= static_cast<int>(planned.robots.size())) continue;
    const int r = robot_index(planned.robots[k].name);
    if (r >= 0) highlights.push_back({SceneHighlight::Kind::kRobot, r, kBlame});
  }
  if (c.object >= 0 && c.object < static_cast<int>(rf.node_parts.size())) {
    for (const std::string& part : rf.node_parts[c.object]) {
      const int i = IndexOf(part_names, part);
      if (i >= 0) highlights.push_back({SceneHighlight::Kind::kPart, i, kObject});
    }
  }
  for (const std::string& body : fs.bodies) {
    if (body == "table") {
      highlights.push_back({SceneHighlight::Kind::kTable, -1, kBlame});
    } else if (const auto slash = body.find('/'); slash != std::string::npos) {
      const int r = robot_index(body.substr(0, slash));
      if (r >= 0) highlights.push_back({SceneHighlight::Kind::kRobot, r, kBlame});
    } else if (const int i = IndexOf(part_names, body); i >= 0) {
      highlights.push_back({SceneHighlight::Kind::kPart, i, kBlame});
    } else if (const int n = IndexOf(rf.nodes, body); n >= 0) {
      for (const std::string& part : rf.node_parts[n]) {
        if (const int j = IndexOf(part_names, part); j >= 0) {
          highlights.push_back({SceneHighlight::Kind::kPart, j, kBlame});
        }
      }
    }
  }
  // The grasp that was tried: an arrow along the gripper's approach axis, ending at the TCP.
  if (c.grasp_part >= 0 && c.grasp_part < static_cast<int>(planned.parts.size())) {
    const int i = IndexOf(part_names, planned.parts[c.grasp_part].name);
    if (i >= 0) {
      const Iso3 X_WG = state.X_WP[i] * c.X_PG;
      const Vec3 tcp = X_WG.translation();
      const Vec3 approach = X_WG.linear().col(2);
      arrows.push_back(SceneArrow{tcp - 0.16 * approach, tcp, kGrasp, 0.012});
    }
  }
  return true;
}

std::vector<std::optional<Rgba>> App::GripperTints(const CellScene& scene) const {
  std::vector<std::optional<Rgba>> tints(scene.robots.size());
  if (!s_.show_utilisation || !s_.plan || s_.PlanStale()) return tints;
  const int under = s_.ActionAt(s_.playback.t);
  if (under < 0) return tints;
  for (const auto& [robot, u] : s_.plan->actions[under].utilisation) {
    if (robot < 0 || robot >= static_cast<int>(s_.plan->robots.size())) continue;
    for (size_t r = 0; r < scene.robots.size(); ++r) {
      if (scene.robots[r].name == s_.plan->robots[robot]) tints[r] = UtilisationColour(u);
    }
  }
  return tints;
}

void App::PlanMarks(const SceneState& state, int selected, std::vector<SceneArrow>& arrows,
                    std::vector<SceneMarker>& markers) {
  const CellScene& scene = s_.viewport.scene();
  if (!s_.plan || s_.PlanStale() || s_.plan->parts.size() != scene.parts.size()) return;
  const Plan& plan = *s_.plan;
  if (selected >= 0 && selected < static_cast<int>(state.X_WP.size())) {
    std::vector<std::pair<int, int>> seen;  // (subassembly, index) of each grasp drawn
    for (const PlanAction& a : plan.actions) {
      for (const PlanHold& h : a.grasps) {
        const PlanGrasp& g = h.grasp;
        if (g.part != selected) continue;
        const std::pair<int, int> key{g.subassembly, g.index};
        if (std::find(seen.begin(), seen.end(), key) != seen.end()) continue;
        seen.push_back(key);
        const Iso3 X_WG = state.X_WP[selected] * g.X_PG;
        const Vec3 tcp = X_WG.translation();
        const Vec3 approach = X_WG.linear().col(2);
        arrows.push_back(SceneArrow{tcp - 0.08 * approach, tcp, {0.1, 0.75, 0.85, 1.0}, 0.006});
      }
    }
  }
  const double top = s_.doc.project().table.height + 0.001;
  for (const PlanAction& a : plan.actions) {
    if (a.type != ActionType::kPlace || a.objects.empty()) continue;
    for (const PlanObject& o : a.keyframe.objects) {
      if (o.node != a.objects[0]) continue;
      Vec3 at = o.X_WA.translation();
      const auto& tree = s_.viewport.check().tree;
      if (tree && o.node >= 0 && o.node < static_cast<int>(tree->nodes.size()) &&
          !tree->nodes[o.node].parts.empty()) {
        at.setZero();
        for (int part : tree->nodes[o.node].parts) {
          at += (o.X_WA * scene.parts[part].X_AP).translation();
        }
        at /= static_cast<double>(tree->nodes[o.node].parts.size());
      }
      markers.push_back(SceneMarker{Vec3(at.x(), at.y(), top), 0.035, {0.1, 0.6, 0.9, 0.55}});
    }
  }
}

SceneState App::CurrentState() {
  const CellScene& scene = s_.viewport.scene();
  const auto& tree = s_.viewport.check().tree;
  // A plan of another state of the project is not played: the document is drawn as it is.
  if (s_.plan && !s_.PlanStale() && tree && s_.plan->robots.size() == scene.robots.size() &&
      s_.plan->parts.size() == scene.parts.size()) {
    const Plan& plan = *s_.plan;
    if (plan.stats.motion && !plan.trajectories.empty()) {
      if (auto st = render::MotionState(scene, *tree, plan, s_.playback.t)) return *st;
    } else {
      if (plan_states_.empty()) {
        if (auto states = render::PlanStates(scene, *tree, plan)) plan_states_ = *states;
      }
      if (!plan_states_.empty()) {
        const int k = std::clamp(static_cast<int>(std::lround(s_.playback.t)), 0,
                                 static_cast<int>(plan_states_.size()) - 1);
        return plan_states_[k];
      }
    }
  }
  return DocumentState();
}

SceneState App::DocumentState() {
  // Initial poses as the document has them now (a drag or a typed pose shows before the cell is
  // rebuilt), robots at home or where their joint sliders put them.
  const CellScene& scene = s_.viewport.scene();
  SceneState state = InitialState(scene);
  const Project& p = s_.doc.project();
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    for (const Part& part : p.parts) {
      if (part.name == scene.parts[i].name) state.X_WP[i] = ToIsometry(part.initial_pose);
    }
  }
  for (size_t r = 0; r < scene.robots.size(); ++r) {
    const auto jog = s_.jog.find(scene.robots[r].name);
    if (jog != s_.jog.end() && jog->second.size() == state.q[r].size()) state.q[r] = jog->second;
  }
  return state;
}

std::optional<SceneArrow> App::StepArrow() {
  const CellScene& scene = s_.viewport.scene();
  const auto& tree = s_.viewport.check().tree;
  if (!tree || s_.selection.step.empty() || (s_.plan && !s_.PlanStale())) return std::nullopt;
  const Project& p = s_.doc.project();
  auto step = std::find_if(p.steps.begin(), p.steps.end(),
                           [&](const Step& st) { return st.name == s_.selection.step; });
  if (step == p.steps.end()) return std::nullopt;
  const int moved = tree->Find(step->mating.moved);
  if (moved < 0 || tree->nodes[moved].parts.empty()) return std::nullopt;
  const int part = tree->nodes[moved].parts.front();
  if (part >= static_cast<int>(scene.parts.size()) || step->mating.axis.norm() < 1e-9) {
    return std::nullopt;
  }
  // From the middle of the part (where it is now) along the direction it travels, out past
  // its far side.
  const ScenePart& sp = scene.parts[part];
  Iso3 X_WP = sp.X_WP_initial;
  for (const Part& q : p.parts) {
    if (q.name == sp.name) X_WP = ToIsometry(q.initial_pose);
  }
  const Iso3 X_WA = X_WP * sp.X_AP.inverse();
  const Vec3 axis_W = X_WA.linear() * step->mating.axis.normalized();
  const Aabb box = sp.mesh ? ComputeAabb(*sp.mesh) : Aabb{};
  const Vec3 centre_W = X_WP * (0.5 * (box.min + box.max));
  const Vec3 axis_P = X_WP.linear().transpose() * axis_W;
  const double half = 0.5 * axis_P.cwiseAbs().dot(box.size());  // centre to the far side
  const Vec3 tail = centre_W + (half + 0.01) * axis_W;
  return SceneArrow{tail, tail + 0.15 * axis_W, {0.95, 0.2, 0.15, 1.0}};
}

}  // namespace wrap::gui
