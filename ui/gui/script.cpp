#include "gui/script.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include "geometry/step_import.h"
#include "gui/commands.h"
#include "gui/fields.h"
#include "gui/panels.h"

namespace wrap::gui {

namespace fs = std::filesystem;

namespace {

// Command name -> (least, most) arguments.
const std::map<std::string, std::pair<int, int>>& Arity() {
  static const std::map<std::string, std::pair<int, int>> arity = [] {
    std::map<std::string, std::pair<int, int>> a = GeometryScriptArity();
    a.insert({{"select", {2, 2}},
                                                                   {"import", {1, 2}},
                                                                   {"add-step", {1, 1}},
                                                                   {"delete-step", {1, 1}},
                                                                   {"rename", {2, 2}},
                                                                   {"add-edge", {2, 2}},
                                                                   {"remove-edge", {2, 2}},
                                                                   {"add-robot", {2, 2}},
                                                                   {"remove-robot", {1, 1}},
                                                                   {"set", {2, 5}},
                                                                   {"undo", {0, 0}},
                                                                   {"redo", {0, 0}},
                                                                   {"option", {2, 2}},
                                                                   {"run", {0, 0}},
                                                                   {"wait", {0, 0}},
                                                                   {"expect-plan", {0, 0}},
                                                                   {"scrub", {1, 1}},
                                                                   {"play", {0, 0}},
                                                                   {"pause", {0, 0}},
                                                                   {"save", {0, 1}},
                                                                   {"screenshot", {1, 1}},
                                                                   {"expect-refused", {1, 6}},
                                                                   {"autosave", {0, 0}},
                                                                   {"sleep", {1, 1}},
                                                                   {"add-urdf", {2, 4}},
                                                                   {"view", {2, 2}},
                                                                   {"new", {0, 0}},
                                                                   {"open", {1, 1}},
                                                                   {"validate", {0, 0}},
                                                                   {"show", {1, 1}},
                                                                   {"jog", {3, 3}},
                                                                   {"measure", {2, 2}},
                                                                   {"expect-problem", {1, 64}},
                                                                   {"expect-no-problem", {1, 64}},
                                                                   {"expect-marked", {1, 1}},
                                                                   {"expect-selected", {2, 2}},
                                                                   {"expect-plan-stale", {0, 0}},
                                                                   {"expect-plan-current", {0, 0}},
                                                                   {"expect-field-error", {1, 64}},
                                                                   {"expect-undo", {1, 64}},
                                                                   {"expect-viewport", {1, 1}}});
    return a;
  }();
  return arity;
}

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

/// `set FIELD VALUE...`: the field path is KIND.NAME.FIELD (part, mating, robot) or
/// KIND.FIELD (table, planner).
Result<void> SetField(AppState& app, const ScriptLine& line) {
  const std::string& path = line.words[1];
  const auto dot1 = path.find('.');
  const auto dot2 = path.rfind('.');
  if (dot1 == std::string::npos) return LineError(line, "field '" + path + "' has no '.'");
  const std::string kind = path.substr(0, dot1);
  const std::string name = dot2 > dot1 ? path.substr(dot1 + 1, dot2 - dot1 - 1) : "";
  const std::string field = path.substr(dot2 + 1);
  const Project& p = app.doc.project();
  auto scalar = [&]() { return Number(line, line.words[2]); };
  constexpr double kDeg = std::numbers::pi / 180.0;
  auto unknown = [&]() { return LineError(line, "unknown field '" + path + "'"); };
  auto run = [&](const Command& c) -> Result<void> {
    if (auto done = app.doc.Execute(c); !done) return LineError(line, done.error().message);
    app.doc.CloseMerge();
    return {};
  };
  // The editors' ranges (fields.h): a value outside them is refused at the field, as typed.
  auto ranged = [&](std::string_view spec_kind, double v) -> Result<void> {
    const FieldSpec* spec = FindField(spec_kind, field);
    if (!spec) return {};
    const std::string key = name.empty() ? kind + "." + field : kind + "." + name + "." + field;
    const std::string why = RefusedValue(*spec, v);
    SetFieldError(app, key, why);
    if (!why.empty()) return LineError(line, why);
    return {};
  };

  if (kind == "part") {
    auto it =
        std::find_if(p.parts.begin(), p.parts.end(), [&](const Part& q) { return q.name == name; });
    if (it == p.parts.end()) return LineError(line, "there is no part '" + name + "'");
    Part part = *it;
    if (field == "mass_kg" || field == "density_kg_m3" || field == "scale") {
      auto v = scalar();
      if (!v) return std::unexpected(v.error());
      if (auto ok = ranged("part", *v); !ok) return ok;
      if (field == "mass_kg") part.mass_kg = *v;
      if (field == "density_kg_m3") part.density_kg_m3 = *v;
      if (field == "scale") part.scale = *v;
    } else if (field == "initial_xyz" || field == "initial_rpy_deg" || field == "color" ||
               field == "assembled_xyz" || field == "assembled_rpy_deg") {
      auto v = Vector(line, 2);
      if (!v) return std::unexpected(v.error());
      if (field == "initial_xyz") part.initial_pose.xyz = *v;
      if (field == "initial_rpy_deg") part.initial_pose.rpy = *v * kDeg;
      if (field == "assembled_xyz") part.assembled_pose.xyz = *v;
      if (field == "assembled_rpy_deg") part.assembled_pose.rpy = *v * kDeg;
      if (field == "color") part.color = {v->x(), v->y(), v->z(), 1.0};
    } else {
      return unknown();
    }
    return run(SetPart(name, part));
  }
  if (kind == "mating") {
    auto it =
        std::find_if(p.steps.begin(), p.steps.end(), [&](const Step& s) { return s.name == name; });
    if (it == p.steps.end()) return LineError(line, "there is no step '" + name + "'");
    Mating m = it->mating;
    if (field == "moved" || field == "base") {
      (field == "moved" ? m.moved : m.base) = line.words[2];
    } else if (field == "axis") {
      auto v = Vector(line, 2);
      if (!v) return std::unexpected(v.error());
      m.axis = *v;
    } else {
      auto v = scalar();
      if (!v) return std::unexpected(v.error());
      if (auto ok = ranged("mating", *v); !ok) return ok;
      if (field == "force_N")
        m.force_N = *v;
      else if (field == "torque_Nm")
        m.torque_Nm = *v;
      else if (field == "transverse_fraction")
        m.transverse_fraction = *v;
      else if (field == "offset_m")
        m.offset_m = *v;
      else if (field == "approach_m")
        m.approach_m = *v;
      else
        return unknown();
    }
    return run(SetMating(name, m));
  }
  if (kind == "robot") {
    auto it = std::find_if(p.robots.begin(), p.robots.end(),
                           [&](const Robot& q) { return q.name == name; });
    if (it == p.robots.end()) return LineError(line, "there is no robot '" + name + "'");
    Robot robot = *it;
    if (field == "end_effector") {
      robot.end_effector = line.words[2];
    } else if (field == "base_xyz" || field == "base_rpy_deg") {
      auto v = Vector(line, 2);
      if (!v) return std::unexpected(v.error());
      if (field == "base_xyz")
        robot.base_pose.xyz = *v;
      else
        robot.base_pose.rpy = *v * kDeg;
    } else {
      return unknown();
    }
    return run(SetRobot(name, robot));
  }
  if (kind == "table") {
    Table t = p.table;
    auto v = scalar();
    if (!v) return std::unexpected(v.error());
    if (auto ok = ranged("table", *v); !ok) return ok;
    if (field == "height")
      t.height = *v;
    else if (field == "friction")
      t.friction = *v;
    else
      return unknown();
    return run(SetTable(t));
  }
  if (kind == "planner") {
    PlannerDefaults d = p.planner;
    auto v = scalar();
    if (!v) return std::unexpected(v.error());
    if (field == "time_limit_s")
      d.time_limit_s = *v;
    else if (field == "seed")
      d.seed = static_cast<std::uint64_t>(*v);
    else if (field == "grasps")
      d.grasps = static_cast<int>(*v);
    else
      return unknown();
    return run(SetPlannerDefaults(d));
  }
  return unknown();
}

/// Words from `first` on, joined by single spaces.
std::string Rest(const ScriptLine& line, size_t first) {
  std::string out;
  for (size_t i = first; i < line.words.size(); ++i) out += (i > first ? " " : "") + line.words[i];
  return out;
}

/// Every line the Problems panel shows: the run's failure (its headline and each failed check)
/// and the validation's diagnostics ("step 's1' / mating.force_N: MESSAGE").
std::vector<std::string> ProblemLines(const AppState& app) {
  std::vector<std::string> lines;
  if (app.run_failure) {
    lines.push_back(app.run_failure->headline);
    if (app.run_failure->failure) {
      for (const FailureCase& c : app.run_failure->failure->cases) lines.push_back(c.text);
    }
  }
  for (const std::string& w : app.run_warnings) lines.push_back("warning " + w);
  const ValidationResult v = app.validation.result();
  const Project& checked = v.project ? *v.project : app.doc.project();
  for (const Diagnostic& d : v.diagnostics.items) {
    const EntityRef e = EntityOfPath(checked, d.path);
    lines.push_back(std::string(d.severity == Severity::kError ? "error " : "warning ") +
                    e.Label() + (e.field.empty() ? "" : " / " + e.field) + ": " + d.message);
  }
  return lines;
}

/// The checks of what a frame drew or the state it left (`expect-*`), or null for another command.
Result<std::function<Result<void>(const AppState&)>> ExpectCheck(const ScriptLine& line) {
  const std::vector<std::string>& w = line.words;
  const std::string& cmd = w[0];
  using Check = std::function<Result<void>(const AppState&)>;
  auto fail = [line](const std::string& message) { return LineError(line, message); };
  if (cmd == "expect-problem" || cmd == "expect-no-problem") {
    const std::string text = Rest(line, 1);
    const bool want = cmd == "expect-problem";
    return Check([text, want, fail](const AppState& app) -> Result<void> {
      const std::vector<std::string> lines = ProblemLines(app);
      const bool found = std::any_of(lines.begin(), lines.end(), [&](const std::string& l) {
        return l.find(text) != std::string::npos;
      });
      if (found == want) return {};
      std::string shown;
      for (const std::string& l : lines) shown += "\n  " + l;
      return fail(
          std::string(want ? "the Problems panel does not show '" : "the Problems panel shows '") +
          text + "'; it shows:" + (shown.empty() ? " nothing" : shown));
    });
  }
  if (cmd == "expect-marked") {
    const std::string step = w[1] == "none" ? "" : w[1];
    return Check([step, fail](const AppState& app) -> Result<void> {
      if (app.canvas_marked == step) return {};
      return fail("the canvas marks '" + app.canvas_marked + "', not '" + step + "'");
    });
  }
  if (cmd == "expect-selected") {
    const std::string kind = w[1], name = w[2];
    return Check([kind, name, fail](const AppState& app) -> Result<void> {
      const std::string& got = kind == "part"   ? app.selection.part
                               : kind == "step" ? app.selection.step
                                                : app.selection.robot;
      if (got == name) return {};
      return fail("selected " + kind + " is '" + got + "', not '" + name + "'");
    });
  }
  if (cmd == "expect-plan-stale" || cmd == "expect-plan-current") {
    const bool stale = cmd == "expect-plan-stale";
    return Check([stale, fail](const AppState& app) -> Result<void> {
      if (!app.plan) return fail("no plan on show");
      if (app.PlanStale() == stale) return {};
      return fail(stale ? "the plan is shown as current" : "the plan is shown as out of date");
    });
  }
  if (cmd == "expect-field-error") {
    const std::string key = w[1], text = Rest(line, 2);
    return Check([key, text, fail](const AppState& app) -> Result<void> {
      auto it = app.field_errors.find(key);
      if (it == app.field_errors.end()) return fail("no refusal shown at field '" + key + "'");
      if (it->second.find(text) == std::string::npos) {
        return fail("field '" + key + "' shows '" + it->second + "', not '" + text + "'");
      }
      return {};
    });
  }
  if (cmd == "expect-undo") {
    const std::string text = Rest(line, 1);
    return Check([text, fail](const AppState& app) -> Result<void> {
      if (app.doc.CanUndo() && app.doc.UndoLabel().find(text) != std::string::npos) return {};
      return fail("Edit > Undo reads '" + app.doc.UndoLabel() + "', not '" + text + "'");
    });
  }
  if (cmd == "expect-viewport") {
    const bool cell = w[1] == "cell";
    if (!cell && w[1] != "empty") return LineError(line, "expect-viewport cell|empty");
    return Check([cell, fail](const AppState& app) -> Result<void> {
      const bool drawn = app.viewport.ready() && (!app.viewport.scene().parts.empty() ||
                                                  !app.viewport.scene().robots.empty());
      if (drawn == cell) return {};
      return fail(cell ? "the viewport draws no cell" : "the viewport still draws a cell");
    });
  }
  return Check{};
}

}  // namespace

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
    auto it = Arity().find(line.words[0]);
    if (it == Arity().end()) return LineError(line, "unknown command '" + line.words[0] + "'");
    const int args = static_cast<int>(line.words.size()) - 1;
    if (args < it->second.first || args > it->second.second) {
      return LineError(line, "'" + line.words[0] + "' takes " + std::to_string(it->second.first) +
                                 (it->second.second != it->second.first
                                      ? " to " + std::to_string(it->second.second)
                                      : std::string()) +
                                 " argument(s), got " + std::to_string(args));
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

Result<ScriptEffect> RunScriptLine(AppState& app, const ScriptLine& line, const fs::path& base) {
  const std::vector<std::string>& w = line.words;
  const std::string& cmd = w[0];
  if (auto done = RunGeometryScriptLine(app, line, base)) return std::move(*done);
  ScriptEffect effect;
  auto run = [&](const Command& c) -> Result<ScriptEffect> {
    if (auto done = app.doc.Execute(c); !done) return LineError(line, done.error().message);
    return effect;
  };
  auto resolve = [&](const std::string& f) {
    return fs::path(f).is_absolute() ? fs::path(f) : base / f;
  };

  if (cmd == "select") {
    if (w[1] == "part")
      app.selection.part = w[2];
    else if (w[1] == "step")
      app.selection.step = w[2];
    else if (w[1] == "robot")
      app.selection.robot = w[2];
    else
      return LineError(line, "select part|step|robot NAME");
    return effect;
  }
  if (cmd == "import" && LooksLikeStep(resolve(w[1]))) {  // a STEP part or assembly: one edit
    auto parts = PrepareStepImport(app.doc.project(), app.doc.ResolvePath(), resolve(w[1]));
    if (!parts) return LineError(line, parts.error().message);
    app.selection.part = parts->front().name;
    return run(AddParts(std::move(*parts)));
  }
  if (cmd == "import") {
    PartImportOptions options;
    if (w.size() > 2) {
      auto unit = std::find_if(MeshUnits().begin(), MeshUnits().end(),
                               [&](const MeshUnit& u) { return w[2] == u.name; });
      if (unit == MeshUnits().end()) return LineError(line, "unit must be m, cm, mm or inch");
      options.scale = unit->scale;
    }
    auto part = PreparePartImport(app.doc.project(), app.doc.ResolvePath(), resolve(w[1]), options);
    if (!part) return LineError(line, part.error().message);
    app.selection.part = part->name;
    return run(AddPart(*part));
  }
  if (cmd == "add-urdf") {
    if (w.size() == 4) return LineError(line, "add-urdf URDF END_EFFECTOR [ROOT TIP]: both links");
    auto robot = PrepareUrdfRobot(app.doc.project(), app.doc.ResolvePath(), resolve(w[1]),
                                  w.size() > 3 ? w[3] : "", w.size() > 4 ? w[4] : "", w[2]);
    if (!robot) return LineError(line, robot.error().message);
    app.selection.robot = robot->name;
    return run(AddRobot(*robot));
  }
  if (cmd == "view") {
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
    return effect;
  }
  if (cmd == "add-step") return run(AddStep(w[1]));
  if (cmd == "delete-step") return run(RemoveStep(w[1]));
  if (cmd == "rename") return run(RenameNode(w[1], w[2]));
  if (cmd == "add-edge") return run(AddInput(w[2], w[1]));
  if (cmd == "remove-edge") return run(RemoveInput(w[2], w[1]));
  if (cmd == "add-robot") return run(AddRobot(w[1], w[2]));
  if (cmd == "remove-robot") return run(RemoveRobot(w[1]));
  if (cmd == "set") {
    if (auto done = SetField(app, line); !done) return std::unexpected(done.error());
    return effect;
  }
  if (cmd == "undo") {
    if (!app.doc.Undo()) return LineError(line, "nothing to undo");
    return effect;
  }
  if (cmd == "redo") {
    if (!app.doc.Redo()) return LineError(line, "nothing to redo");
    return effect;
  }
  if (cmd == "option") {
    PlannerRequest& q = app.request;
    const std::string& v = w[2];
    if (w[1] == "planner")
      q.planner = v;
    else if (w[1] == "wrench")
      q.wrench = v;
    else if (w[1] == "time_limit_s")
      q.time_limit_s = std::atof(v.c_str());
    else if (w[1] == "seed")
      q.seed = std::strtoull(v.c_str(), nullptr, 10);
    else if (w[1] == "budget")
      q.budget = std::atof(v.c_str());
    else if (w[1] == "task_only")
      q.task_only = v == "1" || v == "true";
    else if (w[1] == "grasps")
      q.grasps = std::atoi(v.c_str());
    else
      return LineError(line, "unknown planner option '" + w[1] + "'");
    return effect;
  }
  if (cmd == "run") {
    if (app.job.running()) return LineError(line, "the planner is already running");
    StartRun(app);
    return effect;
  }
  if (cmd == "wait") {
    effect.wait_for_planner = true;
    return effect;
  }
  if (cmd == "expect-plan") {
    if (!app.plan || !app.plan->stats.solved) {
      const JobProgress prog = app.job.progress();
      return LineError(line, "no solved plan (" + std::string(ToString(prog.state)) +
                                 (prog.error.empty() ? "" : ": " + prog.error) + ")");
    }
    return effect;
  }
  if (cmd == "scrub") {
    auto t = Number(line, w[1]);
    if (!t) return std::unexpected(t.error());
    app.playback.t = std::clamp(*t, 0.0, app.Duration());
    app.playback.playing = false;
    return effect;
  }
  if (cmd == "play" || cmd == "pause") {
    app.playback.playing = cmd == "play";
    return effect;
  }
  if (cmd == "save") {
    auto saved = w.size() > 1 ? app.doc.SaveAs(resolve(w[1])) : app.doc.Save();
    if (!saved) return LineError(line, saved.error().message);
    return effect;
  }
  if (cmd == "autosave") {
    effect.autosave = true;
    return effect;
  }
  if (cmd == "sleep") {
    auto seconds = Number(line, w[1]);
    if (!seconds) return std::unexpected(seconds.error());
    if (*seconds < 0 || *seconds > 3600) return LineError(line, "sleep wants 0 to 3600 seconds");
    effect.sleep_s = *seconds;
    return effect;
  }
  if (cmd == "screenshot") {
    effect.screenshot = resolve(w[1]);
    return effect;
  }
  if (cmd.starts_with("expect-") && cmd != "expect-refused" && cmd != "expect-plan") {
    auto check = ExpectCheck(line);
    if (!check) return std::unexpected(check.error());
    effect.check = std::move(*check);
    return effect;
  }
  if (cmd == "new") {
    effect.new_document = true;
    return effect;
  }
  if (cmd == "open") {
    effect.open = resolve(w[1]);
    return effect;
  }
  if (cmd == "validate") {
    effect.wait_for_validation = true;
    return effect;
  }
  if (cmd == "show") {
    if (w[1] == "off") {
      ShowFailureCase(app, -1);
      return effect;
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
    return effect;
  }
  if (cmd == "jog") {
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
      return effect;
    }
    return LineError(line, "there is no robot '" + w[1] + "'");
  }
  if (cmd == "measure") {
    if (w[1] != "idle" && w[1] != "orbit" && w[1] != "play") {
      return LineError(line, "measure idle|orbit|play SECONDS");
    }
    auto seconds = Number(line, w[2]);
    if (!seconds || *seconds <= 0 || *seconds > 600) {
      return LineError(line, "measure wants 0 to 600 seconds");
    }
    effect.measure = w[1];
    effect.measure_s = *seconds;
    return effect;
  }
  if (cmd == "expect-refused") {
    ScriptLine inner{line.number, std::vector<std::string>(w.begin() + 1, w.end())};
    auto it = Arity().find(inner.words[0]);
    if (it == Arity().end()) return LineError(line, "unknown command '" + inner.words[0] + "'");
    const Project before = app.doc.project();
    auto r = RunScriptLine(app, inner, base);
    if (r) return LineError(line, "'" + inner.words[0] + "' was not refused");
    if (!(app.doc.project() == before))
      return LineError(line, "a refused command changed the project");
    app.Notify("Refused as expected: " + r.error().message);
    return effect;
  }
  return LineError(line, "unknown command '" + cmd + "'");
}

}  // namespace wrap::gui
