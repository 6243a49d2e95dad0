// The plan as data: its JSON file (exact round trip, malformed documents refused naming the
// field, never a crash), the actions in words, and matching a plan against its project.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "model/validate.h"
#include "task/plan.h"
#include "task/plan_json.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

// Node ids of projects/stool.json: parts first, then steps.
constexpr int kSeat = 0, kLeg1 = 1, kLeg2 = 2, kLeg3 = 3, kLeg4 = 4, kSeatLeg1 = 5;
constexpr int kA = 0, kB = 1, kC = 2;

Iso3 MakePose(double x, double y, double z, double roll, double pitch, double yaw) {
  return ToIsometry(Pose{Vec3(x, y, z), Vec3(roll, pitch, yaw)});
}

JointVector Joints(double offset) {
  JointVector q(6);
  for (int i = 0; i < 6; ++i) q[i] = offset + 0.1234567890123457 * (i + 1) - 1.0 / 3.0;
  return q;
}

PlanGrasp Grasp(int subassembly, int index, int part, double width_m) {
  PlanGrasp g;
  g.subassembly = subassembly;
  g.index = index;
  g.part = part;
  g.X_PG = MakePose(0.01, -0.02, 0.0312345678901234, 3.14159, 0.2, -1.1);
  g.width_m = width_m;
  return g;
}

Keyframe MakeKeyframe(double offset, bool assembled, bool resting) {
  Keyframe k;
  for (int r = 0; r < 4; ++r) k.q.push_back(Joints(offset + r));
  if (assembled) {
    k.objects.push_back({kSeatLeg1, MakePose(-0.2, 0.0, 0.76 + offset, 0.0, 0.0, 0.3), resting});
  } else {
    k.objects.push_back({kSeat, MakePose(-0.2, 0.0, 0.75 + offset, 0.0, 0.0, 0.1), resting});
    k.objects.push_back({kLeg1, MakePose(0.16, 0.16, 0.75, 0.1, -0.2, 2.9), false});
  }
  k.objects.push_back({kLeg2, MakePose(0.16, 0.05, 0.75, 0, 0, 0), true});
  k.objects.push_back({kLeg3, MakePose(0.16, -0.06, 0.75, 0, 0, 0), true});
  k.objects.push_back({kLeg4, MakePose(0.16, -0.17, 0.75, 0, 0, 0), true});
  return k;
}

PlanAction Action(ActionType type, std::vector<int> robots, std::vector<int> objects,
                  std::vector<PlanHold> grasps, Keyframe keyframe) {
  PlanAction a;
  a.type = type;
  a.robots = std::move(robots);
  a.objects = std::move(objects);
  a.grasps = std::move(grasps);
  a.keyframe = std::move(keyframe);
  a.milestone = 0;
  return a;
}

// A plan of the stool's first step with every action type, an approach and a placement.
Plan StoolPlan() {
  Plan plan;
  plan.project = "stool";
  plan.robots = {"ur5e_a", "ur5e_b", "ur5e_c", "ur5e_d"};
  plan.parts = {"seat", "leg1", "leg2", "leg3", "leg4"};
  plan.nodes = {"seat",      "leg1",         "leg2",         "leg3", "leg4",
                "seat+leg1", "seat+legs1-2", "seat+legs1-3", "stool"};
  plan.milestone_steps = {kSeatLeg1, 6};
  PlanStats& s = plan.stats;
  s.solved = true;
  s.cost = 6;
  s.t_init_s = 1.25;
  s.t_grasp_s = 0.5;
  s.t_bwd_s = 0.001;
  s.t_lp_s = 0.1;
  s.t_fwd_s = 0.2;
  s.t_ik_s = 0.3;
  s.planner = "counting";
  s.objective = "makespan";
  s.makespan_est_s = 42.5;
  s.seed = 18446744073709551615ull;
  s.wrench_mode = "full";
  s.force_scale = 1.5;
  s.grasps = 20;
  s.expansions = 12345678901LL;
  s.validations = 77;
  s.validation_failures = 7;
  s.lp_checks = 40;
  s.lp_cache_hits = 30;
  s.ik_calls = 900;
  s.collision_checks = 800;
  s.milestones = 1;
  s.backtracks = 2;
  s.widenings = 3;
  s.failure = "";
  plan.initial = MakeKeyframe(0.0, false, true);

  plan.actions.push_back(Action(ActionType::kPick, {kC}, {kLeg1},
                                {{kC, Grasp(kLeg1, 2, kLeg1, 0.03)}},
                                MakeKeyframe(0.01, false, true)));
  plan.actions.push_back(
      Action(ActionType::kHandover, {kC, kA}, {kLeg1},
             {{kC, Grasp(kLeg1, 2, kLeg1, 0.03)}, {kA, Grasp(kSeatLeg1, 7, kLeg1, 0.029)}},
             MakeKeyframe(0.02, false, true)));
  plan.actions.push_back(Action(ActionType::kAddGrasp, {kB}, {kSeat},
                                {{kB, Grasp(kSeat, 5, kSeat, 0.0)}},
                                MakeKeyframe(0.03, false, true)));
  PlanAction assemble =
      Action(ActionType::kAssemble, {kA, kB}, {kLeg1, kSeat, kSeatLeg1},
             {{kA, Grasp(kSeatLeg1, 7, kLeg1, 0.029)}, {kB, Grasp(kSeat, 5, kSeat, 0.0)}},
             MakeKeyframe(0.04, true, true));
  assemble.approach = MakeKeyframe(0.035, false, true);
  plan.actions.push_back(assemble);
  plan.actions.push_back(Action(ActionType::kRelease, {kB}, {kSeatLeg1},
                                {{kB, Grasp(kSeat, 5, kSeat, 0.0)}},
                                MakeKeyframe(0.05, true, true)));
  PlanAction place =
      Action(ActionType::kPlace, {kA}, {kSeatLeg1}, {{kA, Grasp(kSeatLeg1, 7, kLeg1, 0.029)}},
             MakeKeyframe(0.06, true, true));
  place.placement = PlanPlacement{1, 4, 2};
  place.milestone = 1;
  place.start_s = 12.5;
  place.end_s = 14.0625;
  plan.actions.push_back(place);
  return plan;
}

