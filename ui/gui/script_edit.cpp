// The script's verbs that edit the document (see script.h): select, import, add-urdf, add-step,
// delete-step, rename, add-edge, remove-edge, add-robot, remove-robot, set, undo and redo. Each
// edit goes through the same commands (and, for `set`, the same field ranges) as the panels.
#include <algorithm>
#include <numbers>
#include <string_view>

#include "geometry/step_import.h"
#include "gui/commands.h"
#include "gui/fields.h"
#include "gui/panels.h"
#include "gui/script_internal.h"

namespace wrap::gui::script_detail {

namespace fs = std::filesystem;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// `set FIELD VALUE...`: the line with its field path split into KIND.NAME.FIELD (part, mating,
/// robot) or KIND.FIELD (table, planner), and what every kind of field does with it.
struct SetLine {
  AppState& app;
  const ScriptLine& line;
  std::string path;   ///< As written, e.g. "part.seat.mass_kg".
  std::string kind;   ///< "part", "mating", "robot", "table" or "planner".
  std::string name;   ///< The part, step or robot; "" for table and planner.
  std::string field;  ///< e.g. "mass_kg".

  /// The value as one number.
  Result<double> Scalar() const { return Number(line, line.words[2]); }
  std::unexpected<Error> Unknown() const { return LineError(line, "unknown field '" + path + "'"); }
  /// Runs the edit, closed so that the next `set` is its own undo step.
  Result<void> Run(const Command& c) const {
    if (auto done = app.doc.Execute(c); !done) return LineError(line, done.error().message);
    app.doc.CloseMerge();
    return {};
  }
  /// The editors' ranges (fields.h): a value outside them is refused at the field, as typed.
  Result<void> Ranged(std::string_view spec_kind, double v) const {
    const FieldSpec* spec = FindField(spec_kind, field);
    if (!spec) return {};
    const std::string key = name.empty() ? kind + "." + field : kind + "." + name + "." + field;
    const std::string why = RefusedValue(*spec, v);
    SetFieldError(app, key, why);
    if (!why.empty()) return LineError(line, why);
    return {};
  }
};

/// part.NAME.{mass_kg, density_kg_m3, scale, initial_xyz, initial_rpy_deg, assembled_xyz,
/// assembled_rpy_deg, color}.
Result<void> SetPartField(const SetLine& s) {
  const Project& p = s.app.doc.project();
  auto it =
      std::find_if(p.parts.begin(), p.parts.end(), [&](const Part& q) { return q.name == s.name; });
  if (it == p.parts.end()) return LineError(s.line, "there is no part '" + s.name + "'");
  Part part = *it;
  const std::string& field = s.field;
  if (field == "mass_kg" || field == "density_kg_m3" || field == "scale") {
    auto v = s.Scalar();
    if (!v) return std::unexpected(v.error());
    if (auto ok = s.Ranged("part", *v); !ok) return ok;
    if (field == "mass_kg") part.mass_kg = *v;
    if (field == "density_kg_m3") part.density_kg_m3 = *v;
    if (field == "scale") part.scale = *v;
  } else if (field == "initial_xyz" || field == "initial_rpy_deg" || field == "color" ||
             field == "assembled_xyz" || field == "assembled_rpy_deg") {
    auto v = Vector(s.line, 2);
    if (!v) return std::unexpected(v.error());
    if (field == "initial_xyz") part.initial_pose.xyz = *v;
    if (field == "initial_rpy_deg") part.initial_pose.rpy = *v * kDeg;
    if (field == "assembled_xyz") part.assembled_pose.xyz = *v;
    if (field == "assembled_rpy_deg") part.assembled_pose.rpy = *v * kDeg;
    if (field == "color") part.color = {v->x(), v->y(), v->z(), 1.0};
  } else {
    return s.Unknown();
  }
  return s.Run(SetPart(s.name, part));
}

/// mating.STEP.{moved, base, axis, force_N, torque_Nm, transverse_fraction, offset_m,
/// approach_m}.
Result<void> SetMatingField(const SetLine& s) {
  const Project& p = s.app.doc.project();
  auto it =
      std::find_if(p.steps.begin(), p.steps.end(), [&](const Step& q) { return q.name == s.name; });
  if (it == p.steps.end()) return LineError(s.line, "there is no step '" + s.name + "'");
  Mating m = it->mating;
  const std::string& field = s.field;
  if (field == "moved" || field == "base") {
    (field == "moved" ? m.moved : m.base) = s.line.words[2];
  } else if (field == "axis") {
    auto v = Vector(s.line, 2);
    if (!v) return std::unexpected(v.error());
    m.axis = *v;
  } else {
    auto v = s.Scalar();
    if (!v) return std::unexpected(v.error());
    if (auto ok = s.Ranged("mating", *v); !ok) return ok;
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
      return s.Unknown();
  }
  return s.Run(SetMating(s.name, m));
}

/// robot.NAME.{end_effector, base_xyz, base_rpy_deg}.
Result<void> SetRobotField(const SetLine& s) {
  const Project& p = s.app.doc.project();
  auto it = std::find_if(p.robots.begin(), p.robots.end(),
                         [&](const Robot& q) { return q.name == s.name; });
  if (it == p.robots.end()) return LineError(s.line, "there is no robot '" + s.name + "'");
  Robot robot = *it;
  if (s.field == "end_effector") {
    robot.end_effector = s.line.words[2];
  } else if (s.field == "base_xyz" || s.field == "base_rpy_deg") {
    auto v = Vector(s.line, 2);
    if (!v) return std::unexpected(v.error());
    if (s.field == "base_xyz")
      robot.base_pose.xyz = *v;
    else
      robot.base_pose.rpy = *v * kDeg;
  } else {
    return s.Unknown();
  }
  return s.Run(SetRobot(s.name, robot));
}

/// table.{height, friction}.
Result<void> SetTableField(const SetLine& s) {
  Table t = s.app.doc.project().table;
  auto v = s.Scalar();
  if (!v) return std::unexpected(v.error());
  if (auto ok = s.Ranged("table", *v); !ok) return ok;
  if (s.field == "height")
    t.height = *v;
  else if (s.field == "friction")
    t.friction = *v;
  else
    return s.Unknown();
  return s.Run(SetTable(t));
}

/// planner.{time_limit_s, seed, grasps}: the project's planner defaults.
Result<void> SetPlannerField(const SetLine& s) {
  PlannerDefaults d = s.app.doc.project().planner;
  auto v = s.Scalar();
  if (!v) return std::unexpected(v.error());
  if (s.field == "time_limit_s")
    d.time_limit_s = *v;
  else if (s.field == "seed")
    d.seed = static_cast<std::uint64_t>(*v);
  else if (s.field == "grasps")
    d.grasps = static_cast<int>(*v);
  else
    return s.Unknown();
  return s.Run(SetPlannerDefaults(d));
}

/// `set FIELD VALUE...`: the field path is KIND.NAME.FIELD (part, mating, robot) or
/// KIND.FIELD (table, planner).
Result<void> SetField(AppState& app, const ScriptLine& line) {
  const std::string& path = line.words[1];
  const auto dot1 = path.find('.');
  const auto dot2 = path.rfind('.');
  if (dot1 == std::string::npos) return LineError(line, "field '" + path + "' has no '.'");
  const SetLine s{app,
                  line,
                  path,
                  path.substr(0, dot1),
                  dot2 > dot1 ? path.substr(dot1 + 1, dot2 - dot1 - 1) : "",
                  path.substr(dot2 + 1)};
  if (s.kind == "part") return SetPartField(s);
  if (s.kind == "mating") return SetMatingField(s);
  if (s.kind == "robot") return SetRobotField(s);
  if (s.kind == "table") return SetTableField(s);
  if (s.kind == "planner") return SetPlannerField(s);
  return s.Unknown();
}

/// `import FILE.step`: a STEP part or assembly, in one edit.
Result<ScriptEffect> ImportStep(AppState& app, const ScriptLine& line, const fs::path& file) {
  auto parts = PrepareStepImport(app.doc.project(), app.doc.ResolvePath(), file);
  if (!parts) return LineError(line, parts.error().message);
  app.selection.part = parts->front().name;
  return RunEdit(app, line, AddParts(std::move(*parts)));
}

/// `import MESH [UNIT]`: a mesh as one part.
Result<ScriptEffect> ImportMesh(AppState& app, const ScriptLine& line, const fs::path& file) {
  const std::vector<std::string>& w = line.words;
  PartImportOptions options;
  if (w.size() > 2) {
    auto unit = std::find_if(MeshUnits().begin(), MeshUnits().end(),
                             [&](const MeshUnit& u) { return w[2] == u.name; });
    if (unit == MeshUnits().end()) return LineError(line, "unit must be m, cm, mm or inch");
    options.scale = unit->scale;
  }
  auto part = PreparePartImport(app.doc.project(), app.doc.ResolvePath(), file, options);
  if (!part) return LineError(line, part.error().message);
  app.selection.part = part->name;
  return RunEdit(app, line, AddPart(*part));
}

}  // namespace

