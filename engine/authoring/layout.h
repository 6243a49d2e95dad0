// Where parts start: each in a stable placement that a robot can pick, laid out on the table
// without overlap, within the robots' reach; and robots placed around the table.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/result.h"
#include "grasp/preprocess.h"
#include "model/project.h"
#include "model/validate.h"

namespace wrap {

/// Options of LayOutParts.
struct LayoutOptions {
  double gap_m = 0.08;   ///< Free space between two parts' footprints [m]: room for fingers.
  double grid_m = 0.01;  ///< Spacing of the positions tried [m].
  int rounds = 4;        ///< Re-layouts of parts no robot could pick.
  std::vector<int> parts;  ///< The parts to lay out (empty: every part); the others stay put.
};

/// What LayOutParts decided.
struct LayoutReport {
  std::vector<std::string> decisions;  ///< One line per part placed (and per retry).
  std::vector<int> unpickable;         ///< Parts no robot can pick in any placement tried.
  std::vector<int> overhanging;        ///< Parts placed over the table's edge (the only way).
};

/// Sets the initial pose of the parts in `options.parts` (every part when empty): the placement
/// in which it stands as assembled when that is stable, else the most stable one, on positions nearest the table's centre that at least
/// two robots reach (one when none does), apart from every other part by the gap and inside the
/// table. Parts that no robot can then pick (the planner's pick checks on a fresh preprocessing)
/// get their next placement, a quarter turn, and at last a place over the table's edge, for up
/// to `rounds` rounds. `project` needs its DAG and robots; `check` its meshes. Fails like
/// Preprocess.
Result<LayoutReport> LayOutParts(Project& project, const ProjectCheck& check,
                                 const std::filesystem::path& project_file,
                                 const LayoutOptions& options = {});

/// The table for robots of `model`: 1.2 x 1.0 m for a UR5e, scaled with the arm's reach.
Table TableFor(const std::string& model);

/// `count` robots of `model` with `end_effector` around the table: on the ellipse through the
/// corners of a rectangle centred on the table (4 robots: its corners), 0.9 x 0.7 m for a UR5e,
/// scaled with the arm's reach; the first at 45 degrees, each facing the centre, on the table
/// top.
std::vector<Robot> RobotsAroundTable(const Table& table, int count, const std::string& model,
                                     const std::string& end_effector);

}  // namespace wrap