std::string ProjectFile(const std::string& name) {
  return (fs::path(WRAP_SOURCE_DIR) / "projects" / (name + ".json")).string();
}

void ExpectPoseNear(const Iso3& a, const Iso3& b, const std::string& what) {
  EXPECT_LE((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), 1e-12) << what;
}

void ExpectKeyframesEqual(const Keyframe& a, const Keyframe& b, const std::string& what) {
  ASSERT_EQ(a.q.size(), b.q.size()) << what;
  for (size_t r = 0; r < a.q.size(); ++r) {
    ASSERT_EQ(a.q[r].size(), b.q[r].size()) << what;
    for (Eigen::Index i = 0; i < a.q[r].size(); ++i) EXPECT_EQ(a.q[r][i], b.q[r][i]) << what;
  }
  ASSERT_EQ(a.objects.size(), b.objects.size()) << what;
  for (size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].node, b.objects[i].node) << what;
    EXPECT_EQ(a.objects[i].resting, b.objects[i].resting) << what;
    ExpectPoseNear(a.objects[i].X_WA, b.objects[i].X_WA, what + " object " + std::to_string(i));
  }
}

void ExpectPlansEqual(const Plan& a, const Plan& b) {
  EXPECT_EQ(a.project, b.project);
  EXPECT_EQ(a.robots, b.robots);
  EXPECT_EQ(a.parts, b.parts);
  EXPECT_EQ(a.nodes, b.nodes);
  EXPECT_EQ(a.milestone_steps, b.milestone_steps);
  const PlanStats &s = a.stats, &t = b.stats;
  EXPECT_EQ(s.solved, t.solved);
  EXPECT_EQ(s.cost, t.cost);
  EXPECT_EQ(s.t_init_s, t.t_init_s);
  EXPECT_EQ(s.t_grasp_s, t.t_grasp_s);
  EXPECT_EQ(s.t_bwd_s, t.t_bwd_s);
  EXPECT_EQ(s.t_lp_s, t.t_lp_s);
  EXPECT_EQ(s.t_fwd_s, t.t_fwd_s);
  EXPECT_EQ(s.t_ik_s, t.t_ik_s);
  EXPECT_EQ(s.planner, t.planner);
  EXPECT_EQ(s.objective, t.objective);
  EXPECT_EQ(s.makespan_est_s, t.makespan_est_s);
  EXPECT_EQ(s.seed, t.seed);
  EXPECT_EQ(s.wrench_mode, t.wrench_mode);
  EXPECT_EQ(s.force_scale, t.force_scale);
  EXPECT_EQ(s.grasps, t.grasps);
  EXPECT_EQ(s.expansions, t.expansions);
  EXPECT_EQ(s.validations, t.validations);
  EXPECT_EQ(s.validation_failures, t.validation_failures);
  EXPECT_EQ(s.lp_checks, t.lp_checks);
  EXPECT_EQ(s.lp_cache_hits, t.lp_cache_hits);
  EXPECT_EQ(s.ik_calls, t.ik_calls);
  EXPECT_EQ(s.collision_checks, t.collision_checks);
  EXPECT_EQ(s.milestones, t.milestones);
  EXPECT_EQ(s.backtracks, t.backtracks);
  EXPECT_EQ(s.widenings, t.widenings);
  EXPECT_EQ(s.failure, t.failure);
  ExpectKeyframesEqual(a.initial, b.initial, "initial");
  ASSERT_EQ(a.actions.size(), b.actions.size());
  for (size_t i = 0; i < a.actions.size(); ++i) {
    const PlanAction &x = a.actions[i], &y = b.actions[i];
    const std::string what = "action " + std::to_string(i);
    EXPECT_EQ(x.type, y.type) << what;
    EXPECT_EQ(x.robots, y.robots) << what;
    EXPECT_EQ(x.objects, y.objects) << what;
    ASSERT_EQ(x.grasps.size(), y.grasps.size()) << what;
    for (size_t k = 0; k < x.grasps.size(); ++k) {
      const PlanHold &g = x.grasps[k], &h = y.grasps[k];
      EXPECT_EQ(g.robot, h.robot) << what;
      EXPECT_EQ(g.grasp.subassembly, h.grasp.subassembly) << what;
      EXPECT_EQ(g.grasp.index, h.grasp.index) << what;
      EXPECT_EQ(g.grasp.part, h.grasp.part) << what;
      EXPECT_EQ(g.grasp.width_m, h.grasp.width_m) << what;
      ExpectPoseNear(g.grasp.X_PG, h.grasp.X_PG, what + " X_PG");
    }
    ASSERT_EQ(x.placement.has_value(), y.placement.has_value()) << what;
    if (x.placement) {
      EXPECT_EQ(x.placement->placement, y.placement->placement);
      EXPECT_EQ(x.placement->slot, y.placement->slot);
      EXPECT_EQ(x.placement->yaw, y.placement->yaw);
    }
    EXPECT_EQ(x.milestone, y.milestone) << what;
    EXPECT_EQ(x.start_s, y.start_s) << what;
    EXPECT_EQ(x.end_s, y.end_s) << what;
    ExpectKeyframesEqual(x.keyframe, y.keyframe, what + " keyframe");
    ASSERT_EQ(x.approach.has_value(), y.approach.has_value()) << what;
    if (x.approach) ExpectKeyframesEqual(*x.approach, *y.approach, what + " approach");
  }
}

