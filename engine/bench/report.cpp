// The report: the paper's tables and figures with our numbers, as Markdown and as HTML (figures
// as SVG files beside the Markdown, inline in the HTML).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "bench/bench.h"
#include "bench/paper_numbers.h"
#include "bench/report_blocks.h"
#include "bench/svg_plot.h"
#include "core/file_io.h"

namespace wrap::bench {

namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kPlannerOrder = {"optimistic", "wrap",  "flat",
                                                "counting",   "exact", "fine"};
// The paper's colours of its planners in the convergence figure.
std::string PlannerColor(const std::string& planner) {
  static const std::map<std::string, std::string> colors = {
      {"wrap", "#111111"},     {"optimistic", "#0072B2"}, {"flat", "#999999"},
      {"counting", "#009E73"}, {"exact", "#D55E00"},      {"fine", "#CC79A7"}};
  const auto it = colors.find(planner);
  return it == colors.end() ? "#E69F00" : it->second;
}

bool IsPlainTaskRun(const RunResult& r) {
  return !r.spec.motion && !r.spec.optimize && r.spec.wrench == "full" && r.spec.force_scale == 1.0;
}

// Number of parts of a scaling project: a prefix of k steps joins k + 1 parts.
int PartsOf(const ProjectSpec& p) {
  if (p.steps > 0) return p.steps + 1;
  static const std::map<std::string, int> parts = {{"cross", 7}, {"cube", 8}, {"cube_2x2x3", 12}};
  const auto it = parts.find(p.base);
  return it == parts.end() ? 0 : it->second;
}

std::string WrenchModel(const RunSpec& s) {
  if (s.wrench == "none") return "no wrench";
  if (s.wrench == "gravity") return "gravity only";
  return "λ = " + Fmt("%g", s.force_scale);
}

class ReportBuilder : public ReportBlocks {
 public:
  explicit ReportBuilder(const std::vector<RunResult>& results) : results_(results) {}

  std::vector<Block> Build(const RunInfo& info) {
    Heading(1, "Wrap benchmark report");
    if (!info.caveats.empty()) Para("**Incomplete: " + info.caveats + ".**");
    Para("Machine: " + info.machine +
         ". Load average (1, 5, 15 min; other work shares the machine): " + info.load + ".");
    Para("Commit: `" + info.commit + "`" +
         (info.commit.find("+changes") != std::string::npos
              ? " (built with uncommitted changes, which the hash after `+changes.` names)"
              : "") +
         ". Date: " + info.date + ". Settings: " + info.settings + ".");
    Para(
        "The paper's numbers (WRAP, Hartmann et al., §V) are means of 10 runs on the authors' "
        "machine with their models of the assemblies; ours are from the runs below, on the "
        "machine above. Times are wall-clock seconds of the planner's own clocks; `t_init` is "
        "the time to the first task plan without preprocessing. Compare with care.");
    Summary();
    Comparison();
    Breakdown();
    ScalingRobots();
    ScalingParts();
    Convergence();
    Simulation();
    OwnMeasures(results_, *this);
    MakespanObjective(results_, *this);
    Failures();
    return blocks();
  }

 private:
  template <typename Pred>
  std::vector<const RunResult*> Select(Pred pred) const {
    std::vector<const RunResult*> v;
    for (const RunResult& r : results_) {
      if (pred(r)) v.push_back(&r);
    }
    return v;
  }

