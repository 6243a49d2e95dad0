// The report's blocks as Markdown and HTML, and the statistics its cells share.
#include "bench/report_blocks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "bench/paper_numbers.h"

namespace wrap::bench {

namespace {

// Markdown table cells cannot hold a bar or a line break.
std::string MdCell(std::string s) {
  std::string r;
  for (char c : s) {
    if (c == '|') {
      r += "\\|";
    } else if (c == '\n') {
      r += ' ';
    } else {
      r += c;
    }
  }
  return r;
}

// Paragraph text: escaped, `code` spans as <code>.
std::string HtmlText(const std::string& s) {
  std::string r;
  bool code = false;
  for (char c : s) {
    if (c == '`') {
      r += code ? "</code>" : "<code>";
      code = !code;
    } else {
      r += XmlEscape(std::string(1, c));
    }
  }
  if (code) r += "</code>";
  return r;
}

}  // namespace

const std::vector<std::string> kPalette = {"#111111", "#0072B2", "#999999", "#009E73",
                                           "#D55E00", "#CC79A7", "#E69F00", "#56B4E9"};

std::string ToMarkdown(const std::vector<Block>& blocks) {
  std::ostringstream o;
  for (const Block& b : blocks) {
    switch (b.kind) {
      case Block::kHeading:
        o << std::string(b.level, '#') << " " << b.text << "\n\n";
        break;
      case Block::kPara:
        o << b.text << "\n\n";
        break;
      case Block::kTable: {
        o << "|";
        for (const std::string& h : b.header) o << " " << MdCell(h) << " |";
        o << "\n|";
        for (size_t i = 0; i < b.header.size(); ++i) o << "---|";
        o << "\n";
        for (const auto& row : b.rows) {
          o << "|";
          for (const std::string& c : row) o << " " << MdCell(c) << " |";
          o << "\n";
        }
        o << "\n";
        break;
      }
      case Block::kFigure:
        o << "![" << b.text << "](" << b.file << ")\n\n";
        break;
    }
  }
  return o.str();
}

std::string ToHtml(const std::vector<Block>& blocks) {
  std::ostringstream o;
  o << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>Wrap benchmark report"
       "</title>\n<style>body{font-family:sans-serif;max-width:1200px;margin:2em auto;padding:0 "
       "1em}table{border-collapse:collapse;margin:1em 0;font-size:13px}td,th{border:1px solid "
       "#ccc;padding:3px 6px;text-align:left}th{background:#f3f3f3}code{background:#f5f5f5}"
       "figure{margin:1em 0}</style></head><body>\n";
  for (const Block& b : blocks) {
    switch (b.kind) {
      case Block::kHeading:
        o << "<h" << b.level << ">" << HtmlText(b.text) << "</h" << b.level << ">\n";
        break;
      case Block::kPara:
        o << "<p>" << HtmlText(b.text) << "</p>\n";
        break;
      case Block::kTable:
        o << "<table><tr>";
        for (const std::string& h : b.header) o << "<th>" << HtmlText(h) << "</th>";
        o << "</tr>\n";
        for (const auto& row : b.rows) {
          o << "<tr>";
          for (const std::string& c : row) o << "<td>" << HtmlText(c) << "</td>";
          o << "</tr>\n";
        }
        o << "</table>\n";
        break;
      case Block::kFigure:
        o << "<figure>" << b.svg << "<figcaption>" << HtmlText(b.text)
          << "</figcaption></figure>\n";
        break;
    }
  }
  o << "</body></html>\n";
  return o.str();
}

void ReportBlocks::Heading(int level, const std::string& text) {
  Block b;
  b.kind = Block::kHeading;
  b.level = level;
  b.text = text;
  blocks_.push_back(b);
}

void ReportBlocks::Para(const std::string& text) {
  Block b;
  b.kind = Block::kPara;
  b.text = text;
  blocks_.push_back(b);
}

void ReportBlocks::Table(std::vector<std::string> header,
                         std::vector<std::vector<std::string>> rows) {
  Block b;
  b.kind = Block::kTable;
  b.header = std::move(header);
  b.rows = std::move(rows);
  blocks_.push_back(b);
}

void ReportBlocks::Figure(const std::string& file, const std::string& caption,
                          const LinePlot& plot) {
  Block b;
  b.kind = Block::kFigure;
  b.file = file;
  b.text = caption;
  b.svg = RenderSvg(plot);
  blocks_.push_back(b);
}

std::vector<std::string> ProjectOrder(const std::set<std::string>& projects) {
  std::vector<std::string> order = PaperComparisonProjects();
  for (const std::string& p : projects) {
    if (std::find(order.begin(), order.end(), p) == order.end()) order.push_back(p);
  }
  return order;
}

std::string Fmt(const char* f, double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

Stat Summarise(const std::vector<double>& v) {
  Stat s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  for (double x : v) s.mean += x;
  s.mean /= s.n;
  if (s.n > 1) {
    for (double x : v) s.std += (x - s.mean) * (x - s.mean);
    s.std = std::sqrt(s.std / (s.n - 1));
  }
  return s;
}

std::string MeanStd(const Stat& s, const char* f) {
  if (s.n == 0) return "–";
  if (s.n == 1) return Fmt(f, s.mean) + " (1 run)";
  return Fmt(f, s.mean) + " ± " + Fmt(f, s.std);
}

std::vector<double> Values(const std::vector<const RunResult*>& runs, const std::string& stat,
                           bool solved_only) {
  std::vector<double> v;
  for (const RunResult* r : runs) {
    if (solved_only && !r->solved()) continue;
    if (auto it = r->stats.find(stat); it != r->stats.end()) v.push_back(it->second);
  }
  return v;
}

std::string LoadedMark(const std::vector<const RunResult*>& runs) {
  const auto n =
      std::count_if(runs.begin(), runs.end(), [](const RunResult* r) { return r->loaded(); });
  return n == 0 ? "" : " †" + std::to_string(n);
}

std::string SolvedCell(const std::vector<const RunResult*>& runs) {
  int solved = 0;
  std::map<std::string, int> other;
  for (const RunResult* r : runs) {
    if (r->solved()) {
      ++solved;
    } else {
      ++other[ToString(r->status)];
    }
  }
  std::string s = std::to_string(solved) + "/" + std::to_string(runs.size());
  if (!other.empty()) {
    s += " (";
    bool first = true;
    for (const auto& [k, n] : other) {
      s += (first ? "" : ", ") + k + " " + std::to_string(n);
      first = false;
    }
    s += ")";
  }
  return s + LoadedMark(runs);
}

}  // namespace wrap::bench