TEST(ActionType, WordsRoundTrip) {
  for (ActionType t : {ActionType::kPick, ActionType::kPlace, ActionType::kHandover,
                       ActionType::kAddGrasp, ActionType::kRelease, ActionType::kAssemble}) {
    EXPECT_EQ(ActionTypeFromString(ToString(t)), t);
  }
  EXPECT_EQ(ToString(ActionType::kAddGrasp), "add_grasp");
  EXPECT_FALSE(ActionTypeFromString("Pick").has_value());
  EXPECT_FALSE(ActionTypeFromString("").has_value());
}

TEST(DescribeAction, NamesRobotsObjectsAndGrasps) {
  const Plan plan = StoolPlan();
  const std::vector<std::string> expected = {
      "ur5e_c picks 'leg1' (grasp 2)",
      "ur5e_c hands 'leg1' over to ur5e_a (grasp 2 -> grasp 7 of 'seat+leg1')",
      "ur5e_b adds grasp 5 on 'seat' (brace)",
      "assembles 'leg1' onto 'seat' -> 'seat+leg1' (held by ur5e_a, ur5e_b)",
      "ur5e_b releases 'seat+leg1'",
      "ur5e_a places 'seat+leg1' on the table (placement 1, slot 4, yaw 2)"};
  ASSERT_EQ(plan.actions.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(DescribeAction(plan, plan.actions[i]), expected[i]);
  }
  // An added grasp on an object in the air is not a brace; a place without a placement.
  PlanAction add = plan.actions[2];
  add.keyframe.objects[0].resting = false;
  EXPECT_EQ(DescribeAction(plan, add), "ur5e_b adds grasp 5 on 'seat'");
  PlanAction place = plan.actions[5];
  place.placement.reset();
  EXPECT_EQ(DescribeAction(plan, place), "ur5e_a places 'seat+leg1' on the table");
  // Broken indices are shown, not dereferenced.
  PlanAction broken = plan.actions[0];
  broken.robots = {42};
  broken.objects = {};
  broken.grasps = {};
  EXPECT_EQ(DescribeAction(plan, broken), "robot #42 picks '?' (grasp ?)");
}

