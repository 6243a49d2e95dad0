// The script's geometry and authoring commands (see script.h): import-assembly, suggest-order,
// lay-out, use-free-direction, and the checks of what the geometry report and the authoring log
// say (expect-path, expect-free-direction, expect-touch, expect-no-touch, expect-count,
// expect-change).
#include <algorithm>
#include <cmath>

#include "gui/geometry_view.h"
#include "gui/panels.h"
#include "gui/script.h"
#include "gui/script_internal.h"
#include "mating/insertion.h"

namespace wrap::gui {

namespace fs = std::filesystem;

using script_detail::Check;
using script_detail::LineError;
using script_detail::Resolve;
using script_detail::Rest;
using script_detail::RunEdit;

namespace {

// The verdict of the validation on step `name` as the document has it now.
Result<StepVerdict> VerdictOf(const AppState& app, const ScriptLine& line,
                              const std::string& name) {
  const Step* step = FindStep(app.doc.project(), name);
  if (!step) return LineError(line, "there is no step '" + name + "'");
  // The result is copied into a holder that outlives the verdict's pointers.
  static thread_local ValidationResult held;
  held = app.validation.result();
  auto verdict = FindStepVerdict(held, *step);
  if (!verdict) {
    return LineError(
        line, "no geometry verdict for step '" + name + "' as it is now (run `validate` first)");
  }
  return *verdict;
}

Result<Check> GeometryCheck(const ScriptLine& line) {
  const std::vector<std::string>& w = line.words;
  const std::string& cmd = w[0];
  if (cmd == "expect-path") {
    if (w[2] != "free" && w[2] != "blocked") {
      return LineError(line, "expect-path STEP free|blocked");
    }
    const std::string step = w[1];
    const bool blocked = w[2] == "blocked";
    return Check([line, step, blocked](const AppState& app) -> Result<void> {
      auto v = VerdictOf(app, line, step);
      if (!v) return std::unexpected(v.error());
      if (v->geometry->blocked() == blocked) return {};
      return LineError(
          line, "step '" + step + "': " + PathVerdictText(*v, *FindStep(app.doc.project(), step)));
    });
  }
  if (cmd == "expect-free-direction") {
    auto direction = script_detail::Vector(line, 2);
    if (!direction) return std::unexpected(direction.error());
    const Vec3 d = *direction;
    if (!(d.norm() > 1e-9)) return LineError(line, "expect-free-direction STEP X Y Z: not zero");
    const std::string step = w[1];
    const Vec3 want = d.normalized();
    return Check([line, step, want](const AppState& app) -> Result<void> {
      auto v = VerdictOf(app, line, step);
      if (!v) return std::unexpected(v.error());
      std::string found;
      for (const Vec3& f : RankedFreeDirections(*v->geometry)) {
        if (f.normalized().dot(want) > std::cos(3.0 * M_PI / 180.0)) return {};
        found += " " + FormatDirection(f);
      }
      return LineError(line, "step '" + step + "' has no free direction " + FormatDirection(want) +
                                 "; free:" + (found.empty() ? " none" : found));
    });
  }
  if (cmd == "expect-touch" || cmd == "expect-no-touch") {
    const bool want = cmd == "expect-touch";
    const std::string a = w[1], b = w[2];
    return Check([line, a, b, want](const AppState& app) -> Result<void> {
      const ValidationResult v = app.validation.result();
      if (!v.geometry) return LineError(line, "no contact graph yet (run `validate` first)");
      if (PartsTouch(v, a, b) == want) return {};
      return LineError(line, "'" + a + "' and '" + b + (want ? "' do not touch" : "' touch"));
    });
  }
  if (cmd == "expect-count") {
    const std::string what = w[1];
    const long n = std::strtol(w[2].c_str(), nullptr, 10);
    if (what != "parts" && what != "steps" && what != "robots") {
      return LineError(line, "expect-count parts|steps|robots N");
    }
    return Check([line, what, n](const AppState& app) -> Result<void> {
      const Project& p = app.doc.project();
      const long got = static_cast<long>(what == "parts"   ? p.parts.size()
                                         : what == "steps" ? p.steps.size()
                                                           : p.robots.size());
      if (got == n) return {};
      return LineError(line, "the project has " + std::to_string(got) + " " + what + ", not " +
                                 std::to_string(n));
    });
  }
  if (cmd == "expect-change") {
    const std::string text = Rest(line, 1);
    return Check([line, text](const AppState& app) -> Result<void> {
      for (const std::string& l : app.authoring_log.lines) {
        if (l.find(text) != std::string::npos) return {};
      }
      std::string shown;
      for (const std::string& l : app.authoring_log.lines) shown += "\n  " + l;
      return LineError(line, "the last changes do not say '" + text +
                                 "'; they say:" + (shown.empty() ? " nothing" : shown));
    });
  }
  return Check{};
}

}  // namespace

const std::map<std::string, std::pair<int, int>>& GeometryScriptArity() {
  static const std::map<std::string, std::pair<int, int>> arity = {
      {"import-assembly", {2, 64}}, {"suggest-order", {0, 0}},
      {"lay-out", {0, 0}},          {"use-free-direction", {2, 2}},
      {"expect-path", {2, 2}},      {"expect-free-direction", {4, 4}},
      {"expect-touch", {2, 2}},     {"expect-no-touch", {2, 2}},
      {"expect-count", {2, 2}},     {"expect-change", {1, 64}}};
  return arity;
}

std::optional<Result<ScriptEffect>> RunGeometryScriptLine(AppState& app, const ScriptLine& line,
                                                          const fs::path& base) {
  const std::vector<std::string>& w = line.words;
  const std::string& cmd = w[0];
  if (!GeometryScriptArity().contains(cmd)) return std::nullopt;
  ScriptEffect effect;
  if (cmd == "import-assembly" || cmd == "suggest-order" || cmd == "lay-out") {
    std::vector<fs::path> meshes;
    LengthUnit unit = LengthUnit::kAuto;
    AuthoringKind kind =
        cmd == "suggest-order" ? AuthoringKind::kSuggestOrder : AuthoringKind::kLayOut;
    if (cmd == "import-assembly") {
      kind = AuthoringKind::kImportAssembly;
      auto u = ParseLengthUnit(w[1]);
      if (!u) return LineError(line, "import-assembly UNIT PATH...: UNIT is auto, mm, cm or m");
      unit = *u;
      for (size_t i = 2; i < w.size(); ++i) {
        meshes.push_back(Resolve(base, w[i]));
      }
    }
    if (!StartAuthoring(app, kind, meshes, unit)) {
      return LineError(line, "an authoring run is under way");
    }
    effect.wait_for_authoring = true;
    return effect;
  }
  if (cmd == "use-free-direction") {
    auto v = VerdictOf(app, line, w[1]);
    if (!v) return std::unexpected(v.error());
    const std::vector<Vec3> free = RankedFreeDirections(*v->geometry);
    const long n = std::strtol(w[2].c_str(), nullptr, 10);
    if (n < 1 || n > static_cast<long>(free.size())) {
      return LineError(
          line, "step '" + w[1] + "' shows " + std::to_string(free.size()) + " free direction(s)");
    }
    if (auto done = RunEdit(app, line, UseInsertionAxis(w[1], free[n - 1])); !done) return done;
    app.Notify("Step '" + w[1] + "': insertion axis set to " + FormatDirection(free[n - 1]));
    return effect;
  }
  auto check = GeometryCheck(line);
  if (!check) return std::unexpected(check.error());
  effect.check = std::move(*check);
  return effect;
}

}  // namespace wrap::gui
