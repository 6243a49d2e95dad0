#include "gui/app.h"

#include <imgui.h>
#include <imgui_internal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ostream>
#include <sstream>
#include <thread>

#include "core/file_io.h"
#include "gui/app_impl.h"
#include "gui/commands.h"
#include "gui/script.h"
#include "model/assembly.h"
#include "render/image.h"

namespace wrap::gui {

namespace fs = std::filesystem;

namespace {

// The recovery file follows the document: written once edits have paused for a second, and at
// least every 30 s during a long run of edits (a drag).
constexpr double kAutosaveQuietS = 1.0;
constexpr double kAutosavePeriodS = 30.0;

bool IsMeshFile(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  for (const char* m :
       {".stl", ".obj", ".ply", ".off", ".glb", ".gltf", ".3mf", ".dae", ".step", ".stp"}) {
    if (ext == m) return true;
  }
  return false;
}

/// The names of a failed run's project (DAG nodes and their parts) for the Problems panel.
RunFailure MakeRunFailure(const JobProgress& prog, std::shared_ptr<const Project> project,
                          const fs::path& file) {
  RunFailure rf;
  rf.failure = prog.failure;
  rf.project = project ? std::move(project) : std::make_shared<const Project>();
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.1f", prog.elapsed_s);
  // The CLI's words: `wrap plan` prints "No plan found in T s: REASON" for a run that searched,
  // and the error itself for one that stopped before (an invalid project, preprocessing).
  rf.headline = prog.state == JobState::kNoPlan
                    ? "No plan found in " + std::string(seconds) + " s: " + prog.error
                    : prog.error;
  Diagnostics diags;
  AssemblyTree tree;
  if (BuildAssemblyTree(*rf.project, file.string(), diags, tree)) {
    for (const AssemblyNode& n : tree.nodes) {
      rf.nodes.push_back(n.name);
      std::vector<std::string> parts;
      for (int p : n.parts) parts.push_back(rf.project->parts[p].name);
      rf.node_parts.push_back(std::move(parts));
    }
  }
  return rf;
}

int WriteScreenshot(const render::Image& image, const fs::path& file, std::ostream& out,
                    std::ostream& err) {
  if (auto written = render::WritePng(image, file); !written) {
    err << file.string() << ": " << written.error().message << "\n";
    return 2;
  }
  out << "Wrote " << file.string() << " (" << image.width << "x" << image.height << ")\n";
  return 0;
}

}  // namespace

App::App(platform::Window& window, bool interactive)
    : win_(window), interactive_(interactive), autosave_(interactive) {
  if (interactive_) LoadRecent();
}

void App::Frame(render::Image* capture) {
  win_.BeginFrame();
  const double now = win_.time();
  const double dt = std::clamp(now - last_time_, 0.0, 0.2);
  if (last_time_ > 0.0) {
    s_.frames.Add(now - last_time_, now);
    if (last_frame_fine_) fine_frame_s_ = now - last_time_;
  }
  last_time_ = now;
  for (const std::string& f : win_.TakeDroppedFiles()) {
    if (IsMeshFile(f)) {
      parts_.Import(s_, f);
    } else if (fs::path(f).extension() == ".json") {
      RequestOpen(f);
    } else if (fs::path(f).extension() == ".urdf") {
      robots_.AddUrdf(s_, f);
    } else {
      s_.Notify(
          "Dropped file not recognised (a mesh or STEP file, a robot .urdf or a project "
          ".json): " +
          f);
    }
  }
  TakeRun();
  TakeAuthoring(s_);
  s_.validation.Update(s_.doc.project(), s_.doc.revision(), s_.doc.ResolvePath(), now);
  if (s_.playback.playing && s_.plan) {
    s_.playback.t += dt * s_.playback.speed;
    const double d = s_.Duration();
    if (s_.playback.t > d) {
      s_.playback.t = s_.playback.loop ? 0.0 : d;
      if (!s_.playback.loop) s_.playback.playing = false;
    }
  }
  Shortcuts();
  const float W = static_cast<float>(win_.width()), H = static_cast<float>(win_.height());
  const float menu_h = MenuBar();
  const float status_h = ImGui::GetFrameHeight() + 4;
  const float body_h = H - menu_h - status_h;
  const float left_w = std::round(0.23f * W), right_w = std::round(0.27f * W);
  const float centre_w = W - left_w - right_w;
  const float top = menu_h;
  parts_.Draw(s_, {0, top, left_w, std::round(0.62f * body_h)});
  robots_.Draw(s_,
               {0, top + std::round(0.62f * body_h), left_w, body_h - std::round(0.62f * body_h)});
  const float view_h = std::round(0.66f * body_h);
  viewport_panel_.Draw(s_, {left_w, top, centre_w, view_h});
  BottomPanel({left_w, top + view_h, centre_w, body_h - view_h});
  const float g_h = std::round(0.40f * body_h), m_h = std::round(0.30f * body_h);
  graph_.Draw(s_, {left_w + centre_w, top, right_w, g_h});
  mating_.Draw(s_, {left_w + centre_w, top + g_h, right_w, m_h});
  planner_.Draw(s_, {left_w + centre_w, top + g_h + m_h, right_w, body_h - g_h - m_h});
  StatusBar({0, H - status_h, W, status_h});
  Popups();
  ImportAssemblyDialog();
  AuthoringWindows();
  UpdateViewport();
  ChooseQuality();
  UpdateTitle();
  if (autosave_) Autosave(now);

  // The cell under the panels: MuJoCo draws into the viewport's rectangle (GL: from below).
  const PanelRect vr = viewport_panel_.rect;
  win_.EndFrame(
      [&] {
        if (!s_.viewport.ready()) return;
        s_.viewport.Draw(static_cast<int>(vr.x), static_cast<int>(H - vr.y - vr.h),
                         static_cast<int>(vr.w), static_cast<int>(vr.h));
      },
      capture);
}

void App::Autosave(double now) {
  if (s_.doc.revision() != autosave_revision_) {
    autosave_revision_ = s_.doc.revision();
    last_edit_ = now;
  }
  const bool quiet = now - last_edit_ >= kAutosaveQuietS;
  if ((quiet || now - last_autosave_ > kAutosavePeriodS) &&
      autosave_failed_ != autosave_revision_) {
    last_autosave_ = now;
    if (auto wrote = s_.doc.WriteRecovery(); !wrote) {
      autosave_failed_ = autosave_revision_;  // not again until the next edit
      s_.Notify("Autosave failed: " + wrote.error().message);
    }
  }
}

/// The viewport's drawing quality for this frame. Auto: fine, unless something moves (the
/// planner runs, the plan plays, a mouse drag) and the last fine frame took longer than 1/20 s;
/// a still scene is drawn fine again.
void App::ChooseQuality() {
  bool fine = s_.quality != QualityMode::kFast;
  if (s_.quality == QualityMode::kAuto) {
    const bool moving = s_.job.running() || s_.playback.playing || ImGui::IsAnyItemActive();
    fine = !(moving && fine_frame_s_ > 1.0 / 20.0);
  }
  s_.viewport.set_quality(fine ? DrawQuality::kFine : DrawQuality::kFast);
  last_frame_fine_ = fine;
}

/// The interactive loop's pacing, so that the window leaves the CPU to the planner: while
/// nothing changes (no run, no playback, no drag, no edit waiting for the recovery file or the
/// live validation) it sleeps until the next input, after drawing a few frames past the last one
/// that changed (ImGui settles hover, focus and popups); while something moves it draws at most
/// 30 frames per second.
void App::Pace() {
  const bool moving = s_.job.running() || s_.playback.playing || ImGui::IsAnyItemActive() ||
                      s_.validation.pending() ||
                      (autosave_ && s_.doc.revision() != autosave_revision_) ||
                      (autosave_ && win_.time() - last_edit_ < kAutosaveQuietS + 0.1);
  if (moving) {
    settle_frames_ = 0;
    const double left = 1.0 / 30.0 - (win_.time() - last_time_);
    if (left > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(left));
    return;
  }
  // Input (or a resize) in this frame: a few more frames before sleeping.
  const ImGuiIO& io = ImGui::GetIO();
  bool input = io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f || io.MouseWheel != 0.0f ||
               io.MouseWheelH != 0.0f || io.InputQueueCharacters.Size > 0 ||
               ImGui::IsAnyMouseDown() || io.DisplaySize.x != last_size_.x ||
               io.DisplaySize.y != last_size_.y;
  for (bool down : io.KeysDown) input = input || down;
  last_size_ = io.DisplaySize;
  // A frame that drew other shapes than the one before (a popup opening after a click, a panel
  // filled by a finished check) is followed by more, for a while after the last input: the
  // window sleeps on a settled picture. The status bar (its frame rate) is left out.
  std::size_t shapes = 0;
  if (const ImDrawData* dd = ImGui::GetDrawData()) {
    shapes = static_cast<std::size_t>(dd->TotalVtxCount) * 31 +
             static_cast<std::size_t>(dd->TotalIdxCount) * 7 +
             static_cast<std::size_t>(dd->CmdListsCount);
    if (const ImGuiWindow* status = ImGui::FindWindowByName("##status")) {
      shapes -= static_cast<std::size_t>(status->DrawList->VtxBuffer.Size) * 31 +
                static_cast<std::size_t>(status->DrawList->IdxBuffer.Size) * 7;
    }
  }
  if (input) frames_since_input_ = 0;
  if (shapes != last_shapes_ && ++frames_since_input_ < 20) input = true;
  last_shapes_ = shapes;
  if (input) settle_frames_ = 0;
  if (++settle_frames_ < 3) return;
  win_.WaitEvents(10.0);     // and at least every 10 s (each wake draws a frame)
  last_time_ = win_.time();  // a wait is not a slow frame
}

void App::HandleCloseRequest() {
  if (!win_.close_requested()) return;
  if (s_.doc.dirty() && interactive_) {
    win_.set_close_requested(false);
    confirm_close_ = true;
  } else {
    quit_ = true;
  }
}

void App::TakeRun() {
  const unsigned long id = s_.job.run_id();
  if (id == taken_run_ || s_.job.running()) return;
  taken_run_ = id;
  const JobProgress prog = s_.job.progress();
  auto plan = s_.job.TakePlan();
  auto snapshot = s_.job.snapshot();
  if (plan) {
    s_.plan = std::move(plan);
    s_.plan_project = snapshot;
    s_.plan_origin = "planned";
    s_.playback = Playback{};
    plan_states_.clear();
    s_.Notify(std::string("Planner: ") + (s_.plan->stats.solved ? "solved" : "no plan") +
              ", cost " + std::to_string(s_.plan->stats.cost));
  }
  s_.showing_case = -1;
  s_.run_warnings = prog.warnings;
  if (prog.state == JobState::kSolved || prog.state == JobState::kCancelled) {
    s_.run_failure.reset();
    if (prog.state == JobState::kCancelled) s_.Notify("Planner: cancelled");
    return;
  }
  s_.run_failure = MakeRunFailure(prog, snapshot, s_.doc.ResolvePath());
  s_.focus_problems = true;
  s_.Notify("Planner: " + std::string(ToString(prog.state)) + " (see Problems)");
}

void App::BottomPanel(const PanelRect& r) {
  PlaceNextWindow(r);
  if (!ImGui::Begin("##bottom", nullptr,
                    ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoTitleBar)) {
    ImGui::End();
    return;
  }
  if (ImGui::BeginTabBar("bottom_tabs")) {
    if (ImGui::BeginTabItem("Plan")) {
      plan_.Contents(s_);
      ImGui::EndTabItem();
    }
    const std::string title = ProblemsPanel::Title(s_) + "###problems";
    const ImGuiTabItemFlags flags = s_.focus_problems ? ImGuiTabItemFlags_SetSelected : 0;
    s_.focus_problems = false;
    if (ImGui::BeginTabItem(title.c_str(), nullptr, flags)) {
      problems_.Contents(s_);
      ImGui::EndTabItem();
    }
    ImGui::EndTabBar();
  }
  ImGui::End();
}

void App::StatusBar(const PanelRect& r) {
  PlaceNextWindow(r);
  ImGui::Begin(
      "##status", nullptr,
      ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings);
  ImGui::Text("%s%s", s_.doc.dirty() ? "* unsaved  " : "",
              s_.doc.path().empty() ? "untitled" : s_.doc.path().string().c_str());
  ImGui::SameLine();
  // Frames drawn over the last second: while idle the window sleeps between inputs.
  const double fps = s_.frames.RecentFps(win_.time());
  if (fps < 2.0) {
    ImGui::TextDisabled("|  idle%s",
                        s_.viewport.quality() == DrawQuality::kFast ? ", fast drawing" : "");
  } else {
    ImGui::TextDisabled("|  %.0f fps%s", fps,
                        s_.viewport.quality() == DrawQuality::kFast ? ", fast drawing" : "");
  }
  // Problems: a click brings the Problems tab to the front.
  const ValidationResult v = s_.validation.result();
  const int errors = v.diagnostics.error_count();
  const int warnings = v.diagnostics.warning_count() + static_cast<int>(s_.run_warnings.size());
  if (errors + warnings > 0 || s_.run_failure) {
    ImGui::SameLine();
    ImGui::TextDisabled("|");
    ImGui::SameLine();
    const ImVec4 colour = errors > 0 || s_.run_failure ? ImVec4(1.0f, 0.45f, 0.4f, 1.0f)
                                                       : ImVec4(1.0f, 0.8f, 0.35f, 1.0f);
    ImGui::PushStyleColor(ImGuiCol_Text, colour);
    const std::string label = std::to_string(errors) + " error(s), " + std::to_string(warnings) +
                              " warning(s)" + (s_.run_failure ? ", no plan" : "");
    if (ImGui::SmallButton(label.c_str())) s_.focus_problems = true;
    ImGui::PopStyleColor();
  }
  // The latest message, cut to the room left; the recent ones on hover.
  if (!s_.messages.empty()) {
    ImGui::SameLine();
    ImGui::TextDisabled("|");
    ImGui::SameLine();
    const float room = ImGui::GetContentRegionAvail().x - 8.0f;
    std::string line = s_.messages.back();
    if (const auto nl = line.find('\n'); nl != std::string::npos)
      line = line.substr(0, nl) + " ...";
    while (line.size() > 4 && ImGui::CalcTextSize(line.c_str()).x > room) {
      line = line.substr(0, line.size() - 5) + "...";
    }
    ImGui::TextDisabled("%s", line.c_str());
    if (ImGui::IsItemHovered()) {
      ImGui::BeginTooltip();
      ImGui::PushTextWrapPos(ImGui::GetFontSize() * 50.0f);
      const size_t from = s_.messages.size() > 8 ? s_.messages.size() - 8 : 0;
      for (size_t i = from; i < s_.messages.size(); ++i) {
        ImGui::TextUnformatted(s_.messages[i].c_str());
      }
      ImGui::PopTextWrapPos();
      ImGui::EndTooltip();
    }
  }
  ImGui::End();
}

void App::UpdateTitle() {
  std::string title =
      "Wrap - " + (s_.doc.project().name.empty() ? std::string("untitled") : s_.doc.project().name);
  if (s_.doc.dirty()) title += " *";
  if (title != title_) {
    win_.SetTitle(title);
    title_ = title;
  }
}

namespace {

/// --screenshot (with --run-plan, --at): plans while frames draw, then saves the window.
int RunScreenshot(App& app, const GuiOptions& options, std::ostream& out, std::ostream& err) {
  AppState& s = app.state();
  int code = 0;
  if (options.run_plan) {
    PlannerRequest q;
    q.time_limit_s = s.doc.project().planner.time_limit_s;
    q.seed = s.doc.project().planner.seed;
    s.job.Start(s.doc.project(), s.doc.ResolvePath(), q);
    // Frames keep drawing while the worker plans (the window stays responsive).
    int frames = 0;
    const auto start = std::chrono::steady_clock::now();
    while (s.job.running()) {
      app.Frame(nullptr);
      ++frames;
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    app.TakeRun();
    const JobProgress prog = s.job.progress();
    out << "Planner " << ToString(prog.state) << " in " << seconds << " s; the window drew "
        << frames << " frames meanwhile (" << (seconds > 0 ? frames / seconds : 0.0)
        << " per second; median of the last " << s.frames.size() << ": " << s.frames.MedianFps()
        << " fps, drawing " << (s.viewport.quality() == DrawQuality::kFast ? "fast" : "fine")
        << ")\n";
    if (prog.state != JobState::kSolved) {
      // The same words as `wrap plan`, and each failed check on its own line, blocker first.
      err << "wrap: planner: " << ToString(prog.state) << "\n";
      if (s.run_failure) {
        err << s.run_failure->headline << "\n";
        if (s.run_failure->failure) {
          for (const FailureCase& c : s.run_failure->failure->cases) err << "  " << c.text << "\n";
        }
      }
      code = 1;
    }
  }
  if (options.at) s.playback.t = std::clamp(*options.at, 0.0, s.Duration());
  for (int i = 0; i < 3; ++i) app.Frame(nullptr);
  render::Image image;
  app.Frame(&image);
  const int written = WriteScreenshot(image, options.screenshot, out, err);
  return written != 0 ? written : code;
}

/// `measure`: frames drawn back to back (no pacing, no vsync: what one frame costs on this GL)
/// for `seconds`, orbiting the camera or playing the plan; prints the frame rate.
void Measure(App& app, const std::string& what, double seconds, std::ostream& out) {
  AppState& s = app.state();
  std::vector<double> frame_s;
  const auto t0 = std::chrono::steady_clock::now();
  auto last = t0;
  if (what == "play") s.playback.playing = true;
  bool fast = false;
  while (std::chrono::duration<double>(last - t0).count() < seconds) {
    if (what == "orbit") s.viewport.Orbit(0.004, 0.0);
    app.Frame(nullptr);
    fast = fast || s.viewport.quality() == DrawQuality::kFast;
    const auto now = std::chrono::steady_clock::now();
    frame_s.push_back(std::chrono::duration<double>(now - last).count());
    last = now;
  }
  if (what == "play") s.playback.playing = false;
  std::vector<double> sorted = frame_s;
  std::sort(sorted.begin(), sorted.end());
  const double total = std::chrono::duration<double>(last - t0).count();
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "measure %s: %zu frames in %.1f s: %.1f fps (median frame %.1f ms, 90th "
                "percentile %.1f ms; drawing %s%s)",
                what.c_str(), frame_s.size(), total, static_cast<double>(frame_s.size()) / total,
                1000.0 * sorted[sorted.size() / 2], 1000.0 * sorted[sorted.size() * 9 / 10],
                fast ? "fast" : "fine", s.job.running() ? ", planner running" : "");
  out << buf << "\n";
}

/// What the frame loop does for one script line after the line ran: New and Open, waits,
/// measurements, the checks of what the frame drew, screenshots. 0, or the exit code.
int AfterScriptLine(App& app, const ScriptLine& line, Result<ScriptEffect>& effect,
                    const GuiOptions& options, std::ostream& out, std::ostream& err) {
  AppState& s = app.state();
  if (effect && effect->new_document) app.NewDocument();
  if (effect && !effect->open.empty() && !app.Open(effect->open)) {
    effect = std::unexpected(
        Error{ErrorCode::kInvalidInput,
              "script line " + std::to_string(line.number) + ": " + s.messages.back()});
  }
  if (!effect) {
    err << options.script << ": " << effect.error().message << "\n";
    return 1;
  }
  if (effect->autosave) app.set_autosave(true);
  if (effect->wait_for_planner) {
    while (s.job.running()) app.Frame(nullptr);
    app.TakeRun();
  }
  if (effect->wait_for_authoring) {
    while (s.authoring.running()) {
      app.Frame(nullptr);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    if (!s.authoring_log.error.empty()) {
      err << options.script << ": script line " << line.number << ": " << s.authoring_log.title
          << ": " << s.authoring_log.error << "\n";
      return 1;
    }
    for (const std::string& l : s.authoring_log.lines) out << "  " << l << "\n";
  }
  if (effect->wait_for_validation) {
    // Frames draw while the worker checks (bounded: a check has no cancel point, but ends).
    while (s.validation.checked_revision() != s.doc.revision()) {
      s.validation.Update(s.doc.project(), s.doc.revision(), s.doc.ResolvePath(), 0.0, true);
      app.Frame(nullptr);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  if (!effect->measure.empty()) Measure(app, effect->measure, effect->measure_s, out);
  if (effect->sleep_s > 0) {
    const auto until =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(effect->sleep_s);
    while (std::chrono::steady_clock::now() < until) app.Frame(nullptr);
  }
  app.Frame(nullptr);
  if (effect->check) {
    // Checks that read what the frame drew (the canvas's marks, the viewport's state). Their
    // message names the line already ("script line N: ...").
    if (auto checked = effect->check(s); !checked) {
      err << options.script << ": " << checked.error().message << "\n";
      return 1;
    }
  }
  if (!effect->screenshot.empty()) {
    render::Image image;
    app.Frame(&image);
    if (WriteScreenshot(image, effect->screenshot, out, err) != 0) return 2;
  }
  return 0;
}

/// --script: one line per frame, then the optional --screenshot.
int RunScript(App& app, const std::vector<ScriptLine>& script, const fs::path& script_dir,
              const GuiOptions& options, std::ostream& out, std::ostream& err) {
  AppState& s = app.state();
  int code = 0;
  app.Frame(nullptr);
  for (const ScriptLine& line : script) {
    auto effect = RunScriptLine(s, line, script_dir);
    code = AfterScriptLine(app, line, effect, options, out, err);
    if (code != 0) break;
    out << "ok " << line.number << ":";
    for (const std::string& w : line.words) out << " " << w;
    out << std::endl;  // flushed: a watching process sees each line as it is done
  }
  if (!options.screenshot.empty()) {
    render::Image image;
    app.Frame(&image);
    if (const int c = WriteScreenshot(image, options.screenshot, out, err); c != 0) return c;
  }
  s.job.Cancel();
  return code;
}

}  // namespace

int RunGui(const GuiOptions& options, std::ostream& out, std::ostream& err) {
  // Read the script first: a bad script is bad input before any window opens.
  std::vector<ScriptLine> script;
  fs::path script_dir;
  if (!options.script.empty()) {
    auto text = ReadFile(options.script);
    if (!text) {
      err << options.script << ": " << text.error().message << "\n";
      return 2;
    }
    auto parsed = ParseScript(*text);
    if (!parsed) {
      err << options.script << ": " << parsed.error().message << "\n";
      return 2;
    }
    script = std::move(*parsed);
    script_dir = fs::absolute(options.script).parent_path();
  }
  const bool headless = !options.screenshot.empty() || !options.script.empty();
  platform::WindowOptions wo;
  wo.width = options.width;
  wo.height = options.height;
  wo.vsync = !headless;
  auto window = platform::Window::Create(wo);
  if (!window) {
    err << "wrap: " << window.error().message << "\n";
    return 2;
  }
  App app(**window, !headless);
  AppState& s = app.state();
  if (!options.project.empty() && !app.Open(options.project)) {
    err << s.messages.back() << "\n";
    return 2;
  }
  if (!options.screenshot.empty() && options.script.empty()) {
    return RunScreenshot(app, options, out, err);
  }
  if (!script.empty()) return RunScript(app, script, script_dir, options, out, err);
  while (!app.quit()) {
    app.Frame(nullptr);
    app.HandleCloseRequest();
    app.Pace();
  }
  s.job.Cancel();
  return 0;
}

}  // namespace wrap::gui
