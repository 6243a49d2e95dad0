#include <nlohmann/json.hpp>

#include "verify/simulate.h"

namespace wrap {

namespace {

// A utilisation as a percentage, null where no gripper of the kind took part.
nlohmann::ordered_json Percent(double u) {
  if (u < 0.0) return nullptr;
  return std::round(1000.0 * u) / 10.0;
}

}  // namespace

std::string SerializeSimReport(const SimReport& report) {
  using Json = nlohmann::ordered_json;
  Json j;
  j["format"] = "wrap-sim-report";
  j["version"] = 1;
  j["success"] = report.success;
  j["tasks_completed"] = report.tasks_completed;
  j["tasks_total"] = report.tasks_total;
  j["tasks"] = std::to_string(report.tasks_completed) + "/" + std::to_string(report.tasks_total);
  if (report.failure) {
    j["failure"] = {{"action", report.failure->action},
                    {"reason", report.failure->reason},
                    {"detail", report.failure->detail},
                    {"t_s", report.failure->t_s}};
  } else {
    j["failure"] = nullptr;
  }
  j["peak_utilisation_percent"] = {{"transport",
                                    {{"two_finger", Percent(report.peak.two_finger_transport)},
                                     {"vacuum", Percent(report.peak.vacuum_transport)}}},
                                   {"insertion",
                                    {{"two_finger", Percent(report.peak.two_finger_insertion)},
                                     {"vacuum", Percent(report.peak.vacuum_insertion)}}},
                                   {"connection", Percent(report.peak.connection)},
                                   {"table_friction", Percent(report.peak.table_friction)}};
  Json actions = Json::array();
  for (size_t i = 0; i < report.actions.size(); ++i) {
    const SimActionStatus& a = report.actions[i];
    actions.push_back({{"index", i},
                       {"type", a.type},
                       {"status", a.status},
                       {"peak_utilisation_percent", Percent(a.peak_utilisation)}});
  }
  j["actions"] = std::move(actions);
  j["final_position_error_m"] = report.final_position_error_m;
  j["final_angle_error_rad"] = report.final_angle_error_rad;
  j["simulated_s"] = report.simulated_s;
  j["steps"] = report.steps;
  j["robots_driven"] = report.driving;
  j["motion"] = report.motion;
  j["collisions_judged"] = report.collisions_judged;
  j["collision_checks"] = report.collision_checks;
  j["split_measurements"] = report.split_measurements;
  j["notes"] = report.notes;
  j["warnings"] = report.warnings;
  return j.dump(2) + "\n";
}

}  // namespace wrap
