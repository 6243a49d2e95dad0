// SVG line plots: linear or logarithmic y, "nice" ticks, staircase lines for cost over time.
#include "bench/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace wrap::bench {

namespace {

std::string F(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string Label(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Ticks at 1, 2 or 5 times a power of ten covering [lo, hi].
std::vector<double> NiceTicks(double lo, double hi) {
  if (!(hi > lo)) hi = lo + 1.0;
  const double raw = (hi - lo) / 5.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (raw <= step) break;
  }
  std::vector<double> t;
  for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step) {
    t.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  }
  return t;
}

}  // namespace

std::string XmlEscape(const std::string& s) {
  std::string r;
  for (char c : s) {
    switch (c) {
      case '&':
        r += "&amp;";
        break;
      case '<':
        r += "&lt;";
        break;
      case '>':
        r += "&gt;";
        break;
      case '"':
        r += "&quot;";
        break;
      default:
        r += c;
    }
  }
  return r;
}

std::string RenderSvg(const LinePlot& plot) {
  const double W = plot.width_px, H = plot.height_px;
  const double left = 62, right = 180, top = 30, bottom = 46;
  const double pw = W - left - right, ph = H - top - bottom;

  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const PlotSeries& s : plot.series) {
    for (const auto& [x, y] : s.points) {
      if (plot.log_y && y <= 0.0) continue;
      x0 = std::min(x0, x);
      x1 = std::max(x1, std::max(x, s.step ? s.step_end_x : x));
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  for (double t : plot.x_ticks) {
    x0 = std::min(x0, t);
    x1 = std::max(x1, t);
  }
  if (plot.y_from_zero && !plot.log_y && std::isfinite(y0)) y0 = std::min(y0, 0.0);
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
    << "\" viewBox=\"0 0 " << W << " " << H << "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o << "<text x=\"" << F(left + pw / 2) << "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">"
    << XmlEscape(plot.title) << "</text>\n";
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
    << "\" fill=\"none\" stroke=\"#444\"/>\n";
  if (!std::isfinite(x0)) {
    o << "<text x=\"" << F(left + pw / 2) << "\" y=\"" << F(top + ph / 2)
      << "\" text-anchor=\"middle\" fill=\"#888\">no data</text>\n</svg>\n";
    return o.str();
  }
  // Value ranges with a margin; a logarithmic axis spans whole decades.
  if (x1 <= x0) {
    x0 -= 1.0;
    x1 += 1.0;
  }
  std::vector<double> yticks;
  double ly0 = 0, ly1 = 0;
  if (plot.log_y) {
    ly0 = std::floor(std::log10(y0));
    ly1 = std::ceil(std::log10(y1));
    if (ly1 <= ly0) ly1 = ly0 + 1;
    for (double e = ly0; e <= ly1 + 1e-9; e += 1.0) yticks.push_back(std::pow(10.0, e));
  } else {
    if (y1 <= y0) {
      y0 -= 1.0;
      y1 += 1.0;
    }
    const double m = 0.08 * (y1 - y0);
    const double m_low = plot.y_from_zero && y0 == 0.0 ? 0.0 : m;  // the axis starts at 0
    yticks = NiceTicks(y0 - m_low, y1 + m);
    y0 = std::min(y0 - m_low, yticks.front());
    y1 = std::max(y1 + m, yticks.back());
  }
  const double xm = plot.x_ticks.empty() ? 0.0 : 0.05 * (x1 - x0);
  const double xa = x0 - xm, xb = x1 + xm;
  const auto X = [&](double x) { return left + (x - xa) / (xb - xa) * pw; };
  const auto Y = [&](double y) {
    if (plot.log_y) return top + ph - (std::log10(y) - ly0) / (ly1 - ly0) * ph;
    return top + ph - (y - y0) / (y1 - y0) * ph;
  };
  const std::vector<double> xticks = plot.x_ticks.empty() ? NiceTicks(xa, xb) : plot.x_ticks;
  for (double t : xticks) {
    if (t < xa - 1e-9 || t > xb + 1e-9) continue;
    o << "<line x1=\"" << F(X(t)) << "\" y1=\"" << top << "\" x2=\"" << F(X(t)) << "\" y2=\""
      << top + ph << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << F(X(t)) << "\" y=\"" << F(top + ph + 15) << "\" text-anchor=\"middle\">"
      << Label(t) << "</text>\n";
  }
  for (double t : yticks) {
    o << "<line x1=\"" << left << "\" y1=\"" << F(Y(t)) << "\" x2=\"" << left + pw << "\" y2=\""
      << F(Y(t)) << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << left - 5 << "\" y=\"" << F(Y(t) + 4) << "\" text-anchor=\"end\">"
      << Label(t) << "</text>\n";
  }
  o << "<text x=\"" << F(left + pw / 2) << "\" y=\"" << H - 8 << "\" text-anchor=\"middle\">"
    << XmlEscape(plot.x_label) << "</text>\n";
  o << "<text transform=\"translate(14," << F(top + ph / 2)
    << ") rotate(-90)\" text-anchor=\"middle\">" << XmlEscape(plot.y_label) << "</text>\n";

  int legend_row = 0;
  for (const PlotSeries& s : plot.series) {
    std::vector<std::pair<double, double>> pts;
    for (const auto& p : s.points) {
      if (!plot.log_y || p.second > 0.0) pts.push_back(p);
    }
    if (pts.empty()) continue;
    std::ostringstream path;
    for (size_t i = 0; i < pts.size(); ++i) {
      if (i == 0) {
        path << "M" << F(X(pts[i].first)) << "," << F(Y(pts[i].second));
      } else if (s.step) {
        path << " H" << F(X(pts[i].first)) << " V" << F(Y(pts[i].second));
      } else {
        path << " L" << F(X(pts[i].first)) << "," << F(Y(pts[i].second));
      }
    }
    if (s.step && s.step_end_x > pts.back().first) path << " H" << F(X(s.step_end_x));
    o << "<path d=\"" << path.str() << "\" fill=\"none\" stroke=\"" << s.color
      << "\" stroke-width=\"1.6\"" << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/>\n";
    if (s.markers) {
      for (const auto& [x, y] : pts) {
        o << "<circle cx=\"" << F(X(x)) << "\" cy=\"" << F(Y(y)) << "\" r=\"2.8\" fill=\""
          << s.color << "\"/>\n";
      }
    }
    if (s.in_legend) {
      const double ly = top + 8 + 16 * legend_row++;
      o << "<line x1=\"" << left + pw + 10 << "\" y1=\"" << F(ly) << "\" x2=\"" << left + pw + 30
        << "\" y2=\"" << F(ly) << "\" stroke=\"" << s.color << "\" stroke-width=\"2\""
        << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/>\n";
      o << "<text x=\"" << left + pw + 35 << "\" y=\"" << F(ly + 4) << "\">" << XmlEscape(s.name)
        << "</text>\n";
    }
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace wrap::bench
