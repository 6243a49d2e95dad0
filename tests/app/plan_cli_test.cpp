// `wrap plan` through the CLI: the contract's exit codes, the words it prints and the plan file.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"

namespace wrap::cli {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("wrap_plan_cli_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(PlanCli, PlansValidatesAndWritesThePlan) {
  const fs::path dir = TempDir("stool");
  const fs::path out = dir / "plan.json";
  const CliRun r = Wrap({"plan", Project("half_stool"), "-o", out.string(), "--validate"});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Solved: cost"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1. "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("assembles 'leg1' onto 'seat'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Validated:"), std::string::npos) << r.out;
  // With motion (the default): the makespans, and the independent check of the trajectories.
  EXPECT_NE(r.out.find("Motion: makespan"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Trajectories checked:"), std::string::npos) << r.out;
  std::ifstream in(out);
  const nlohmann::json plan = nlohmann::json::parse(in);
  EXPECT_EQ(plan["format"], "wrap-plan");
  EXPECT_TRUE(plan["stats"]["motion"].get<bool>());
  EXPECT_GT(plan["stats"]["makespan_s"].get<double>(), 0.0);
  EXPECT_LE(plan["stats"]["makespan_s"].get<double>(),
            plan["stats"]["makespan_sequential_s"].get<double>());
  ASSERT_TRUE(plan.contains("trajectories"));
  EXPECT_EQ(plan["trajectories"].size(), plan["robots"].size());
  EXPECT_TRUE(plan["actions"][0].contains("end_s"));
  EXPECT_TRUE(plan["stats"]["solved"].get<bool>());
  EXPECT_EQ(plan["stats"]["cost"].get<int>(), static_cast<int>(plan["actions"].size()));
  for (const char* key : {"t_init_s", "t_grasp_s", "t_bwd_s", "t_lp_s", "t_fwd_s", "t_ik_s"}) {
    EXPECT_TRUE(plan["stats"].contains(key)) << key;
  }
  EXPECT_EQ(plan["stats"]["planner"], "wrap");  // the default
  EXPECT_EQ(plan["stats"]["seed"].get<int>(), 0);
  ASSERT_FALSE(plan["actions"].empty());
  EXPECT_TRUE(plan["actions"][0].contains("keyframe"));
  EXPECT_TRUE(plan["actions"][0]["keyframe"]["q"].contains("left"));
  // Every assemble says how hard each gripper holding its inputs works (full wrench model; a
  // validated plan stays within the limits).
  int assembles = 0;
  for (const auto& a : plan["actions"]) {
    if (a["type"] != "assemble") continue;
    ++assembles;
    ASSERT_TRUE(a.contains("utilisation")) << a.dump();
    for (const auto& who : a["robots"]) {
      ASSERT_TRUE(a["utilisation"].contains(who.get<std::string>())) << a.dump();
      const double u = a["utilisation"][who.get<std::string>()].get<double>();
      EXPECT_GT(u, 0.0) << a.dump();
      EXPECT_LE(u, 1.0 + 1e-6) << a.dump();
    }
  }
  EXPECT_EQ(assembles, 2);

  // `wrap validate --plan` also checks the trajectories of a plan with motion, and catches a
  // knot moved off its path.
  const CliRun again = Wrap({"validate", Project("half_stool"), "--plan", out.string()});
  EXPECT_EQ(again.code, 0) << again.out << again.err;
  EXPECT_NE(again.out.find("Trajectories checked:"), std::string::npos) << again.out;
  nlohmann::ordered_json moved = nlohmann::ordered_json::parse(std::ifstream(out));
  nlohmann::ordered_json& q = moved["trajectories"][0]["q"];
  ASSERT_GT(q.size(), 2u);
  q[q.size() / 2][0] = q[q.size() / 2][0].get<double>() + 0.5;
  const fs::path bad = dir / "moved_knot.json";
  std::ofstream(bad) << moved.dump(2);
  const CliRun caught = Wrap({"validate", Project("half_stool"), "--plan", bad.string()});
  EXPECT_EQ(caught.code, 1) << caught.out << caught.err;
  EXPECT_NE(caught.err.find("Trajectory check FAILED"), std::string::npos) << caught.err;
}

// --log writes the topics' lines to stderr and changes nothing in the plan; an unknown topic is
// a usage error listing the known ones.
// The plumber's block's block slides into its base with no clearance: an insertion thinned to
// the usual half millimetre cut 0.3 mm into the base, the trajectory check refused every task
// plan, and seed 2 found no motion in 600 s. The insertion skill now keeps the moved input
// within the touch depth (SegmentBuilder::InsertionWithinOverlap). No wall-clock bound: only
// the work budgets end the run.
TEST(PlanCli, AnInsertionWithNoClearanceKeepsToItsLine) {
  if (!fs::exists(fs::path(WRAP_SHARED_DIR) / "fabrica")) {
    GTEST_SKIP() << "the Fabrica meshes are not beside the repository";
  }
  const CliRun r = Wrap({"plan", Project("fabrica_plumbers_block"), "--seed", "2", "--validate",
                         "--time-limit", "3600", "-o", (TempDir("block") / "plan.json").string()});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Motion: makespan"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("events and grasps: no issue"), std::string::npos) << r.out;
}

TEST(PlanCli, LogTopicsGoToStderrAndLeaveThePlanAlone) {
  const fs::path dir = TempDir("log");
  const CliRun quiet = Wrap({"plan", Project("half_stool"), "-o", (dir / "quiet.json").string()});
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("[motion]"), std::string::npos) << quiet.err;
  const CliRun logged = Wrap({"plan", Project("half_stool"), "-o", (dir / "logged.json").string(),
                              "--log", "motion,task"});
  ASSERT_EQ(logged.code, 0) << logged.err;
  EXPECT_NE(logged.err.find("[motion] free: action 1"), std::string::npos) << logged.err;
  EXPECT_NE(logged.err.find("[task] milestone 0"), std::string::npos) << logged.err;
  auto actions = [](const fs::path& file) {
    std::ifstream in(file);
    const nlohmann::json plan = nlohmann::json::parse(in);
    return plan["actions"].dump() + plan["trajectories"].dump();
  };
  EXPECT_EQ(actions(dir / "logged.json"), actions(dir / "quiet.json"));
  const CliRun bad = Wrap({"plan", Project("half_stool"), "--log", "motoin"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("unknown log topic 'motoin'"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("motion.diag"), std::string::npos) << bad.err;
}

TEST(PlanCli, SeedAndWrenchModeReachTheStats) {
  const fs::path dir = TempDir("seed");
  const fs::path out = dir / "plan.json";
  const CliRun r =
      Wrap({"plan", Project("half_stool"), "-o", out.string(), "--seed", "5", "--wrench", "gravity",
            "--force-scale", "0.5", "--objective", "makespan", "--task-only"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("estimated makespan"), std::string::npos) << r.out;
  std::ifstream in(out);
  const nlohmann::json plan = nlohmann::json::parse(in);
  EXPECT_EQ(plan["stats"]["seed"].get<int>(), 5);
  EXPECT_EQ(plan["stats"]["wrench_mode"], "gravity");
  EXPECT_DOUBLE_EQ(plan["stats"]["force_scale"].get<double>(), 0.5);
  EXPECT_EQ(plan["stats"]["objective"], "makespan");
  EXPECT_GT(plan["stats"]["makespan_est_s"].get<double>(), 0.0);
}

// --optimize reports the improvement and records the cost over time; every variant is known.
TEST(PlanCli, OptimizeRecordsTheCostOverTime) {
  const fs::path dir = TempDir("optimize");
  const fs::path out = dir / "plan.json";
  const CliRun r =
      Wrap({"plan", Project("half_stool"), "-o", out.string(), "--optimize", "--time-limit", "20",
            "--planner", "counting", "--validate", "--task-only"});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Improved: cost "), std::string::npos) << r.out;
  std::ifstream in(out);
  const nlohmann::json plan = nlohmann::json::parse(in);
  const nlohmann::json& st = plan["stats"];
  EXPECT_EQ(st["planner"], "counting");
  ASSERT_TRUE(st["cost_history"].is_array());
  ASSERT_GE(st["cost_history"].size(), 1u);
  EXPECT_EQ(st["cost_history"][0][1], st["first_cost"]);
  EXPECT_EQ(st["cost_history"].back()[1], st["cost"]);
  EXPECT_LE(st["cost"].get<int>(), st["first_cost"].get<int>());
  for (const char* variant : {"optimistic", "flat", "exact", "fine"}) {
    const CliRun v = Wrap({"plan", Project("half_stool"), "--planner", variant, "--task-only"});
    EXPECT_EQ(v.code, 0) << variant << ": " << v.out << v.err;
  }
}

TEST(PlanCli, BadInputExitsTwo) {
  EXPECT_EQ(Wrap({"plan", Project("half_stool"), "--wrench", "strong"}).code, 2);
  EXPECT_EQ(Wrap({"plan", Project("half_stool"), "--force-scale", "-1"}).code, 2);
  EXPECT_EQ(Wrap({"plan", Project("half_stool"), "--time-limit", "0"}).code, 2);
  EXPECT_EQ(Wrap({"plan", Project("half_stool"), "--planner", "magic"}).code, 2);
  EXPECT_EQ(Wrap({"plan", Project("half_stool"), "--objective", "fast"}).code, 2);
  EXPECT_EQ(Wrap({"plan", Project("half_stool"), "--memory-limit", "0"}).code, 2);
  const CliRun missing = Wrap({"plan", "/nonexistent/project.json"});
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("project.json"), std::string::npos) << missing.err;
}

TEST(PlanCli, UnwritableOutputLeavesNothingAndExitsTwo) {
  const fs::path dir = TempDir("unwritable");
  const fs::path out = dir / "no_such_folder" / "plan.json";
  const CliRun r = Wrap({"plan", Project("half_stool"), "-o", out.string()});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// `wrap validate PROJECT --plan PLAN`: a planned plan replays valid (exit 0); the same plan with
// one robot's joints moved at one keyframe is not (exit 1, naming the action); a plan of another
// project and a file that is no plan are bad input (exit 2).
TEST(PlanCli, ValidateReplaysAPlanFile) {
  const fs::path dir = TempDir("validate_plan");
  const fs::path good = dir / "plan.json";
  ASSERT_EQ(Wrap({"plan", Project("half_stool"), "-o", good.string(), "--task-only"}).code, 0);
  const CliRun ok = Wrap({"validate", Project("half_stool"), "--plan", good.string()});
  EXPECT_EQ(ok.code, 0) << ok.out << ok.err;
  EXPECT_NE(ok.out.find("Validated:"), std::string::npos) << ok.out;

  std::ifstream in(good);
  nlohmann::ordered_json plan = nlohmann::ordered_json::parse(in);
  // The first action's acting robot turns its first joint by 0.5 rad: its TCP leaves the grasp.
  nlohmann::ordered_json& a0 = plan["actions"][0];
  const std::string robot = a0["robots"][0];
  a0["keyframe"]["q"][robot][0] = a0["keyframe"]["q"][robot][0].get<double>() + 0.5;
  const fs::path bad = dir / "moved.json";
  std::ofstream(bad) << plan.dump(2);
  const CliRun moved = Wrap({"validate", Project("half_stool"), "--plan", bad.string()});
  EXPECT_EQ(moved.code, 1) << moved.out << moved.err;
  EXPECT_NE(moved.err.find("Validation FAILED"), std::string::npos) << moved.err;
  EXPECT_NE(moved.err.find("action 0"), std::string::npos) << moved.err;

  const CliRun other = Wrap({"validate", Project("cross"), "--plan", good.string()});
  EXPECT_EQ(other.code, 2) << other.out << other.err;
  const fs::path junk = dir / "junk.json";
  std::ofstream(junk) << "{\"format\": \"wrap-plan\", \"actions\": 3}";
  const CliRun garbage = Wrap({"validate", Project("half_stool"), "--plan", junk.string()});
  EXPECT_EQ(garbage.code, 2) << garbage.out << garbage.err;
  EXPECT_NE(garbage.err.find("junk.json"), std::string::npos) << garbage.err;
}

// Only vacuum cups and a step that needs transverse force: exit 1 naming the step.
TEST(PlanCli, InfeasibleProjectExitsOneNamingTheStep) {
  const fs::path dir = TempDir("infeasible");
  std::ifstream in(Project("stool"));
  nlohmann::ordered_json p = nlohmann::ordered_json::parse(in);
  for (auto& robot : p["robots"]) robot["end_effector"] = "vacuum_cup";
  p["steps"][0]["mating"]["transverse_fraction"] = 0.5;
  p["steps"][0]["mating"]["offset_m"] = 0.01;
  // Meshes are relative to the project file: point them back at the repository.
  for (auto& part : p["parts"]) {
    part["mesh"] = (fs::path(Project("stool")).parent_path() / part["mesh"].get<std::string>())
                       .lexically_normal()
                       .string();
  }
  const fs::path file = dir / "vacuum_stool.json";
  std::ofstream(file) << p.dump(2);
  const CliRun r = Wrap({"plan", file.string(), "--time-limit", "120", "--task-only"});
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("seat+leg1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("vacuum"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace wrap::cli