  void Summary() {
    Heading(2, "Runs");
    std::map<std::string, std::map<std::string, int>> by_group;
    int loaded = 0;
    for (const RunResult& r : results_) {
      ++by_group[r.spec.group][ToString(r.status)];
      ++by_group[r.spec.group]["all"];
      if (r.loaded()) {
        ++by_group[r.spec.group]["loaded"];
        ++loaded;
      }
    }
    std::vector<std::vector<std::string>> rows;
    for (const auto& [g, c] : by_group) {
      const auto n = [&](const char* k) {
        const auto it = c.find(k);
        return std::to_string(it == c.end() ? 0 : it->second);
      };
      rows.push_back({g, n("all"), n("solved"), n("unsolved"), n("timeout"), n("oom"), n("crash"),
                      n("error"), n("loaded")});
    }
    Para(
        "Every run is one child process (`wrap plan`, then `wrap sim` where asked) under a "
        "wall-clock and a memory limit, on cores of its own where the machine has enough; one "
        "row per run is in `results.csv`.");
    Para(loaded == 0
             ? std::string("No run was made while the machine was loaded (on average at least one "
                           "thread more ready to run than the machine has cores).")
             : std::to_string(loaded) + " of " + std::to_string(results_.size()) +
                   " runs were made while the machine was loaded (on average at least one thread "
                   "more ready to run than the machine has cores): their times are inflated. "
                   "A cell with such runs is marked † and their number; `wrap bench` with the "
                   "same options, the same -o and `--rerun-loaded` runs them again.");
    Table({"group", "runs", "solved", "unsolved", "timeout", "oom", "crash", "error", "loaded"},
          rows);
    double wall = 0.0, cpu = 0.0;
    for (const RunResult& r : results_) {
      wall += r.wall_s + r.sim_wall_s;
      cpu += r.cpu_s;
    }
    const auto hours = [](double s) {
      return s < 3600.0 ? Fmt("%.1f", s / 60.0) + " min" : Fmt("%.2f", s / 3600.0) + " h";
    };
    Para("The runs took " + hours(wall) +
         " of run time (plan and simulation children, wall "
         "clock, summed over the runs) and " +
         hours(cpu) + " of CPU time.");
  }

  void Comparison() {
    const auto runs = Select([](const RunResult& r) {
      return IsPlainTaskRun(r) && r.spec.project.robots == 0 && r.spec.project.steps == 0;
    });
    std::set<std::string> projects;
    for (const RunResult* r : runs) projects.insert(r->spec.project.name);
    if (projects.empty()) return;
    Heading(2, "Comparison (paper Table \"comparison\")");
    Para(
        "Time to first task plan `t_init` [s] and cost (number of actions) of the first plan: "
        "mean ± std over the solved runs; the paper's mean beside ours and the ratio ours / "
        "paper (below 1: we are faster or cheaper). Task plans only (`--task-only`).");
    std::vector<std::vector<std::string>> rows;
    const std::vector<std::string> order = ProjectOrder(projects);
    for (const std::string& p : order) {
      if (!projects.contains(p)) continue;
      for (const std::string& planner : kPlannerOrder) {
        const auto cell = Select([&](const RunResult& r) {
          return IsPlainTaskRun(r) && r.spec.project.robots == 0 && r.spec.project.steps == 0 &&
                 r.spec.project.name == p && r.spec.planner == planner;
        });
        if (cell.empty()) continue;
        const Stat t = Summarise(Values(cell, "t_init_s"));
        const Stat c = Summarise(Values(cell, "first_cost"));
        const auto paper = PaperComparisonCell(p, planner);
        std::string pt = "–", pc = "–", rt = "–", rc = "–";
        if (paper && !paper->outcome.empty()) {
          pt = pc = paper->outcome;
        } else if (paper) {
          pt = Fmt("%.2f", paper->t_init_s);
          pc = Fmt("%g", paper->cost);
          if (t.n > 0) rt = Fmt("%.3g", t.mean / paper->t_init_s);
          if (c.n > 0) rc = Fmt("%.2f", c.mean / paper->cost);
        }
        rows.push_back({PaperProjectName(p), PaperPlannerName(planner), SolvedCell(cell),
                        MeanStd(t), pt, rt, MeanStd(c, "%.1f"), pc, rc});
      }
    }
    Table({"assembly", "planner", "solved", "t_init ours", "t_init paper", "ratio", "cost ours",
           "cost paper", "ratio"},
          rows);
  }

