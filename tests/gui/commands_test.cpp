// Every command: what it does, that undo restores the project exactly and redo reapplies it,
// and the edits it refuses (cycles, duplicate names, unknown catalog entries).
#include "gui/commands.h"

#include <gtest/gtest.h>

#include "gui/document.h"
#include "gui_fixture.h"
#include "model/validate.h"

namespace wrap::gui {
namespace {

using testing::ExampleProject;
using testing::OpenStool;
namespace fs = std::filesystem;

/// Runs `command` on `doc`, checks that it changed the project, that undo gives back exactly
/// the project before and redo exactly the project after; leaves it done.
void ExpectDoesAndUndoes(Document& doc, const Command& command) {
  const Project before = doc.project();
  auto r = doc.Execute(command);
  ASSERT_TRUE(r) << command.label << ": " << r.error().message;
  const Project after = doc.project();
  EXPECT_NE(after, before) << command.label;
  EXPECT_TRUE(doc.dirty());
  ASSERT_TRUE(doc.Undo());
  EXPECT_EQ(doc.project(), before) << command.label;
  ASSERT_TRUE(doc.Redo());
  EXPECT_EQ(doc.project(), after) << command.label;
}

/// Expects `command` refused with kInvalidInput, a message containing `phrase`, and nothing
/// changed.
void ExpectRefused(Document& doc, const Command& command, const std::string& phrase) {
  const Project before = doc.project();
  auto r = doc.Execute(command);
  ASSERT_FALSE(r) << command.label;
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(r.error().message.find(phrase), std::string::npos) << r.error().message;
  EXPECT_EQ(doc.project(), before);
}

const Step& StepNamed(const Project& p, const std::string& name) {
  for (const Step& s : p.steps) {
    if (s.name == name) return s;
  }
  ADD_FAILURE() << "no step " << name;
  static Step none;
  return none;
}

TEST(PartCommands, AddSetRemove) {
  Document doc = OpenStool();
  Part p;
  p.name = "bolt";
  p.mesh = "../assets/parts/stool/leg.stl";
  p.scale = 0.001;
  ExpectDoesAndUndoes(doc, AddPart(p));
  EXPECT_EQ(doc.project().parts.back().name, "bolt");

  Part edited = doc.project().parts.back();
  edited.mass_kg = 0.3;
  edited.density_kg_m3 = 900;
  edited.color = {1, 0, 0, 1};
  edited.scale = 0.01;
  edited.initial_pose.xyz = Vec3(0.1, 0.2, 0.75);
  edited.initial_pose.rpy = Vec3(0, 0, 1.0);
  ExpectDoesAndUndoes(doc, SetPart("bolt", edited));
  EXPECT_EQ(doc.project().parts.back(), edited);

  ExpectDoesAndUndoes(doc, RemovePart("bolt"));
  EXPECT_EQ(doc.project().parts.size(), 5u);
}

TEST(PartCommands, RefusesDuplicateNamesAndRemovingAnInput) {
  Document doc = OpenStool();
  Part p;
  p.name = "seat+leg1";  // a step's name: parts and steps share one namespace
  ExpectRefused(doc, AddPart(p), "already used");
  ExpectRefused(doc, RemovePart("leg2"), "input of step 'seat+legs1-2'");
  ExpectRefused(doc, RemovePart("nothing"), "no part");
  Part seat = doc.project().parts[0];
  seat.name = "leg1";
  ExpectRefused(doc, SetPart("seat", seat), "already used");
}

TEST(PartCommands, RenamingAPartThroughSetPartCarriesIntoSteps) {
  Document doc = OpenStool();
  Part seat = doc.project().parts[0];
  seat.name = "top";
  ExpectDoesAndUndoes(doc, SetPart("seat", seat));
  const Step& s = StepNamed(doc.project(), "seat+leg1");
  EXPECT_EQ(s.inputs[0], "top");
  EXPECT_EQ(s.mating.base, "top");
}

TEST(PartCommands, ImportMeshWithUnitRestsOnTheTable) {
  Document doc = OpenStool();
  PartImportOptions options;
  options.scale = 0.001;  // mm
  options.mass_kg = 0.05;
  const auto mesh = std::filesystem::path(WRAP_SOURCE_DIR) / "assets/parts/stool/leg.stl";
  auto part = PreparePartImport(doc.project(), doc.ResolvePath(), mesh, options);
  ASSERT_TRUE(part) << part.error().message;
  EXPECT_EQ(part->name, "leg") << "named after the file";
  EXPECT_EQ(part->mesh, "../assets/parts/stool/leg.stl") << "relative to the project";
  EXPECT_DOUBLE_EQ(part->scale, 0.001);
  ASSERT_TRUE(part->mass_kg);
  EXPECT_DOUBLE_EQ(*part->mass_kg, 0.05);
  ExpectDoesAndUndoes(doc, AddPart(*part));
  // It validates as resting on the table: a project with it and a step using it loads.
  ProjectCheck check = ValidateProject(doc.project(), doc.ResolvePath());
  for (const Diagnostic& d : check.diagnostics.items) {
    EXPECT_EQ(d.path.find("parts[5].initial_pose"), std::string::npos) << Format(d);
  }
  // A second import of the same file gets a new name.
  auto second = PreparePartImport(doc.project(), doc.ResolvePath(), mesh, options);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->name, "leg_2");
}

TEST(PartCommands, ImportOfAMissingMeshFailsNamingTheFile) {
  Document doc = OpenStool();
  auto part = PreparePartImport(doc.project(), doc.ResolvePath(), "/nonexistent/x.stl", {});
  ASSERT_FALSE(part);
  EXPECT_NE(part.error().message.find("x.stl"), std::string::npos);
  PartImportOptions bad;
  bad.scale = -1;
  auto refused = PreparePartImport(doc.project(), doc.ResolvePath(), "/nonexistent/x.stl", bad);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("scale"), std::string::npos);
}