Result<ScriptEffect> SelectVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  const std::vector<std::string>& w = line.words;
  if (w[1] == "part")
    app.selection.part = w[2];
  else if (w[1] == "step")
    app.selection.step = w[2];
  else if (w[1] == "robot")
    app.selection.robot = w[2];
  else
    return LineError(line, "select part|step|robot NAME");
  return ScriptEffect{};
}

Result<ScriptEffect> ImportVerb(AppState& app, const ScriptLine& line, const fs::path& base) {
  const fs::path file = Resolve(base, line.words[1]);
  if (LooksLikeStep(file)) return ImportStep(app, line, file);
  return ImportMesh(app, line, file);
}

Result<ScriptEffect> AddUrdfVerb(AppState& app, const ScriptLine& line, const fs::path& base) {
  const std::vector<std::string>& w = line.words;
  if (w.size() == 4) return LineError(line, "add-urdf URDF END_EFFECTOR [ROOT TIP]: both links");
  auto robot = PrepareUrdfRobot(app.doc.project(), app.doc.ResolvePath(), Resolve(base, w[1]),
                                w.size() > 3 ? w[3] : "", w.size() > 4 ? w[4] : "", w[2]);
  if (!robot) return LineError(line, robot.error().message);
  app.selection.robot = robot->name;
  return RunEdit(app, line, AddRobot(*robot));
}