TEST(PlanJson, RoundTripIsExact) {
  const Plan plan = StoolPlan();
  const std::string text = SerializePlan(plan);
  auto parsed = ParsePlan(text, "plan.json");
  ASSERT_TRUE(parsed.has_value()) << parsed.error().message;
  ExpectPlansEqual(plan, *parsed);
  // Written again, the document keeps its keys, order and descriptions.
  const json a = json::parse(text), b = json::parse(SerializePlan(*parsed));
  EXPECT_EQ(a["actions"][3]["description"], b["actions"][3]["description"]);
  EXPECT_EQ(a["stats"], b["stats"]);
  EXPECT_EQ(a["initial"]["q"], b["initial"]["q"]);
}

// Per-action gripper utilisation: written by robot name, read back exactly, and checked.
TEST(PlanJson, UtilisationRoundTripsAndIsChecked) {
  Plan plan = StoolPlan();
  plan.actions[1].utilisation = {{0, 0.625}, {2, 1.25}};
  const std::string text = SerializePlan(plan);
  auto parsed = ParsePlan(text, "plan.json");
  ASSERT_TRUE(parsed.has_value()) << parsed.error().message;
  EXPECT_EQ(parsed->actions[1].utilisation, plan.actions[1].utilisation);
  EXPECT_TRUE(parsed->actions[0].utilisation.empty());
  json d = json::parse(text);
  EXPECT_EQ(d["actions"][1]["utilisation"]["ur5e_a"], 0.625);
  EXPECT_EQ(d["actions"][1]["utilisation"]["ur5e_c"], 1.25);
  EXPECT_FALSE(d["actions"][0].contains("utilisation"));
  json unknown = d;
  unknown["actions"][1]["utilisation"]["nobody"] = 0.5;
  auto bad = ParsePlan(unknown.dump(), "plan.json");
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("actions[1].utilisation.nobody: no robot 'nobody'"),
            std::string::npos)
      << bad.error().message;
  json negative = d;
  negative["actions"][1]["utilisation"]["ur5e_a"] = -0.1;
  bad = ParsePlan(negative.dump(), "plan.json");
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("actions[1].utilisation.ur5e_a: expected a non-negative"),
            std::string::npos)
      << bad.error().message;
}

// A reduced grasp's type and torque scale: written only for reduced grasps (a full-pad grasp's
// entry reads as before grasp types existed), read back exactly, checked.
TEST(PlanJson, ReducedGraspTypeRoundTripsAndIsChecked) {
  Plan plan = StoolPlan();
  ASSERT_FALSE(plan.actions[1].grasps.empty());
  PlanGrasp& g = plan.actions[1].grasps[0].grasp;
  g.type = GraspType::kFingertip;
  g.torque_scale = Vec3(0.5, 0.25, 1.0);
  const std::string text = SerializePlan(plan);
  auto parsed = ParsePlan(text, "plan.json");
  ASSERT_TRUE(parsed.has_value()) << parsed.error().message;
  const PlanGrasp& back = parsed->actions[1].grasps[0].grasp;
  EXPECT_EQ(back.type, GraspType::kFingertip);
  EXPECT_EQ(back.torque_scale, Vec3(0.5, 0.25, 1.0));
  EXPECT_EQ(parsed->actions[0].grasps.at(0).grasp.type, GraspType::kFullPad);
  json d = json::parse(text);
  EXPECT_EQ(d["actions"][1]["grasps"][0]["grasp_type"], "fingertip");
  EXPECT_FALSE(d["actions"][0]["grasps"][0].contains("grasp_type"));
  EXPECT_FALSE(d["actions"][0]["grasps"][0].contains("torque_scale"));
  json big = d;
  big["actions"][1]["grasps"][0]["torque_scale"] = {0.5, 1.5, 1.0};
  auto bad = ParsePlan(big.dump(), "plan.json");
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("torque_scale: expected fractions in [0, 1]"),
            std::string::npos)
      << bad.error().message;
  json unknown = d;
  unknown["actions"][1]["grasps"][0]["grasp_type"] = "palm";
  ASSERT_FALSE(ParsePlan(unknown.dump(), "plan.json").has_value());
}