TEST(StepCommands, CreateRenameDelete) {
  Document doc = OpenStool();
  ExpectDoesAndUndoes(doc, AddStep("spare"));
  EXPECT_EQ(doc.project().steps.back().name, "spare");
  EXPECT_TRUE(doc.project().steps.back().inputs.empty());
  ExpectDoesAndUndoes(doc, RenameNode("seat+leg1", "first"));
  const Step& second = StepNamed(doc.project(), "seat+legs1-2");
  EXPECT_EQ(second.inputs[0], "first");
  EXPECT_EQ(second.mating.base, "first");
  ExpectRefused(doc, RenameNode("first", "leg2"), "already used");
  ExpectRefused(doc, RenameNode("first", ""), "empty");
  ExpectDoesAndUndoes(doc, RemoveStep("first"));
  const Step& orphan = StepNamed(doc.project(), "seat+legs1-2");
  EXPECT_EQ(orphan.inputs, std::vector<std::string>{"leg2"});
  EXPECT_TRUE(orphan.mating.base.empty());
  EXPECT_EQ(orphan.mating.moved, "leg2");
}

TEST(StepCommands, AddAndRemoveInputs) {
  Document doc = OpenStool();
  ASSERT_TRUE(doc.Execute(RemoveStep("stool")));  // leg4 and seat+legs1-3 are free again
  ExpectDoesAndUndoes(doc, AddStep("top"));
  ExpectDoesAndUndoes(doc, AddInput("top", "seat+legs1-3"));
  ExpectDoesAndUndoes(doc, AddInput("top", "leg4"));
  const Step& top = StepNamed(doc.project(), "top");
  EXPECT_EQ(top.inputs, (std::vector<std::string>{"seat+legs1-3", "leg4"}));
  EXPECT_EQ(top.mating.base, "seat+legs1-3") << "the first input is the base";
  EXPECT_EQ(top.mating.moved, "leg4") << "the second is moved";
  // The rebuilt project is valid again (the same DAG under another root name).
  ProjectCheck check = ValidateProject(doc.project(), doc.ResolvePath());
  EXPECT_FALSE(check.diagnostics.has_errors());
  ExpectDoesAndUndoes(doc, RemoveInput("top", "leg4"));
  EXPECT_TRUE(StepNamed(doc.project(), "top").mating.moved.empty());
  ExpectRefused(doc, RemoveInput("top", "leg4"), "not an input");
}

TEST(StepCommands, RefusesACycleWithAMessage) {
  Document doc = OpenStool();
  ASSERT_TRUE(doc.Execute(RemoveInput("seat+leg1", "leg1")));
  // seat+leg1 is (transitively) an input of stool: stool as its input closes a cycle.
  ExpectRefused(doc, AddInput("seat+leg1", "stool"), "cycle");
  auto why = CheckNewInput(doc.project(), "seat+leg1", "stool");
  ASSERT_FALSE(why);
  EXPECT_NE(why.error().message.find("'seat+legs1-2'"), std::string::npos)
      << "names the chain: " << why.error().message;
  ExpectRefused(doc, AddInput("seat+leg1", "seat+leg1"), "itself");
}

