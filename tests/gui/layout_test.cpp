// What the panels compute without drawing: the DAG canvas's automatic layout and the plan
// timeline's length.
#include <gtest/gtest.h>

#include "gui/commands.h"
#include "gui/panels.h"
#include "gui_fixture.h"

namespace wrap::gui {
namespace {

TEST(GraphLayout, InputsStandLeftOfTheirStepAndPartsInTheFirstColumn) {
  Document doc = testing::OpenStool();
  const Project& p = doc.project();
  GraphPanel graph;
  graph.canvas_width = 1000;
  graph.AutoLayout(p);
  ASSERT_EQ(graph.pos.size(), p.parts.size() + p.steps.size());
  for (const Part& part : p.parts) EXPECT_FLOAT_EQ(graph.pos[part.name].x, 0.0f) << part.name;
  for (const Step& step : p.steps) {
    for (const std::string& in : step.inputs) {
      EXPECT_LT(graph.pos[in].x, graph.pos[step.name].x) << in << " -> " << step.name;
    }
  }
  // No two nodes on the same spot.
  for (const auto& [a, pa] : graph.pos) {
    for (const auto& [b, pb] : graph.pos) {
      if (a < b) {
        EXPECT_FALSE(pa.x == pb.x && pa.y == pb.y) << a << " and " << b;
      }
    }
  }
}

TEST(GraphLayout, TheSignatureChangesWithTheEdgesOnly) {
  Document doc = testing::OpenStool();
  const std::string before = GraphPanel::Signature(doc.project());
  Part seat = doc.project().parts[0];
  seat.color = {0, 0, 1, 1};
  ASSERT_TRUE(doc.Execute(SetPart("seat", seat)));
  EXPECT_EQ(GraphPanel::Signature(doc.project()), before) << "a colour is not a graph change";
  ASSERT_TRUE(doc.Execute(RemoveInput("stool", "leg4")));
  EXPECT_NE(GraphPanel::Signature(doc.project()), before);
}

TEST(Timeline, DurationIsTheMakespanOrTheLastKeyframe) {
  AppState app;
  EXPECT_EQ(app.Duration(), 0.0) << "no plan";
  auto plan = std::make_shared<Plan>();
  plan->actions.resize(3);
  plan->actions[1].approach = Keyframe{};
  app.plan = plan;
  EXPECT_EQ(app.Duration(), 4.0) << "initial + 3 keyframes + 1 approach = 5 keyframes: 0..4";
  plan->stats.motion = true;
  plan->stats.makespan_s = 12.5;
  plan->trajectories.resize(1);
  plan->trajectories[0].knots.resize(2);
  plan->trajectories[0].knots[1].t = 12.5;
  EXPECT_EQ(app.Duration(), 12.5);
}

}  // namespace
}  // namespace wrap::gui
