// What the GUI shows of the geometry report of the live validation (mating/check.h): which parts
// touch, a step's insertion-path verdict and free directions, the "use this direction" edit, and
// the shapes the viewport draws for them (contacts, the swept outline of an insertion). Plain
// C++ on the validation's result: no ImGui, no GL, no extra geometry computed.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/pose.h"
#include "gui/document.h"
#include "gui/validation_job.h"
#include "model/project.h"

namespace wrap::gui {

/// The geometry report's verdict on one step of the document, when the last validation checked
/// that step as it is now (same inputs, axis, approach, final poses).
struct StepVerdict {
  const StepGeometry* geometry = nullptr;  ///< Into the result's report.
  const Project* checked = nullptr;        ///< The project as checked (names of parts).
};

/// The verdict on `step` from `result`, or none when the result has no report or checked another
/// version of the step (the document changed since; the next validation will tell).
std::optional<StepVerdict> FindStepVerdict(const ValidationResult& result, const Step& step);

/// The parts touching `part` in the report of `result`, with their contact's words, e.g.
/// "seat (4.1 cm2)". Empty when the part touches nothing or there is no report.
std::vector<std::string> TouchingParts(const ValidationResult& result, const std::string& part);

/// True when the report says parts `a` and `b` touch (assembled).
bool PartsTouch(const ValidationResult& result, const std::string& a, const std::string& b);

/// The free directions of a blocked step, most natural first (AxisPreference: from above, then
/// level, axis-aligned first). Empty for a free path.
std::vector<Vec3> RankedFreeDirections(const StepGeometry& geometry);

/// The verdict in words, e.g. "blocked: 'leg1' hits 'seat' 14.2 mm before its mating pose" or
/// "free over 30.0 mm of approach".
std::string PathVerdictText(const StepVerdict& verdict, const Step& step);

/// Sets step `step`'s insertion axis to `axis` (one undoable edit, labelled with the direction).
Command UseInsertionAxis(const std::string& step, const Vec3& axis);

/// Where the assembly frame goes in the world for the assembled view: the assembly's bounding
/// box (parts at their assembled poses) centred over the table's centre, resting on its top.
/// `boxes_A` are the parts' boxes in the assembly frame.
Iso3 AssembledPlacement(const Table& table, const std::vector<Aabb>& boxes_A);

/// A segment drawn in the viewport (assembly frame), in one of three colours.
struct SweepSegment {
  Vec3 from_A = Vec3::Zero();
  Vec3 to_A = Vec3::Zero();
  enum class Kind { kFree, kBlocked, kOutline } kind = Kind::kFree;
};

/// The moved input's outline swept along its insertion: its bounding box (assembly frame, at the
/// mating pose `X_BM` times the assembled poses) drawn at the approach pose (`length_m` back along
/// the axis) and at the mating pose, joined corner to corner along the axis; the part of the
/// sweep from where the path is blocked (`blocked_at_m` before the mating pose, negative: free)
/// to the mating pose is kBlocked, the rest kFree, the two boxes kOutline.
std::vector<SweepSegment> InsertionSweep(const Aabb& moved_box_A, const Vec3& axis_A,
                                         double length_m, double blocked_at_m);

}  // namespace wrap::gui
