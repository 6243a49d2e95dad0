// The report as blocks (headings, paragraphs, tables, SVG figures), written once as Markdown and
// once as HTML, and the statistics its cells share (mean ± std, solved counts, loaded marks).
#pragma once

#include <set>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "bench/svg_plot.h"

namespace wrap::bench {

/// One block of the report.
struct Block {
  enum Kind { kHeading, kPara, kTable, kFigure } kind = kPara;
  int level = 2;                               ///< kHeading
  std::string text;                            ///< heading, paragraph, figure caption
  std::vector<std::string> header;             ///< kTable
  std::vector<std::vector<std::string>> rows;  ///< kTable
  std::string file;                            ///< kFigure: SVG file name
  std::string svg;                             ///< kFigure: its text
};

/// Collects blocks in order.
class ReportBlocks {
 public:
  void Heading(int level, const std::string& text);
  void Para(const std::string& text);
  void Table(std::vector<std::string> header, std::vector<std::vector<std::string>> rows);
  void Figure(const std::string& file, const std::string& caption, const LinePlot& plot);
  const std::vector<Block>& blocks() const { return blocks_; }

 private:
  std::vector<Block> blocks_;
};

/// The blocks as Markdown (figures as links to their SVG files).
std::string ToMarkdown(const std::vector<Block>& blocks);
/// The blocks as one HTML page (figures inline).
std::string ToHtml(const std::vector<Block>& blocks);

/// printf of one number.
std::string Fmt(const char* format, double v);

/// Mean and sample standard deviation.
struct Stat {
  int n = 0;
  double mean = 0.0, std = 0.0;
};
Stat Summarise(const std::vector<double>& v);
/// "1.23 ± 0.45", "1.23 (1 run)" or "–".
std::string MeanStd(const Stat& s, const char* format = "%.2f");

/// A stat of the runs (of the solved ones unless `solved_only` is false), where they have it.
std::vector<double> Values(const std::vector<const RunResult*>& runs, const std::string& stat,
                           bool solved_only = true);
/// " †k" when k of the runs were made on a loaded machine (RunResult::loaded), else "".
std::string LoadedMark(const std::vector<const RunResult*>& runs);
/// "2/3", the other outcomes in words ("0/3 (timeout 3)"), and the loaded mark.
std::string SolvedCell(const std::vector<const RunResult*>& runs);

/// Colours of the figures' series.
extern const std::vector<std::string> kPalette;
/// The paper's assemblies in its tables' order, then the other projects of `projects` by name.
std::vector<std::string> ProjectOrder(const std::set<std::string>& projects);

/// Wrap's own measures beside the paper's (makespan, robot utilisation over time, simulation
/// success per assembly) from WRAP's runs with motion under the full wrench model.
void OwnMeasures(const std::vector<RunResult>& results, ReportBlocks& report);

/// The makespan suite's section (issue 33): per assembly and way of planning (default, or
/// `--optimize --objective makespan`), the runs with motion, median / mean of makespan_s, of
/// makespan_sequential_s and of their ratio, and the mean number of actions.
void MakespanObjective(const std::vector<RunResult>& results, ReportBlocks& report);

}  // namespace wrap::bench
