// The editors' numeric fields in one table: each field's range, unit and meaning. The panels draw
// them with a tooltip that says what the field means, and refuse a value outside the range with a
// message at the field (nothing reaches the document); the scripted mode's `set` goes through the
// same check, so a test sees what a user sees.
#pragma once

#include <string>
#include <string_view>

#include "gui/app_state.h"

namespace wrap::gui {

/// One editable number (or each component of a vector) and what it may hold.
struct FieldSpec {
  const char* name;   ///< Field name in the script's `set`, e.g. "force_N".
  const char* label;  ///< Label in the editor, e.g. "force [N]".
  double min;         ///< Least value allowed.
  double max;         ///< Largest value allowed.
  const char* help;   ///< Tooltip: what it means, its unit and its range.
};

/// The spec of field `name` of a `kind` ("part", "mating", "table", "limits", "planner"), or
/// null for a field without a range.
const FieldSpec* FindField(std::string_view kind, std::string_view name);

/// Why `value` is refused for `spec`, in words ("force must be at least 0 N; -5 refused"), or ""
/// when it is allowed.
std::string RefusedValue(const FieldSpec& spec, double value);

/// A drag field for one number with `spec`'s tooltip and range: dragging stays inside the range,
/// a typed value outside it is refused: the message is kept in app.field_errors[key] and shown
/// under the field until a valid value is entered. True when `value` changed to a valid value.
bool RangedDouble(AppState& app, const FieldSpec& spec, const std::string& key, double& value,
                  float speed, const char* format);
/// The same for a 3-vector (each component within the range), labelled `label`.
bool RangedVec3(AppState& app, const FieldSpec& spec, const std::string& key, const char* label,
                Vec3& value, float speed, const char* format);

/// Records (or clears, with an empty message) the refusal shown at field `key`.
void SetFieldError(AppState& app, const std::string& key, const std::string& message);

}  // namespace wrap::gui
