// Reading what a bench child wrote: plan file, simulation report, log.
#include "bench/child_output.h"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "core/file_io.h"

namespace wrap::bench {

namespace {

using Json = nlohmann::json;

using Intervals = std::vector<std::pair<double, double>>;

// Sorted, disjoint intervals covering the same time as `v`.
Intervals Union(Intervals v) {
  std::sort(v.begin(), v.end());
  Intervals out;
  for (const auto& [a, b] : v) {
    if (b <= a) continue;
    if (!out.empty() && a <= out.back().second) {
      out.back().second = std::max(out.back().second, b);
    } else {
      out.emplace_back(a, b);
    }
  }
  return out;
}

double Overlap(const Intervals& v, double a, double b) {
  double t = 0.0;
  for (const auto& [x, y] : v) t += std::max(0.0, std::min(b, y) - std::max(a, x));
  return t;
}

}  // namespace

double Utilisation::MeanMoving() const {
  if (moving.empty()) return 0.0;
  double sum = 0.0;
  for (const auto& [robot, share] : moving) sum += share;
  return sum / static_cast<double>(moving.size());
}

std::optional<Utilisation> UtilisationOfPlan(const std::string& plan_json) {
  const Json j = Json::parse(plan_json, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("segments") || !j["segments"].is_array() ||
      !j.contains("robots") || !j["robots"].is_array()) {
    return std::nullopt;
  }
  std::map<std::string, Intervals> busy;
  for (const Json& r : j["robots"]) {
    if (r.is_string()) busy[r.get<std::string>()];
  }
  double makespan = 0.0;
  if (j.contains("stats") && j["stats"].is_object()) {
    const Json& v = j["stats"].value("makespan_s", Json());
    if (v.is_number()) makespan = v.get<double>();
  }
  for (const Json& s : j["segments"]) {
    if (!s.is_object() || !s.contains("robots") || !s["robots"].is_array()) continue;
    const double a = s.value("start_s", 0.0), b = s.value("end_s", 0.0);
    makespan = std::max(makespan, b);
    for (const Json& r : s["robots"]) {
      if (r.is_string()) busy[r.get<std::string>()].emplace_back(a, b);
    }
  }
  if (busy.empty() || makespan <= 0.0) return std::nullopt;
  Utilisation u;
  u.profile.assign(kProfileBins, 0.0);
  const double bin = makespan / kProfileBins;
  for (auto& [robot, intervals] : busy) {
    const Intervals merged = Union(intervals);
    u.moving[robot] = Overlap(merged, 0.0, makespan) / makespan;
    for (int k = 0; k < kProfileBins; ++k) {
      u.profile[k] += Overlap(merged, k * bin, (k + 1) * bin) / bin;
    }
  }
  return u;
}

PlanOutcome ReadPlanFile(RunResult& r, const std::filesystem::path& plan_file) {
  PlanOutcome outcome;
  auto text = ReadFile(plan_file);
  if (!text) return outcome;
  const Json j = Json::parse(*text, nullptr, false);
  if (j.is_discarded() || !j.contains("stats") || !j["stats"].is_object()) return outcome;
  const Json& st = j["stats"];
  const bool solved = st.value("solved", false);
  const bool motion = st.value("motion", false);
  for (const std::string& k : PlanStatKeys()) {
    if (!st.contains(k) || !st[k].is_number()) continue;
    // Cost and its history mean nothing without a plan; the times do.
    const bool makespan = k == "makespan_s" || k == "makespan_sequential_s";
    if (!solved && (k == "cost" || k == "first_cost" || makespan)) continue;
    // Motion times where motion was tried (also when it failed), none for a task-only plan.
    const bool motion_stat = k == "t_kf_s" || k == "t_mp_s" || k == "t_retime_s";
    if (motion_stat && !motion && st[k].get<double>() == 0.0) continue;
    if (makespan && !motion) continue;
    r.stats[k] = st[k].get<double>();
  }
  if (solved && st.contains("cost_history") && st["cost_history"].is_array()) {
    for (const Json& h : st["cost_history"]) {
      if (h.is_array() && h.size() == 2) {
        r.cost_history.emplace_back(h[0].get<double>(), h[1].get<double>());
      }
    }
  }
  if (solved && motion) r.utilisation = UtilisationOfPlan(*text);
  outcome.failure = st.value("failure", "");
  outcome.out_of_memory = st.value("out_of_memory", false);
  return outcome;
}

void ReadSimReport(RunResult& r, const std::filesystem::path& report_file) {
  auto text = ReadFile(report_file);
  const Json j = text ? Json::parse(*text, nullptr, false) : Json();
  if (!text || j.is_discarded() || !j.is_object() || !j.contains("success")) {
    r.sim_success = false;
    r.sim_failure = "no sim report";
    return;
  }
  r.sim_success = j.value("success", false);
  r.sim_tasks_completed = j.value("tasks_completed", 0);
  r.sim_tasks_total = j.value("tasks_total", 0);
  if (j.contains("failure") && j["failure"].is_object()) {
    r.sim_failure = j["failure"].value("reason", "failed");
  }
  if (j.contains("peak_utilisation_percent")) {
    const Json& u = j["peak_utilisation_percent"];
    const auto get = [&](const char* phase, const char* kind, const char* name) {
      if (u.contains(phase) && u[phase].contains(kind) && u[phase][kind].is_number()) {
        r.sim_util[name] = u[phase][kind].get<double>();
      }
    };
    get("transport", "two_finger", "transport_2f");
    get("transport", "vacuum", "transport_vac");
    get("insertion", "two_finger", "insertion_2f");
    get("insertion", "vacuum", "insertion_vac");
  }
}

std::string LastLine(const std::filesystem::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  if (last.size() > 300) last = last.substr(0, 300) + "...";
  return last;
}

bool LogMentions(const std::filesystem::path& log, const std::string& what) {
  std::ifstream in(log);
  std::stringstream s;
  s << in.rdbuf();
  return s.str().find(what) != std::string::npos;
}

}  // namespace wrap::bench
