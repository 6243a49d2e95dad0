// The scripted mode (see script.h): the table of verbs with the arguments each takes and its
// handler, ParseScript and RunScriptLine, and the verbs that drive the session rather than edit
// the document (view, planner options and runs, the timeline, files, the Problems panel's
// "Show", joint jogging and frame-rate measures). The edits are in script_edit.cpp, the checks in
// script_expect.cpp, the geometry and authoring verbs in script_authoring.cpp.
#include "gui/script.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include "gui/commands.h"
#include "gui/panels.h"
#include "gui/script_internal.h"

namespace wrap::gui {

namespace fs = std::filesystem;

namespace script_detail {

std::unexpected<Error> LineError(const ScriptLine& line, const std::string& message) {
  return Fail(ErrorCode::kInvalidInput,
              "script line " + std::to_string(line.number) + ": " + message);
}

Result<double> Number(const ScriptLine& line, const std::string& word) {
  char* end = nullptr;
  const double v = std::strtod(word.c_str(), &end);
  if (word.empty() || *end != '\0' || !std::isfinite(v)) {
    return LineError(line, "'" + word + "' is not a number");
  }
  return v;
}

Result<Vec3> Vector(const ScriptLine& line, size_t first) {
  if (line.words.size() != first + 3) return LineError(line, "expected three numbers");
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    auto x = Number(line, line.words[first + i]);
    if (!x) return std::unexpected(x.error());
    v[i] = *x;
  }
  return v;
}

std::string Rest(const ScriptLine& line, size_t first) {
  std::string out;
  for (size_t i = first; i < line.words.size(); ++i) out += (i > first ? " " : "") + line.words[i];
  return out;
}

fs::path Resolve(const fs::path& base, const std::string& file) {
  return fs::path(file).is_absolute() ? fs::path(file) : base / file;
}

Result<ScriptEffect> RunEdit(AppState& app, const ScriptLine& line, const Command& command) {
  if (auto done = app.doc.Execute(command); !done) return LineError(line, done.error().message);
  return ScriptEffect{};
}

namespace {

/// `view utilisation|assembled|contacts on|off`, `view quality auto|fine|fast`.
Result<ScriptEffect> ViewVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  const std::vector<std::string>& w = line.words;
  if (w[1] == "utilisation" && (w[2] == "on" || w[2] == "off")) {
    app.show_utilisation = w[2] == "on";
  } else if (w[1] == "quality" && w[2] == "auto") {
    app.quality = QualityMode::kAuto;
  } else if (w[1] == "quality" && w[2] == "fine") {
    app.quality = QualityMode::kFine;
  } else if (w[1] == "quality" && w[2] == "fast") {
    app.quality = QualityMode::kFast;
  } else if ((w[1] == "assembled" || w[1] == "contacts") && (w[2] == "on" || w[2] == "off")) {
    (w[1] == "assembled" ? app.show_assembled : app.show_contacts) = w[2] == "on";
  } else {
    return LineError(line,
                     "view utilisation|assembled|contacts on|off, or view quality "
                     "auto|fine|fast");
  }
  return ScriptEffect{};
}

/// The numeric options of `option NAME VALUE`, refused (naming the word) unless a positive number
/// (seed, grasps: whole numbers from 0; grasps 0: the project's).
Result<ScriptEffect> NumericOption(PlannerRequest& q, const ScriptLine& line) {
  const std::string& name = line.words[1];
  auto x = Number(line, line.words[2]);
  if (!x) return std::unexpected(x.error());
  const bool whole = *x == std::floor(*x) && *x < 1e15;
  if (name == "seed" && whole && *x >= 0) {
    q.seed = static_cast<uint64_t>(*x);
  } else if (name == "grasps" && whole && *x >= 0) {
    q.grasps = static_cast<int>(std::min(*x, 1e6));
  } else if ((name == "time_limit_s" || name == "budget") && *x > 0) {
    (name == "budget" ? q.budget : q.time_limit_s) = *x;
  } else {
    return LineError(line, "option " + name + ": '" + line.words[2] + "' is out of range");
  }
  return ScriptEffect{};
}

/// `option NAME VALUE`: the Planner panel's options for the next run.
Result<ScriptEffect> OptionVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  const std::vector<std::string>& w = line.words;
  PlannerRequest& q = app.request;
  const std::string& v = w[2];
  if (w[1] == "planner")
    q.planner = v;
  else if (w[1] == "wrench")
    q.wrench = v;
  else if (w[1] == "objective" && (v == "actions" || v == "makespan"))
    q.objective = v;
  else if (w[1] == "task_only" && (v == "0" || v == "1" || v == "true" || v == "false"))
    q.task_only = v == "1" || v == "true";
  else if (w[1] == "time_limit_s" || w[1] == "budget" || w[1] == "seed" || w[1] == "grasps")
    return NumericOption(q, line);
  else
    return LineError(line, "unknown planner option '" + w[1] + "' or value '" + v + "'");
  return ScriptEffect{};
}

