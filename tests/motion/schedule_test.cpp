// The concurrent schedule (retime.h) on hand-made motion in the stool's cell (four UR5e at the
// corners of the table, the parts on it): robots whose motions keep apart move at the same time;
// robots whose motions cross do not collide (the independent trajectory check says so) and the
// later one waits, naming the other; a shared object keeps the order; the same input gives the
// same schedule. No planning: the segments are made here from IK.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "motion/retime.h"
#include "motion/scene.h"
#include "motion/trajectory_check.h"
#include "motion_fixture.h"
#include "robot/kinematics.h"

namespace wrap {
namespace {

// The stool's world, unplanned.
struct Unplanned : PreparedProject {
  void Solve(const std::string&) {}
};

class Schedule : public ::testing::Test {
 protected:
  void SetUp() override {
    const Unplanned& p = PrepareOnce<Unplanned>("stool");
    ASSERT_TRUE(p.error.empty()) << p.error;
    w_ = &*p.world;
    // A plan with no actions: the robots at home, the parts where they start.
    for (const TaskRobot& r : w_->robots) {
      plan_.robots.push_back(r.name);
      plan_.initial.q.push_back(r.home);
    }
    for (int part = 0; part < w_->num_parts; ++part) {
      plan_.parts.push_back(w_->tree->nodes[part].name);
      plan_.initial.objects.push_back({part, w_->initial_X_WA[part], true});
    }
    for (const AssemblyNode& n : w_->tree->nodes) plan_.nodes.push_back(n.name);
  }

  // Robot r's joints with its gripper pointing down at p_W (the IK solution nearest home).
  JointVector Reach(int r, const Vec3& p_W) const {
    const TaskRobot& robot = w_->robots[r];
    Iso3 X_WT = Iso3::Identity();
    X_WT.linear() = Vec3(1, -1, -1).asDiagonal();
    X_WT.translation() = p_W;
    const UrIkSolutions s = robot.ur->SolveTcp(robot.X_BW * X_WT, robot.end_effector.X_FT);
    EXPECT_GT(s.count, 0) << "robot " << r << " cannot reach the point";
    JointVector best;
    double best_d = 1e9;
    for (int k = 0; k < s.count; ++k) {
      const JointVector q = NearestEquivalent(robot.chain, s.q[k], robot.home);
      const double d = (q - robot.home).cwiseAbs().sum();
      if (d < best_d) {
        best_d = d;
        best = q;
      }
    }
    return best;
  }

  // Robot r from home to `q` and back, a free path naming `objects`.
  GeoSegment There(int r, const JointVector& q, std::vector<int> objects = {},
                   SegmentKind kind = SegmentKind::kFree) const {
    GeoSegment seg;
    seg.kind = kind;
    seg.robots = {r};
    seg.objects = std::move(objects);
    seg.waypoints = {{w_->robots[r].home}, {q}, {w_->robots[r].home}};
    seg.openings.assign(w_->robots.size(), -1.0);
    return seg;
  }

  // The plan with the timing; the trajectory check's issues in words (empty: valid).
  std::string Checked(const Timing& timing) {
    plan_.trajectories = timing.trajectories;
    plan_.segments = timing.segments;
    auto check = CheckTrajectories(*w_, plan_, {});
    EXPECT_TRUE(check) << check.error().message;
    std::string issues;
    for (const TrajectoryIssue& i : check->issues) issues += FormatTrajectoryIssue(plan_, i) + "\n";
    return issues;
  }