  void Breakdown() {
    // With motion (t_mp) where the suite planned it (then also simulated: the simulation does
    // not change the plan's times); else WRAP's task-only runs.
    std::set<std::string> projects;
    for (const RunResult& r : results_) {
      if (r.spec.planner == "wrap" && !r.spec.optimize && r.spec.wrench == "full" &&
          r.spec.force_scale == 1.0 && r.spec.project.robots == 0 && r.spec.project.steps == 0) {
        projects.insert(r.spec.project.name);
      }
    }
    if (projects.empty()) return;
    Heading(2, "Where the time goes (paper Table \"search_time_spent\")");
    Para(
        "WRAP (`--planner wrap`), mean ± std [s] over the runs that reached a task plan, each "
        "with the paper's mean after the slash. `t_grasp` preprocessing, `t_bwd` the backward "
        "abstraction, `t_lp` the wrench LPs, `t_fwd` the forward search without IK and LPs, "
        "`t_ik` IK and collision checks of keyframes, `t_mp` motion planning (runs with motion "
        "only, also where it failed: then the time until it gave up); `motion` counts the runs "
        "whose motion and retiming succeeded (and the mean makespan of their plans).");
    std::vector<std::vector<std::string>> rows;
    const std::vector<std::string> order = ProjectOrder(projects);
    for (const std::string& p : order) {
      if (!projects.contains(p)) continue;
      auto runs = Select([&](const RunResult& r) {
        return r.spec.project.name == p && r.spec.planner == "wrap" && r.spec.motion &&
               !r.spec.optimize && r.spec.wrench == "full" && r.spec.force_scale == 1.0 &&
               r.spec.project.robots == 0 && r.spec.project.steps == 0;
      });
      const bool with_motion = !runs.empty();
      if (!with_motion) {
        runs = Select([&](const RunResult& r) {
          return r.spec.project.name == p && r.spec.planner == "wrap" && IsPlainTaskRun(r) &&
                 r.spec.project.robots == 0 && r.spec.project.steps == 0;
        });
      }
      const auto paper = PaperBreakdownRow(p);
      const auto cell = [&](const std::string& stat, double paper_value) {
        // Task stages of runs that found a task plan, even where motion then failed.
        std::vector<const RunResult*> reached;
        for (const RunResult* r : runs) {
          if (r->solved() || r->stats.contains("t_mp_s") || r->message.starts_with("no motion")) {
            reached.push_back(r);
          }
        }
        std::string s = MeanStd(Summarise(Values(reached, stat, false)));
        if (paper) s += " / " + Fmt("%.2f", paper_value);
        return s;
      };
      std::string motion = "task only";
      if (with_motion) {
        int ok = 0;
        for (const RunResult* r : runs) ok += r->solved() ? 1 : 0;
        motion = std::to_string(ok) + "/" + std::to_string(runs.size()) + LoadedMark(runs);
        const Stat m = Summarise(Values(runs, "makespan_s"));
        if (m.n > 0) motion += ", makespan " + Fmt("%.0f", m.mean) + " s";
      }
      if (std::none_of(runs.begin(), runs.end(), [](const RunResult* r) {
            return r->solved() || r->message.starts_with("no motion");
          })) {
        continue;  // no run reached a task plan: nothing to break down (see the failures)
      }
      const PaperBreakdown pb = paper.value_or(PaperBreakdown{});
      rows.push_back(
          {PaperProjectName(p), motion, cell("t_grasp_s", pb.t_grasp), cell("t_bwd_s", pb.t_bwd),
           cell("t_lp_s", pb.t_lp), cell("t_fwd_s", pb.t_fwd), cell("t_ik_s", pb.t_ik),
           with_motion ? cell("t_mp_s", pb.t_mp)
                       : std::string("–") + (paper ? " / " + Fmt("%.2f", pb.t_mp) : "")});
    }
    Table({"assembly", "motion", "t_grasp", "t_bwd", "t_lp", "t_fwd", "t_ik", "t_mp"}, rows);
  }

