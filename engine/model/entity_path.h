// What a diagnostic's JSON path points at, by name: `steps[0].mating.force_N` of a project is the
// field `mating.force_N` of step 'seat+leg1'. Front ends list problems by entity name and select
// the entity on a click; the CLI keeps the JSON path.
#pragma once

#include <string>

#include "core/diagnostics.h"
#include "model/project.h"

namespace wrap {

/// The kind of entity a JSON path starts in.
enum class EntityKind { kProject, kPart, kStep, kRobot, kMobileBase, kTable, kPlanner, kOther };

/// The entity a JSON path names.
struct EntityRef {
  EntityKind kind = EntityKind::kProject;  ///< What it is (kProject: the file as a whole).
  std::string name;   ///< Its name (parts, steps, robots, mobile bases); empty otherwise.
  std::string field;  ///< The rest of the path inside it, e.g. "mating.force_N"; may be empty.
  /// In words: "step 'seat+leg1'", "part 'leg1'", "table", "planner defaults", "project".
  std::string Label() const;
};

/// Resolves `json_path` (e.g. "parts[3].initial_pose", "table.height", "") against `project`.
/// An index beyond the project's lists, or a top-level key it does not know, gives kOther with
/// the path itself as the field.
EntityRef EntityOfPath(const Project& project, const std::string& json_path);

/// A diagnostic in one line with its entity named rather than indexed, for people reading a
/// terminal: `stool.json: part 'leg_1', mesh: error: ...` where Format(d) gives
/// `stool.json: parts[1].mesh: error: ...`. A path that names no entity of `project` (the table,
/// the planner, an index beyond its lists, a part without a name) is printed as Format prints it.
std::string FormatNamed(const Diagnostic& d, const Project& project);

/// FormatNamed when `project` is known, Format otherwise.
std::string FormatNamed(const Diagnostic& d, const Project* project);

}  // namespace wrap
