// What the panels compute without drawing: the DAG canvas's automatic layout and the plan
// timeline's length.
#include <gtest/gtest.h>

#include <cmath>

#include "gui/commands.h"
#include "gui/fields.h"
#include "gui/gizmo.h"
#include "gui/panels.h"
#include "gui_fixture.h"

namespace wrap::gui {
namespace {

TEST(GraphLayout, InputsComeBeforeTheirStepInTheFlow) {
  Document doc = testing::OpenStool();
  const Project& p = doc.project();
  for (const ImVec2 canvas : {ImVec2(1000, 300), ImVec2(360, 260)}) {
    GraphPanel graph;
    graph.canvas_width = canvas.x;
    graph.canvas_height = canvas.y;
    graph.AutoLayout(p);
    ASSERT_EQ(graph.pos.size(), p.parts.size() + p.steps.size());
    // Along the flow (right, or down): every input before its step.
    for (const Step& step : p.steps) {
      for (const std::string& in : step.inputs) {
        if (graph.vertical) {
          EXPECT_LT(graph.pos[in].y, graph.pos[step.name].y) << in << " -> " << step.name;
        } else {
          EXPECT_LT(graph.pos[in].x, graph.pos[step.name].x) << in << " -> " << step.name;
        }
      }
    }
    // The seat and the first leg, inputs of the first step, start the flow.
    EXPECT_FLOAT_EQ(graph.vertical ? graph.pos["seat"].y : graph.pos["seat"].x, 0.0f);
    EXPECT_FLOAT_EQ(graph.vertical ? graph.pos["leg1"].y : graph.pos["leg1"].x, 0.0f);
  }
  // The stool is a chain of four steps: in a narrow canvas its levels go down as rows, which
  // shows it larger than five columns side by side.
  GraphPanel narrow;
  narrow.canvas_width = 360;
  narrow.canvas_height = 300;
  narrow.AutoLayout(p);
  EXPECT_TRUE(narrow.vertical);
  narrow.FitToView();
  EXPECT_GT(narrow.zoom, 0.75f) << "names stay readable";
}

TEST(GraphLayout, NodesAreAsWideAsTheirNamesAndFitInView) {
  Document doc = testing::OpenStool();
  ASSERT_TRUE(doc.Execute(RenameNode("seat+leg1", "seat_with_its_first_round_leg")));
  const Project& p = doc.project();
  GraphPanel graph;
  graph.canvas_width = 360;
  graph.canvas_height = 240;
  graph.AutoLayout(p);
  graph.FitToView();
  const std::string longest = "seat_with_its_first_round_leg";
  // Without a font the width is estimated at 7 px per character: never cut to a few letters.
  EXPECT_GE(graph.width[longest], 7.0f * static_cast<float>(longest.size()));
  // No two nodes overlap (boxes of their width and height, with room for a label below).
  for (const auto& [a, pa] : graph.pos) {
    for (const auto& [b, pb] : graph.pos) {
      if (a >= b) continue;
      const bool apart_x = pa.x + graph.width[a] <= pb.x || pb.x + graph.width[b] <= pa.x;
      const bool apart_y = pa.y + 26.0f <= pb.y || pb.y + 26.0f <= pa.y;
      EXPECT_TRUE(apart_x || apart_y) << a << " overlaps " << b;
    }
  }
  // Fit to view: every node inside the canvas.
  for (const auto& [n, q] : graph.pos) {
    const float x0 = graph.scroll.x + q.x * graph.zoom;
    const float x1 = graph.scroll.x + (q.x + graph.width[n]) * graph.zoom;
    const float y0 = graph.scroll.y + q.y * graph.zoom;
    const float y1 = graph.scroll.y + (q.y + 26.0f) * graph.zoom;
    EXPECT_GE(x0, 0.0f) << n;
    EXPECT_LE(x1, graph.canvas_width) << n;
    EXPECT_GE(y0, 0.0f) << n;
    EXPECT_LE(y1, graph.canvas_height) << n;
  }
  EXPECT_LE(graph.zoom, 1.0f);
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

TEST(FrameRate, RecentCountsTheFramesOfTheLastSecond) {
  FrameStats f;
  // A burst of ten quick frames after a long wait reads as ten per second, not hundreds.
  for (int i = 0; i < 10; ++i) f.Add(0.001, 5.0 + 0.001 * i);
  EXPECT_DOUBLE_EQ(f.RecentFps(5.01), 10.0);
  EXPECT_GT(f.MedianFps(), 500.0) << "the median frame time still says what a frame costs";
  EXPECT_DOUBLE_EQ(f.RecentFps(7.0), 0.0) << "nothing drawn for two seconds: idle";
}

TEST(Gizmo, ProjectsTheLookAtPointToTheCentre) {
  ScreenCamera cam;
  cam.view.lookat = Vec3(0.1, -0.2, 0.8);
  cam.view.azimuth_deg = 105;
  cam.view.elevation_deg = -35;
  cam.view.distance_m = 2.0;
  cam.fovy_deg = 45;
  cam.origin = ImVec2(100, 50);
  cam.size = ImVec2(800, 600);
  ImVec2 c;
  ASSERT_TRUE(cam.Project(cam.view.lookat, c));
  EXPECT_NEAR(c.x, 500.0f, 1e-3);
  EXPECT_NEAR(c.y, 350.0f, 1e-3);
  // World up is up on screen; the point behind the camera is not drawn.
  ImVec2 up;
  ASSERT_TRUE(cam.Project(cam.view.lookat + Vec3(0, 0, 0.1), up));
  EXPECT_LT(up.y, c.y);
  ImVec2 behind;
  const double az = 105 * M_PI / 180, el = -35 * M_PI / 180;
  const Vec3 forward(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  const Vec3 back = cam.view.lookat - (cam.view.distance_m + 1.0) * forward;
  EXPECT_FALSE(cam.Project(back, behind));
  // At the look-at distance a pixel is 2 d tan(fovy / 2) / height metres.
  EXPECT_NEAR(cam.MetresPerPixel(cam.view.lookat), 2.0 * 2.0 * std::tan(22.5 * M_PI / 180) / 600,
              1e-9);
}

TEST(Gizmo, DraggingTheXArrowMovesAlongXAndTheRingTurnsAboutThePivot) {
  ScreenCamera cam;
  cam.view.lookat = Vec3(0, 0, 0.8);
  cam.view.azimuth_deg = 90;  // looking along +y: world x points right on screen
  cam.view.elevation_deg = -20;
  cam.view.distance_m = 2.0;
  cam.size = ImVec2(800, 600);
  const Vec3 pivot(0, 0, 0.8);
  ImVec2 o, e;
  ASSERT_TRUE(cam.Project(pivot, o));
  ASSERT_TRUE(cam.Project(pivot + Vec3(0.05, 0, 0), e));
  EXPECT_EQ(GizmoHandleAt(cam, pivot, false, ImVec2(o.x + 60, o.y)), 0) << "the x arrow";
  const GizmoMotion m = GizmoDrag(cam, pivot, 0, ImVec2(o.x + 60, o.y), ImVec2(e.x - o.x, 0));
  EXPECT_NEAR(m.translation_W.x(), 0.05, 2e-3);
  EXPECT_NEAR(m.translation_W.y(), 0.0, 1e-12);
  EXPECT_NEAR(m.translation_W.z(), 0.0, 1e-12);
  // A quarter turn about z through the pivot.
  GizmoMotion turn;
  turn.axis_W = Vec3::UnitZ();
  turn.angle_rad = M_PI / 2;
  const Iso3 X(Eigen::Translation3d(0.1, 0, 0.8));
  const Iso3 Y = ApplyGizmo(X, pivot, turn);
  EXPECT_NEAR(Y.translation().x(), 0.0, 1e-12);
  EXPECT_NEAR(Y.translation().y(), 0.1, 1e-12);
  EXPECT_NEAR(Y.translation().z(), 0.8, 1e-12);
}

TEST(Fields, RangesRefuseOutOfRangeValuesWithAMessage) {
  const FieldSpec* force = FindField("mating", "force_N");
  ASSERT_NE(force, nullptr);
  EXPECT_EQ(RefusedValue(*force, 5.0), "");
  const std::string why = RefusedValue(*force, -5.0);
  EXPECT_NE(why.find("at least 0"), std::string::npos) << why;
  EXPECT_NE(why.find("-5"), std::string::npos) << why;
  EXPECT_NE(RefusedValue(*FindField("mating", "transverse_fraction"), 1.5), "");
  EXPECT_NE(RefusedValue(*FindField("limits", "torque_Nm"), -0.1), "");
  EXPECT_EQ(RefusedValue(*FindField("mating", "torque_Nm"), -2.0), "") << "a sense, not a size";
  // Every mating and wrench field has a tooltip.
  for (const char* name : {"force_N", "torque_Nm", "transverse_fraction", "offset_m", "approach_m",
                           "axis", "connection_force_N", "connection_torque_Nm"}) {
    ASSERT_NE(FindField("mating", name), nullptr) << name;
    EXPECT_GT(std::string(FindField("mating", name)->help).size(), 20u) << name;
  }
}

}  // namespace
}  // namespace wrap::gui