  void ScalingRobots() {
    const auto in_study = [](const RunResult& r) {
      return r.spec.planner == "wrap" && !r.spec.motion && !r.spec.optimize &&
             r.spec.project.steps == 0 &&
             (r.spec.project.base == "cross" || r.spec.project.base == "cube_2x2x3");
    };
    const auto runs = Select(in_study);
    // Only when the suite ran the study (fewer robots or other wrench models), not for the one
    // point that the comparison shares with it.
    if (std::none_of(runs.begin(), runs.end(), [](const RunResult* r) {
          return r->spec.project.robots != 0 || r->spec.wrench != "full" ||
                 r->spec.force_scale != 1.0;
        })) {
      return;
    }
    Heading(2, "Scaling with robots and wrench models (paper Figure \"scaling\")");
    Para(
        "Time to first task plan (mean of the solved runs, log scale) of the cross (two-finger "
        "grippers) and the 2x2x3 cube (vacuum) with the first 2, 3 and 4 of their robots, "
        "without wrench checks, with gravity only, and with the mating wrench scaled by λ. The "
        "2- and 3-robot projects are derived by `wrap bench` from the 4-robot examples (their "
        "first robots kept; written to `projects/` in the output folder). A missing point: no "
        "run of it solved (see the table).");
    std::vector<std::string> models = {"no wrench", "gravity only"};
    for (double l : {0.0, 0.01, 0.1, 0.5, 1.0, 2.0}) models.push_back("λ = " + Fmt("%g", l));
    for (const std::string base : {"cross", "cube_2x2x3"}) {
      if (std::none_of(runs.begin(), runs.end(),
                       [&](const RunResult* r) { return r->spec.project.base == base; })) {
        continue;  // not in this suite
      }
      LinePlot plot;
      plot.title = base == "cross" ? "Cross, two-finger grippers" : "Cube 2x2x3, vacuum grippers";
      plot.x_label = "robots";
      plot.y_label = "t_init [s]";
      plot.log_y = true;
      plot.x_ticks = {2, 3, 4};
      std::vector<std::vector<std::string>> rows;
      for (size_t m = 0; m < models.size(); ++m) {
        PlotSeries s;
        s.name = models[m];
        s.color = kPalette[m % kPalette.size()];
        s.dashed = m < 2;
        std::vector<std::string> row = {models[m]};
        for (int robots : {2, 3, 4}) {
          const auto cell = Select([&](const RunResult& r) {
            return in_study(r) && r.spec.project.base == base &&
                   (r.spec.project.robots == 0 ? 4 : r.spec.project.robots) == robots &&
                   WrenchModel(r.spec) == models[m];
          });
          const Stat t = Summarise(Values(cell, "t_init_s"));
          if (t.n > 0) s.points.emplace_back(robots, std::max(t.mean, 1e-3));
          row.push_back(cell.empty() ? "–" : MeanStd(t) + " [" + SolvedCell(cell) + "]");
        }
        rows.push_back(row);
        plot.series.push_back(s);
      }
      Figure("fig_scaling_robots_" + base + ".svg", plot.title, plot);
      Table({base + ": wrench model", "2 robots: t_init [s] [solved]", "3 robots", "4 robots"},
            rows);
    }
  }

