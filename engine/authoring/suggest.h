// `wrap suggest`: what the geometry says is wrong with a project, as concrete edits.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/result.h"
#include "model/project.h"
#include "model/validate.h"

namespace wrap {

/// One proposed edit.
struct Suggestion {
  std::string path;  ///< The JSON path it changes, e.g. "steps[0].mating.axis".
  std::string what;  ///< The edit and why, in words.
};

/// The edits, and the project with them made.
struct SuggestResult {
  std::vector<Suggestion> suggestions;  ///< Empty when the geometry finds nothing to fix.
  Project edited;                       ///< The project with every suggestion applied.
};

/// Checks what the geometry checks check and proposes: a free axis for a blocked insertion (the
/// best of the free directions: from above, then level, axis-aligned first); a new order (the
/// DAG of assembly-by-disassembly) when a step joins inputs that do not touch or no free axis
/// exists; swapping moved and base where only the base has grasps that clear the other input
/// where mated; new initial poses for parts that overlap at the start or that no robot can pick.
/// `check` must hold the meshes and the DAG (LoadProject). Fails like Preprocess.
/// A new assembly order for a whole project.
struct OrderSuggestion {
  std::vector<Step> steps;       ///< The DAG, in assembly order.
  std::vector<std::string> why;  ///< One line per step: the choice and its reason.
};

/// The DAG of assembly by disassembly over the project's contact graph (as `wrap new` finds
/// it, with the grasps of the project's end effectors): each step's inputs, moved and base roles
/// and free axis; its other mating fields those of the project's first step (defaults when it
/// has none). `check` must hold the meshes (ValidateProject). Fails with kInfeasible naming the
/// parts when they are interlocked, kInvalidInput when a mesh did not load.
Result<OrderSuggestion> SuggestOrder(const Project& project, const ProjectCheck& check);

Result<SuggestResult> SuggestFixes(const Project& project, const ProjectCheck& check,
                                   const std::filesystem::path& project_file);

}  // namespace wrap