TEST(StepCommands, RefusesAThirdInputASharedInputAndUnknownNames) {
  Document doc = OpenStool();
  ASSERT_TRUE(doc.Execute(AddStep("extra")));
  ExpectRefused(doc, AddInput("seat+leg1", "extra"), "two inputs");
  ExpectRefused(doc, AddInput("extra", "leg1"), "already an input of step 'seat+leg1'");
  ExpectRefused(doc, AddInput("extra", "ghost"), "no part or step");
  ExpectRefused(doc, AddInput("ghost", "leg1"), "no step");
}

TEST(MatingCommands, SetEveryField) {
  Document doc = OpenStool();
  Mating m = StepNamed(doc.project(), "seat+leg1").mating;
  std::swap(m.moved, m.base);
  m.axis = Vec3(1, 0, 0);
  m.force_N = 25;
  m.torque_Nm = 0.5;
  m.transverse_fraction = 0.2;
  m.offset_m = 0.01;
  m.approach_m = 0.05;
  Pose final_pose;
  final_pose.xyz = Vec3(0.085, 0.085, -0.185);
  m.final_poses = {final_pose};
  m.connection_limits = WrenchBox{Vec3(100, 100, 50), Vec3(5, 5, 5)};
  ExpectDoesAndUndoes(doc, SetMating("seat+leg1", m));
  EXPECT_EQ(StepNamed(doc.project(), "seat+leg1").mating, m);
  Mating bad = m;
  bad.moved = "leg2";
  ExpectRefused(doc, SetMating("seat+leg1", bad), "not an input");
  bad = m;
  bad.base = bad.moved;
  ExpectRefused(doc, SetMating("seat+leg1", bad), "must differ");
}

TEST(RobotCommands, AddEditRemoveFromTheCatalog) {
  Document doc = OpenStool();
  ExpectDoesAndUndoes(doc, AddRobot("ur10e", "robotiq_2f85"));
  const Robot added = doc.project().robots.back();
  EXPECT_EQ(added.name, "ur10e_1");
  EXPECT_EQ(added.model, "ur10e");
  EXPECT_EQ(added.end_effector, "robotiq_2f85");
  EXPECT_DOUBLE_EQ(added.base_pose.xyz.z(), doc.project().table.height);

  Robot edited = added;
  edited.name = "big";
  edited.end_effector = "vacuum_cup";
  edited.base_pose.xyz = Vec3(0.5, 0.5, 0.75);
  edited.base_pose.rpy = Vec3(0, 0, 2.0);
  ExpectDoesAndUndoes(doc, SetRobot("ur10e_1", edited));
  EXPECT_EQ(doc.project().robots.back(), edited);

  ExpectDoesAndUndoes(doc, RemoveRobot("big"));
  EXPECT_EQ(doc.project().robots.size(), 4u);
}

TEST(RobotCommands, AddFromAUrdf) {
  Document doc = OpenStool();
  const fs::path urdf = fs::path(WRAP_SOURCE_DIR) / "tests/fuzz/seeds/urdf/three_joint_arm.urdf";
  auto robot = PrepareUrdfRobot(doc.project(), ExampleProject("stool"), urdf, "", "", "vacuum_cup");
  ASSERT_TRUE(robot) << robot.error().message;
  EXPECT_EQ(robot->name, "three_joint_arm");
  EXPECT_EQ(robot->urdf, "../tests/fuzz/seeds/urdf/three_joint_arm.urdf")
      << "relative to the project's folder";
  EXPECT_TRUE(robot->model.empty());
  EXPECT_EQ(robot->end_effector, "vacuum_cup");
  EXPECT_DOUBLE_EQ(robot->base_pose.xyz.z(), doc.project().table.height);
  ExpectDoesAndUndoes(doc, AddRobot(*robot));
  EXPECT_EQ(doc.project().robots.back(), *robot);
  // A second one gets a new name; the same name again is refused.
  auto second = PrepareUrdfRobot(doc.project(), ExampleProject("stool"), urdf, "base_link",
                                 "tool0", "robotiq_2f85");
  ASSERT_TRUE(second) << second.error().message;
  EXPECT_EQ(second->name, "three_joint_arm_2");
  EXPECT_EQ(second->urdf_root, "base_link");
  EXPECT_EQ(second->urdf_tip, "tool0");
  ExpectRefused(doc, AddRobot(*robot), "already a robot");
  // The project with the URDF robot passes the loader's checks (the chain loads from the path).
  const ProjectCheck check = ValidateProject(doc.project(), ExampleProject("stool"));
  for (const Diagnostic& d : check.diagnostics.items) ADD_FAILURE() << Format(d);
}