  const TaskWorld* w_ = nullptr;
  Plan plan_;
};

// Robots at opposite corners (a at +x+y, c at -x-y) each reach 20 cm above the table on their
// own side: the two motions overlap in time, neither waits.
TEST_F(Schedule, RobotsThatKeepApartMoveAtTheSameTime) {
  const double z = w_->table_top + 0.2;
  const std::vector<GeoSegment> segments = {There(0, Reach(0, Vec3(0.25, 0.2, z))),
                                            There(2, Reach(2, Vec3(-0.25, -0.2, z)))};
  auto timing = Retime(*w_, plan_, segments);
  ASSERT_TRUE(timing) << timing.error().message;
  EXPECT_EQ(timing->segment_start_s[0], 0.0);
  EXPECT_EQ(timing->segment_start_s[1], 0.0);
  EXPECT_NEAR(timing->makespan_s, std::max(timing->segment_end_s[0], timing->segment_end_s[1]),
              1e-12);
  EXPECT_LT(timing->makespan_s, timing->makespan_sequential_s - 1.0);
  for (const MotionSegment& m : timing->segments) {
    EXPECT_EQ(m.wait, "none");
    EXPECT_EQ(m.wait_segment, -1);
  }
  EXPECT_EQ(Checked(*timing), "");
}

// Both reach the same point above the table centre: at once their grippers would meet (the
// premise, in the motion planner's scene); scheduled, the second waits until the first is back
// and says so, and the trajectory check finds no collision.
TEST_F(Schedule, RobotsWhosePathsCrossWaitAndDoNotCollide) {
  const Vec3 centre(0.0, 0.0, w_->table_top + 0.3);
  const JointVector qa = Reach(0, centre), qc = Reach(2, centre);
  {
    auto scene = MotionScene::Build(*w_);
    ASSERT_TRUE(scene);
    PlanState state = InitialPlanState(plan_.initial, static_cast<int>(w_->robots.size()));
    std::vector<JointVector> q = plan_.initial.q;
    q[0] = qa;
    q[2] = qc;
    const std::vector<double> open(w_->robots.size(), -1.0);
    ASSERT_TRUE(scene->Set(state, open, q));
    ASSERT_TRUE(scene->Collides()) << "premise: both robots at the centre at once collide";
    q[2] = w_->robots[2].home;
    ASSERT_TRUE(scene->Set(state, open, q));
    ASSERT_FALSE(scene->Collides()) << "premise: one robot at the centre alone is free";
  }
  auto timing = Retime(*w_, plan_, {There(0, qa), There(2, qc)});
  ASSERT_TRUE(timing) << timing.error().message;
  EXPECT_EQ(timing->segment_start_s[0], 0.0);
  EXPECT_GT(timing->segment_start_s[1], 0.0);
  // It waits no longer than for the other to end (the sequential start is always feasible).
  EXPECT_LE(timing->segment_start_s[1], timing->segment_end_s[0] + 1e-12);
  EXPECT_EQ(timing->collision_waits, 1);
  const MotionSegment& second = timing->segments[1];  // (by start)
  EXPECT_EQ(second.robots, std::vector<int>{2});
  EXPECT_EQ(second.wait, "collision");
  EXPECT_EQ(second.wait_segment, 0);
  EXPECT_EQ(Checked(*timing), "");
}

// A segment that acts on an object another robot's segment acted on starts after it, however far
// apart the robots are; a free path that only heads for the object does not wait.
TEST_F(Schedule, ASharedObjectKeepsTheOrder) {
  const double z = w_->table_top + 0.2;
  const int leg = 1;  // a part's node
  const JointVector qa = Reach(0, Vec3(0.25, 0.2, z)), qc = Reach(2, Vec3(-0.25, -0.2, z));
  auto shared = Retime(
      *w_, plan_,
      {There(0, qa, {leg}, SegmentKind::kApproach), There(2, qc, {leg}, SegmentKind::kApproach)});
  ASSERT_TRUE(shared) << shared.error().message;
  EXPECT_NEAR(shared->segment_start_s[1], shared->segment_end_s[0], 1e-12);
  EXPECT_EQ(shared->segments[1].wait, "object");
  EXPECT_EQ(shared->segments[1].wait_segment, 0);
  auto heading = Retime(
      *w_, plan_,
      {There(0, qa, {leg}, SegmentKind::kApproach), There(2, qc, {leg}, SegmentKind::kFree)});
  ASSERT_TRUE(heading);
  EXPECT_EQ(heading->segment_start_s[1], 0.0);
}

// Same input, same schedule, to the bit; one robot's segments keep their order.
TEST_F(Schedule, SameInputSameSchedule) {
  const Vec3 centre(0.0, 0.0, w_->table_top + 0.3);
  const double z = w_->table_top + 0.2;
  const std::vector<GeoSegment> segments = {There(0, Reach(0, centre)), There(2, Reach(2, centre)),
                                            There(1, Reach(1, Vec3(-0.25, 0.2, z))),
                                            There(0, Reach(0, Vec3(0.25, 0.2, z)))};
  auto a = Retime(*w_, plan_, segments);
  auto b = Retime(*w_, plan_, segments);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->segment_start_s, b->segment_start_s);
  ASSERT_EQ(a->segments.size(), b->segments.size());
  for (size_t k = 0; k < a->segments.size(); ++k) {
    EXPECT_EQ(a->segments[k].wait, b->segments[k].wait);
    EXPECT_EQ(a->segments[k].wait_segment, b->segments[k].wait_segment);
  }
  EXPECT_GE(a->segment_start_s[3], a->segment_end_s[0]);
  EXPECT_EQ(Checked(*a), "");
}

// One segment at a time when asked: the sequential makespan.
TEST_F(Schedule, OneAtATimeWhenNotConcurrent) {
  const double z = w_->table_top + 0.2;
  RetimeOptions options;
  options.concurrent = false;
  auto timing = Retime(
      *w_, plan_,
      {There(0, Reach(0, Vec3(0.25, 0.2, z))), There(2, Reach(2, Vec3(-0.25, -0.2, z)))}, options);
  ASSERT_TRUE(timing);
  EXPECT_NEAR(timing->makespan_s, timing->makespan_sequential_s, 1e-9);
  EXPECT_NEAR(timing->segment_start_s[1], timing->segment_end_s[0], 1e-12);
}

}  // namespace
}  // namespace wrap
