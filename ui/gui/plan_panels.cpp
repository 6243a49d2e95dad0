// The planner panel (options, Run/Cancel, progress, log, errors) and the plan panel (actions in
// words, timeline with play/pause/speed/loop, scrubber, per-robot lanes).
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gui/panels.h"

namespace wrap::gui {

namespace {

ImU32 UtilisationImColour(double u) {
  const Rgba c = UtilisationColour(u);
  return IM_COL32(static_cast<int>(255 * c[0]), static_cast<int>(255 * c[1]),
                  static_cast<int>(255 * c[2]), 255);
}

}  // namespace

Rgba UtilisationColour(double u) {
  const double x = std::clamp(u, 0.0, 1.0);
  const double r = x < 0.7 ? x / 0.7 : 1.0;
  const double g = x < 0.7 ? 1.0 : std::max(0.0, 1.0 - (x - 0.7) / 0.3);
  return {(60 + 195 * r) / 255.0, (60 + 160 * g) / 255.0, 60 / 255.0, 1.0};
}

std::vector<double> AppState::KeyframeTimes() const {
  std::vector<double> times;
  if (!plan) return times;
  const bool motion = plan->stats.motion && !plan->trajectories.empty();
  double k = 0;
  for (const PlanAction& a : plan->actions) {
    k += a.approach ? 2 : 1;
    times.push_back(motion ? a.end_s : k);
  }
  return times;
}

int AppState::ActionAt(double t) const {
  if (!plan) return -1;
  const bool motion = plan->stats.motion && !plan->trajectories.empty();
  const std::vector<double> at = KeyframeTimes();
  for (size_t i = 0; i < at.size(); ++i) {
    const double from = motion ? plan->actions[i].start_s : at[i] - 1;
    if (t >= from && t <= at[i]) return static_cast<int>(i);
  }
  return -1;
}

double AppState::Duration() const {
  if (!plan) return 0.0;
  if (plan->stats.motion && !plan->trajectories.empty()) {
    double end = plan->stats.makespan_s;
    for (const RobotTrajectory& tr : plan->trajectories) {
      if (!tr.knots.empty()) end = std::max(end, tr.knots.back().t);
    }
    return end;
  }
  int keyframes = 1;
  for (const PlanAction& a : plan->actions) keyframes += a.approach ? 2 : 1;
  return static_cast<double>(keyframes - 1);
}

void PlannerPanel::Draw(AppState& app, const PanelRect& r) {
  PlaceNextWindow(r);
  if (!ImGui::Begin("Planner", nullptr, ImGuiWindowFlags_NoCollapse)) {
    ImGui::End();
    return;
  }
  PlannerRequest& q = app.request;
  static const char* kPlanners[] = {"wrap", "optimistic", "flat", "counting", "exact", "fine"};
  static const char* kWrench[] = {"full", "gravity", "none"};
  static const char* kObjectives[] = {"actions", "makespan"};
  const bool running = app.job.running();
  ImGui::BeginDisabled(running);
  ImGui::SetNextItemWidth(120);
  if (ImGui::BeginCombo("variant", q.planner.c_str())) {
    for (const char* v : kPlanners) {
      if (ImGui::Selectable(v, q.planner == v)) q.planner = v;
    }
    ImGui::EndCombo();
  }
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90);
  if (ImGui::BeginCombo("wrench", q.wrench.c_str())) {
    for (const char* v : kWrench) {
      if (ImGui::Selectable(v, q.wrench == v)) q.wrench = v;
    }
    ImGui::EndCombo();
  }
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("time limit [s]", &q.time_limit_s, 1.0, 10.0, "%.0f");
  q.time_limit_s = std::clamp(q.time_limit_s, 1.0, 36000.0);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("Wall-clock bound of the whole run. The work budget, not the machine's "
                      "speed, decides the plan; this only stops a run that takes too long.");
  }
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("work budget x", &q.budget, 0.5, 2.0, "%.2g");
  q.budget = std::clamp(q.budget, 0.01, 1000.0);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("Scale of the motion searches' budgets (collision checks per path search, "
                      "poses per carry search), as `wrap plan --budget`. More finds paths in "
                      "harder scenes; the same budget and seed give the same plan on any machine.");
  }
  ImGui::SetNextItemWidth(120);
  ImGui::InputScalar("seed", ImGuiDataType_U64, &q.seed);
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("force scale", &q.force_scale, 0.1, 1.0, "%.2f");
  q.force_scale = std::clamp(q.force_scale, 0.0, 1e6);
  ImGui::Checkbox("optimize", &q.optimize);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90);
  if (ImGui::BeginCombo("objective", q.objective.c_str())) {
    for (const char* v : kObjectives) {
      if (ImGui::Selectable(v, q.objective == v)) q.objective = v;
    }
    ImGui::EndCombo();
  }
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("What the planner minimises, as `wrap plan --objective`: the number of "
                      "actions, or the task plan's makespan estimate (work spread over robots).");
  }
  ImGui::SameLine();
  ImGui::Checkbox("task only (no motion)", &q.task_only);
  ImGui::EndDisabled();

  if (!running) {
    if (ImGui::Button("Run", ImVec2(90, 0))) StartRun(app);
  } else if (ImGui::Button("Cancel", ImVec2(90, 0))) {
    app.job.Cancel();
  }
  const JobProgress prog = app.job.progress();
  ImGui::SameLine();
  ImGui::Text("%s  %.1f s", ToString(prog.state), prog.elapsed_s);
  if (prog.state == JobState::kRunning) {
    // Every stage the run went through, with its time, then the current one's progress: the
    // stage's name and its count ("motion: action 5/12: free path 3 for 'ur5e_a'").
    std::string trail;
    for (size_t i = 0; i < prog.stages.size(); ++i) {
      const JobStage& st = prog.stages[i];
      const double end = i + 1 < prog.stages.size() ? prog.stages[i + 1].start_s : prog.elapsed_s;
      char t[32];
      std::snprintf(t, sizeof t, " %.1f s", end - st.start_s);
      trail += (i ? " > " : "") + st.name + t;
    }
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("%s", trail.c_str());
    ImGui::PopStyleColor();
    const float f = prog.fraction >= 0 ? static_cast<float>(prog.fraction)
                                       : static_cast<float>(std::fmod(prog.elapsed_s, 1.0));
    ImGui::ProgressBar(f, ImVec2(-1, 0), (prog.stage + ": " + prog.message).c_str());
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("%s: %s", prog.stage.c_str(), prog.message.c_str());
  }
  if (!prog.error.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
    ImGui::TextWrapped("%s", prog.error.c_str());
    ImGui::PopStyleColor();
    if (app.run_failure && ImGui::SmallButton("Show in Problems")) app.focus_problems = true;
  }
  ImGui::BeginChild("log", ImVec2(0, 0), true);
  for (const std::string& line : prog.log) ImGui::TextWrapped("%s", line.c_str());
  if (prog.state == JobState::kRunning) ImGui::SetScrollHereY(1.0f);
  ImGui::EndChild();
  ImGui::End();
}

