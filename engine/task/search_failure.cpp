// The failure record of the task search (task/failure.h): what each tallied check was about, as
// the cases of a milestone that found no plan, with the cell at each.
#include <algorithm>

#include "task/search.h"

namespace wrap {

void GateTally::Add(Gate gate, const std::string& message, const CheckSubject& about) {
  const int i = static_cast<int>(gate);
  ++count[i];
  if (example[i].empty()) {
    example[i] = message;
    subject[i] = about;
  }
  last_gate = gate;
  last_message = message;
  last_subject = about;
}

std::string GateTally::Summary(int max_gates) const {
  const std::vector<Gate> order = Order();
  std::string out;
  for (int k = 0; k < static_cast<int>(order.size()) && k < max_gates; ++k) {
    if (!out.empty()) out += "; ";
    out += Words(order[k]);
  }
  return out.empty() ? "no candidate action passed the cheap checks" : out;
}

std::vector<Gate> GateTally::Order() const {
  std::vector<Gate> order;
  for (int i = 1; i < kNumGates; ++i) {
    if (count[i] > 0) order.push_back(static_cast<Gate>(i));
  }
  std::stable_sort(order.begin(), order.end(), [&](Gate a, Gate b) {
    return count[static_cast<int>(a)] > count[static_cast<int>(b)];
  });
  return order;
}

std::string GateTally::Words(Gate gate) const {
  const int i = static_cast<int>(gate);
  std::string out = std::string(GateName(gate)) + " failed " + std::to_string(count[i]) + "x";
  if (!example[i].empty()) out += " (e.g. " + example[i] + ")";
  return out;
}

FailureScene TaskSearch::SceneOf(const SymState& s, const ContState& c) const {
  FailureScene scene;
  scene.q = c.q;
  scene.X_WP.assign(world_.num_parts, Iso3::Identity());
  for (int node = 0;
       node < static_cast<int>(s.loc.size()) && node < static_cast<int>(c.X_WA.size()); ++node) {
    if (s.loc[node] == kInactive) continue;
    for (int p : world_.tree->nodes[node].parts) scene.X_WP[p] = c.X_WA[node] * world_.X_AP[p];
  }
  return scene;
}

FailureCase TaskSearch::Case(Gate gate, const FailureScene& start) const {
  const int i = static_cast<int>(gate);
  const CheckSubject& about = tally_.subject[i];
  FailureCase fc;
  fc.check = std::string(GateName(gate));
  fc.count = tally_.count[i];
  fc.text = tally_.Words(gate);
  fc.example = tally_.example[i];
  fc.object = about.object;
  fc.robot = about.robot;
  if (about.grasp >= 0) {
    const GraspRef& g = tables_.grasp(about.grasp);
    fc.grasp_part = g.part;
    fc.X_PG = g.X_PG;
    fc.grasp_index = g.index;
  }
  if (about.loc >= 0) {
    fc.X_WA = tables_.location(about.loc).X_WA;
  } else if (about.X_WA) {
    fc.X_WA = about.X_WA;
  }
  if (!tally_.scene[i].X_WP.empty()) {
    fc.scene = tally_.scene[i];  // the cell as the failing check saw it
    return fc;
  }
  fc.scene = start;
  if (fc.X_WA && fc.object >= 0) {
    for (int p : world_.tree->nodes[fc.object].parts) fc.scene.X_WP[p] = *fc.X_WA * world_.X_AP[p];
  }
  // The bodies a cheap check names (its words say which).
  auto gripper = [&](int r) {
    const TaskRobot& R = world_.robots[r];
    return R.name + "/" + (R.end_effector.name.empty() ? "end_effector" : R.end_effector.name);
  };
  if (about.robot >= 0 && (about.hit_table || about.hit_node >= 0)) {
    fc.scene.bodies.push_back(gripper(about.robot));
  }
  if (about.hit_table) fc.scene.bodies.push_back("table");
  if (about.hit_node >= 0 && !world_.tree->nodes[about.hit_node].parts.empty()) {
    fc.scene.bodies.push_back(world_.tree->nodes[about.hit_node].name);
  }
  return fc;
}

std::vector<FailureCase> TaskSearch::Cases(const FailureScene& start) const {
  // The gates Summary names (its words are the report's), most failures first.
  constexpr int kReported = 3;
  std::vector<FailureCase> cases;
  for (Gate g : tally_.Order()) {
    if (static_cast<int>(cases.size()) == kReported) break;
    cases.push_back(Case(g, start));
  }
  return cases;
}

void TaskSearch::Explain(const SymState& s0, const ContState& c0, MilestoneResult& result) const {
  result.start = SceneOf(s0, c0);
  result.cases = Cases(result.start);
}

}  // namespace wrap
