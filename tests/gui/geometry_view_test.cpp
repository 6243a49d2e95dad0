// The GUI's reading of the geometry report and of authoring edits, without a window: the swept
// outline of an insertion (free and blocked parts), where the assembled view puts the assembly,
// the "use this free direction" edit and its undo, and the words that say what an edit changed.
#include <gtest/gtest.h>

#include <algorithm>

#include "gui/authoring_job.h"
#include "gui/geometry_view.h"
#include "gui_fixture.h"

namespace wrap::gui {
namespace {

long CountKind(const std::vector<SweepSegment>& s, SweepSegment::Kind k) {
  return std::count_if(s.begin(), s.end(), [k](const SweepSegment& g) { return g.kind == k; });
}

TEST(GeometryView, TheSweepIsGreenUpToTheHitAndRedFromIt) {
  Aabb box;
  box.min = Vec3(0, 0, 0);
  box.max = Vec3(0.01, 0.02, 0.03);
  const auto blocked = InsertionSweep(box, Vec3(0, 0, 2), 0.03, 0.01);
  EXPECT_EQ(CountKind(blocked, SweepSegment::Kind::kOutline), 24);  // approach and mating boxes
  EXPECT_EQ(CountKind(blocked, SweepSegment::Kind::kFree), 8);      // corners, approach to hit
  EXPECT_EQ(CountKind(blocked, SweepSegment::Kind::kBlocked), 12 + 8);  // box at hit, on to mate
  for (const SweepSegment& s : blocked) {
    if (s.kind != SweepSegment::Kind::kFree) continue;
    EXPECT_NEAR(s.to_A.z() - s.from_A.z(), 0.02, 1e-12);  // from 30 mm back to 10 mm back
  }
  const auto free = InsertionSweep(box, Vec3(0, 0, 1), 0.03, -1.0);
  EXPECT_EQ(CountKind(free, SweepSegment::Kind::kBlocked), 0);
  EXPECT_EQ(CountKind(free, SweepSegment::Kind::kFree), 8);
  EXPECT_TRUE(InsertionSweep(box, Vec3::Zero(), 0.03, -1.0).empty());
}

TEST(GeometryView, TheAssembledViewRestsTheAssemblyOnTheTableCentre) {
  Table table;
  table.center_xy = Vec3(0.1, -0.2, 0);
  table.height = 0.75;
  Aabb a, b;
  a.min = Vec3(-0.1, -0.1, -0.05);
  a.max = Vec3(0.1, 0.1, 0.0);
  b.min = Vec3(-0.02, -0.02, 0.0);
  b.max = Vec3(0.02, 0.3, 0.2);
  const Iso3 X = AssembledPlacement(table, {a, b});
  EXPECT_TRUE(X.linear().isIdentity());
  EXPECT_NEAR(X.translation().x(), 0.1, 1e-12);
  EXPECT_NEAR(X.translation().y(), -0.2 - 0.1, 1e-12);  // box centre y = 0.1
  EXPECT_NEAR(X.translation().z(), 0.75 + 0.05, 1e-12);
}

TEST(GeometryView, UsingAFreeDirectionIsOneUndoableEdit) {
  Document doc = testing::OpenStool();
  ASSERT_FALSE(doc.project().steps.empty());
  const std::string step = doc.project().steps[0].name;
  const Vec3 before = doc.project().steps[0].mating.axis;
  ASSERT_TRUE(doc.Execute(UseInsertionAxis(step, Vec3(0, 0, -2))));
  EXPECT_TRUE(doc.project().steps[0].mating.axis.isApprox(Vec3(0, 0, -1)));
  EXPECT_NE(doc.UndoLabel().find("[0, 0, -1]"), std::string::npos) << doc.UndoLabel();
  ASSERT_TRUE(doc.Undo());
  EXPECT_EQ(doc.project().steps[0].mating.axis, before);
  EXPECT_FALSE(doc.Execute(UseInsertionAxis("no_such_step", Vec3(0, 0, 1))));
}

TEST(GeometryView, ChangesAreSaidInWords) {
  Document doc = testing::OpenStool();
  Project after = doc.project();
  after.parts[1].initial_pose.xyz += Vec3(0.1, 0, 0);
  after.steps.pop_back();
  Step extra = doc.project().steps.back();
  extra.name = "again";
  after.steps.push_back(extra);
  const auto lines = DescribeChanges(doc.project(), after);
  auto says = [&](const std::string& text) {
    return std::any_of(lines.begin(), lines.end(),
                       [&](const std::string& l) { return l.find(text) != std::string::npos; });
  };
  EXPECT_TRUE(says("part '" + after.parts[1].name + "' moved on the table"));
  EXPECT_TRUE(says("step 'again' added"));
  EXPECT_TRUE(says("step '" + doc.project().steps.back().name + "' removed"));
  EXPECT_EQ(lines.size(), 3u);
  // An outcome that failed applies nothing.
  AuthoringOutcome failed;
  failed.error = "no";
  EXPECT_FALSE(doc.Execute(ApplyAuthoring(failed)));
}

}  // namespace
}  // namespace wrap::gui
