// The editors: parts (with import and a small file browser), the mating of the selected step,
// robots with their wrench-limit tables.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "geometry/step_import.h"
#include "gui/commands.h"
#include "gui/fields.h"
#include "gui/panels.h"
#include "model/catalog.h"
#include "robot/kinematics.h"

namespace wrap::gui {

namespace fs = std::filesystem;

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

/// Drag fields for a 3-vector; true when changed.
bool EditVec3(const char* label, Vec3& v, float speed, const char* format) {
  double a[3] = {v.x(), v.y(), v.z()};
  const bool changed =
      ImGui::DragScalarN(label, ImGuiDataType_Double, a, 3, speed, nullptr, nullptr, format);
  if (changed) v = Vec3(a[0], a[1], a[2]);
  return changed;
}

/// A pose as xyz [m] and roll-pitch-yaw [deg]; true when changed.
bool EditPose(const char* id, Pose& pose) {
  ImGui::PushID(id);
  bool changed = EditVec3("xyz [m]", pose.xyz, 0.001f, "%.3f");
  Vec3 deg = pose.rpy * kDeg;
  if (EditVec3("rpy [deg]", deg, 0.5f, "%.1f")) {
    pose.rpy = deg / kDeg;
    changed = true;
  }
  ImGui::PopID();
  return changed;
}

/// A wrench box (force and torque limits per axis) with its fields' ranges and tooltips;
/// `kind` "limits" (a gripper's) or "connection" (a mating's T_pq); `key` names it for refusals.
bool EditBox(AppState& app, const char* id, const std::string& key, WrenchBox& box,
             bool connection) {
  ImGui::PushID(id);
  const FieldSpec& force =
      connection ? *FindField("mating", "connection_force_N") : *FindField("limits", "force_N");
  const FieldSpec& torque =
      connection ? *FindField("mating", "connection_torque_Nm") : *FindField("limits", "torque_Nm");
  bool changed = RangedVec3(app, force, key + ".force_N", "force [N]", box.force_N, 0.1f, "%.1f");
  changed |=
      RangedVec3(app, torque, key + ".torque_Nm", "torque [N m]", box.torque_Nm, 0.01f, "%.2f");
  ImGui::PopID();
  return changed;
}

/// Ends an undo merge when the widget edited last frame is let go.
void CloseMergeOnRelease(AppState& app) {
  if (ImGui::IsItemDeactivatedAfterEdit()) app.doc.CloseMerge();
}

}  // namespace

void PlaceNextWindow(const PanelRect& r) {
  ImGui::SetNextWindowPos(ImVec2(r.x, r.y), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(r.w, r.h), ImGuiCond_Always);
}

void FileBrowser::Draw(const char* id, const std::vector<std::string>& extensions,
                       const std::string& start_dir, std::string& path) {
  ImGui::PushID(id);
  if (ImGui::Button(open ? "Hide files" : "Browse...")) {
    open = !open;
    if (dir.empty()) dir = start_dir;
  }
  if (open) {
    ImGui::TextDisabled("%s", dir.c_str());
    ImGui::BeginChild("browser", ImVec2(0, 140), true);
    std::error_code ec;
    if (ImGui::Selectable("..")) dir = fs::path(dir).parent_path().string();
    std::vector<fs::directory_entry> entries;
    for (const auto& e : fs::directory_iterator(dir, ec)) entries.push_back(e);
    std::sort(entries.begin(), entries.end(),
              [](const auto& a, const auto& b) { return a.path() < b.path(); });
    for (const auto& e : entries) {
      const std::string name = e.path().filename().string();
      if (e.is_directory(ec)) {
        if (ImGui::Selectable((name + "/").c_str())) dir = e.path().string();
        continue;
      }
      std::string ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
      if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) continue;
      if (ImGui::Selectable(name.c_str(), path == e.path().string())) path = e.path().string();
    }
    ImGui::EndChild();
  }
  ImGui::PopID();
}

