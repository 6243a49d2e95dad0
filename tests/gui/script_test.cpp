// The scripted mode's commands against the document, without a window; and the planner job
// (worker thread, cancel, errors) without a window.
#include "gui/script.h"

#include <gtest/gtest.h>

#include "gui/commands.h"
#include "gui/planner_job.h"
#include "gui_fixture.h"

namespace wrap::gui {
namespace {

using testing::ExampleProject;
using testing::ScratchDir;

Result<ScriptEffect> RunScript(AppState& app, const std::string& text) {
  auto lines = ParseScript(text);
  if (!lines) return std::unexpected(lines.error());
  ScriptEffect last;
  for (const ScriptLine& line : *lines) {
    auto effect = RunScriptLine(app, line, WRAP_SOURCE_DIR);
    if (!effect) return effect;
    last = *effect;
  }
  return last;
}

void OpenStool(AppState& app) {
  auto doc = Document::Open(ExampleProject("stool"));
  ASSERT_TRUE(doc);
  app.doc = std::move(*doc);
}

TEST(Script, ParseSkipsCommentsAndNamesBadLines) {
  auto ok = ParseScript("# comment\n\nselect part seat  # trailing\nundo\n");
  ASSERT_TRUE(ok) << ok.error().message;
  ASSERT_EQ(ok->size(), 2u);
  EXPECT_EQ((*ok)[0].number, 3);
  EXPECT_EQ((*ok)[0].words, (std::vector<std::string>{"select", "part", "seat"}));
  auto unknown = ParseScript("undo\nfly away\n");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find("line 2"), std::string::npos);
  EXPECT_NE(unknown.error().message.find("unknown command 'fly'"), std::string::npos);
  auto arity = ParseScript("add-edge onlyone\n");
  ASSERT_FALSE(arity);
  EXPECT_NE(arity.error().message.find("argument"), std::string::npos);
}

TEST(Script, EditsGoThroughTheDocumentAndUndo) {
  AppState app;
  OpenStool(app);
  const Project before = app.doc.project();
  ASSERT_TRUE(RunScript(app,
                        "set part.seat.mass_kg 0.25\n"
                        "set part.leg1.initial_xyz 0.1 0.2 0.75\n"
                        "set mating.stool.axis 0 1 0\n"
                        "set mating.stool.force_N 22\n"
                        "set robot.ur5e_a.end_effector vacuum_cup\n"
                        "set table.friction 0.5\n"
                        "add-robot ur10e robotiq_2f85\n"
                        "select step stool\n"));
  const Project& p = app.doc.project();
  ASSERT_TRUE(p.parts[0].mass_kg);
  EXPECT_DOUBLE_EQ(*p.parts[0].mass_kg, 0.25);
  EXPECT_EQ(p.parts[1].initial_pose.xyz, Vec3(0.1, 0.2, 0.75));
  EXPECT_EQ(p.steps[3].mating.axis, Vec3(0, 1, 0));
  EXPECT_DOUBLE_EQ(p.steps[3].mating.force_N, 22);
  EXPECT_EQ(p.robots[0].end_effector, "vacuum_cup");
  EXPECT_DOUBLE_EQ(p.table.friction, 0.5);
  EXPECT_EQ(p.robots.size(), 5u);
  EXPECT_EQ(app.selection.step, "stool");
  // Seven edits, seven undo entries (script edits are not merged).
  ASSERT_TRUE(RunScript(app, "undo\nundo\nundo\nundo\nundo\nundo\nundo\n"));
  EXPECT_EQ(app.doc.project(), before);
  EXPECT_FALSE(RunScript(app, "undo\n")) << "nothing left to undo";
}

TEST(Script, RefusalsFailTheLineAndExpectRefusedChecksThem) {
  AppState app;
  OpenStool(app);
  ASSERT_TRUE(RunScript(app, "remove-edge leg1 seat+leg1\n"));
  auto cycle = RunScript(app, "add-edge stool seat+leg1\n");
  ASSERT_FALSE(cycle);
  EXPECT_NE(cycle.error().message.find("cycle"), std::string::npos);
  EXPECT_NE(cycle.error().message.find("line 1"), std::string::npos);
  EXPECT_TRUE(RunScript(app, "expect-refused add-edge stool seat+leg1\n"));
  auto not_refused = RunScript(app, "expect-refused add-edge leg1 seat+leg1\n");
  ASSERT_FALSE(not_refused);
  EXPECT_NE(not_refused.error().message.find("was not refused"), std::string::npos);
  EXPECT_FALSE(RunScript(app, "set part.ghost.mass_kg 1\n"));
  EXPECT_FALSE(RunScript(app, "set part.seat.colour 1 0 0\n"));
  EXPECT_FALSE(RunScript(app, "set part.seat.mass_kg heavy\n"));
}

// Planner options and check arguments are numbers or refused; junk never becomes 0.
TEST(Script, OptionsAndCheckArgumentsRefuseWhatIsNotANumber) {
  AppState app;
  OpenStool(app);
  ASSERT_TRUE(RunScript(app,
                        "option seed 7\noption grasps 32\noption time_limit_s 12.5\n"
                        "option budget 2\noption task_only 1\noption objective makespan\n"));
  EXPECT_EQ(app.request.seed, 7u);
  EXPECT_EQ(app.request.grasps, 32);
  EXPECT_DOUBLE_EQ(app.request.time_limit_s, 12.5);
  EXPECT_DOUBLE_EQ(app.request.budget, 2.0);
  EXPECT_TRUE(app.request.task_only);
  EXPECT_EQ(app.request.objective, "makespan");
  const PlannerRequest before = app.request;
  for (const char* bad : {"option seed abc\n", "option seed -1\n", "option seed 1.5\n",
                          "option grasps many\n", "option time_limit_s 0\n", "option budget 2x\n",
                          "option task_only yes\n", "option objective speed\n"}) {
    auto r = RunScript(app, bad);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().message.find("line 1"), std::string::npos) << r.error().message;
  }
  auto junk = RunScript(app, "option seed abc\n");
  ASSERT_FALSE(junk);
  EXPECT_NE(junk.error().message.find("'abc' is not a number"), std::string::npos)
      << junk.error().message;
  EXPECT_EQ(app.request.seed, before.seed);
  EXPECT_EQ(app.request.grasps, before.grasps);
  EXPECT_DOUBLE_EQ(app.request.time_limit_s, before.time_limit_s);
  auto direction = RunScript(app, "expect-free-direction seat+leg1 0 0 up\n");
  ASSERT_FALSE(direction);
  EXPECT_NE(direction.error().message.find("'up' is not a number"), std::string::npos)
      << direction.error().message;
}