/// `run`: starts the planner on the document.
Result<ScriptEffect> RunVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  if (app.job.running()) return LineError(line, "the planner is already running");
  StartRun(app);
  return ScriptEffect{};
}

/// `wait`: holds the script until the planner ends.
Result<ScriptEffect> WaitVerb(AppState&, const ScriptLine&, const fs::path&) {
  ScriptEffect effect;
  effect.wait_for_planner = true;
  return effect;
}

/// `scrub T`: the timeline's time, clamped to the plan, paused.
Result<ScriptEffect> ScrubVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  auto t = Number(line, line.words[1]);
  if (!t) return std::unexpected(t.error());
  app.playback.t = std::clamp(*t, 0.0, app.Duration());
  app.playback.playing = false;
  return ScriptEffect{};
}

/// `play` / `pause`.
Result<ScriptEffect> PlayVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  app.playback.playing = line.words[0] == "play";
  return ScriptEffect{};
}

/// `save [FILE]`: File > Save, or Save as FILE.
Result<ScriptEffect> SaveVerb(AppState& app, const ScriptLine& line, const fs::path& base) {
  const std::vector<std::string>& w = line.words;
  auto saved = w.size() > 1 ? app.doc.SaveAs(Resolve(base, w[1])) : app.doc.Save();
  if (!saved) return LineError(line, saved.error().message);
  return ScriptEffect{};
}

/// `autosave`: turns the recovery autosave on.
Result<ScriptEffect> AutosaveVerb(AppState&, const ScriptLine&, const fs::path&) {
  ScriptEffect effect;
  effect.autosave = true;
  return effect;
}

/// `sleep SECONDS`: keeps drawing frames.
Result<ScriptEffect> SleepVerb(AppState&, const ScriptLine& line, const fs::path&) {
  auto seconds = Number(line, line.words[1]);
  if (!seconds) return std::unexpected(seconds.error());
  if (*seconds < 0 || *seconds > 3600) return LineError(line, "sleep wants 0 to 3600 seconds");
  ScriptEffect effect;
  effect.sleep_s = *seconds;
  return effect;
}

/// `screenshot FILE`: the window, saved at the next frame.
Result<ScriptEffect> ScreenshotVerb(AppState&, const ScriptLine& line, const fs::path& base) {
  ScriptEffect effect;
  effect.screenshot = Resolve(base, line.words[1]);
  return effect;
}

/// `new`: File > New.
Result<ScriptEffect> NewVerb(AppState&, const ScriptLine&, const fs::path&) {
  ScriptEffect effect;
  effect.new_document = true;
  return effect;
}

/// `open FILE`: File > Open.
Result<ScriptEffect> OpenVerb(AppState&, const ScriptLine& line, const fs::path& base) {
  ScriptEffect effect;
  effect.open = Resolve(base, line.words[1]);
  return effect;
}

