// Wrap's own measures beside the paper's tables: makespan, robot utilisation over time and
// simulation success per assembly, from WRAP's runs with motion under the full wrench model.
#include <algorithm>
#include <map>

#include "bench/paper_numbers.h"
#include "bench/report_blocks.h"

namespace wrap::bench {

namespace {

bool IsOwnMeasureRun(const RunResult& r) {
  return r.spec.planner == "wrap" && r.spec.motion && !r.spec.optimize && r.spec.wrench == "full" &&
         r.spec.force_scale == 1.0 && r.spec.project.robots == 0 && r.spec.project.steps == 0;
}

// The simulation columns of one assembly: runs simulated, held, actions completed, failures.
std::vector<std::string> SimCells(const std::vector<const RunResult*>& runs) {
  int simulated = 0, held = 0;
  double done = 0.0, total = 0.0;
  std::map<std::string, int> failures;
  for (const RunResult* r : runs) {
    if (!r->solved() || !r->sim_success) continue;  // no plan: nothing was simulated
    ++simulated;
    if (*r->sim_success) ++held;
    done += r->sim_tasks_completed;
    total += r->sim_tasks_total;
    if (!r->sim_failure.empty()) ++failures[r->sim_failure];
  }
  if (simulated == 0) return {"–", "–", "–"};
  std::string fail;
  for (const auto& [f, n] : failures) {
    fail += (fail.empty() ? "" : ", ") + f + " (" + std::to_string(n) + ")";
  }
  return {std::to_string(held) + "/" + std::to_string(simulated) + " (" +
              Fmt("%.0f", 100.0 * held / simulated) + "%)",
          Fmt("%.1f", done / simulated) + "/" + Fmt("%.1f", total / simulated),
          fail.empty() ? "--" : fail};
}

}  // namespace

void OwnMeasures(const std::vector<RunResult>& results, ReportBlocks& report) {
  std::map<std::string, std::vector<const RunResult*>> by_project;
  for (const RunResult& r : results) {
    if (IsOwnMeasureRun(r)) by_project[r.spec.project.name].push_back(&r);
  }
  if (by_project.empty()) return;
  std::set<std::string> names;
  for (const auto& [p, runs] : by_project) names.insert(p);

  report.Heading(2, "Beyond the paper: makespan, robot utilisation, simulation");
  report.Para(
      "WRAP's plans with motion under the full wrench model (the breakdown's and the "
      "ablation's runs): the makespan of the timed plan, how much of it the robots move (a "
      "robot moves while it takes part in a motion segment: a free path, an approach, a lift, a "
      "carry, an insertion, a descent, a retreat, its gripper closing or opening; holding still "
      "does not count), the busiest twentieth of the makespan (robots moving on average), and "
      "`wrap sim`'s verdict on the plans that were simulated. Mean ± std over the runs with "
      "motion.");
  std::vector<std::vector<std::string>> rows;
  LinePlot plot;
  plot.title = "Robots moving over the makespan";
  plot.x_label = "time [% of the makespan]";
  plot.y_label = "robots moving (mean)";
  plot.x_ticks = {0, 25, 50, 75, 100};
  plot.y_from_zero = true;
  int color = 0;
  for (const std::string& p : ProjectOrder(names)) {
    const auto it = by_project.find(p);
    if (it == by_project.end()) continue;
    const std::vector<const RunResult*>& runs = it->second;
    std::vector<double> moving, busiest;
    std::vector<double> profile(kProfileBins, 0.0);
    int profiled = 0, solved = 0;
    for (const RunResult* r : runs) {
      solved += r->solved() ? 1 : 0;
      if (!r->solved() || !r->utilisation) continue;
      const Utilisation& u = *r->utilisation;
      moving.push_back(100.0 * u.MeanMoving());
      busiest.push_back(u.profile.empty() ? 0.0
                                          : *std::max_element(u.profile.begin(), u.profile.end()));
      for (int k = 0; k < kProfileBins && k < static_cast<int>(u.profile.size()); ++k) {
        profile[k] += u.profile[k];
      }
      ++profiled;
    }
    if (profiled > 0) {
      PlotSeries s;
      s.name = PaperProjectName(p);
      s.color = kPalette[(color++) % kPalette.size()];
      for (int k = 0; k < kProfileBins; ++k) {
        s.points.emplace_back(100.0 * (k + 0.5) / kProfileBins, profile[k] / profiled);
      }
      plot.series.push_back(s);
    }
    std::vector<std::string> row = {
        PaperProjectName(p),
        std::to_string(solved) + "/" + std::to_string(runs.size()) + LoadedMark(runs),
        MeanStd(Summarise(Values(runs, "makespan_s")), "%.1f"), MeanStd(Summarise(moving), "%.0f"),
        MeanStd(Summarise(busiest), "%.1f")};
    for (const std::string& c : SimCells(runs)) row.push_back(c);
    rows.push_back(row);
  }
  report.Table({"assembly", "with motion", "makespan [s]", "robots moving [% of makespan]",
                "busiest twentieth [robots]", "holds in simulation", "actions completed",
                "simulation failures"},
               rows);
  if (!plot.series.empty()) {
    report.Para(
        "Robots moving over the makespan: each run's makespan cut into twenty equal slices, "
        "the robots moving averaged over each slice, then over the runs of an assembly.");
    report.Figure("fig_utilisation.svg", plot.title, plot);
  }
}

}  // namespace wrap::bench
