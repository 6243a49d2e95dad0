// Run results as files: one JSON per run (runs/KEY.json), results.csv, merging shard folders.
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "bench/bench.h"
#include "core/file_io.h"

namespace wrap::bench {

namespace {

using Json = nlohmann::ordered_json;

const std::vector<std::string> kUtilColumns = {"transport_2f", "transport_vac", "insertion_2f",
                                               "insertion_vac"};

std::string Num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// RFC 4180: quoted when it holds a comma, a quote or a line break.
std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

}  // namespace

const std::vector<std::string>& PlanStatKeys() {
  static const std::vector<std::string> keys = {"cost",       "first_cost",
                                                "t_init_s",   "t_grasp_s",
                                                "t_bwd_s",    "t_lp_s",
                                                "t_fwd_s",    "t_ik_s",
                                                "t_kf_s",     "t_mp_s",
                                                "t_retime_s", "t_opt_s",
                                                "makespan_s", "makespan_sequential_s"};
  return keys;
}

std::string RunResultToJson(const RunResult& r) {
  Json j;
  j["format"] = "wrap-bench-run";
  j["version"] = 1;
  j["project"] = {{"name", r.spec.project.name},
                  {"base", r.spec.project.base},
                  {"robots", r.spec.project.robots},
                  {"steps", r.spec.project.steps}};
  j["group"] = r.spec.group;
  j["planner"] = r.spec.planner;
  j["wrench"] = r.spec.wrench;
  j["force_scale"] = r.spec.force_scale;
  j["optimize"] = r.spec.optimize;
  j["objective"] = r.spec.objective;
  j["motion"] = r.spec.motion;
  j["sim"] = r.spec.sim;
  j["seed"] = r.spec.seed;
  j["time_limit_s"] = r.spec.time_limit_s;
  j["status"] = ToString(r.status);
  j["exit_code"] = r.exit_code;
  j["signal"] = r.signal;
  j["wall_s"] = r.wall_s;
  j["peak_rss_mib"] = r.peak_rss_mib;
  j["cpu_s"] = r.cpu_s;
  j["sim_wall_s"] = r.sim_wall_s;
  Json stats = Json::object();
  for (const auto& [k, v] : r.stats) stats[k] = v;
  j["stats"] = stats;
  Json hist = Json::array();
  for (const auto& [t, c] : r.cost_history) hist.push_back({t, c});
  j["cost_history"] = hist;
  if (r.sim_success) {
    Json util = Json::object();
    for (const auto& [k, v] : r.sim_util) util[k] = v;
    j["sim"] = {{"success", *r.sim_success},
                {"tasks_completed", r.sim_tasks_completed},
                {"tasks_total", r.sim_tasks_total},
                {"failure", r.sim_failure},
                {"peak_utilisation_percent", util}};
  }
  if (r.utilisation) {
    Json moving = Json::object();
    for (const auto& [k, v] : r.utilisation->moving) moving[k] = v;
    j["utilisation"] = {{"moving", moving}, {"profile", r.utilisation->profile}};
  }
  j["load"] = r.load;
  j["cores"] = r.cores;
  j["host"] = r.host;
  j["message"] = r.message;
  return j.dump(2) + "\n";
}

Result<RunResult> RunResultFromJson(const std::string& text, const std::string& source) {
  const Json j = Json::parse(text, nullptr, false);
  const auto bad = [&](const std::string& field) {
    return Fail(ErrorCode::kInvalidInput,
                source + ": " + field + ": missing or of the wrong type (a wrap-bench-run file?)");
  };
  if (j.is_discarded() || !j.is_object()) return bad("(root)");
  if (j.value("format", "") != "wrap-bench-run") return bad("format");
  RunResult r;
  try {
    const Json& p = j.at("project");
    r.spec.project.name = p.at("name").get<std::string>();
    r.spec.project.base = p.value("base", r.spec.project.name);
    r.spec.project.robots = p.value("robots", 0);
    r.spec.project.steps = p.value("steps", 0);
    r.spec.group = j.at("group").get<std::string>();
    r.spec.project.group = r.spec.group;
    r.spec.planner = j.at("planner").get<std::string>();
    r.spec.wrench = j.at("wrench").get<std::string>();
    r.spec.force_scale = j.at("force_scale").get<double>();
    r.spec.optimize = j.at("optimize").get<bool>();
    // Files written before the objective was a setting were planned with the default.
    r.spec.objective = j.value("objective", "actions");
    if (r.spec.objective != "actions" && r.spec.objective != "makespan") return bad("objective");
    r.spec.motion = j.at("motion").get<bool>();
    r.spec.seed = j.at("seed").get<std::uint64_t>();
    r.spec.time_limit_s = j.at("time_limit_s").get<double>();
    const auto status = ParseStatus(j.at("status").get<std::string>());
    if (!status) return bad("status");
    r.status = *status;
    r.exit_code = j.value("exit_code", -1);
    r.signal = j.value("signal", 0);
    r.wall_s = j.value("wall_s", 0.0);
    r.peak_rss_mib = j.value("peak_rss_mib", 0.0);
    r.cpu_s = j.value("cpu_s", 0.0);
    r.sim_wall_s = j.value("sim_wall_s", 0.0);
    for (const auto& [k, v] : j.at("stats").items()) r.stats[k] = v.get<double>();
    for (const Json& h : j.at("cost_history")) {
      r.cost_history.emplace_back(h.at(0).get<double>(), h.at(1).get<double>());
    }
    const Json& sim = j.at("sim");
    if (sim.is_object()) {
      r.spec.sim = true;
      r.sim_success = sim.at("success").get<bool>();
      r.sim_tasks_completed = sim.value("tasks_completed", 0);
      r.sim_tasks_total = sim.value("tasks_total", 0);
      r.sim_failure = sim.value("failure", "");
      for (const auto& [k, v] : sim.at("peak_utilisation_percent").items()) {
        r.sim_util[k] = v.get<double>();
      }
    } else {
      r.spec.sim = sim.get<bool>();
    }
    if (j.contains("utilisation")) {
      Utilisation u;
      for (const auto& [k, v] : j.at("utilisation").at("moving").items()) {
        u.moving[k] = v.get<double>();
      }
      u.profile = j.at("utilisation").at("profile").get<std::vector<double>>();
      r.utilisation = u;
    }
    r.load = j.value("load", -1.0);
    r.cores = j.value("cores", 0);
    r.host = j.value("host", "");
    r.message = j.value("message", "");
  } catch (const Json::exception& e) {
    return Fail(ErrorCode::kInvalidInput, source + ": " + e.what());
  }
  return r;
}

std::string ResultsCsv(const std::vector<RunResult>& results) {
  std::ostringstream s;
  s << "project,planner,options,seed,status,solved";
  for (const std::string& c : PlanStatKeys()) s << "," << c;
  s << ",peak_rss_mib,wall_s,cpu_s,sim_wall_s,exit_code,signal,sim_success,sim_tasks,sim_failure";
  for (const std::string& c : kUtilColumns) s << ",sim_util_" << c;
  s << ",robots_moving_percent,moving_profile,load,cores,loaded,host,cost_history,group,message\n";
  for (const RunResult& r : results) {
    s << CsvField(r.spec.project.name) << "," << r.spec.planner << "," << r.spec.Options() << ","
      << r.spec.seed << "," << ToString(r.status) << "," << (r.solved() ? 1 : 0);
    for (const std::string& c : PlanStatKeys()) {
      s << ",";
      if (auto it = r.stats.find(c); it != r.stats.end()) s << Num(it->second);
    }
    s << "," << Num(r.peak_rss_mib) << "," << Num(r.wall_s) << "," << Num(r.cpu_s) << ","
      << Num(r.sim_wall_s) << "," << r.exit_code << "," << r.signal << ",";
    if (r.sim_success) s << (*r.sim_success ? 1 : 0);
    s << ",";
    if (r.sim_success) s << r.sim_tasks_completed << "/" << r.sim_tasks_total;
    s << "," << CsvField(r.sim_failure);
    for (const std::string& c : kUtilColumns) {
      s << ",";
      if (auto it = r.sim_util.find(c); it != r.sim_util.end()) s << Num(it->second);
    }
    s << ",";
    if (r.utilisation) {
      s << Num(100.0 * r.utilisation->MeanMoving()) << ",";
      std::string profile;
      for (double v : r.utilisation->profile) profile += (profile.empty() ? "" : " ") + Num(v);
      s << profile;
    } else {
      s << ",";
    }
    s << ",";
    if (r.load >= 0.0) s << Num(r.load);
    s << "," << r.cores << "," << (r.loaded() ? 1 : 0) << "," << CsvField(r.host);
    std::string hist;
    for (const auto& [t, c] : r.cost_history) {
      hist += (hist.empty() ? "" : " ") + Num(t) + ":" + Num(c);
    }
    s << "," << hist << "," << r.spec.group << "," << CsvField(r.message) << "\n";
  }
  return s.str();
}

Result<std::vector<RunResult>> ReadRunResults(const std::vector<std::filesystem::path>& dirs) {
  namespace fs = std::filesystem;
  std::vector<RunResult> all;
  std::set<std::string> keys;
  for (const fs::path& dir : dirs) {
    const fs::path runs = dir / "runs";
    std::error_code ec;
    if (!fs::is_directory(runs, ec)) {
      return Fail(ErrorCode::kInvalidInput,
                  runs.string() + ": no runs folder (not the output of `wrap bench`?)");
    }
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(runs, ec)) {
      if (e.path().extension() == ".json") files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      auto text = ReadFile(f);
      if (!text) return std::unexpected(text.error());
      auto r = RunResultFromJson(*text, f.string());
      if (!r) return std::unexpected(r.error());
      if (keys.insert(r->spec.Key()).second) all.push_back(std::move(*r));
    }
  }
  SortResults(all);
  return all;
}

}  // namespace wrap::bench