/// `validate`: holds the script until the live validation is current.
Result<ScriptEffect> ValidateVerb(AppState&, const ScriptLine&, const fs::path&) {
  ScriptEffect effect;
  effect.wait_for_validation = true;
  return effect;
}

/// `show N` / `show off`: the Problems panel's "Show" of failed check N, or back to the cell.
Result<ScriptEffect> ShowVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  const std::vector<std::string>& w = line.words;
  if (w[1] == "off") {
    ShowFailureCase(app, -1);
    return ScriptEffect{};
  }
  auto n = Number(line, w[1]);
  if (!n) return std::unexpected(n.error());
  const int count = app.run_failure && app.run_failure->failure
                        ? static_cast<int>(app.run_failure->failure->cases.size())
                        : 0;
  if (*n < 1 || *n > count) {
    return LineError(
        line, "show N: the last run has " + std::to_string(count) + " failed check(s) to show");
  }
  ShowFailureCase(app, static_cast<int>(*n) - 1);
  return ScriptEffect{};
}

/// `jog ROBOT JOINT DEG`: a robot's joint slider (joint from 1).
Result<ScriptEffect> JogVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  const std::vector<std::string>& w = line.words;
  auto joint = Number(line, w[2]);
  auto deg = Number(line, w[3]);
  if (!joint || !deg) return LineError(line, "jog ROBOT JOINT DEG: numbers expected");
  if (!app.viewport.ready()) return LineError(line, "jog: no cell drawn");
  for (const SceneRobot& r : app.viewport.scene().robots) {
    if (r.name != w[1]) continue;
    const int j = static_cast<int>(*joint) - 1;
    if (j < 0 || j >= static_cast<int>(r.home.size())) {
      return LineError(line,
                       "robot '" + w[1] + "' has joints 1 to " + std::to_string(r.home.size()));
    }
    JointVector q = app.jog.count(w[1]) ? app.jog[w[1]] : r.home;
    q[j] = *deg * std::numbers::pi / 180.0;
    app.jog[w[1]] = q;
    return ScriptEffect{};
  }
  return LineError(line, "there is no robot '" + w[1] + "'");
}

/// `measure idle|orbit|play SECONDS`: the frame rate over that long.
Result<ScriptEffect> MeasureVerb(AppState&, const ScriptLine& line, const fs::path&) {
  const std::vector<std::string>& w = line.words;
  if (w[1] != "idle" && w[1] != "orbit" && w[1] != "play") {
    return LineError(line, "measure idle|orbit|play SECONDS");
  }
  auto seconds = Number(line, w[2]);
  if (!seconds || *seconds <= 0 || *seconds > 600) {
    return LineError(line, "measure wants 0 to 600 seconds");
  }
  ScriptEffect effect;
  effect.measure = w[1];
  effect.measure_s = *seconds;
  return effect;
}

/// A verb: the arguments it takes (least, most) and what it does.
struct Verb {
  int least = 0;
  int most = 0;
  VerbHandler run = nullptr;
};

