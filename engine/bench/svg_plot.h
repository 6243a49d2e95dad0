// Line plots as standalone SVG text (the report's figures; no plotting dependency).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace wrap::bench {

/// One line of a plot: points in data units, drawn in `color` with markers.
struct PlotSeries {
  std::string name;                               ///< Legend entry.
  std::string color = "#000000";                  ///< CSS colour.
  std::vector<std::pair<double, double>> points;  ///< (x, y), drawn in this order.
  bool step = false;        ///< Draw as a staircase (value holds until the next point).
  double step_end_x = 0.0;  ///< With `step`: the last value holds until this x (if larger).
  bool markers = true;      ///< Circles at the points.
  bool dashed = false;      ///< Dashed line.
  bool in_legend = true;    ///< Listed in the legend.
};

/// A 2D plot with axes, ticks, a title and a legend.
struct LinePlot {
  std::string title;               ///< Above the plot.
  std::string x_label;             ///< Under the x axis.
  std::string y_label;             ///< Beside the y axis.
  bool log_y = false;              ///< Logarithmic y axis (points with y <= 0 are left out).
  bool y_from_zero = false;        ///< A linear y axis that starts at 0 (counts, shares).
  std::vector<double> x_ticks;     ///< Fixed x ticks; empty: automatic.
  std::vector<PlotSeries> series;  ///< The lines.
  int width_px = 620;              ///< Image size [px].
  int height_px = 340;             ///< Image size [px].
};

/// The plot as an SVG document. A plot without points says "no data" in its frame.
std::string RenderSvg(const LinePlot& plot);

/// Escapes &, <, > and quotes for XML and HTML text.
std::string XmlEscape(const std::string& s);

}  // namespace wrap::bench