// Motion segments say what each waited for; plans written before they did still read (no
// wait); a wait that is not a known one or names no segment is refused.
TEST(PlanJson, SegmentWaitsRoundTripAndOldPlansStillRead) {
  Plan plan = StoolPlan();
  for (size_t r = 0; r < plan.robots.size(); ++r) {
    RobotTrajectory tr;
    tr.robot = static_cast<int>(r);
    TrajectoryKnot k;
    k.q = plan.initial.q[r];
    k.qd = JointVector::Zero(k.q.size());
    tr.knots.push_back(k);
    plan.trajectories.push_back(tr);
  }
  MotionSegment first{"free", 0, {2}, {1}, 0.0, 1.5, "none", -1};
  MotionSegment second{"free", 0, {0}, {}, 1.25, 2.0, "collision", 0};
  MotionSegment third{"approach", 0, {2}, {1}, 1.5, 2.25, "robot", 0};
  plan.segments = {first, second, third};
  const std::string text = SerializePlan(plan);
  auto parsed = ParsePlan(text, "plan.json");
  ASSERT_TRUE(parsed.has_value()) << parsed.error().message;
  ASSERT_EQ(parsed->segments.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(parsed->segments[k].wait, plan.segments[k].wait);
    EXPECT_EQ(parsed->segments[k].wait_segment, plan.segments[k].wait_segment);
  }
  const json doc = json::parse(text);
  EXPECT_EQ(doc["segments"][1]["wait"], "collision");
  EXPECT_EQ(doc["segments"][1]["wait_segment"], 0);
  json old = doc;
  for (json& seg : old["segments"]) {
    seg.erase("wait");
    seg.erase("wait_segment");
  }
  auto before = ParsePlan(old.dump(), "plan.json");
  ASSERT_TRUE(before.has_value()) << before.error().message;
  EXPECT_EQ(before->segments[1].wait, "");
  EXPECT_EQ(before->segments[1].wait_segment, -1);
  json unknown = doc;
  unknown["segments"][1]["wait"] = "lunch";
  auto bad = ParsePlan(unknown.dump(), "plan.json");
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("segments[1].wait: unknown wait 'lunch'"), std::string::npos)
      << bad.error().message;
  json beyond = doc;
  beyond["segments"][2]["wait_segment"] = 3;
  bad = ParsePlan(beyond.dump(), "plan.json");
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("segments[2].wait_segment"), std::string::npos)
      << bad.error().message;
}

TEST(PlanJson, DocumentLayout) {
  const json doc = json::parse(SerializePlan(StoolPlan()));
  std::vector<std::string> keys;
  for (const auto& [key, value] : doc.items()) keys.push_back(key);
  EXPECT_EQ(keys, (std::vector<std::string>{"format", "version", "project", "robots", "parts",
                                            "nodes", "milestones", "stats", "initial", "actions"}));
  EXPECT_EQ(doc["format"], "wrap-plan");
  EXPECT_EQ(doc["version"], 1);
  EXPECT_EQ(doc["milestones"], json::array({"seat+leg1", "seat+legs1-2"}));
  EXPECT_EQ(doc["stats"]["seed"].get<std::uint64_t>(), 18446744073709551615ull);
  const json& pick = doc["actions"][0];
  EXPECT_EQ(pick["type"], "pick");
  EXPECT_EQ(pick["robots"], json::array({"ur5e_c"}));
  EXPECT_EQ(pick["objects"], json::array({"leg1"}));
  EXPECT_EQ(pick["grasps"][0]["part"], "leg1");
  EXPECT_EQ(pick["keyframe"]["q"]["ur5e_a"].size(), 6u);
  EXPECT_FALSE(pick.contains("placement"));
  EXPECT_FALSE(pick.contains("approach"));
  EXPECT_FALSE(pick.contains("start_s"));
  EXPECT_EQ(pick["description"], "ur5e_c picks 'leg1' (grasp 2)");
  EXPECT_TRUE(doc["actions"][3].contains("approach"));
  const json& place = doc["actions"][5];
  EXPECT_EQ(place["placement"], (json{{"placement", 1}, {"slot", 4}, {"yaw", 2}}));
  EXPECT_EQ(place["start_s"], 12.5);
  EXPECT_EQ(place["end_s"], 14.0625);
}