void StartRun(AppState& app) {
  if (app.job.Start(app.doc.project(), app.doc.ResolvePath(), app.request)) {
    app.showing_case = -1;
    app.Notify("Planning started on a snapshot of the project");
  }
}

void PlanPanel::Contents(AppState& app) {
  if (!app.plan) {
    ImGui::TextDisabled("No plan yet: run the planner (Planner panel) or open a plan file.");
    return;
  }
  const Plan& plan = *app.plan;
  const bool motion = plan.stats.motion && !plan.trajectories.empty();
  const double duration = app.Duration();
  Playback& pb = app.playback;
  // A plan of another state of the project: greyed, not played, with a way to plan again.
  const bool stale = app.PlanStale();
  if (stale) {
    pb.playing = false;
    ImGui::PushStyleColor(ImGuiCol_ChildBg, ImVec4(0.35f, 0.25f, 0.08f, 1.0f));
    ImGui::BeginChild("stale", ImVec2(0, ImGui::GetFrameHeightWithSpacing() + 6), true,
                      ImGuiWindowFlags_NoScrollbar);
    ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.35f, 1.0f),
                       "Out of date: the project changed since this plan was made.");
    ImGui::SameLine();
    ImGui::BeginDisabled(app.job.running());
    if (ImGui::SmallButton("Re-plan")) StartRun(app);
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::TextDisabled("(undo back to it to show it again)");
    ImGui::EndChild();
    ImGui::PopStyleColor();
  }
  ImGui::BeginDisabled(stale);
  if (ImGui::Button(pb.playing ? "Pause" : "Play", ImVec2(60, 0))) pb.playing = !pb.playing;
  ImGui::SameLine();
  if (ImGui::Button("|<")) pb.t = 0;
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90);
  float speed = static_cast<float>(pb.speed);
  if (ImGui::SliderFloat("speed", &speed, 0.1f, 8.0f, "%.1fx", ImGuiSliderFlags_Logarithmic)) {
    pb.speed = speed;
  }
  ImGui::SameLine();
  ImGui::Checkbox("loop", &pb.loop);
  ImGui::SameLine();
  ImGui::Text(
      "%s, cost %d, %s", plan.stats.solved ? "solved" : "not solved", plan.stats.cost,
      motion ? ("makespan " + std::to_string(plan.stats.makespan_s).substr(0, 5) + " s").c_str()
             : "keyframes only");
  ImGui::SetNextItemWidth(-1);
  float t = static_cast<float>(pb.t);
  if (ImGui::SliderFloat("##time", &t, 0.0f, static_cast<float>(std::max(duration, 1e-3)),
                         motion ? "t = %.2f s" : "keyframe %.0f")) {
    pb.t = t;
    pb.playing = false;
  }

  // Lanes: one per robot, a bar per action it takes part in (start..end with motion; one
  // keyframe wide without).
  const int n_robots = static_cast<int>(plan.robots.size());
  const float lane_h = 14.0f;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float label_w = 80.0f;
  const float width = std::max(50.0f, ImGui::GetContentRegionAvail().x - label_w);
  auto x_of = [&](double time) {
    return origin.x + label_w + static_cast<float>(time / std::max(duration, 1e-9)) * width;
  };
  const std::vector<double> keyframe_time = app.KeyframeTimes();
  for (int rb = 0; rb < n_robots; ++rb) {
    const float y = origin.y + rb * (lane_h + 3);
    dl->AddText(ImVec2(origin.x, y), IM_COL32(200, 200, 200, 255), plan.robots[rb].c_str());
    dl->AddRectFilled(ImVec2(origin.x + label_w, y), ImVec2(origin.x + label_w + width, y + lane_h),
                      IM_COL32(40, 42, 46, 255));
    for (size_t i = 0; i < plan.actions.size(); ++i) {
      const PlanAction& a = plan.actions[i];
      if (std::find(a.robots.begin(), a.robots.end(), rb) == a.robots.end()) continue;
      const double end = keyframe_time[i];
      const double start = motion ? std::max(0.0, a.start_s) : end - (a.approach ? 2 : 1);
      const ImU32 col = stale                             ? IM_COL32(90, 92, 96, 255)
                        : a.type == ActionType::kAssemble ? IM_COL32(230, 140, 50, 255)
                        : a.type == ActionType::kPick     ? IM_COL32(80, 150, 220, 255)
                                                          : IM_COL32(120, 180, 120, 255);
      dl->AddRectFilled(ImVec2(x_of(start), y + 1),
                        ImVec2(std::max(x_of(end), x_of(start) + 2), y + lane_h - 1), col, 2.0f);
      // The gripper's wrench utilisation at this action as a band along the bar's foot.
      if (const auto u = a.utilisation.find(rb); u != a.utilisation.end() && !stale) {
        dl->AddRectFilled(ImVec2(x_of(start), y + lane_h - 4),
                          ImVec2(std::max(x_of(end), x_of(start) + 2), y + lane_h - 1),
                          UtilisationImColour(u->second));
      }
    }
  }
  const float lanes_h = n_robots * (lane_h + 3);
  dl->AddLine(ImVec2(x_of(pb.t), origin.y), ImVec2(x_of(pb.t), origin.y + lanes_h),
              IM_COL32(255, 255, 255, 255), 2.0f);
  ImGui::InvisibleButton("lanes", ImVec2(label_w + width, std::max(lanes_h, 1.0f)));
  if (ImGui::IsItemActive() && !stale) {
    const double f = (ImGui::GetIO().MousePos.x - origin.x - label_w) / width;
    pb.t = std::clamp(f, 0.0, 1.0) * duration;
    pb.playing = false;
  }

  // The wrench utilisation of the action under the cursor, per gripper.
  const int under = app.ActionAt(pb.t);
  if (under >= 0 && !plan.actions[under].utilisation.empty()) {
    ImGui::Text("Action %d, wrench utilisation:", under + 1);
    for (const auto& [robot, u] : plan.actions[under].utilisation) {
      ImGui::SameLine();
      ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(UtilisationImColour(u)), "%s %.0f%%",
                         plan.robots[robot].c_str(), 100.0 * u);
    }
  } else if (under >= 0) {
    ImGui::TextDisabled("Action %d: no gripper carries a load", under + 1);
  } else {
    ImGui::TextDisabled("Between actions");
  }

  // Actions in words; click to jump to the action's moment.
  ImGui::BeginChild("actions", ImVec2(0, 0), true);
  for (size_t i = 0; i < plan.actions.size(); ++i) {
    const double at = keyframe_time[i];
    const double from = motion ? plan.actions[i].start_s : at - 1;
    const bool current = pb.t >= from && pb.t <= at;
    std::string line = std::to_string(i + 1) + ". " + DescribeAction(plan, plan.actions[i]);
    if (!plan.actions[i].utilisation.empty()) {
      double peak = 0.0;
      for (const auto& [robot, u] : plan.actions[i].utilisation) peak = std::max(peak, u);
      line += "  (peak gripper load " + std::to_string(static_cast<int>(std::lround(100 * peak))) +
              "%)";
    }
    if (ImGui::Selectable(line.c_str(), current)) {
      pb.t = at;
      pb.playing = false;
    }
  }
  ImGui::EndChild();
  ImGui::EndDisabled();
}

}  // namespace wrap::gui