  void ScalingParts() {
    const auto runs = Select([](const RunResult& r) {
      return IsPlainTaskRun(r) && r.spec.planner == "wrap" && r.spec.project.robots == 0 &&
             (r.spec.project.base == "cross" || r.spec.project.base == "cube_2x2x3");
    });
    if (std::none_of(runs.begin(), runs.end(),
                     [](const RunResult* r) { return r->spec.project.steps > 0; })) {
      return;
    }
    Heading(2, "Scaling with parts");
    Para(
        "WRAP's time to first task plan against the number of parts: prefixes of the 2x2x3 "
        "cube's sequence (4 cubes = 2x2x1, 8 = 2x2x2, 12 = 2x2x3; vacuum) and of the cross (the "
        "centre and 1 to 6 arms; two-finger), derived by `wrap bench` from the examples.");
    LinePlot plot;
    plot.title = "Parts scaling";
    plot.x_label = "parts";
    plot.y_label = "t_init [s]";
    plot.log_y = true;
    std::vector<std::vector<std::string>> rows;
    int color = 0;
    for (const std::string base : {"cube_2x2x3", "cross"}) {
      PlotSeries s;
      s.name = base == "cross" ? "cross arms" : "cube 2x2xN";
      s.color = kPalette[(color++) * 3 % kPalette.size()];
      std::map<int, std::vector<const RunResult*>> by_parts;
      for (const RunResult* r : runs) {
        if (r->spec.project.base == base) {
          by_parts[PartsOf(r->spec.project)].push_back(r);
        }
      }
      for (const auto& [parts, cell] : by_parts) {
        const Stat t = Summarise(Values(cell, "t_init_s"));
        if (t.n > 0) s.points.emplace_back(parts, std::max(t.mean, 1e-3));
        rows.push_back({cell.front()->spec.project.name, std::to_string(parts), SolvedCell(cell),
                        MeanStd(t), MeanStd(Summarise(Values(cell, "first_cost")), "%.1f")});
      }
      plot.series.push_back(s);
    }
    Figure("fig_scaling_parts.svg", "Parts scaling", plot);
    Table({"project", "parts", "solved", "t_init [s]", "cost"}, rows);
  }

  void Convergence() {
    const auto runs = Select([](const RunResult& r) { return r.spec.optimize && !r.spec.motion; });
    if (runs.empty()) return;
    Heading(2, "Convergence of `--optimize` (paper Figure \"search_conv\")");
    Para(
        "Cost of the best plan over time, one line per run, coloured by planner: the first plan "
        "at `t_init`, then every improvement of the large neighbourhood search until the time "
        "limit. The table gives the first and the final cost (mean ± std of the solved runs).");
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> order = {"cross", "stool", "chair"};
    for (const RunResult* r : runs) {
      if (std::find(order.begin(), order.end(), r->spec.project.name) == order.end()) {
        order.push_back(r->spec.project.name);
      }
    }
    for (const std::string& p : order) {
      LinePlot plot;
      plot.title = PaperProjectName(p);
      plot.x_label = "time [s]";
      plot.y_label = "cost (actions)";
      bool any = false;
      for (size_t k = 0; k < kPlannerOrder.size(); ++k) {
        const std::string& planner = kPlannerOrder[k];
        const auto cell = Select([&](const RunResult& r) {
          return r.spec.optimize && !r.spec.motion && r.spec.project.name == p &&
                 r.spec.planner == planner;
        });
        if (cell.empty()) continue;
        any = true;
        bool first = true;
        for (const RunResult* r : cell) {
          if (!r->solved() || r->cost_history.empty()) continue;
          PlotSeries s;
          s.name = PaperPlannerName(planner);
          s.color = PlannerColor(planner);
          s.step = true;
          s.step_end_x = r->spec.time_limit_s;
          s.points = r->cost_history;
          s.in_legend = first;
          first = false;
          plot.series.push_back(s);
        }
        rows.push_back({PaperProjectName(p), PaperPlannerName(planner), SolvedCell(cell),
                        MeanStd(Summarise(Values(cell, "first_cost")), "%.1f"),
                        MeanStd(Summarise(Values(cell, "cost")), "%.1f"),
                        MeanStd(Summarise(Values(cell, "t_opt_s")), "%.1f")});
      }
      if (any) Figure("fig_convergence_" + p + ".svg", plot.title, plot);
    }
    Table({"assembly", "planner", "solved", "first cost", "final cost", "t_opt [s]"}, rows);
  }

