#include "gui/fields.h"

#include <imgui.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace wrap::gui {

namespace {

constexpr double kBig = 1e6;

// Ranges agree with validation (model/validate.cpp): forces, fractions, offsets, approaches and
// limits are non-negative; masses, densities, scales and friction positive. The upper bounds
// catch a slipped digit before it reaches the planner.
const FieldSpec kMating[] = {
    {"force_N", "force [N]", 0.0, 1e4,
     "Mating force [N] along the insertion axis that the step needs to join the inputs (press "
     "fit, snap fit). At least 0."},
    {"torque_Nm", "torque [N m]", -1e3, 1e3,
     "Mating torque [N m] about the insertion axis (screw motions); the sign gives the sense."},
    {"transverse_fraction", "transverse fraction", 0.0, 1.0,
     "Uncertainty of the mating force: a force across the insertion axis of up to this fraction "
     "of the mating force, in any direction (robust LP vertices). 0 to 1, no unit."},
    {"offset_m", "offset [m]", 0.0, 1.0,
     "Uncertainty of where the mating force acts: its point may be this far [m] from the "
     "interface's centre, across the axis (robust LP vertices). At least 0."},
    {"approach_m", "approach [m]", 0.0, 1.0,
     "Distance [m] back along the insertion axis from which the moved input is inserted in a "
     "straight line (the approach keyframe). At least 0."},
    {"axis", "insertion axis", -kBig, kBig,
     "Direction the moved input travels to its mating pose, in the assembly frame (normalised "
     "when used; must not be zero)."},
    {"connection_force_N", "force [N]", 0.0, kBig,
     "Connection limits T_pq: the largest force [N] along each axis of the mating frame that "
     "the joint sustains once made. At least 0."},
    {"connection_torque_Nm", "torque [N m]", 0.0, kBig,
     "Connection limits T_pq: the largest torque [N m] about each axis of the mating frame "
     "that the joint sustains once made. At least 0."},
};
const FieldSpec kLimits[] = {
    {"force_N", "force [N]", 0.0, kBig,
     "Gripper wrench limits: the largest force [N] the grasp transmits along each axis of the "
     "grasp frame (x, y, z; z along the gripper's approach). At least 0."},
    {"torque_Nm", "torque [N m]", 0.0, kBig,
     "Gripper wrench limits: the largest torque [N m] the grasp transmits about each axis of "
     "the grasp frame. At least 0."},
};
const FieldSpec kPart[] = {
    {"mass_kg", "mass [kg]", 1e-6, 1e4, "Mass of the part [kg], instead of density x volume."},
    {"density_kg_m3", "density [kg/m3]", 1.0, 1e5,
     "Density [kg/m3] that gives the mass from the mesh's volume (PLA: 1240)."},
    {"scale", "scale [m/unit]", 1e-6, 100.0,
     "Metres per mesh unit (0.001 for a mesh in mm, 0.01 in cm, 1 in m)."},
};
const FieldSpec kTable[] = {
    {"friction", "friction", 1e-3, 2.0,
     "Coulomb friction coefficient between parts and the table (PLA on wood: about 0.4)."},
    {"height", "table height [m]", 0.0, 3.0, "World z of the table top [m]."},
};
const FieldSpec kPlanner[] = {
    {"time_limit_s", "time limit [s]", 1.0, 36000.0, "Time limit of a planner run [s]."},
    {"grasps", "grasps", 1.0, 1000.0, "Grasp-set size per subassembly and end-effector kind."},
};

template <size_t N>
const FieldSpec* Find(const FieldSpec (&specs)[N], std::string_view name) {
  for (const FieldSpec& s : specs) {
    if (name == s.name) return &s;
  }
  return nullptr;
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

void Tooltip(const FieldSpec& spec) {
  if (!ImGui::IsItemHovered()) return;
  ImGui::BeginTooltip();
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 32.0f);
  ImGui::TextUnformatted(spec.help);
  if (spec.min > -kBig || spec.max < kBig) {
    ImGui::TextDisabled("Range: %s to %s", Num(spec.min).c_str(), Num(spec.max).c_str());
  }
  ImGui::PopTextWrapPos();
  ImGui::EndTooltip();
}

void ShowError(const AppState& app, const std::string& key) {
  auto it = app.field_errors.find(key);
  if (it == app.field_errors.end()) return;
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
  ImGui::TextWrapped("%s", it->second.c_str());
  ImGui::PopStyleColor();
}

}  // namespace

const FieldSpec* FindField(std::string_view kind, std::string_view name) {
  if (kind == "mating") return Find(kMating, name);
  if (kind == "limits") return Find(kLimits, name);
  if (kind == "part") return Find(kPart, name);
  if (kind == "table") return Find(kTable, name);
  if (kind == "planner") return Find(kPlanner, name);
  return nullptr;
}

std::string RefusedValue(const FieldSpec& spec, double value) {
  std::string what = spec.label;
  if (const auto bracket = what.find(" ["); bracket != std::string::npos) what.resize(bracket);
  if (!std::isfinite(value)) return what + " must be a finite number";
  if (value < spec.min) {
    return what + " must be at least " + Num(spec.min) + "; " + Num(value) + " refused";
  }
  if (value > spec.max) {
    return what + " must be at most " + Num(spec.max) + "; " + Num(value) + " refused";
  }
  return "";
}

void SetFieldError(AppState& app, const std::string& key, const std::string& message) {
  if (message.empty()) {
    app.field_errors.erase(key);
  } else {
    app.field_errors[key] = message;
  }
}

bool RangedDouble(AppState& app, const FieldSpec& spec, const std::string& key, double& value,
                  float speed, const char* format) {
  double v = value;
  // The range bounds the drag; a typed value is not clamped (no AlwaysClamp): it is checked.
  const bool changed =
      ImGui::DragScalar(spec.label, ImGuiDataType_Double, &v, speed, &spec.min, &spec.max, format);
  Tooltip(spec);
  bool applied = false;
  if (changed) {
    const std::string why = RefusedValue(spec, v);
    SetFieldError(app, key, why);
    if (why.empty()) {
      value = v;
      applied = true;
    }
  }
  ShowError(app, key);
  return applied;
}

bool RangedVec3(AppState& app, const FieldSpec& spec, const std::string& key, const char* label,
                Vec3& value, float speed, const char* format) {
  double a[3] = {value.x(), value.y(), value.z()};
  const bool changed =
      ImGui::DragScalarN(label, ImGuiDataType_Double, a, 3, speed, &spec.min, &spec.max, format);
  Tooltip(spec);
  bool applied = false;
  if (changed) {
    std::string why;
    for (double x : a) {
      if (why.empty()) why = RefusedValue(spec, x);
    }
    SetFieldError(app, key, why);
    if (why.empty()) {
      value = Vec3(a[0], a[1], a[2]);
      applied = true;
    }
  }
  ShowError(app, key);
  return applied;
}

}  // namespace wrap::gui
