// The script's checks (see script.h): the `expect-*` verbs that check what the next frame drew
// or the state it left (the Problems panel, the canvas's mark, the selection, the plan's
// staleness, a field's refusal, the undo label, the viewport), expect-plan and expect-refused.
#include <algorithm>

#include "gui/panels.h"
#include "gui/script_internal.h"

namespace wrap::gui::script_detail {

namespace fs = std::filesystem;

namespace {

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

/// `expect-problem TEXT...` / `expect-no-problem TEXT...`.
Check ProblemCheck(const ScriptLine& line) {
  const std::string text = Rest(line, 1);
  const bool want = line.words[0] == "expect-problem";
  return [line, text, want](const AppState& app) -> Result<void> {
    const std::vector<std::string> lines = ProblemLines(app);
    const bool found = std::any_of(lines.begin(), lines.end(), [&](const std::string& l) {
      return l.find(text) != std::string::npos;
    });
    if (found == want) return {};
    std::string shown;
    for (const std::string& l : lines) shown += "\n  " + l;
    return LineError(line, std::string(want ? "the Problems panel does not show '"
                                            : "the Problems panel shows '") +
                               text + "'; it shows:" + (shown.empty() ? " nothing" : shown));
  };
}

/// `expect-marked STEP|none`.
Check MarkedCheck(const ScriptLine& line) {
  const std::string step = line.words[1] == "none" ? "" : line.words[1];
  return [line, step](const AppState& app) -> Result<void> {
    if (app.canvas_marked == step) return {};
    return LineError(line, "the canvas marks '" + app.canvas_marked + "', not '" + step + "'");
  };
}

/// `expect-selected part|step|robot NAME`.
Check SelectedCheck(const ScriptLine& line) {
  const std::string kind = line.words[1], name = line.words[2];
  return [line, kind, name](const AppState& app) -> Result<void> {
    const std::string& got = kind == "part"   ? app.selection.part
                             : kind == "step" ? app.selection.step
                                              : app.selection.robot;
    if (got == name) return {};
    return LineError(line, "selected " + kind + " is '" + got + "', not '" + name + "'");
  };
}

/// `expect-plan-stale` / `expect-plan-current`.
Check PlanStaleCheck(const ScriptLine& line) {
  const bool stale = line.words[0] == "expect-plan-stale";
  return [line, stale](const AppState& app) -> Result<void> {
    if (!app.plan) return LineError(line, "no plan on show");
    if (app.PlanStale() == stale) return {};
    return LineError(line,
                     stale ? "the plan is shown as current" : "the plan is shown as out of date");
  };
}

/// `expect-field-error FIELD [TEXT...]`.
Check FieldErrorCheck(const ScriptLine& line) {
  const std::string key = line.words[1], text = Rest(line, 2);
  return [line, key, text](const AppState& app) -> Result<void> {
    auto it = app.field_errors.find(key);
    if (it == app.field_errors.end()) {
      return LineError(line, "no refusal shown at field '" + key + "'");
    }
    if (it->second.find(text) == std::string::npos) {
      return LineError(line, "field '" + key + "' shows '" + it->second + "', not '" + text + "'");
    }
    return {};
  };
}

/// `expect-undo TEXT...`.
Check UndoCheck(const ScriptLine& line) {
  const std::string text = Rest(line, 1);
  return [line, text](const AppState& app) -> Result<void> {
    if (app.doc.CanUndo() && app.doc.UndoLabel().find(text) != std::string::npos) return {};
    return LineError(line, "Edit > Undo reads '" + app.doc.UndoLabel() + "', not '" + text + "'");
  };
}

/// `expect-viewport cell|empty`.
Result<Check> ViewportCheck(const ScriptLine& line) {
  const bool cell = line.words[1] == "cell";
  if (!cell && line.words[1] != "empty") return LineError(line, "expect-viewport cell|empty");
  return Check([line, cell](const AppState& app) -> Result<void> {
    const bool drawn = app.viewport.ready() && (!app.viewport.scene().parts.empty() ||
                                                !app.viewport.scene().robots.empty());
    if (drawn == cell) return {};
    return LineError(line, cell ? "the viewport draws no cell" : "the viewport still draws a cell");
  });
}

/// The check of an `expect-*` line; an empty one for a verb it does not know.
Result<Check> ExpectCheck(const ScriptLine& line) {
  const std::string& cmd = line.words[0];
  if (cmd == "expect-problem" || cmd == "expect-no-problem") return ProblemCheck(line);
  if (cmd == "expect-marked") return MarkedCheck(line);
  if (cmd == "expect-selected") return SelectedCheck(line);
  if (cmd == "expect-plan-stale" || cmd == "expect-plan-current") return PlanStaleCheck(line);
  if (cmd == "expect-field-error") return FieldErrorCheck(line);
  if (cmd == "expect-undo") return UndoCheck(line);
  if (cmd == "expect-viewport") return ViewportCheck(line);
  return Check{};
}

}  // namespace

Result<ScriptEffect> ExpectVerb(AppState&, const ScriptLine& line, const fs::path&) {
  auto check = ExpectCheck(line);
  if (!check) return std::unexpected(check.error());
  ScriptEffect effect;
  effect.check = std::move(*check);
  return effect;
}

Result<ScriptEffect> ExpectPlanVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  if (!app.plan || !app.plan->stats.solved) {
    const JobProgress prog = app.job.progress();
    return LineError(line, "no solved plan (" + std::string(ToString(prog.state)) +
                               (prog.error.empty() ? "" : ": " + prog.error) + ")");
  }
  return ScriptEffect{};
}

Result<ScriptEffect> ExpectRefusedVerb(AppState& app, const ScriptLine& line,
                                       const fs::path& base) {
  const std::vector<std::string>& w = line.words;
  ScriptLine inner{line.number, std::vector<std::string>(w.begin() + 1, w.end())};
  if (!VerbArity(inner.words[0])) {
    return LineError(line, "unknown command '" + inner.words[0] + "'");
  }
  const Project before = app.doc.project();
  auto r = RunScriptLine(app, inner, base);
  if (r) return LineError(line, "'" + inner.words[0] + "' was not refused");
  if (!(app.doc.project() == before)) {
    return LineError(line, "a refused command changed the project");
  }
  app.Notify("Refused as expected: " + r.error().message);
  return ScriptEffect{};
}

}  // namespace wrap::gui::script_detail