TEST(RobotCommands, UrdfErrorsNameTheFileAndTheProblem) {
  Document doc = OpenStool();
  const fs::path dir = fs::path(WRAP_SOURCE_DIR) / "tests/fuzz";
  auto missing = PrepareUrdfRobot(doc.project(), ExampleProject("stool"), dir / "none.urdf", "",
                                  "", "vacuum_cup");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kIo);
  EXPECT_NE(missing.error().message.find("none.urdf"), std::string::npos)
      << missing.error().message;
  auto loop = PrepareUrdfRobot(doc.project(), ExampleProject("stool"),
                               dir / "regressions/urdf/joint_from_link_to_itself.urdf", "", "",
                               "vacuum_cup");
  ASSERT_FALSE(loop);
  EXPECT_EQ(loop.error().code, ErrorCode::kInvalidInput);
  auto tip = PrepareUrdfRobot(doc.project(), ExampleProject("stool"),
                              dir / "seeds/urdf/three_joint_arm.urdf", "", "no_such_link",
                              "vacuum_cup");
  ASSERT_FALSE(tip);
  EXPECT_NE(tip.error().message.find("no_such_link"), std::string::npos) << tip.error().message;
  auto ee = PrepareUrdfRobot(doc.project(), ExampleProject("stool"),
                             dir / "seeds/urdf/three_joint_arm.urdf", "", "", "hand");
  ASSERT_FALSE(ee);
  EXPECT_NE(ee.error().message.find("not in the catalog"), std::string::npos);
}

TEST(RobotCommands, RefusesUnknownCatalogEntriesAndDuplicateNames) {
  Document doc = OpenStool();
  ExpectRefused(doc, AddRobot("r2d2", "robotiq_2f85"), "not in the catalog");
  ExpectRefused(doc, AddRobot("ur5e", "hand"), "not in the catalog");
  Robot r = doc.project().robots[0];
  r.name = "ur5e_b";
  ExpectRefused(doc, SetRobot("ur5e_a", r), "already a robot");
  ExpectRefused(doc, RemoveRobot("nobody"), "no robot");
}

TEST(RobotCommands, WrenchLimitTables) {
  Document doc = OpenStool();
  WrenchLimits limits = doc.project().wrench_limits;
  EXPECT_DOUBLE_EQ(limits.two_finger.force_N.y(), 39.7) << "the paper's adopted value";
  limits.vacuum_transport.force_N.z() = 90;
  ExpectDoesAndUndoes(doc, SetWrenchLimits("", limits));
  EXPECT_EQ(doc.project().wrench_limits, limits);
  WrenchLimits own;
  own.two_finger.torque_Nm = Vec3(1, 1, 1);
  ExpectDoesAndUndoes(doc, SetWrenchLimits("ur5e_c", own));
  EXPECT_EQ(doc.project().robots[2].wrench_limits, own);
  ExpectDoesAndUndoes(doc, SetWrenchLimits("ur5e_c", std::nullopt));
  EXPECT_FALSE(doc.project().robots[2].wrench_limits);
  ExpectRefused(doc, SetWrenchLimits("", std::nullopt), "cannot be removed");
}

TEST(ProjectCommands, TablePlannerInfoConnectionLimits) {
  Document doc = OpenStool();
  Table t = doc.project().table;
  t.friction = 0.6;
  t.size = Vec3(2, 1, 0.05);
  ExpectDoesAndUndoes(doc, SetTable(t));
  PlannerDefaults planner = doc.project().planner;
  planner.seed = 7;
  planner.time_limit_s = 20;
  ExpectDoesAndUndoes(doc, SetPlannerDefaults(planner));
  ExpectDoesAndUndoes(doc, SetProjectInfo("renamed", "new text"));
  ExpectDoesAndUndoes(doc, SetConnectionLimits(WrenchBox{Vec3(1, 1, 1), Vec3(2, 2, 2)}));
  EXPECT_EQ(doc.project().name, "renamed");
  EXPECT_EQ(doc.project().planner.seed, 7u);
}

TEST(Names, UniqueName) {
  Document doc = OpenStool();
  EXPECT_EQ(UniqueName(doc.project(), "seat"), "seat_2");
  EXPECT_EQ(UniqueName(doc.project(), "spoke"), "spoke");
}

}  // namespace
}  // namespace wrap::gui