TEST(Script, SaveAndScreenshotPathsResolveAgainstTheScriptFolder) {
  const auto dir = ScratchDir("script_save");
  AppState app;
  OpenStool(app);
  auto lines = ParseScript("set part.seat.mass_kg 0.3\nsave out.json\nscreenshot s.png\n");
  ASSERT_TRUE(lines);
  ASSERT_TRUE(RunScriptLine(app, (*lines)[0], dir));
  ASSERT_TRUE(RunScriptLine(app, (*lines)[1], dir));
  EXPECT_FALSE(app.doc.dirty());
  auto again = Document::Open(dir / "out.json");
  ASSERT_TRUE(again);
  EXPECT_EQ(again->project(), app.doc.project());
  auto shot = RunScriptLine(app, (*lines)[2], dir);
  ASSERT_TRUE(shot);
  EXPECT_EQ(shot->screenshot, dir / "s.png");
}

TEST(PlannerJob, PlansOnASnapshotWhileTheDocumentChanges) {
  auto doc = Document::Open(ExampleProject("half_stool"));
  ASSERT_TRUE(doc);
  PlannerJob job;
  PlannerRequest q;
  q.task_only = true;
  q.time_limit_s = 60;
  ASSERT_TRUE(job.Start(doc->project(), doc->ResolvePath(), q));
  EXPECT_FALSE(job.Start(doc->project(), doc->ResolvePath(), q)) << "one run at a time";
  // Editing the document meanwhile does not touch the run's snapshot.
  ASSERT_TRUE(doc->Execute(RemoveStep(doc->project().steps.back().name)));
  job.Wait();
  const JobProgress prog = job.progress();
  EXPECT_EQ(prog.state, JobState::kSolved) << prog.error;
  EXPECT_FALSE(prog.log.empty());
  auto plan = job.TakePlan();
  ASSERT_TRUE(plan);
  EXPECT_TRUE(plan->stats.solved);
  EXPECT_EQ(plan->milestone_steps.size(), 2u) << "both steps of the snapshot were planned";
  EXPECT_FALSE(job.TakePlan()) << "taken once";
}

TEST(PlannerJob, AnInvalidProjectFailsWithReasons) {
  auto doc = Document::Open(ExampleProject("stool"));
  ASSERT_TRUE(doc);
  ASSERT_TRUE(doc->Execute(RemoveInput("stool", "leg4")));
  PlannerJob job;
  ASSERT_TRUE(job.Start(doc->project(), doc->ResolvePath(), {}));
  job.Wait();
  const JobProgress prog = job.progress();
  EXPECT_EQ(prog.state, JobState::kFailed);
  EXPECT_NE(prog.error.find("not valid"), std::string::npos) << prog.error;
  EXPECT_FALSE(job.TakePlan());
}

TEST(PlannerJob, CancelStopsTheRun) {
  auto doc = Document::Open(ExampleProject("stool"));
  ASSERT_TRUE(doc);
  PlannerJob job;
  PlannerRequest q;
  q.time_limit_s = 600;  // with motion: seconds of work, so the cancel arrives first
  ASSERT_TRUE(job.Start(doc->project(), doc->ResolvePath(), q));
  job.Cancel();
  job.Wait();
  EXPECT_EQ(job.progress().state, JobState::kCancelled);
  EXPECT_FALSE(job.running());
  // A new run can start after a cancelled one.
  PlannerRequest quick;
  quick.task_only = true;
  ASSERT_TRUE(job.Start(doc->project(), doc->ResolvePath(), quick));
  job.Wait();
  EXPECT_EQ(job.progress().state, JobState::kSolved) << job.progress().error;
}

}  // namespace
}  // namespace wrap::gui