  void Simulation() {
    const auto runs = Select([](const RunResult& r) { return r.spec.sim; });
    if (runs.empty()) return;
    Heading(2, "Simulation of the wrench ablation (paper Table \"wrench_sim\")");
    Para(
        "Plans with motion under each wrench model, run in MuJoCo by `wrap sim`: how many runs "
        "found a plan with motion, how many of all runs held in simulation, the mean actions "
        "completed, the failures, and the mean peak utilisation [%] of the grippers' limits "
        "(two-finger / vacuum) in transport and insertion; the paper's row after the slash.");
    std::vector<std::vector<std::string>> rows;
    for (const std::string p : {"cross", "cube", "chair"}) {
      for (const std::string wrench : {"none", "gravity", "full"}) {
        const auto cell = Select([&](const RunResult& r) {
          return r.spec.sim && r.spec.project.name == p && r.spec.wrench == wrench;
        });
        if (cell.empty()) continue;
        int held = 0, planned = 0;
        double done = 0, total = 0;
        std::map<std::string, int> failures;
        std::map<std::string, std::vector<double>> util;
        for (const RunResult* r : cell) {
          if (r->solved()) ++planned;
          if (r->sim_success && *r->sim_success) ++held;
          done += r->sim_tasks_completed;
          total += r->sim_tasks_total;
          if (!r->sim_failure.empty()) ++failures[r->sim_failure];
          for (const auto& [k, v] : r->sim_util) util[k].push_back(v);
        }
        const auto u = [&](const char* k) {
          const Stat s = Summarise(util[k]);
          return s.n == 0 ? std::string("--") : Fmt("%.0f", s.mean);
        };
        std::string fail;
        for (const auto& [f, n] : failures) {
          fail += (fail.empty() ? "" : ", ") + f + " (" + std::to_string(n) + ")";
        }
        const auto paper = PaperSimRow(p, wrench);
        const auto with = [&](const std::string& ours, const std::string& theirs) {
          return paper ? ours + " / " + theirs : ours;
        };
        const double n = static_cast<double>(cell.size());
        rows.push_back(
            {PaperProjectName(p),
             wrench == "none"      ? "w/o wrench"
             : wrench == "gravity" ? "gravity"
                                   : "full",
             std::to_string(planned) + "/" + std::to_string(cell.size()) + LoadedMark(cell),
             with(Fmt("%.0f", 100.0 * held / n), paper ? paper->success : ""),
             with(Fmt("%.1f", done / n) + "/" + Fmt("%.1f", total / n), paper ? paper->tasks : ""),
             with(fail.empty() ? "--" : fail, paper ? paper->failure : ""),
             with(u("transport_2f"), paper ? paper->transport_2f : ""),
             with(u("transport_vac"), paper ? paper->transport_vac : ""),
             with(u("insertion_2f"), paper ? paper->insertion_2f : ""),
             with(u("insertion_vac"), paper ? paper->insertion_vac : "")});
      }
    }
    Table(
        {"assembly", "model", "planned", "success [%] / paper", "tasks / paper", "failures / paper",
         "transport 2F [%] / paper", "transport vac", "insertion 2F", "insertion vac"},
        rows);
  }

  void Failures() {
    std::vector<std::vector<std::string>> rows;
    for (const RunResult& r : results_) {
      if (r.solved()) continue;
      rows.push_back({r.spec.project.name, r.spec.planner, r.spec.Options(),
                      std::to_string(r.spec.seed), ToString(r.status), r.message});
    }
    if (rows.empty()) return;
    Heading(2, "Runs without a plan");
    Table({"project", "planner", "options", "seed", "status", "why"}, rows);
  }

  const std::vector<RunResult>& results_;
};

}  // namespace

Result<void> WriteReport(const std::vector<RunResult>& given, const RunInfo& info,
                         const fs::path& out) {
  std::vector<RunResult> results = given;
  SortResults(results);
  if (auto w = WriteFileAtomic(out / "results.csv", ResultsCsv(results)); !w) return w;
  const std::vector<Block> blocks = ReportBuilder(results).Build(info);
  for (const Block& b : blocks) {
    if (b.kind != Block::kFigure) continue;
    if (auto w = WriteFileAtomic(out / b.file, b.svg); !w) return w;
  }
  if (auto w = WriteFileAtomic(out / "report.md", ToMarkdown(blocks)); !w) return w;
  return WriteFileAtomic(out / "report.html", ToHtml(blocks));
}

}  // namespace wrap::bench