void PartsPanel::Import(AppState& app, const std::string& path) {
  if (LooksLikeStep(path)) {  // a part or a whole assembly, in the file's own unit
    auto parts = PrepareStepImport(app.doc.project(), app.doc.ResolvePath(), path);
    if (!parts) {
      app.Notify("Import failed: " + parts.error().message);
      return;
    }
    const std::string first = parts->front().name;
    const size_t count = parts->size();
    if (app.Do(AddParts(std::move(*parts)))) {
      app.selection.part = first;
      app.Notify(count == 1 ? "Imported '" + first + "' from " + path
                            : "Imported " + std::to_string(count) + " parts from " + path);
    }
    return;
  }
  PartImportOptions options;
  options.scale =
      MeshUnits()[std::clamp(import_unit, 0, static_cast<int>(MeshUnits().size()) - 1)].scale;
  auto part = PreparePartImport(app.doc.project(), app.doc.ResolvePath(), path, options);
  if (!part) {
    app.Notify("Import failed: " + part.error().message);
    return;
  }
  const std::string name = part->name;
  if (app.Do(AddPart(std::move(*part)))) {
    app.selection.part = name;
    app.Notify("Imported '" + name + "' from " + path);
  }
}

void PartsPanel::Draw(AppState& app, const PanelRect& r) {
  PlaceNextWindow(r);
  if (!ImGui::Begin("Parts", nullptr, ImGuiWindowFlags_NoCollapse)) {
    ImGui::End();
    return;
  }
  const Project& p = app.doc.project();
  if (ImGui::CollapsingHeader("Project", ImGuiTreeNodeFlags_DefaultOpen)) {
    std::string name = p.name, description = p.description;
    bool changed = ImGui::InputText("name", &name);
    changed |= ImGui::InputText("description", &description);
    if (changed) app.Do(SetProjectInfo(name, description));
    CloseMergeOnRelease(app);
    Table table = p.table;
    bool t = EditVec3("table size [m]", table.size, 0.01f, "%.2f");
    t |= RangedDouble(app, *FindField("table", "height"), "table.height", table.height, 0.005f,
                      "%.3f");
    t |= RangedDouble(app, *FindField("table", "friction"), "table.friction", table.friction, 0.01f,
                      "%.2f");
    if (t) app.Do(SetTable(table, "table"));
    CloseMergeOnRelease(app);
  }

  // Import: a path field with a unit, a small file browser, and files dropped on the window.
  if (ImGui::CollapsingHeader("Import mesh", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::InputText("file", &import_path);
    ImGui::SetNextItemWidth(80);
    if (ImGui::BeginCombo("unit", MeshUnits()[import_unit].name)) {
      for (int i = 0; i < static_cast<int>(MeshUnits().size()); ++i) {
        if (ImGui::Selectable(MeshUnits()[i].name, i == import_unit)) import_unit = i;
      }
      ImGui::EndCombo();
    }
    ImGui::SameLine();
    if (ImGui::Button("Import") && !import_path.empty()) Import(app, import_path);
    ImGui::SameLine();
    browser.Draw("meshes",
                 {".stl", ".obj", ".ply", ".off", ".glb", ".gltf", ".3mf", ".dae", ".step", ".stp"},
                 app.doc.ResolvePath().parent_path().string(), import_path);
    ImGui::TextDisabled("or drop mesh or STEP files onto the window (STEP: in its own unit)");
  }

  if (ImGui::CollapsingHeader("Parts", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::BeginChild("part_list", ImVec2(0, 110), true);
    for (const Part& part : p.parts) {
      ImGui::ColorButton(("##c" + part.name).c_str(),
                         ImVec4(part.color[0], part.color[1], part.color[2], 1.0f),
                         ImGuiColorEditFlags_NoTooltip, ImVec2(12, 12));
      ImGui::SameLine();
      if (ImGui::Selectable(part.name.c_str(), app.selection.part == part.name)) {
        app.selection.part = part.name;
      }
    }
    ImGui::EndChild();
    auto it = std::find_if(p.parts.begin(), p.parts.end(),
                           [&](const Part& q) { return q.name == app.selection.part; });
    if (it != p.parts.end()) {
      Part part = *it;
      const std::string key = "part:" + part.name + ":";
      ImGui::Text("Part '%s'", part.name.c_str());
      ImGui::SameLine();
      if (ImGui::SmallButton("Remove")) {
        if (app.Do(RemovePart(part.name))) app.selection.part.clear();
      } else {
        std::string name = part.name;
        if (ImGui::InputText("name", &name, ImGuiInputTextFlags_EnterReturnsTrue)) {
          if (app.Do(RenameNode(part.name, name))) app.selection.part = name;
        }
        ImGui::TextDisabled("mesh: %s", part.mesh.c_str());
        PartContactsSection(app, part.name);
        bool changed = false;
        changed |= RangedDouble(app, *FindField("part", "scale"), key + "scale", part.scale,
                                0.0001f, "%.4g");
        bool has_mass = part.mass_kg.has_value();
        if (ImGui::Checkbox("given mass", &has_mass)) {
          part.mass_kg = has_mass ? std::optional<double>(0.1) : std::nullopt;
          changed = true;
        }
        if (part.mass_kg) {
          changed |= RangedDouble(app, *FindField("part", "mass_kg"), key + "mass_kg",
                                  *part.mass_kg, 0.001f, "%.3f");
        } else {
          changed |= RangedDouble(app, *FindField("part", "density_kg_m3"), key + "density_kg_m3",
                                  part.density_kg_m3, 1.0f, "%.0f");
        }
        float c[4] = {static_cast<float>(part.color[0]), static_cast<float>(part.color[1]),
                      static_cast<float>(part.color[2]), static_cast<float>(part.color[3])};
        if (ImGui::ColorEdit4("colour", c)) {
          part.color = {c[0], c[1], c[2], c[3]};
          changed = true;
        }
        ImGui::TextUnformatted("initial pose on the table");
        changed |= EditPose("initial", part.initial_pose);
        ImGui::TextUnformatted("assembled pose (assembly frame)");
        changed |= EditPose("assembled", part.assembled_pose);
        if (changed) app.Do(SetPart(part.name, part, key + "fields"));
        if (!ImGui::IsAnyItemActive()) app.doc.CloseMerge();
      }
    }
  }
  ImGui::End();
}

void MatingPanel::Draw(AppState& app, const PanelRect& r) {
  PlaceNextWindow(r);
  if (!ImGui::Begin("Mating", nullptr, ImGuiWindowFlags_NoCollapse)) {
    ImGui::End();
    return;
  }
  const Project& p = app.doc.project();
  auto it = std::find_if(p.steps.begin(), p.steps.end(),
                         [&](const Step& s) { return s.name == app.selection.step; });
  if (it == p.steps.end()) {
    ImGui::TextDisabled("Select a step in the assembly graph.");
    ImGui::End();
    return;
  }
  const Step& step = *it;
  Mating m = step.mating;
  ImGui::Text("Step '%s'", step.name.c_str());
  bool changed = false;
  auto pick = [&](const char* label, std::string& value) {
    if (ImGui::BeginCombo(label, value.empty() ? "(none)" : value.c_str())) {
      for (const std::string& input : step.inputs) {
        if (ImGui::Selectable(input.c_str(), value == input)) {
          value = input;
          changed = true;
        }
      }
      ImGui::EndCombo();
    }
  };
  pick("moved input", m.moved);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("The input the robots bring to the other one along the insertion axis.");
  }
  pick("base input", m.base);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("The input that stays: held by robots, or resting on the table.");
  }
  if (ImGui::SmallButton("Swap moved and base")) {
    std::swap(m.moved, m.base);
    changed = true;
  }
  const std::string key = "mating." + step.name + ".";
  changed |= RangedVec3(app, *FindField("mating", "axis"), key + "axis", "insertion axis", m.axis,
                        0.01f, "%.2f");
  ImGui::SameLine();
  ImGui::TextDisabled("(assembly frame)");
  if (StepGeometrySection(app, step)) {
    ImGui::End();  // the axis was set: `step` belongs to the project before the edit
    return;
  }
  ImGui::Separator();
  struct NumberField {
    const char* name;
    double* value;
    float speed;
    const char* format;
  };
  for (const NumberField& f :
       {NumberField{"force_N", &m.force_N, 0.1f, "%.1f"},
        NumberField{"torque_Nm", &m.torque_Nm, 0.01f, "%.2f"},
        NumberField{"transverse_fraction", &m.transverse_fraction, 0.005f, "%.3f"},
        NumberField{"offset_m", &m.offset_m, 0.0005f, "%.4f"},
        NumberField{"approach_m", &m.approach_m, 0.001f, "%.3f"}}) {
    changed |=
        RangedDouble(app, *FindField("mating", f.name), key + f.name, *f.value, f.speed, f.format);
  }
  ImGui::Text("final poses: %s", m.final_poses.empty() ? "from the assembled poses" : "");
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip(
        "Valid final poses of the moved input relative to the base (symmetric parts have\n"
        "several), xyz [m] and roll-pitch-yaw [deg] in the assembly frame; none: the parts'\n"
        "assembled poses.");
  }
  for (size_t i = 0; i < m.final_poses.size(); ++i) {
    ImGui::PushID(static_cast<int>(i));
    changed |= EditPose("final", m.final_poses[i]);
    if (ImGui::SmallButton("remove pose")) {
      m.final_poses.erase(m.final_poses.begin() + static_cast<long>(i));
      changed = true;
      ImGui::PopID();
      break;
    }
    ImGui::PopID();
  }
  if (ImGui::SmallButton("Add final pose")) {
    m.final_poses.push_back(Pose{});
    changed = true;
  }
  bool own_limits = m.connection_limits.has_value();
  if (ImGui::Checkbox("own connection limits", &own_limits)) {
    m.connection_limits = own_limits ? std::optional<WrenchBox>(p.connection_limits) : std::nullopt;
    changed = true;
  }
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip(
        "T_pq: the wrench the new connection sustains once made (a box in the mating frame);\n"
        "off: the project's default connection limits.");
  }
  if (m.connection_limits) {
    changed |= EditBox(app, "limits", key + "connection", *m.connection_limits, true);
  }
  if (changed) app.Do(SetMating(step.name, m, "mating:" + step.name));
  if (!ImGui::IsAnyItemActive()) app.doc.CloseMerge();
  ImGui::End();
}

