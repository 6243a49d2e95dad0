// The wrench LP's view of a moment of the task plan (paper §IV-A): one body per part of the
// objects involved, the connections already made inside them, the grippers holding them, the
// table under resting ones, and the mating of an assembly step.
#pragma once

#include <span>
#include <utility>
#include <vector>

#include "task/state.h"
#include "task/world.h"
#include "wrench/wrench.h"

namespace wrap {

/// An object as the wrench model sees it.
struct WrenchObject {
  int node = -1;                            ///< DAG node.
  Iso3 X_WA = Iso3::Identity();             ///< Pose.
  bool resting = false;                     ///< On the table.
  std::vector<std::pair<int, int>> holders; ///< (robot, grasp id).
};

/// The configuration of `objects`; with `mating_step` >= 0 (a step node) the mating load of that
/// step between its interface parts, which must be among the objects' parts.
StepConfiguration BuildWrenchConfig(const TaskWorld& world, const TaskTables& tables,
                                    std::span<const WrenchObject> objects, int mating_step = -1);

}  // namespace wrap
