// The scripted mode of the GUI (`wrap PROJECT --script FILE`): a small list of UI commands, one
// per line, run one per frame against the same AppState the panels edit, so that GUI flows are
// tested in CI. '#' starts a comment. Commands:
//   select part|step|robot NAME        set the shared selection
//   import MESH [m|cm|mm|inch]         import a mesh as a part (relative to the script's folder);
//                                      a STEP file imports as one part or, for an assembly, one
//                                      part per instance (in its own unit), in one edit
//   add-step NAME | delete-step NAME | rename OLD NEW
//   add-edge INPUT STEP | remove-edge INPUT STEP     inputs of a step (cycles are refused)
//   add-robot MODEL END_EFFECTOR | remove-robot NAME
//   add-urdf URDF END_EFFECTOR [ROOT TIP]   a robot from a URDF (relative to the script's folder)
//   set FIELD VALUE...                 a field, e.g. `set part.seat.mass_kg 0.2` (part: mass_kg,
//                                      density_kg_m3, scale, color, initial_xyz, initial_rpy_deg,
//                                      assembled_xyz, assembled_rpy_deg; mating: moved, base,
//                                      axis, force_N, torque_Nm, transverse_fraction, offset_m,
//                                      approach_m; robot: end_effector, base_xyz, base_rpy_deg;
//                                      table.height|friction; planner.time_limit_s|seed|grasps),
//                                      `set mating.s1.axis 0 0 1`, `set robot.r1.base_xyz 0 0 .75`
//   undo | redo
//   option NAME VALUE                  planner option: planner, wrench, objective (actions|makespan),
//                                      time_limit_s, budget, seed, task_only (0/1), grasps
//   run                                start the planner on the document (non-blocking)
//   wait                               wait until the planner ends (frames keep drawing)
//   expect-plan                        fail unless the last run gave a solved plan
//   scrub T | play | pause             the timeline [s, or keyframe index without motion]
//   save [FILE] | screenshot FILE      (relative to the script's folder)
//   expect-refused COMMAND...          run COMMAND and fail unless it is refused
//   autosave                           write the recovery file as the interactive window does
//                                      (off in scripts otherwise, so that they leave none)
//   sleep SECONDS                      keep drawing frames for that long
//   view utilisation on|off            grippers tinted by wrench utilisation during playback
//   view quality auto|fine|fast        the viewport's drawing quality (View menu)
//   new | open FILE                    File > New, File > Open (unsaved edits discarded)
//   validate                           wait for the live validation of the document as it is
//   show N | show off                  the Problems panel's "Show" of failed check N (1: the
//                                      blocker), or back to the cell
//   jog ROBOT JOINT DEG                a robot's joint slider (joint from 1)
//   measure idle|orbit|play SECONDS    draw frames for that long (orbiting the camera, or
//                                      playing the plan) and print the frame rate
//   expect-problem TEXT...             fail unless the Problems panel shows TEXT (the run's
//                                      failure or a validation diagnostic)
//   expect-no-problem TEXT...          the opposite
//   expect-marked STEP|none            the DAG canvas marks STEP as where the last run failed
//   expect-selected part|step|robot NAME
//   expect-plan-stale | expect-plan-current
//   expect-field-error FIELD [TEXT...] a refusal is shown at FIELD (e.g. mating.s1.force_N)
//   expect-undo TEXT...                the Edit menu's undo label holds TEXT
//   expect-viewport cell|empty         the viewport has a cell drawn, or none
//   view assembled|contacts on|off     View > Assembled view (insertion path of the selected
//                                      step), View > Contacts
//   import-assembly UNIT PATH...       Assembly > Import assembly (UNIT auto|mm|cm|m; mesh files
//                                      or a folder), waiting for it; fails when nothing applied
//   suggest-order | lay-out            Assembly > Suggest assembly order, > Lay out parts on the
//                                      table, waiting for them; fail when nothing applied
//   use-free-direction STEP N          the mating editor's "Use" button of the Nth free direction
//                                      (as listed, from 1; needs a current `validate`)
//   expect-path STEP free|blocked      the validation's verdict on the step's insertion path
//   expect-free-direction STEP X Y Z   that direction is among the step's free directions
//   expect-touch A B | expect-no-touch A B   parts A and B touch (the contact graph) or not
//   expect-count parts|steps|robots N  the project has N of them
//   expect-change TEXT...              the last authoring edit's changes or decisions say TEXT
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/result.h"
#include "gui/app_state.h"

namespace wrap::gui {

/// One line of a script, split into words.
struct ScriptLine {
  int number = 0;                  ///< Line number in the file, from 1.
  std::vector<std::string> words;  ///< The command and its arguments.
};

/// Splits a script into command lines (skipping blanks and comments). Fails with kInvalidInput
/// naming the line for an unknown command or a wrong number of arguments.
Result<std::vector<ScriptLine>> ParseScript(const std::string& text);

/// What a line asks of the frame loop besides the edit it did.
struct ScriptEffect {
  bool wait_for_planner = false;     ///< Hold the script until the planner ends.
  std::filesystem::path screenshot;  ///< Save the window to this file at the next frame.
  bool autosave = false;             ///< Turn the recovery autosave on.
  double sleep_s = 0.0;              ///< Keep drawing frames this long before the next line.
  bool new_document = false;         ///< File > New.
  std::filesystem::path open;        ///< File > Open this project.
  bool wait_for_validation = false;  ///< Hold the script until the live validation is current.
  bool wait_for_authoring = false;   ///< Hold the script until the authoring run is taken.
  std::string measure;               ///< Measure the frame rate: "idle", "orbit" or "play".
  double measure_s = 0.0;            ///< ... for this long [s].
  /// A check of what the next frame drew (run after it); fails the line with its message, which
  /// names the line ("script line N: ...").
  std::function<Result<void>(const AppState&)> check;
};

/// The geometry and authoring commands (script_authoring.cpp): their arity by name.
const std::map<std::string, std::pair<int, int>>& GeometryScriptArity();
/// Runs one of them (nullopt when `line` is another command).
std::optional<Result<ScriptEffect>> RunGeometryScriptLine(AppState& app, const ScriptLine& line,
                                                          const std::filesystem::path& base_dir);

/// Runs one line against `app`; relative paths resolve against `base_dir`. A refused edit fails
/// with its reason (kInvalidInput), prefixed by the line number.
Result<ScriptEffect> RunScriptLine(AppState& app, const ScriptLine& line,
                                   const std::filesystem::path& base_dir);

}  // namespace wrap::gui
