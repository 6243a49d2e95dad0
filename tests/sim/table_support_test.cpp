// The wrench LP's table support against MuJoCo (issue 30): a part resting on the table, pushed
// at a point by an insertion-like force (down and sideways), holds in the physics run of
// `wrap sim` (SimulatePlan, the same code path) at 50% and 90% of the largest force the LP
// accepts, and slides at 110%; the LP itself says feasible, feasible, infeasible. Three hand-made
// scenes: a box pushed at the centre of its top (sliding binds; the LP's limit has a closed form),
// a long beam pushed across at one end and an L pushed across the tip of a leg (the table's
// torque about the vertical binds with the sliding: friction at the corners of the support
// polygon).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "geometry/convex_hull.h"
#include "geometry/mesh.h"
#include "model/assembly.h"
#include "model/project.h"
#include "model/validate.h"
#include "robot/kinematics.h"
#include "sim/scene.h"
#include "task/plan.h"
#include "verify/simulate.h"
#include "wrench/wrench.h"

namespace wrap {
namespace {

constexpr double kMu = 0.4;                 // Table friction (project default).
constexpr double kTableTop = 0.75;          // [m]
constexpr double kDensity = 1240.0;         // PLA [kg/m^3]
constexpr double kPushStart_s = 0.3;        // The part settles on its contacts first.
constexpr double kPushEnd_s = 1.3;          // One second of push (an insertion lasts 1-1.5 s).
constexpr double kHoldsMaxShift_m = 1e-3;   // Held: moved less than this by the push ...
constexpr double kHoldsMaxTurn_rad = 0.01;  // ... and turned less than this.
constexpr double kSlidesMinShift_m = 0.01;  // Slid: moved more than this ...
constexpr double kSlidesMinTurn_rad = 0.1;  // ... or turned more than this.

// A resting part and how it is pushed. The part rests unrotated at (0, 0) on the table, its
// frame's z = 0 on the table top.
struct PushScene {
  std::string name;
  TriangleMesh mesh;          // Part frame; bottom face at z = 0 [m].
  Vec3 p_push_P;              // Where the push acts, part frame [m].
  Vec3 axis = Vec3::UnitZ();  // Unit direction of the push (world = part axes).
};

// A closed prism of height h over the counter-clockwise polygon `xy`, which is star-shaped from
// its vertex `fan` (the triangles of the bottom and top fan out from it).
TriangleMesh Prism(const std::vector<Eigen::Vector2d>& xy, double h, int fan) {
  TriangleMesh m;
  const int n = static_cast<int>(xy.size());
  for (const auto& p : xy) m.vertices.emplace_back(p.x(), p.y(), 0.0);
  for (const auto& p : xy) m.vertices.emplace_back(p.x(), p.y(), h);
  for (int k = 1; k + 1 < n; ++k) {
    const int a = (fan + k) % n, b = (fan + k + 1) % n;
    m.triangles.emplace_back(fan, b, a);              // Bottom, seen from below.
    m.triangles.emplace_back(n + fan, n + a, n + b);  // Top.
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.triangles.emplace_back(i, j, n + j);
    m.triangles.emplace_back(i, n + j, n + i);
  }
  return m;
}

// Unit direction tilted `deg` from straight down towards the horizontal `toward`.
Vec3 Tilted(double deg, const Vec3& toward) {
  const double t = deg * std::numbers::pi / 180.0;
  return (std::sin(t) * toward.normalized() - std::cos(t) * Vec3::UnitZ()).normalized();
}

PushScene BoxScene() {
  // 80 x 80 x 50 mm, 397 g, pushed at the centre of its top, 45 degrees from vertical along +x.
  return {"box", BoxMesh(Vec3(-0.04, -0.04, 0.0), Vec3(0.04, 0.04, 0.05)), Vec3(0, 0, 0.05),
          Tilted(45.0, Vec3::UnitX())};
}

PushScene BeamScene() {
  // 150 x 18 x 13 mm (Fabrica's beam), 44 g, pushed at mid-height 10 mm from one end, across it
  // (+y), 45 degrees from vertical.
  return {"beam", BoxMesh(Vec3(-0.075, -0.009, 0.0), Vec3(0.075, 0.009, 0.013)),
          Vec3(0.065, 0.0, 0.0065), Tilted(45.0, Vec3::UnitY())};
}

PushScene LScene() {
  // An L: legs 80 mm long and 25 mm wide, 20 mm tall, 81 g; pushed at mid-height 10 mm from
  // the tip of the leg along x, across it (+y), 45 degrees from vertical.
  const std::vector<Eigen::Vector2d> xy = {{0, 0},         {0.08, 0},     {0.08, 0.025},
                                           {0.025, 0.025}, {0.025, 0.08}, {0, 0.08}};
  return {"L", Prism(xy, 0.02, 3), Vec3(0.07, 0.0125, 0.01), Tilted(45.0, Vec3(0, 1, 0))};
}

Iso3 BasePose() {
  Iso3 X = Iso3::Identity();
  X.translation() = Vec3(0.0, 0.0, kTableTop);
  return X;
}

// The LP's question for `scene` pushed with `force_N` (nothing holds the part; the pusher is not
// modelled): its weight and the push against the table's friction at the corners of its support
// polygon (hull vertices on the table, as task/world.cpp TableContacts).
StepConfiguration LpQuestion(const PushScene& scene, double force_N) {
  const Iso3 X_WP = BasePose();
  const MassProperties mp = ComputeMassProperties(scene.mesh);
  StepConfiguration config;
  config.bodies.push_back({"base", kDensity * mp.volume_m3, X_WP * mp.com});
  std::vector<Eigen::Vector2d> xy;
  for (const Vec3& v : scene.mesh.vertices) {
    if (v.z() < 1e-9) xy.emplace_back(v.x(), v.y());
  }
  WrenchTableSupport table;
  table.body = 0;
  table.friction = kMu;
  for (int i : ConvexHull2d(xy)) table.p_WV.push_back(X_WP * Vec3(xy[i].x(), xy[i].y(), 0.0));
  config.tables.push_back(table);
  MatingLoad push;
  push.moved = -1;
  push.base = 0;
  push.axis_W = scene.axis;
  push.p_WContact = X_WP * scene.p_push_P;
  push.force_N = force_N;
  config.mating = push;
  return config;
}

bool LpHolds(const PushScene& scene, double force_N) {
  auto check = CheckWrench(LpQuestion(scene, force_N));
  EXPECT_TRUE(check) << check.error().message;
  return check && check->feasible;
}

// The largest push the LP accepts [N], by bisection to 1e-4 relative.
double LpLimit(const PushScene& scene) {
  double lo = 0.0, hi = 100.0;
  EXPECT_TRUE(LpHolds(scene, lo));
  EXPECT_FALSE(LpHolds(scene, hi)) << scene.name << ": the LP holds even 100 N";
  while (hi - lo > 1e-4 * hi) {
    const double mid = 0.5 * (lo + hi);
    (LpHolds(scene, mid) ? lo : hi) = mid;
  }
  return lo;
}

// A project of the scene: the part "base" resting, a small cube "pusher" inside it at the push
// point (its mating partner: the insertion's interface is the centre of their overlap, the cube's
// centre), one step mating the pusher onto the base along the push direction with `force_N`,
// one UR5e to hold the pusher.
struct SimScene {
  Project project;
  ProjectCheck check;
};

void AddPart(SimScene& s, const std::string& name, const TriangleMesh& mesh, const Vec3& p_AP) {
  Part part;
  part.name = name;
  part.mesh = name + ".stl";
  part.assembled_pose.xyz = p_AP;
  part.initial_pose.xyz = BasePose() * p_AP;
  part.density_kg_m3 = kDensity;
  s.project.parts.push_back(part);
  PartGeometry g;
  g.loaded = true;
  g.resolved = part.mesh;  // Parts share a scene mesh by file: one file each.
  g.mesh = mesh;
  g.topology = AnalyzeTopology(mesh);
  g.mass_properties = ComputeMassProperties(mesh);
  g.aabb = ComputeAabb(mesh);
  g.mass_kg = kDensity * g.mass_properties.volume_m3;
  s.check.parts.push_back(g);
}

SimScene MakeSimScene(const PushScene& scene, double force_N) {
  SimScene s;
  s.project.name = "push_" + scene.name;
  s.project.table.size = Vec3(1.2, 1.0, 0.05);
  s.project.table.height = kTableTop;
  s.project.table.friction = kMu;
  AddPart(s, "base", scene.mesh, Vec3::Zero());
  AddPart(s, "pusher", BoxMesh(Vec3::Constant(-0.004), Vec3::Constant(0.004)), scene.p_push_P);
  Step step;
  step.name = "pushed";
  step.inputs = {"base", "pusher"};
  step.mating.moved = "pusher";
  step.mating.base = "base";
  step.mating.axis = scene.axis;
  step.mating.force_N = force_N;
  s.project.steps.push_back(step);
  Robot r;
  r.name = "a";
  r.model = "ur5e";
  r.end_effector = "robotiq_2f85";
  r.base_pose.xyz = Vec3(0.45, 0.35, kTableTop);
  s.project.robots.push_back(r);
  AssemblyTree tree;
  EXPECT_TRUE(BuildAssemblyTree(s.project, "test", s.check.diagnostics, tree));
  s.check.tree = tree;
  return s;
}

// The plan: the robot, at home, grips the pusher where it is (pick at t = 0; the grasp is
// where its TCP is then), the insertion pushes from kPushStart_s to kPushEnd_s, then the two are
// mated. The robot does not move.
Plan MakePlan(const SimScene& s) {
  const AssemblyTree& tree = *s.check.tree;
  const int base = tree.Find("base"), pusher = tree.Find("pusher"), pushed = tree.Find("pushed");
  auto cell = BuildCellScene(s.project, s.check, "push.json");
  EXPECT_TRUE(cell) << cell.error().message;
  const SceneRobot& robot = cell->robots.front();
  const JointVector q = robot.home;
  const Iso3 X_WT = TcpPose(robot.chain, robot.X_WB, q, robot.end_effector.X_FT);
  Plan plan;
  plan.project = s.project.name;
  plan.robots = {"a"};
  plan.parts = {"base", "pusher"};
  for (const AssemblyNode& n : tree.nodes) plan.nodes.push_back(n.name);
  plan.initial.q = {q};
  plan.initial.objects = {{base, BasePose(), true}, {pusher, BasePose(), false}};
  PlanHold hold;
  hold.robot = 0;
  hold.grasp.subassembly = pusher;
  hold.grasp.index = 0;
  hold.grasp.part = tree.nodes[pusher].parts.front();
  hold.grasp.X_PG = ToIsometry(s.project.parts[hold.grasp.part].initial_pose).inverse() * X_WT;
  PlanAction pick;
  pick.type = ActionType::kPick;
  pick.robots = {0};
  pick.objects = {pusher};
  pick.grasps = {hold};
  pick.keyframe = plan.initial;
  pick.start_s = pick.end_s = 0.0;
  PlanAction assemble = pick;
  assemble.type = ActionType::kAssemble;
  assemble.objects = {pusher, base, pushed};
  assemble.end_s = kPushEnd_s;
  plan.actions = {pick, assemble};
  RobotTrajectory still;
  still.robot = 0;
  still.knots = {{0.0, q, JointVector::Zero(6)}, {kPushEnd_s, q, JointVector::Zero(6)}};
  plan.trajectories = {still};
  MotionSegment insert;
  insert.kind = "insert";
  insert.action = 1;
  insert.robots = {0};
  insert.objects = {pusher, base};
  insert.start_s = kPushStart_s;
  insert.end_s = kPushEnd_s;
  plan.segments = {insert};
  plan.stats.solved = true;
  plan.stats.motion = true;
  return plan;
}

// What MuJoCo did to the resting part under the push.
struct SimOutcome {
  SimReport report;
  double shift_m = 0.0;   // Largest distance from where it was when the push started [m].
  double turn_rad = 0.0;  // Largest turn from it [rad].
};

SimOutcome Simulate(const PushScene& scene, double force_N) {
  SimScene s = MakeSimScene(scene, force_N);
  const Plan plan = MakePlan(s);
  SimOutcome out;
  std::optional<Iso3> at_start;
  SimOptions options;
  options.check_collisions = false;  // The robot is a prop: only the table's support is judged.
  options.settle_s = 0.2;
  options.frame_interval_s = 0.01;
  options.on_frame = [&](double t, const SceneState& state) {
    const Iso3& X = state.X_WP[0];
    if (t < kPushStart_s) {
      at_start = X;
      return;
    }
    if (!at_start || t > kPushEnd_s) return;
    out.shift_m = std::max(out.shift_m, (X.translation() - at_start->translation()).norm());
    out.turn_rad =
        std::max(out.turn_rad,
                 std::abs(Eigen::AngleAxisd(at_start->linear().transpose() * X.linear()).angle()));
  };
  RunContext ctx(0);
  auto report = SimulatePlan(s.project, s.check, "push.json", plan, options, ctx);
  EXPECT_TRUE(report) << report.error().message;
  if (report) out.report = *report;
  return out;
}

std::string Describe(const SimOutcome& o) {
  std::string s = "moved " + std::to_string(o.shift_m * 1e3) + " mm, turned " +
                  std::to_string(o.turn_rad * 180.0 / std::numbers::pi) + " deg; ";
  if (!o.report.failure) return s + "the plan holds";
  return s + o.report.failure->reason + ": " + o.report.failure->detail;
}

// The LP's verdicts at 50%, 90% and 110% of its limit, then MuJoCo's: holds, holds, slides.
void ExpectHoldsHoldsSlides(const PushScene& scene, double limit_N) {
  SCOPED_TRACE(scene.name + ", LP limit " + std::to_string(limit_N) + " N");
  EXPECT_TRUE(LpHolds(scene, 0.5 * limit_N));
  EXPECT_TRUE(LpHolds(scene, 0.9 * limit_N));
  EXPECT_FALSE(LpHolds(scene, 1.1 * limit_N));
  for (double fraction : {0.5, 0.9}) {
    const SimOutcome o = Simulate(scene, fraction * limit_N);
    EXPECT_TRUE(o.report.success) << fraction << ": " << Describe(o);
    EXPECT_LT(o.shift_m, kHoldsMaxShift_m) << fraction << ": " << Describe(o);
    EXPECT_LT(o.turn_rad, kHoldsMaxTurn_rad) << fraction << ": " << Describe(o);
  }
  const SimOutcome o = Simulate(scene, 1.1 * limit_N);
  EXPECT_TRUE(o.shift_m > kSlidesMinShift_m || o.turn_rad > kSlidesMinTurn_rad) << Describe(o);
  ASSERT_TRUE(o.report.failure.has_value()) << Describe(o);
  EXPECT_EQ(o.report.failure->reason, "no support") << Describe(o);
  EXPECT_NE(o.report.failure->detail.find("'base'"), std::string::npos) << Describe(o);
}

// Sliding binds: the push F at 45 degrees slides the box when F sin45 > mu (m g + F cos45), so
// the LP's limit is mu m g / (sin45 - mu cos45) (its friction pyramid is exact along x). The
// push at the top, 50 mm up, does not tip it: at that limit the table's force leans by
// atan(mu), which passes 20 mm inside the 40 mm half-width.
TEST(TableSupport, BoxPushedAtItsTopHoldsHoldsSlides) {
  const PushScene scene = BoxScene();
  const double mass = kDensity * ComputeMassProperties(scene.mesh).volume_m3;
  const double s = std::sin(std::numbers::pi / 4), c = std::cos(std::numbers::pi / 4);
  const double closed_form = kMu * mass * 9.81 / (s - kMu * c);
  const double limit = LpLimit(scene);
  EXPECT_NEAR(limit, closed_form, 1e-3 * closed_form);
  ExpectHoldsHoldsSlides(scene, limit);
}

// Torque binds: pushed across at one end, the beam turns about the vertical as it slides, so
// the LP accepts less than the pure sliding limit of the box's formula.
TEST(TableSupport, BeamPushedAcrossAtOneEndHoldsHoldsSlides) {
  const PushScene scene = BeamScene();
  const double mass = kDensity * ComputeMassProperties(scene.mesh).volume_m3;
  const double s = std::sin(std::numbers::pi / 4), c = std::cos(std::numbers::pi / 4);
  const double sliding = kMu * mass * 9.81 / (s - kMu * c);
  const double limit = LpLimit(scene);
  EXPECT_LT(limit, 0.9 * sliding);
  ExpectHoldsHoldsSlides(scene, limit);
}

// Not symmetric: the L's centre of mass is off its support polygon's centre, and the reflex
// corner of its footprint is no support (inside the hull).
TEST(TableSupport, LPushedAtALegTipHoldsHoldsSlides) {
  const PushScene scene = LScene();
  const double limit = LpLimit(scene);
  ExpectHoldsHoldsSlides(scene, limit);
}

// Fabrica's beam under a post's insertion (fabrica_beam seed 2): the 44 g beam pressed straight
// down with 10 N (23 times its weight) 44 mm from its centre, at mid-height where the post
// enters its hole. The LP holds it at any force (the press is inside its support polygon and
// needs no friction); so must MuJoCo. Before the table's contacts were as stiff as the parts' and
// carried by the corners of the support polygon, MuJoCo pressed the beam 0.5 mm, then mm, into
// the table on two contact points along its centre line, and it rolled over.
TEST(TableSupport, LightBeamPressedHardNearOneEndStaysPut) {
  PushScene scene = BeamScene();
  scene.p_push_P = Vec3(-0.044, 0.0, 0.0065);
  scene.axis = -Vec3::UnitZ();
  EXPECT_TRUE(LpHolds(scene, 10.0));
  EXPECT_TRUE(LpHolds(scene, 1000.0));
  const SimOutcome o = Simulate(scene, 10.0);
  EXPECT_TRUE(o.report.success) << Describe(o);
  EXPECT_LT(o.shift_m, kHoldsMaxShift_m) << Describe(o);
  EXPECT_LT(o.turn_rad, kHoldsMaxTurn_rad) << Describe(o);
}

}  // namespace
}  // namespace wrap
