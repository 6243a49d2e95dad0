// A plan file that does not match its project (other parts, other robots, another project) is
// refused with a message naming the plan file and what differs, not replayed: `wrap validate
// --plan`, `wrap render --plan`, `wrap sim --plan`, and the engine check the GUI's plan loading
// calls (CheckPlanMatchesProject, ui/gui/app.cpp MatchPlan).
#include <string>
#include <vector>

#include "model/validate.h"
#include "reliability_fixture.h"
#include "task/plan_json.h"

namespace wrap::reliability {
namespace {

using cli::CliRun;
using cli::Wrap;
using nlohmann::json;

/// The half stool's project as JSON with its mesh paths made absolute, so that a copy in another
/// folder still finds them.
json HalfStool() {
  const fs::path file = cli::Project("half_stool");
  json p = json::parse(ReadBytes(file));
  for (json& part : p["parts"]) {
    part["mesh"] =
        (file.parent_path() / part["mesh"].get<std::string>()).lexically_normal().string();
  }
  return p;
}

struct Variant {
  std::string name;
  json project;
  std::vector<std::string> phrases;
};

std::vector<Variant> Variants() {
  json renamed_part = HalfStool();
  renamed_part["parts"][1]["name"] = "peg1";
  for (json& step : renamed_part["steps"]) {
    for (json& input : step["inputs"]) {
      if (input == "leg1") input = "peg1";
    }
    if (step["mating"]["moved"] == "leg1") step["mating"]["moved"] = "peg1";
    if (step["mating"]["base"] == "leg1") step["mating"]["base"] = "peg1";
  }
  json renamed_robot = HalfStool();
  renamed_robot["robots"][0]["name"] = "port";
  json extra_robot = HalfStool();
  json third = extra_robot["robots"][1];
  third["name"] = "third";
  third.erase("mounted_on");
  third.erase("mount");
  third["base_pose"] = {{"xyz", {0.6, 0.4, 0.75}}};
  extra_robot["robots"].push_back(third);
  return {
      {"other_parts", renamed_part, {"parts[1]", "leg1", "other parts"}},
      {"other_robots", renamed_robot, {"robots[0]", "left", "other robots"}},
      {"more_robots", extra_robot, {"robots", "third"}},
  };
}

// The copied half stool accepts its own plan: the variants below differ only where they say.
TEST(PlanMismatch, OwnProjectAcceptsThePlan) {
  TempDir dir("own");
  const fs::path project = WriteBytes(dir.path / "half_stool.json", HalfStool().dump(2));
  const CliRun r = Wrap({"validate", project.string(), "--plan", HalfStoolPlan().string()});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("Validated:"), std::string::npos) << r.out;
}

void ExpectRefused(const std::string& project, const std::vector<std::string>& phrases,
                   const std::string& what) {
  const std::string plan = HalfStoolPlan().string();
  TempDir dir("refused");
  const fs::path out = dir.path / "out";
  std::vector<std::vector<std::string>> commands = {
      {"validate", project, "--plan", plan},
      {"sim", project, "--plan", plan, "-o", (out / "report.json").string()},
  };
#ifdef WRAP_TEST_HAVE_RENDER
  commands.push_back({"render", project, "--plan", plan, "-o", (out / "render").string()});
#endif
  for (const auto& args : commands) {
    const CliRun r = Wrap(args);
    EXPECT_EQ(r.code, 2) << what << ": wrap " << args[0] << "\n" << r.out << r.err;
    EXPECT_NE(r.err.find("half_stool_plan.json: "), std::string::npos)
        << what << ": wrap " << args[0] << " does not name the plan file:\n"
        << r.err;
    for (const std::string& phrase : phrases) {
      EXPECT_NE(r.err.find(phrase), std::string::npos)
          << what << ": wrap " << args[0] << ": '" << phrase << "' not on stderr:\n"
          << r.err;
    }
    // Refused before anything was replayed, drawn or simulated.
    EXPECT_EQ(r.out.find("Validated"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("holds"), std::string::npos) << r.out;
  }
  for (const std::string& f : ListFiles(out)) {
    EXPECT_EQ(f, "render") << what << " wrote '" << f << "'";
  }
  for (const std::string& f : ListFiles(out / "render")) ADD_FAILURE() << what << " drew " << f;
}

TEST(PlanMismatch, OtherPartsOrRobotsAreRefusedByTheCommands) {
  for (const Variant& v : Variants()) {
    TempDir dir(v.name);
    const fs::path project = WriteBytes(dir.path / (v.name + ".json"), v.project.dump(2));
    ExpectRefused(project.string(), v.phrases, v.name);
  }
}

TEST(PlanMismatch, AnotherProjectIsRefusedByTheCommands) {
  ExpectRefused(cli::Project("cross"), {"other robots", "'cross'"}, "cross");
  ExpectRefused(cli::Project("stool"), {"other robots", "'stool'"}, "stool");
}

// What the GUI runs when it loads a plan: the same engine check on the project as loaded.
TEST(PlanMismatch, EngineCheckRefusesOtherPartsAndRobots) {
  auto plan = ReadPlanFile(HalfStoolPlan());
  ASSERT_TRUE(plan) << plan.error().message;
  for (const Variant& v : Variants()) {
    TempDir dir(v.name);
    const fs::path project = WriteBytes(dir.path / (v.name + ".json"), v.project.dump(2));
    ValidationOptions options;
    options.load_meshes = false;
    const LoadedProject loaded = LoadProject(project, options);
    ASSERT_TRUE(loaded.project && loaded.check.tree) << v.name;
    auto ok = CheckPlanMatchesProject(*plan, *loaded.project, *loaded.check.tree, "the_plan.json");
    ASSERT_FALSE(ok.has_value()) << v.name;
    EXPECT_EQ(ok.error().code, ErrorCode::kInvalidInput);
    EXPECT_EQ(ok.error().message.rfind("the_plan.json: ", 0), 0u) << ok.error().message;
    for (const std::string& phrase : v.phrases) {
      EXPECT_NE(ok.error().message.find(phrase), std::string::npos)
          << v.name << ": '" << phrase << "' not in: " << ok.error().message;
    }
  }
}

}  // namespace
}  // namespace wrap::reliability
