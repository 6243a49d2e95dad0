// What a bench child left behind, read into its run result: the plan file's stats, cost history
// and robot utilisation, the simulation report, the log's last line.
#pragma once

#include <filesystem>
#include <string>

#include "bench/bench.h"

namespace wrap::bench {

/// What the plan file says beyond the stats copied into the result.
struct PlanOutcome {
  std::string failure;         ///< stats.failure: why the planner stopped without a plan.
  bool out_of_memory = false;  ///< stats.out_of_memory.
};

/// Copies the plan file's stats, cost history and (plans with motion) robot utilisation into
/// `r`; a missing or unreadable file leaves `r` as it is.
PlanOutcome ReadPlanFile(RunResult& r, const std::filesystem::path& plan_file);

/// The robots' motion in a plan (its "segments" and "robots"), or nullopt when it has no motion
/// or no makespan. `plan_json` is the plan file's text.
std::optional<Utilisation> UtilisationOfPlan(const std::string& plan_json);

/// Copies `wrap sim`'s report (success, tasks, failure, peak utilisations) into `r`; a missing or
/// malformed report is a failed simulation ("no sim report").
void ReadSimReport(RunResult& r, const std::filesystem::path& report_file);

/// The last non-empty line of a log file (at most 300 characters).
std::string LastLine(const std::filesystem::path& log);
/// Whether the log contains `what`.
bool LogMentions(const std::filesystem::path& log, const std::string& what);

}  // namespace wrap::bench