TEST(PlanJson, SaveAndReadFile) {
  const fs::path dir = fs::temp_directory_path() / ("wrap_plan_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / "plan.json";
  const Plan plan = StoolPlan();
  ASSERT_TRUE(SavePlan(plan, file).has_value());
  auto read = ReadPlanFile(file);
  ASSERT_TRUE(read.has_value()) << read.error().message;
  ExpectPlansEqual(plan, *read);
  auto missing = ReadPlanFile(dir / "none.json");
  ASSERT_FALSE(missing.has_value());
  EXPECT_EQ(missing.error().code, ErrorCode::kIo);
  EXPECT_NE(missing.error().message.find("none.json"), std::string::npos);
  // Unwritable: a folder below a regular file.
  auto bad = SavePlan(plan, file / "sub.json");
  ASSERT_FALSE(bad.has_value());
  EXPECT_EQ(bad.error().code, ErrorCode::kIo);
  fs::remove_all(dir);
}

// A malformed document: the good plan's JSON with one change, and a phrase the message must hold
// (the field's path and the problem).
struct Malformed {
  std::string name;
  std::function<void(json&)> change;
  std::vector<std::string> phrases;
};

std::string Text(const std::function<void(json&)>& change) {
  json doc = json::parse(SerializePlan(StoolPlan()));
  change(doc);
  return doc.dump(1);
}

TEST(PlanJson, MalformedDocumentsAreRefusedNamingTheField) {
  const std::vector<Malformed> cases = {
      {"format",
       [](json& d) { d["format"] = "wrap-project"; },
       {"plan.json: format:", "wrap-plan"}},
      {"version", [](json& d) { d["version"] = 2; }, {"version:", "expected 1"}},
      {"missing_actions", [](json& d) { d.erase("actions"); }, {"actions: required field"}},
      {"missing_stats_field",
       [](json& d) { d["stats"].erase("t_init_s"); },
       {"stats.t_init_s: required field"}},
      {"duplicate_robot",
       [](json& d) { d["robots"][1] = "ur5e_a"; },
       {"robots[1]: duplicate name 'ur5e_a'"}},
      {"nodes_not_parts_first",
       [](json& d) { std::swap(d["nodes"][0], d["nodes"][1]); },
       {"nodes[0]: expected part 'seat'"}},
      {"joint_count",
       [](json& d) { d["actions"][3]["keyframe"]["q"]["ur5e_a"].erase(0); },
       {"actions[3].keyframe.q.ur5e_a: expected 6 numbers", "found 5"}},
      {"joint_type",
       [](json& d) { d["initial"]["q"]["ur5e_b"][2] = "0.5"; },
       {"initial.q.ur5e_b[2]: expected a number, found a string"}},
      {"joint_missing",
       [](json& d) { d["actions"][0]["keyframe"]["q"].erase("ur5e_d"); },
       {"actions[0].keyframe.q.ur5e_d", "missing"}},
      {"joint_unknown_robot",
       [](json& d) {
         d["initial"]["q"]["ur10e"] = json::array({0, 0, 0, 0, 0, 0});
       },
       {"initial.q.ur10e: unknown robot"}},
      {"too_many_joints",
       [](json& d) { d["initial"]["q"]["ur5e_a"] = std::vector<double>(11, 0.0); },
       {"initial.q.ur5e_a: expected an array of 1 to 10 numbers"}},
      {"unknown_type",
       [](json& d) { d["actions"][2]["type"] = "fly"; },
       {"actions[2].type: unknown action type 'fly'"}},
      {"unknown_robot",
       [](json& d) { d["actions"][0]["robots"][0] = "r9"; },
       {"actions[0].robots[0]: unknown robot 'r9'"}},
      {"unknown_object",
       [](json& d) { d["actions"][4]["objects"][0] = "table"; },
       {"actions[4].objects[0]: unknown node 'table'"}},
      {"arity",
       [](json& d) { d["actions"][1]["robots"].erase(1); },
       {"actions[1].robots: a handover action has 2 robot(s), found 1"}},
      {"assemble_objects",
       [](json& d) { d["actions"][3]["objects"].erase(2); },
       {"actions[3].objects: an assemble action has 3 object(s)"}},
      {"grasp_count",
       [](json& d) { d["actions"][3]["grasps"].erase(1); },
       {"actions[3].grasps: expected one grasp per robot (2), found 1"}},
      {"grasp_robot_order",
       [](json& d) { d["actions"][1]["grasps"][0]["robot"] = "ur5e_a"; },
       {"actions[1].grasps[0].robot: expected 'ur5e_c'"}},
      {"grasp_index_negative",
       [](json& d) { d["actions"][0]["grasps"][0]["index"] = -3; },
       {"actions[0].grasps[0].index: expected an integer in [0,"}},
      {"grasp_index_fraction",
       [](json& d) { d["actions"][0]["grasps"][0]["index"] = 2.5; },
       {"actions[0].grasps[0].index: expected an integer, found a fraction"}},
      {"grasp_index_huge",
       [](json& d) { d["actions"][0]["grasps"][0]["index"] = 99999999999LL; },
       {"actions[0].grasps[0].index: expected an integer in"}},
      {"width_negative",
       [](json& d) { d["actions"][0]["grasps"][0]["width_m"] = -0.01; },
       {"actions[0].grasps[0].width_m: expected a number >= 0"}},
      {"pose_short",
       [](json& d) { d["actions"][0]["grasps"][0]["X_PG"]["rpy"].erase(0); },
       {"actions[0].grasps[0].X_PG.rpy: expected an array of 3 numbers, found an array of 2"}},
      {"resting_type",
       [](json& d) { d["initial"]["objects"][0]["resting"] = "yes"; },
       {"initial.objects[0].resting: expected true or false, found a string"}},
      {"object_twice",
       [](json& d) { d["initial"]["objects"][1]["name"] = "seat"; },
       {"initial.objects[1].name: object 'seat' is listed twice"}},
      {"milestone_range",
       [](json& d) { d["actions"][0]["milestone"] = 99; },
       {"actions[0].milestone: expected an integer in [-1, 1]"}},
      {"milestone_part",
       [](json& d) { d["milestones"][0] = "leg2"; },
       {"milestones[0]: 'leg2' is a part"}},
      {"index_mismatch",
       [](json& d) { d["actions"][2]["index"] = 5; },
       {"actions[2].index: expected 2"}},
      {"placement_on_pick",
       [](json& d) {
         d["actions"][0]["placement"] = json{{"placement", 0}, {"slot", 0}, {"yaw", 0}};
       },
       {"actions[0].placement: only a place action"}},
      {"approach_on_pick",
       [](json& d) { d["actions"][0]["approach"] = d["actions"][0]["keyframe"]; },
       {"actions[0].approach: only an assemble action"}},
      {"times_backwards",
       [](json& d) { d["actions"][5]["end_s"] = 1.0; },
       {"actions[5].end_s: ends before it starts"}},
      {"unknown_field",
       [](json& d) { d["actions"][1]["colour"] = "red"; },
       {"actions[1].colour: unknown field"}},
      {"seed_negative",
       [](json& d) { d["stats"]["seed"] = -1; },
       {"stats.seed: expected an integer >= 0"}},
      {"stats_type", [](json& d) { d["stats"] = json::array(); }, {"stats: expected an object"}},
      {"actions_type",
       [](json& d) { d["actions"] = "none"; },
       {"actions: expected an array, found a string"}},
      {"action_type_null",
       [](json& d) { d["actions"][1] = nullptr; },
       {"actions[1]: expected an object, found null"}},
      {"top_level_array",
       [](json& d) {
         d = json::array({1, 2});
       },
       {"plan.json: expected a JSON object"}},
  };
  ASSERT_GE(cases.size(), 12u);
  for (const Malformed& c : cases) {
    auto parsed = ParsePlan(Text(c.change), "plan.json");
    ASSERT_FALSE(parsed.has_value()) << c.name;
    EXPECT_EQ(parsed.error().code, ErrorCode::kInvalidInput) << c.name;
    for (const std::string& phrase : c.phrases) {
      EXPECT_NE(parsed.error().message.find(phrase), std::string::npos)
          << c.name << ": '" << phrase << "' not in: " << parsed.error().message;
    }
  }
}

TEST(PlanJson, BrokenTextIsRefusedWithoutCrashing) {
  struct Case {
    std::string text, phrase;
  };
  const std::vector<Case> cases = {
      {"", "malformed JSON"},
      {"{", "malformed JSON"},
      {"{\"format\": NaN}", "malformed JSON"},
      {"{\"format\": \"wrap-plan\", \"version\": 1e999}", "malformed JSON"},
      {"{\"format\": \"wrap-plan\", \"format\": \"wrap-plan\"}", "duplicate key \"format\""},
      {std::string(100000, '['), "malformed JSON"},
      {"\"wrap-plan\"", "expected a JSON object at the top level, found a string"},
      {"{\"format\": \"wrap-plan\", \"version\": " + std::string(50000, '[') +
           std::string(50000, ']') + "}",
       "version: expected 1 (the version this build reads), found an array"},
      {"{\"format\": \"wrap-plan\", \"version\": 1, \"deep\": " + std::string(50000, '[') +
           std::string(50000, ']') + "}",
       "deep: unknown field"},
  };
  for (const Case& c : cases) {
    auto parsed = ParsePlan(c.text, "p.json");
    ASSERT_FALSE(parsed.has_value()) << c.text.substr(0, 40);
    EXPECT_NE(parsed.error().message.find(c.phrase), std::string::npos) << parsed.error().message;
    EXPECT_EQ(parsed.error().message.rfind("p.json: ", 0), 0u) << parsed.error().message;
  }
  // Every truncation of a good document is refused, never crashes.
  const std::string good = SerializePlan(StoolPlan());
  for (size_t n = 0; n + 2 < good.size(); n += 97) {
    EXPECT_FALSE(ParsePlan(good.substr(0, n), "p.json").has_value()) << n;
  }
  // Duplicate keys deep inside are found too.
  std::string dup = good;
  const std::string key = "\"resting\": true";
  const size_t at = dup.find(key);
  ASSERT_NE(at, std::string::npos);
  dup.insert(at, key + ", ");
  auto parsed = ParsePlan(dup, "p.json");
  ASSERT_FALSE(parsed.has_value());
  EXPECT_NE(parsed.error().message.find("duplicate key \"resting\""), std::string::npos);
}

class MatchesProject : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ValidationOptions options;
    options.load_meshes = false;
    stool_ = new LoadedProject(LoadProject(ProjectFile("stool"), options));
    cross_ = new LoadedProject(LoadProject(ProjectFile("cross"), options));
  }
  static void TearDownTestSuite() {
    delete stool_;
    delete cross_;
  }
  static Result<void> Check(const Plan& plan, const LoadedProject& p) {
    return CheckPlanMatchesProject(plan, *p.project, *p.check.tree, "my_plan.json");
  }
  static void ExpectRefused(const Plan& plan, const LoadedProject& p,
                            const std::vector<std::string>& phrases) {
    auto ok = Check(plan, p);
    ASSERT_FALSE(ok.has_value());
    EXPECT_EQ(ok.error().code, ErrorCode::kInvalidInput);
    EXPECT_EQ(ok.error().message.rfind("my_plan.json: ", 0), 0u) << ok.error().message;
    for (const std::string& phrase : phrases) {
      EXPECT_NE(ok.error().message.find(phrase), std::string::npos)
          << "'" << phrase << "' not in: " << ok.error().message;
    }
  }
  static LoadedProject* stool_;
  static LoadedProject* cross_;
};