/// Every verb but the geometry and authoring ones (GeometryScriptArity).
const std::map<std::string, Verb>& Verbs() {
  static const std::map<std::string, Verb> verbs = {
      // The document's edits (script_edit.cpp).
      {"select", {2, 2, SelectVerb}},
      {"import", {1, 2, ImportVerb}},
      {"add-urdf", {2, 4, AddUrdfVerb}},
      {"add-step", {1, 1, AddStepVerb}},
      {"delete-step", {1, 1, DeleteStepVerb}},
      {"rename", {2, 2, RenameVerb}},
      {"add-edge", {2, 2, AddEdgeVerb}},
      {"remove-edge", {2, 2, RemoveEdgeVerb}},
      {"add-robot", {2, 2, AddRobotVerb}},
      {"remove-robot", {1, 1, RemoveRobotVerb}},
      {"set", {2, 5, SetVerb}},
      {"undo", {0, 0, UndoVerb}},
      {"redo", {0, 0, RedoVerb}},
      // The session: view, planner, timeline, files, the Problems panel, the viewport.
      {"view", {2, 2, ViewVerb}},
      {"option", {2, 2, OptionVerb}},
      {"run", {0, 0, RunVerb}},
      {"wait", {0, 0, WaitVerb}},
      {"scrub", {1, 1, ScrubVerb}},
      {"play", {0, 0, PlayVerb}},
      {"pause", {0, 0, PlayVerb}},
      {"save", {0, 1, SaveVerb}},
      {"autosave", {0, 0, AutosaveVerb}},
      {"sleep", {1, 1, SleepVerb}},
      {"screenshot", {1, 1, ScreenshotVerb}},
      {"new", {0, 0, NewVerb}},
      {"open", {1, 1, OpenVerb}},
      {"validate", {0, 0, ValidateVerb}},
      {"show", {1, 1, ShowVerb}},
      {"jog", {3, 3, JogVerb}},
      {"measure", {2, 2, MeasureVerb}},
      // The checks (script_expect.cpp).
      {"expect-plan", {0, 0, ExpectPlanVerb}},
      {"expect-refused", {1, 6, ExpectRefusedVerb}},
      {"expect-problem", {1, 64, ExpectVerb}},
      {"expect-no-problem", {1, 64, ExpectVerb}},
      {"expect-marked", {1, 1, ExpectVerb}},
      {"expect-selected", {2, 2, ExpectVerb}},
      {"expect-plan-stale", {0, 0, ExpectVerb}},
      {"expect-plan-current", {0, 0, ExpectVerb}},
      {"expect-field-error", {1, 64, ExpectVerb}},
      {"expect-undo", {1, 64, ExpectVerb}},
      {"expect-viewport", {1, 1, ExpectVerb}}};
  return verbs;
}

}  // namespace

std::optional<std::pair<int, int>> VerbArity(const std::string& verb) {
  if (auto it = Verbs().find(verb); it != Verbs().end()) {
    return std::pair{it->second.least, it->second.most};
  }
  if (auto it = GeometryScriptArity().find(verb); it != GeometryScriptArity().end()) {
    return it->second;
  }
  return std::nullopt;
}

}  // namespace script_detail

using script_detail::LineError;

Result<std::vector<ScriptLine>> ParseScript(const std::string& text) {
  std::vector<ScriptLine> lines;
  std::istringstream in(text);
  std::string raw;
  int number = 0;
  while (std::getline(in, raw)) {
    ++number;
    if (auto hash = raw.find('#'); hash != std::string::npos) raw.resize(hash);
    ScriptLine line{number, {}};
    std::istringstream words(raw);
    for (std::string w; words >> w;) line.words.push_back(w);
    if (line.words.empty()) continue;
    const auto arity = script_detail::VerbArity(line.words[0]);
    if (!arity) return LineError(line, "unknown command '" + line.words[0] + "'");
    const int args = static_cast<int>(line.words.size()) - 1;
    if (args < arity->first || args > arity->second) {
      return LineError(line,
                       "'" + line.words[0] + "' takes " + std::to_string(arity->first) +
                           (arity->second != arity->first ? " to " + std::to_string(arity->second)
                                                          : std::string()) +
                           " argument(s), got " + std::to_string(args));
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

Result<ScriptEffect> RunScriptLine(AppState& app, const ScriptLine& line, const fs::path& base) {
  const std::string& cmd = line.words[0];
  if (auto done = RunGeometryScriptLine(app, line, base)) return std::move(*done);
  if (auto it = script_detail::Verbs().find(cmd); it != script_detail::Verbs().end()) {
    return it->second.run(app, line, base);
  }
  // An expect-* verb ParseScript does not know checks nothing (as it always has).
  if (cmd.starts_with("expect-")) return script_detail::ExpectVerb(app, line, base);
  return LineError(line, "unknown command '" + cmd + "'");
}

}  // namespace wrap::gui