void RobotsPanel::JointSliders(AppState& app, const std::string& name) {
  if (!app.viewport.ready()) return;
  const CellScene& scene = app.viewport.scene();
  auto it = std::find_if(scene.robots.begin(), scene.robots.end(),
                         [&](const SceneRobot& r) { return r.name == name; });
  if (it == scene.robots.end()) return;
  const SceneRobot& robot = *it;
  if (!ImGui::TreeNode("Joints (jog)")) return;
  JointVector q =
      app.jog.count(name) && app.jog[name].size() == robot.home.size() ? app.jog[name] : robot.home;
  bool changed = false;
  for (size_t j = 0; j < robot.chain.joints.size() && static_cast<long>(j) < q.size(); ++j) {
    const Joint& joint = robot.chain.joints[j];
    const bool revolute = joint.type == Joint::Type::kRevolute;
    double v = revolute ? q[j] * kDeg : q[j];
    const double lo = revolute ? joint.lower * kDeg : joint.lower;
    const double hi = revolute ? joint.upper * kDeg : joint.upper;
    const std::string label = joint.name + (revolute ? " [deg]" : " [m]");
    if (ImGui::SliderScalar(label.c_str(), ImGuiDataType_Double, &v, &lo, &hi,
                            revolute ? "%.1f" : "%.3f", ImGuiSliderFlags_AlwaysClamp)) {
      q[j] = revolute ? v / kDeg : v;
      changed = true;
    }
    if (ImGui::IsItemHovered()) {
      ImGui::SetTooltip(
          "Joint %zu of '%s', limits %.1f to %.1f%s: the viewport shows the arm here "
          "(not saved; the planner starts every robot at home)",
          j + 1, name.c_str(), lo, hi, revolute ? " deg" : " m");
    }
  }
  if (changed) app.jog[name] = q;
  const Iso3 X_WT = TcpPose(robot.chain, robot.X_WB, q, robot.end_effector.X_FT);
  const Vec3 rpy = RpyFromRotation(X_WT.linear()) * kDeg;
  ImGui::TextDisabled("TCP xyz %.3f %.3f %.3f m, rpy %.1f %.1f %.1f deg", X_WT.translation().x(),
                      X_WT.translation().y(), X_WT.translation().z(), rpy.x(), rpy.y(), rpy.z());
  if (ImGui::SmallButton("Home")) app.jog.erase(name);
  ImGui::TreePop();
}