LoadedProject* MatchesProject::stool_ = nullptr;
LoadedProject* MatchesProject::cross_ = nullptr;

TEST_F(MatchesProject, AcceptsThePlanOfItsProject) {
  ASSERT_TRUE(stool_->project && stool_->check.tree);
  auto ok = Check(StoolPlan(), *stool_);
  EXPECT_TRUE(ok.has_value()) << ok.error().message;
}

TEST_F(MatchesProject, RefusesAPlanForOtherRobotsOrParts) {
  Plan robots = StoolPlan();
  robots.robots[1] = "ur10e_b";
  ExpectRefused(robots, *stool_, {"robots[1]", "ur10e_b", "other robots", "'stool'"});
  Plan fewer = StoolPlan();
  fewer.robots.pop_back();
  ExpectRefused(fewer, *stool_, {"robots[3]", "ur5e_d"});
  Plan parts = StoolPlan();
  parts.parts[2] = "backrest";
  ExpectRefused(parts, *stool_, {"parts[2]", "backrest", "other parts"});
  Plan nodes = StoolPlan();
  nodes.nodes[6] = "seat+leg2";
  ExpectRefused(nodes, *stool_, {"nodes[6]", "seat+leg2"});
  // The stool's plan against the cross project: its parts are cubes.
  ASSERT_TRUE(cross_->project && cross_->check.tree);
  ExpectRefused(StoolPlan(), *cross_, {"my_plan.json: "});
}

