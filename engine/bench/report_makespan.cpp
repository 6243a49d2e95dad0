// The makespan suite's section (issue 33, cycle time): per assembly, the plans with motion as
// planned by default, with `--objective makespan` and with `--optimize --objective makespan`,
// their makespan with the robots at work together beside the same segments one at a time, and
// the ratio of the two.
#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "bench/paper_numbers.h"
#include "bench/report_blocks.h"

namespace wrap::bench {

namespace {

// How the run's task plan was chosen, as its `wrap plan` options say it.
std::string PlanFlags(const RunSpec& s) {
  std::string flags;
  if (s.optimize) flags += "--optimize";
  if (s.objective != "actions") {
    flags += (flags.empty() ? "" : " ") + ("--objective " + s.objective);
  }
  return flags.empty() ? "default" : "`" + flags + "`";
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// "median / mean" of the values, or "–" when there are none.
std::string MedianMean(const std::vector<double>& v, const char* format) {
  if (v.empty()) return "–";
  return Fmt(format, Median(v)) + " / " + Fmt(format, Summarise(v).mean);
}

// The row of one assembly and one way of planning it. A run counts where its motion succeeded:
// it is solved only then, and only then has a makespan.
std::vector<std::string> Row(const std::string& project, const std::string& flags,
                             const std::vector<const RunResult*>& runs) {
  std::vector<double> ratios;
  for (const RunResult* r : runs) {
    const auto m = r->stats.find("makespan_s"), q = r->stats.find("makespan_sequential_s");
    if (!r->solved() || m == r->stats.end() || q == r->stats.end() || q->second <= 0.0) continue;
    ratios.push_back(m->second / q->second);
  }
  const std::vector<double> actions = Values(runs, "cost");
  return {PaperProjectName(project),
          flags,
          SolvedCell(runs),
          MedianMean(Values(runs, "makespan_s"), "%.1f"),
          MedianMean(Values(runs, "makespan_sequential_s"), "%.1f"),
          MedianMean(ratios, "%.2f"),
          actions.empty() ? "–" : Fmt("%.1f", Summarise(actions).mean)};
}

}  // namespace

void MakespanObjective(const std::vector<RunResult>& results, ReportBlocks& report) {
  // By project, then by how the plan was chosen: the default first.
  using Way = std::pair<bool, std::string>;  // optimize, objective
  std::map<std::string, std::map<Way, std::vector<const RunResult*>>> by_project;
  for (const RunResult& r : results) {
    if (r.spec.group != "makespan") continue;
    by_project[r.spec.project.name][{r.spec.optimize, r.spec.objective}].push_back(&r);
  }
  if (by_project.empty()) return;
  std::set<std::string> names;
  for (const auto& [p, ways] : by_project) names.insert(p);

  report.Heading(2, "Cycle time: robots at work together (issue 33)");
  report.Para(
      "WRAP's plans with motion, planned by default (fewest actions), with `--objective "
      "makespan` (the task plan's makespan estimate breaks the search's ties) and with "
      "`--optimize --objective makespan` (the estimate minimised; the improvements share the "
      "time limit with motion). `makespan` is the "
      "timed plan with the robots moving at the same time, `sequential` the same motion segments "
      "one at a time, and their ratio says how much the robots' working together saves (1: "
      "nothing). Median / mean over the runs with motion; actions: the mean number of actions "
      "of their plans.");
  std::vector<std::vector<std::string>> rows;
  for (const std::string& p : ProjectOrder(names)) {
    const auto it = by_project.find(p);
    if (it == by_project.end()) continue;
    for (const auto& [way, runs] : it->second) {
      rows.push_back(Row(p, PlanFlags(runs.front()->spec), runs));
    }
  }
  report.Table({"assembly", "plan", "with motion", "makespan [s]", "sequential [s]",
                "makespan / sequential", "actions"},
               rows);
}

}  // namespace wrap::bench
