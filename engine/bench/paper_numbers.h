// The WRAP paper's published numbers (§V, Tables "comparison", "search_time_spent",
// "wrench_sim"), for the report to print beside ours.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace wrap::bench {

/// The example projects that have a column of Table "comparison", in the paper's order.
const std::vector<std::string>& PaperComparisonProjects();

/// A cell of Table "comparison": mean time to first plan [s] and cost, or a word.
struct PaperComparison {
  double t_init_s = 0.0;  ///< Mean of 10 runs [s]; 0 when `outcome` is set.
  double cost = 0.0;      ///< Number of actions.
  std::string outcome;    ///< "timeout" or "OOM" where the paper has no numbers; else empty.
};

/// Table "comparison" for `planner` (wrap, optimistic, flat, counting, exact, fine) on `project`
/// (our example name, e.g. "fabrica_car"); nullopt where the paper has no column for it.
std::optional<PaperComparison> PaperComparisonCell(const std::string& project,
                                                   const std::string& planner);

/// A row of Table "search_time_spent" (means of 10 runs) [s].
struct PaperBreakdown {
  double t_grasp = 0, t_bwd = 0, t_lp = 0, t_fwd = 0, t_ik = 0, t_mp = 0;
};
/// The breakdown row for `project`; nullopt where the paper has none.
std::optional<PaperBreakdown> PaperBreakdownRow(const std::string& project);

/// A row of Table "wrench_sim" as printed (success %, tasks, failure, utilisations).
struct PaperSim {
  std::string success, tasks, failure, transport_2f, transport_vac, insertion_2f, insertion_vac;
};
/// The row for `project` (cross, cube, chair) under `wrench` (none, gravity, full).
std::optional<PaperSim> PaperSimRow(const std::string& project, const std::string& wrench);

/// The paper's name of an example project, e.g. "F. Car" for "fabrica_car"; else the name.
std::string PaperProjectName(const std::string& project);
/// The paper's name of a planner variant, e.g. "Milestones + counting" for "counting".
std::string PaperPlannerName(const std::string& planner);

}  // namespace wrap::bench