Result<ScriptEffect> AddStepVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  return RunEdit(app, line, AddStep(line.words[1]));
}

Result<ScriptEffect> DeleteStepVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  return RunEdit(app, line, RemoveStep(line.words[1]));
}

Result<ScriptEffect> RenameVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  return RunEdit(app, line, RenameNode(line.words[1], line.words[2]));
}

Result<ScriptEffect> AddEdgeVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  return RunEdit(app, line, AddInput(line.words[2], line.words[1]));
}

Result<ScriptEffect> RemoveEdgeVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  return RunEdit(app, line, RemoveInput(line.words[2], line.words[1]));
}

Result<ScriptEffect> AddRobotVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  return RunEdit(app, line, AddRobot(line.words[1], line.words[2]));
}

Result<ScriptEffect> RemoveRobotVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  return RunEdit(app, line, RemoveRobot(line.words[1]));
}

Result<ScriptEffect> SetVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  if (auto done = SetField(app, line); !done) return std::unexpected(done.error());
  return ScriptEffect{};
}

Result<ScriptEffect> UndoVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  if (!app.doc.Undo()) return LineError(line, "nothing to undo");
  return ScriptEffect{};
}

Result<ScriptEffect> RedoVerb(AppState& app, const ScriptLine& line, const fs::path&) {
  if (!app.doc.Redo()) return LineError(line, "nothing to redo");
  return ScriptEffect{};
}

}  // namespace wrap::gui::script_detail