TEST_F(MatchesProject, RefusesWrongJointCountsAndIndices) {
  Plan dof = StoolPlan();
  for (Keyframe* k : {&dof.initial}) {
    for (JointVector& q : k->q) q = JointVector::Zero(7);
  }
  ExpectRefused(dof, *stool_, {"initial.q.ur5e_a: expected 6 numbers", "'ur5e'", "found 7"});
  Plan approach = StoolPlan();
  approach.actions[3].approach->q[2] = JointVector::Zero(5);
  ExpectRefused(approach, *stool_, {"actions[3].approach.q.ur5e_c: expected 6 numbers"});
  Plan grasp = StoolPlan();
  grasp.actions[0].grasps[0].grasp.part = kSeat;
  ExpectRefused(grasp, *stool_,
                {"actions[0].grasps[0].part", "'seat' is not in subassembly 'leg1'"});
  Plan range = StoolPlan();
  range.actions[2].objects[0] = 40;
  ExpectRefused(range, *stool_, {"actions[2].objects[0]", "out of range"});
  Plan milestone = StoolPlan();
  milestone.milestone_steps[0] = kLeg2;
  ExpectRefused(milestone, *stool_, {"milestones[0]", "not an assembly step"});
}

TEST_F(MatchesProject, RefusesKeyframesThatLoseOrDoubleAPart) {
  Plan lost = StoolPlan();
  lost.actions[1].keyframe.objects.pop_back();  // leg4
  ExpectRefused(lost, *stool_, {"actions[1].keyframe.objects", "part 'leg4' is in no object"});
  Plan twice = StoolPlan();
  twice.actions[4].keyframe.objects.push_back({kSeat, Iso3::Identity(), true});
  ExpectRefused(twice, *stool_,
                {"actions[4].keyframe.objects", "part 'seat' is in both 'seat+leg1' and 'seat'"});
}

}  // namespace
}  // namespace wrap