void RobotsPanel::AddUrdf(AppState& app, const std::string& path) {
  const auto& ees = EndEffectors();
  const std::string ee =
      ees.empty() ? std::string() : ees[std::clamp(add_ee, 0, static_cast<int>(ees.size()) - 1)].name;
  auto robot = PrepareUrdfRobot(app.doc.project(), app.doc.ResolvePath(), path, urdf_root,
                                urdf_tip, ee);
  if (!robot) {
    app.Notify("URDF robot not added: " + robot.error().message);
    return;
  }
  const std::string name = robot->name;
  if (app.Do(AddRobot(*robot))) {
    app.selection.robot = name;
    app.Notify("Added robot '" + name + "' from " + path);
  }
}

void RobotsPanel::Draw(AppState& app, const PanelRect& r) {
  PlaceNextWindow(r);
  if (!ImGui::Begin("Robots", nullptr, ImGuiWindowFlags_NoCollapse)) {
    ImGui::End();
    return;
  }
  const Project& p = app.doc.project();
  const auto& models = RobotModels();
  const auto& ees = EndEffectors();
  if (!models.empty() && !ees.empty()) {
    add_model = std::clamp(add_model, 0, static_cast<int>(models.size()) - 1);
    add_ee = std::clamp(add_ee, 0, static_cast<int>(ees.size()) - 1);
    ImGui::SetNextItemWidth(110);
    if (ImGui::BeginCombo("##model", models[add_model].name.c_str())) {
      for (int i = 0; i < static_cast<int>(models.size()); ++i) {
        if (ImGui::Selectable(models[i].title.c_str(), i == add_model)) add_model = i;
      }
      ImGui::EndCombo();
    }
    ImGui::SameLine();
    ImGui::SetNextItemWidth(130);
    if (ImGui::BeginCombo("##ee", ees[add_ee].name.c_str())) {
      for (int i = 0; i < static_cast<int>(ees.size()); ++i) {
        if (ImGui::Selectable(ees[i].title.c_str(), i == add_ee)) add_ee = i;
      }
      ImGui::EndCombo();
    }
    ImGui::SameLine();
    if (ImGui::Button("Add robot")) {
      if (app.Do(AddRobot(models[add_model].name, ees[add_ee].name))) {
        app.selection.robot = app.doc.project().robots.back().name;
      }
    }
  }
  // A user's arm from its URDF, with the end effector chosen above.
  if (ImGui::TreeNode("Add from URDF")) {
    ImGui::InputText("urdf file", &urdf_path);
    ImGui::SetNextItemWidth(100);
    ImGui::InputText("root link", &urdf_root);
    ImGui::SameLine();
    ImGui::SetNextItemWidth(100);
    ImGui::InputText("tip link", &urdf_tip);
    if (ImGui::Button("Add URDF robot") && !urdf_path.empty()) AddUrdf(app, urdf_path);
    ImGui::SameLine();
    browser.Draw("urdf", {".urdf"}, app.doc.ResolvePath().parent_path().string(), urdf_path);
    ImGui::TextDisabled("or drop a .urdf file onto the window; links empty: the URDF's root\n"
                        "and its one tip");
    ImGui::TreePop();
  }
  for (const Robot& robot : p.robots) {
    const std::string label = robot.name + "  (" +
                              (robot.model.empty() ? robot.urdf : robot.model) + ", " +
                              robot.end_effector + ")";
    if (ImGui::Selectable(label.c_str(), app.selection.robot == robot.name)) {
      app.selection.robot = robot.name;
    }
  }
  auto it = std::find_if(p.robots.begin(), p.robots.end(),
                         [&](const Robot& q) { return q.name == app.selection.robot; });
  if (it != p.robots.end()) {
    Robot robot = *it;
    ImGui::Separator();
    ImGui::Text("Robot '%s'", robot.name.c_str());
    ImGui::SameLine();
    if (ImGui::SmallButton("Remove robot")) {
      app.Do(RemoveRobot(robot.name));
      app.selection.robot.clear();
      ImGui::End();
      return;
    }
    bool changed = false;
    if (ImGui::BeginCombo("end effector", robot.end_effector.c_str())) {
      for (const auto& ee : ees) {
        if (ImGui::Selectable(ee.name.c_str(), ee.name == robot.end_effector)) {
          robot.end_effector = ee.name;
          changed = true;
        }
      }
      ImGui::EndCombo();
    }
    ImGui::TextUnformatted(robot.mounted_on.empty() ? "base pose (world)"
                                                    : "base pose (mount frame)");
    changed |= EditPose("base", robot.base_pose);
    if (changed) app.Do(SetRobot(robot.name, robot, "robot:" + robot.name));
    JointSliders(app, robot.name);

    // Wrench limits: the robot's own table, or the project's (shared by every robot).
    bool own = robot.wrench_limits.has_value();
    if (ImGui::Checkbox("own wrench limits", &own)) {
      app.Do(SetWrenchLimits(robot.name,
                             own ? std::optional<WrenchLimits>(p.wrench_limits) : std::nullopt));
    }
    WrenchLimits limits = own && robot.wrench_limits ? *robot.wrench_limits : p.wrench_limits;
    ImGui::TextDisabled(own ? "limits of this robot (grasp frame)"
                            : "project's limits, all robots (grasp frame; paper's values)");
    bool l = false;
    const std::string lkey = "limits." + (own ? robot.name : std::string("project")) + ".";
    if (ImGui::TreeNodeEx("two-finger", ImGuiTreeNodeFlags_DefaultOpen)) {
      l |= EditBox(app, "tf", lkey + "two_finger", limits.two_finger, false);
      ImGui::TreePop();
    }
    if (ImGui::TreeNode("vacuum, assembly")) {
      l |= EditBox(app, "va", lkey + "vacuum_assembly", limits.vacuum_assembly, false);
      ImGui::TreePop();
    }
    if (ImGui::TreeNode("vacuum, transport")) {
      l |= EditBox(app, "vt", lkey + "vacuum_transport", limits.vacuum_transport, false);
      ImGui::TreePop();
    }
    if (l) app.Do(SetWrenchLimits(own ? robot.name : "", limits, "limits:" + robot.name));
    if (!ImGui::IsAnyItemActive()) app.doc.CloseMerge();
  }
  ImGui::End();
}

}  // namespace wrap::gui
