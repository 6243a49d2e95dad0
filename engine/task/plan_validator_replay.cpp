// The plan validator's replay: who holds what, action by action, from the project's initial
// state. Each action type has its own function that checks the action's preconditions, says what
// its keyframe may show (a Moment for plan_validator_keyframe.cpp), runs its wrench gate and
// applies its effects to the replayed state.
//
// This replay is independent of the planner ON PURPOSE: it must never call the search's own
// state-update code (task/state.h, task/world.h and friends) but keeps its own objects, holders
// and joints, so that a bug in the planner's model of an action cannot hide by being repeated
// here. (The plan module does not link the task module, so such a call would not even build.)
// Nor does it use task/plan_state.h's ApplyAction, which the motion scene, the keyframe
// optimisation, the simulation and the renderer share: the validator checks plans against
// plan.h's semantics and must not reuse the code it checks. When the semantics of an action
// change, change plan.h, ApplyAction, the planner and this replay, each on its own.
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "task/plan_validator_internal.h"

namespace wrap::plan_validator_internal {

PlanValidation Validator::Run() {
  CheckNames();
  CheckInitial();
  const int n_actions = static_cast<int>(plan_.actions.size());
  bool stopped = false;
  for (int i = 0; i < n_actions; ++i) {
    const int before = out_.actions;
    ReplayAction(i);
    if (out_.actions == before) {
      stopped = true;
      break;
    }
  }
  if (options_.require_complete && !stopped) CheckComplete(n_actions - 1);
  out_.valid = out_.issues.empty();
  return std::move(out_);
}

// After the last action (`last`): the root alone, resting, every robot free.
void Validator::CheckComplete(int last) {
  const int root = tree_.root;
  if (objects_.size() != 1 || !objects_.count(root)) {
    std::string names;
    for (const auto& [node, s] : objects_)
      names += (names.empty() ? "" : ", ") + Quote(NodeName(node));
    Issue(last, "incomplete",
          "the plan ends with " + std::to_string(objects_.size()) + " objects (" + names +
              "), not with the assembly " + Quote(NodeName(root)) + " alone");
  } else if (!objects_.at(root).resting) {
    Issue(last, "incomplete",
          "the plan ends with " + Quote(NodeName(root)) +
              " in the air instead of resting on the table");
  }
  for (size_t r = 0; r < robots_.size(); ++r) {
    if (holding_[r] >= 0) {
      Issue(last, "incomplete",
            "the plan ends with robot " + Quote(robots_[r].name) + " still holding " +
                Quote(NodeName(holding_[r])));
    }
  }
}

void Validator::CheckInitial() {
  // Every part rests at its initial pose; robots at home (the plan's initial joints).
  for (size_t p = 0; p < project_.parts.size(); ++p) {
    ObjectState s;
    s.X_WA = ToIsometry(project_.parts[p].initial_pose) * X_AP_[p].inverse();
    objects_[static_cast<int>(p)] = s;
  }
  q_ = plan_.initial.q;
  holding_.assign(robots_.size(), -1);
  may_move_.assign(robots_.size(), 0);
  Moment m;
  for (const auto& [node, s] : objects_) m.rest_check.insert(node);
  CheckKeyframe(-1, "initial keyframe: ", plan_.initial, m);
}

void Validator::ReplayAction(int i) {
  const PlanAction& a = plan_.actions[i];
  if (!ActionShapeOk(i, a)) return;
  freed_now_.clear();
  Moment m;
  m.acted.insert(a.objects.begin(), a.objects.end());
  switch (a.type) {
    case ActionType::kPick:
      ReplayPick(i, a, m);
      break;
    case ActionType::kPlace:
      ReplayPlace(i, a, m);
      break;
    case ActionType::kHandover:
      ReplayHandover(i, a, m);
      break;
    case ActionType::kAddGrasp:
      ReplayAddGrasp(i, a, m);
      break;
    case ActionType::kRelease:
      ReplayRelease(i, a, m);
      break;
    case ActionType::kAssemble:
      if (!ReplayAssemble(i, a, m)) return;
      break;
  }

  // Objects the action moved took their keyframe pose (in its Replay*); the robots take their
  // joints.
  q_ = a.keyframe.q;
  for (size_t r = 0; r < robots_.size(); ++r) may_move_[r] = freed_now_.count(static_cast<int>(r));
  ++out_.actions;
}

bool Validator::ActionShapeOk(int index, const PlanAction& a) {
  size_t robots = 1, objects = 1;
  switch (a.type) {
    case ActionType::kHandover:
      robots = 2;
      break;
    case ActionType::kAssemble:
      robots = a.robots.empty() ? 1 : a.robots.size();
      objects = 3;
      break;
    default:
      break;
  }
  if (a.robots.size() != robots || a.objects.size() != objects || a.grasps.size() != robots) {
    Issue(index, "precondition",
          std::string(ToString(a.type)) + " is malformed: " + std::to_string(a.robots.size()) +
              " robots, " + std::to_string(a.objects.size()) + " objects and " +
              std::to_string(a.grasps.size()) + " grasps (expected " + std::to_string(robots) +
              ", " + std::to_string(objects) + ", " + std::to_string(robots) +
              "); the replay stops here");
    return false;
  }
  std::set<int> distinct(a.robots.begin(), a.robots.end());
  if (distinct.size() != a.robots.size()) {
    Issue(index, "precondition", "a robot appears twice in the action's robots");
  }
  for (size_t k = 0; k < a.robots.size(); ++k) {
    if (a.grasps[k].robot != a.robots[k]) {
      Issue(index, "precondition",
            "grasp " + std::to_string(k) + " belongs to robot " +
                Quote(RobotName(a.grasps[k].robot)) + ", but the action's robot " +
                std::to_string(k) + " is " + Quote(RobotName(a.robots[k])));
    }
  }
  for (size_t k = 0; k < objects; ++k) {
    const int o = a.objects[k];
    const bool result = a.type == ActionType::kAssemble && k == 2;
    if (!result && !objects_.count(o)) {
      Issue(index, "precondition",
            Quote(NodeName(o)) + " does not exist as an object at this point of the plan (it " +
                (tree_.nodes[o].step >= 0 ? "has not been assembled yet or " : "") +
                "is part of a larger object); the replay stops here");
      return false;
    }
  }
  return true;
}

void Validator::ReplayPick(int i, const PlanAction& a, Moment& m) {
  const Keyframe& kf = a.keyframe;
  const int o = a.objects[0];
  const int r = a.robots[0];
  const PlanHold& g = a.grasps[0];
  ObjectState& obj = objects_[o];
  if (!obj.resting) {
    Issue(i, "precondition", "pick: " + Quote(NodeName(o)) + " is in the air, not resting");
  }
  if (!obj.holders.empty()) {
    Issue(i, "precondition",
          "pick: " + Quote(NodeName(o)) + " is already held by " +
              Quote(RobotName(obj.holders[0].robot)));
  }
  RequireFree(i, r, "the picking robot");
  if (!NodeHasPart(o, g.grasp.part)) {
    Issue(i, "precondition",
          "the grasp is on " + Quote(PartName(g.grasp.part)) + ", which is not a part of " +
              Quote(NodeName(o)));
  }
  m.new_holds.emplace_back(o, g);
  const std::map<int, Iso3> X = CheckKeyframe(i, "", kf, m);
  StepConfiguration config;
  std::vector<int> body(project_.parts.size(), -1);
  AddObject(o, X.at(o), {g}, false, config, body);
  RunGate(i, WrenchGate::kTransport, config,
          Quote(RobotName(r)) + " carrying " + Quote(NodeName(o)));
  Detach(r);
  ObjectState& after = objects_[o];
  after.resting = false;
  after.holders = {g};
  holding_[r] = o;
}

void Validator::ReplayPlace(int i, const PlanAction& a, Moment& m) {
  const Keyframe& kf = a.keyframe;
  const int o = a.objects[0];
  const int r = a.robots[0];
  ObjectState& obj = objects_[o];
  if (obj.resting) {
    Issue(i, "precondition", "place: " + Quote(NodeName(o)) + " already rests on the table");
  }
  if (obj.holders.size() != 1 || obj.holders[0].robot != r) {
    Issue(i, "precondition",
          "place: " + Quote(RobotName(r)) + " must be the only holder of " + Quote(NodeName(o)) +
              " (it has " + std::to_string(obj.holders.size()) + " holders)");
  }
  GraspMatches(i, o, a.grasps[0]);
  m.moving.insert(o);
  m.rest_check.insert(o);
  const std::map<int, Iso3> X = CheckKeyframe(i, "", kf, m);
  StepConfiguration config;
  std::vector<int> body(project_.parts.size(), -1);
  AddObject(o, X.at(o), {}, true, config, body);
  RunGate(i, WrenchGate::kRest, config, Quote(NodeName(o)) + " set down on the table");
  if (obj.holders.size() == 1) {
    // Carried down to the table by its holder alone.
    StepConfiguration carried;
    std::vector<int> carried_body(project_.parts.size(), -1);
    AddObject(o, X.at(o), {obj.holders[0]}, false, carried, carried_body);
    RunGate(i, WrenchGate::kTransport, carried,
            Quote(RobotName(r)) + " carrying " + Quote(NodeName(o)) + " down to the table");
  }
  for (const PlanHold& h : objects_[o].holders) {
    holding_[h.robot] = -1;
    freed_now_.insert(h.robot);
  }
  ObjectState& after = objects_[o];
  after.X_WA = X.at(o);
  after.resting = true;
  after.at_rest_pose = true;
  after.holders.clear();
}

void Validator::ReplayHandover(int i, const PlanAction& a, Moment& m) {
  const Keyframe& kf = a.keyframe;
  const int o = a.objects[0];
  const int giver = a.robots[0];
  const int receiver = a.robots[1];
  const PlanHold& g2 = a.grasps[1];
  ObjectState& obj = objects_[o];
  if (obj.resting) {
    Issue(i, "precondition", "handover: " + Quote(NodeName(o)) + " rests on the table");
  }
  if (obj.holders.size() != 1 || obj.holders[0].robot != giver) {
    Issue(i, "precondition",
          "handover: the giver " + Quote(RobotName(giver)) + " must be the only holder of " +
              Quote(NodeName(o)));
  }
  GraspMatches(i, o, a.grasps[0]);
  RequireFree(i, receiver, "the receiver");
  if (!NodeHasPart(o, g2.grasp.part)) {
    Issue(i, "precondition",
          "the receiver's grasp is on " + Quote(PartName(g2.grasp.part)) +
              ", which is not a part of " + Quote(NodeName(o)));
  }
  m.moving.insert(o);
  m.new_holds.emplace_back(o, g2);
  const std::map<int, Iso3> X = CheckKeyframe(i, "", kf, m);
  StepConfiguration config;
  std::vector<int> body(project_.parts.size(), -1);
  AddObject(o, X.at(o), {g2}, false, config, body);
  RunGate(i, WrenchGate::kTransport, config,
          Quote(RobotName(receiver)) + " carrying " + Quote(NodeName(o)) + " alone");
  const bool moved =
      Difference(objects_[o].X_WA, X.at(o)).position_m > options_.position_tolerance_m;
  for (const PlanHold& h : objects_[o].holders) {
    holding_[h.robot] = -1;
    freed_now_.insert(h.robot);
  }
  Detach(receiver);
  ObjectState& after = objects_[o];
  after.X_WA = X.at(o);
  after.at_rest_pose = after.at_rest_pose && !moved;
  after.holders = {g2};
  holding_[receiver] = o;
  freed_now_.erase(receiver);
}

void Validator::ReplayAddGrasp(int i, const PlanAction& a, Moment& m) {
  const Keyframe& kf = a.keyframe;
  const int o = a.objects[0];
  const int r = a.robots[0];
  const PlanHold& g = a.grasps[0];
  ObjectState& obj = objects_[o];
  RequireFree(i, r, "the bracing robot");
  if (!obj.resting && obj.holders.empty()) {
    Issue(i, "precondition", "add_grasp: " + Quote(NodeName(o)) + " is neither resting nor held");
  }
  if (!NodeHasPart(o, g.grasp.part)) {
    Issue(i, "precondition",
          "the grasp is on " + Quote(PartName(g.grasp.part)) + ", which is not a part of " +
              Quote(NodeName(o)));
  }
  if (!obj.resting) m.moving.insert(o);
  m.new_holds.emplace_back(o, g);
  const std::map<int, Iso3> X = CheckKeyframe(i, "", kf, m);
  std::vector<PlanHold> all = objects_[o].holders;
  all.push_back(g);
  StepConfiguration config;
  std::vector<int> body(project_.parts.size(), -1);
  AddObject(o, X.at(o), all, objects_[o].resting, config, body);
  RunGate(i, WrenchGate::kRelease, config,
          Quote(NodeName(o)) + " held still by " + std::to_string(all.size()) + " robots" +
              (objects_[o].resting ? " and the table" : ""));
  Detach(r);
  ObjectState& after = objects_[o];
  if (!after.resting) {
    after.at_rest_pose = after.at_rest_pose && Difference(after.X_WA, X.at(o)).position_m <=
                                                   options_.position_tolerance_m;
    after.X_WA = X.at(o);
  }
  after.holders.push_back(g);
  holding_[r] = o;
}

void Validator::ReplayRelease(int i, const PlanAction& a, Moment& m) {
  const Keyframe& kf = a.keyframe;
  const int o = a.objects[0];
  const int r = a.robots[0];
  ObjectState& obj = objects_[o];
  const bool holds = GraspMatches(i, o, a.grasps[0]) || HoldOf(o, r) != nullptr;
  if (holds && !obj.resting && obj.holders.size() < 2) {
    Issue(i, "precondition",
          "release: " + Quote(NodeName(o)) + " is in the air and " + Quote(RobotName(r)) +
              " is its only holder: it would fall");
  }
  const std::map<int, Iso3> X = CheckKeyframe(i, "", kf, m);
  std::vector<PlanHold> remaining;
  for (const PlanHold& h : objects_[o].holders) {
    if (h.robot != r) remaining.push_back(h);
  }
  StepConfiguration config;
  std::vector<int> body(project_.parts.size(), -1);
  const bool resting = objects_[o].resting;
  AddObject(o, X.at(o), remaining, resting, config, body);
  if (!remaining.empty()) {
    RunGate(i, WrenchGate::kRelease, config,
            Quote(NodeName(o)) + " held by the remaining " + std::to_string(remaining.size()) +
                " robot(s)" + (resting ? " and the table" : ""));
  } else if (resting) {
    RunGate(i, WrenchGate::kRest, config, Quote(NodeName(o)) + " left on the table");
  }
  if (holding_[r] == o) {
    Detach(r);
    freed_now_.insert(r);
  }
}

// The step an assemble's moved and base inputs build; -1 when they build none (the replay stops).
int Validator::AssembledStep(int i, const PlanAction& a) {
  const int M = a.objects[0];
  const int B = a.objects[1];
  if (M == B) {
    Issue(i, "precondition",
          "assemble: the moved and the base input are the same object " + Quote(NodeName(M)) +
              "; the replay stops here");
    return -1;
  }
  int S = -1;
  for (size_t n = 0; n < tree_.nodes.size(); ++n) {
    const std::vector<int>& in = tree_.nodes[n].inputs;
    if (in.size() == 2 && ((in[0] == M && in[1] == B) || (in[0] == B && in[1] == M))) {
      S = static_cast<int>(n);
    }
  }
  if (S < 0) {
    Issue(i, "precondition",
          "assemble: " + Quote(NodeName(M)) + " and " + Quote(NodeName(B)) +
              " are not the two inputs of any assembly step; the replay "
              "stops here");
  }
  return S;
}

// An assemble's preconditions on step S: the result it names, the direction, the moved input
// held in the air, the base resting or held, the robots exactly the inputs' holders.
void Validator::CheckAssembleInputs(int i, const PlanAction& a, int S) {
  const int M = a.objects[0];
  const int B = a.objects[1];
  if (a.objects[2] != S) {
    Issue(i, "precondition",
          "assemble: joining " + Quote(NodeName(M)) + " and " + Quote(NodeName(B)) + " builds " +
              Quote(NodeName(S)) + ", not " + Quote(NodeName(a.objects[2])));
  }
  const Interface& f = interfaces_[S];
  if (f.moved_node != M) {
    Issue(i, "precondition",
          "assemble: step " + Quote(NodeName(S)) + " moves " + Quote(NodeName(f.moved_node)) +
              " onto " + Quote(NodeName(f.base_node)) + ", the plan the other way");
  }
  const ObjectState& mo = objects_[M];
  const ObjectState& bo = objects_[B];
  if (mo.resting) {
    Issue(i, "precondition",
          "assemble: the moved input " + Quote(NodeName(M)) +
              " rests on the table; it must be held in the air");
  }
  if (mo.holders.empty()) {
    Issue(i, "precondition", "assemble: nothing holds the moved input " + Quote(NodeName(M)));
  }
  if (!bo.resting && bo.holders.empty()) {
    Issue(i, "precondition",
          "assemble: the base input " + Quote(NodeName(B)) + " is neither resting nor held");
  }
  std::set<int> expected, named(a.robots.begin(), a.robots.end());
  for (const PlanHold& h : mo.holders) expected.insert(h.robot);
  for (const PlanHold& h : bo.holders) expected.insert(h.robot);
  if (expected != named) {
    Issue(i, "precondition",
          "assemble: the action's robots must be exactly those holding " + Quote(NodeName(M)) +
              " or " + Quote(NodeName(B)));
  }
  for (const PlanHold& h : a.grasps) {
    if (holding_[h.robot] == M || holding_[h.robot] == B) GraspMatches(i, holding_[h.robot], h);
  }
}

bool Validator::ReplayAssemble(int i, const PlanAction& a, Moment& m) {
  const Keyframe& kf = a.keyframe;
  const int M = a.objects[0];
  const int B = a.objects[1];
  const int S = AssembledStep(i, a);
  if (S < 0) return false;
  CheckAssembleInputs(i, a, S);
  const Interface& f = interfaces_[S];
  const ObjectState& bo = objects_[B];
  const bool base_moves = !bo.resting;
  m.moving.insert(M);
  if (base_moves) m.moving.insert(B);

  // B where the keyframe puts it (the state's pose when it may not move or is not listed).
  Iso3 X_WB = bo.X_WA;
  if (base_moves) {
    for (const PlanObject& po : kf.objects) {
      if (po.node == B) X_WB = po.X_WA;
    }
  }
  CheckApproach(i, a, m, f, X_WB, base_moves);
  CheckInsertionPath(i, f, X_WB);
  m.allowed_pairs.emplace_back(M, B);
  m.required[M] = {X_WB, "its mating pose on " + Quote(NodeName(B)) + " (X_WM = X_WB)"};
  const std::map<int, Iso3> X = CheckKeyframe(i, "", kf, m);
  RunAssemblyGate(i, M, B, f, X);
  JoinInputs(M, B, S, X);
  return true;
}

// The approach keyframe: the moved input `approach_m` back along the insertion axis from its
// mating pose on B (at X_WB), a moving base where the assemble keyframe has it.
void Validator::CheckApproach(int i, const PlanAction& a, const Moment& m, const Interface& f,
                              const Iso3& X_WB, bool base_moves) {
  const int M = a.objects[0];
  const int B = a.objects[1];
  if (a.approach) {
    Moment ap = m;
    Iso3 X_WM_ap = X_WB;
    X_WM_ap.translation() -= f.step->mating.approach_m * (X_WB.linear() * f.axis_A);
    ap.required[M] = {X_WM_ap, "its approach pose (" + Mm(f.step->mating.approach_m) +
                                   " back along the insertion axis from " + Quote(NodeName(B)) +
                                   ")"};
    if (base_moves) ap.required[B] = {X_WB, "its pose at the assemble keyframe"};
    // Along the insertion the moved input may slide on the base (touching faces).
    ap.allowed_pairs.emplace_back(M, B);
    CheckKeyframe(i, "approach: ", *a.approach, ap);
  } else {
    Issue(i, "pose", "assemble has no approach keyframe");
  }
}

void Validator::RunAssemblyGate(int i, int M, int B, const Interface& f,
                                const std::map<int, Iso3>& X) {
  StepConfiguration config;
  std::vector<int> body(project_.parts.size(), -1);
  // The moved input rests on the table where it touches it (a part slid along the table
  // into a resting base): its parts that reach the top get their support polygons.
  AddObject(M, X.at(M), objects_[M].holders, true, config, body);
  AddObject(B, X.at(B), objects_[B].holders, objects_[B].resting, config, body);
  if (f.moved_part >= 0 && body[f.moved_part] >= 0 && body[f.base_part] >= 0) {
    config.mating = MatingLoadFromProject(f.step->mating, X.at(B), body[f.moved_part],
                                          body[f.base_part], X.at(B) * f.p_A);
  }
  RunGate(i, WrenchGate::kAssembly, config,
          "mating " + Quote(NodeName(M)) + " onto " + Quote(NodeName(B)));
}

void Validator::JoinInputs(int M, int B, int S, const std::map<int, Iso3>& X) {
  ObjectState s;
  s.X_WA = X.at(B);
  s.resting = objects_[B].resting;
  s.at_rest_pose = objects_[B].at_rest_pose && Difference(objects_[B].X_WA, X.at(B)).position_m <=
                                                   options_.position_tolerance_m;
  s.holders = objects_[M].holders;
  s.holders.insert(s.holders.end(), objects_[B].holders.begin(), objects_[B].holders.end());
  objects_.erase(M);
  objects_.erase(B);
  for (const PlanHold& h : s.holders) holding_[h.robot] = S;
  objects_[S] = std::move(s);
}

const PlanHold* Validator::HoldOf(int node, int robot) const {
  auto it = objects_.find(node);
  if (it == objects_.end()) return nullptr;
  for (const PlanHold& h : it->second.holders) {
    if (h.robot == robot) return &h;
  }
  return nullptr;
}

// The grasp an action names for a robot that already holds `node` must be the one it holds.
bool Validator::GraspMatches(int index, int node, const PlanHold& hold) {
  const PlanHold* held = HoldOf(node, hold.robot);
  if (held == nullptr) {
    Issue(index, "precondition",
          "robot " + Quote(RobotName(hold.robot)) + " does not hold " + Quote(NodeName(node)));
    return false;
  }
  const PoseError e = Difference(held->grasp.X_PG, hold.grasp.X_PG);
  if (held->grasp.part != hold.grasp.part || e.position_m > options_.position_tolerance_m ||
      e.rotation_rad > options_.rotation_tolerance_rad) {
    Issue(index, "precondition",
          "robot " + Quote(RobotName(hold.robot)) + " holds " + Quote(NodeName(node)) +
              " by a grasp on " + Quote(PartName(held->grasp.part)) +
              ", but the action names another grasp (on " + Quote(PartName(hold.grasp.part)) +
              ", " + Mm(e.position_m) + " / " + Deg(e.rotation_rad) + " away)");
    return false;
  }
  return true;
}

void Validator::RequireFree(int index, int robot, std::string_view role) {
  if (holding_[robot] >= 0) {
    Issue(index, "precondition",
          std::string(role) + " " + Quote(RobotName(robot)) + " must be free but holds " +
              Quote(NodeName(holding_[robot])) + " (a robot holds one object at most)");
  }
}

// Takes a robot off whatever it holds (keeps the state sane after a precondition failure).
void Validator::Detach(int robot) {
  const int node = holding_[robot];
  holding_[robot] = -1;
  if (auto it = objects_.find(node); it != objects_.end()) {
    std::erase_if(it->second.holders, [&](const PlanHold& h) { return h.robot == robot; });
  }
}

}  // namespace wrap::plan_validator_internal
