// Tests of the preprocessing stage (paper §IV-B): grasps on boxes, vacuum on large faces only,
// collision-free grasps, determinism, subassemblies, table slots, cancellation, JSON.
#include "grasp/preprocess.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stop_token>
#include <thread>

#include "../geometry/test_meshes.h"
#include "grasp/preprocess_json.h"
#include "robot/catalog.h"
#include "robot/collision.h"
#include "robot/ik.h"
#include "scenes.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;
using test_meshes::MakeBox;
using test_meshes::MakeCylinder;
using test_scenes::AddPart;
using test_scenes::AddRobots;
using test_scenes::AddStep;
using test_scenes::Finish;
using test_scenes::Scene;

// Options for the small scenes: no table IK (tested on its own), the rest default.
PreprocessOptions Quick(int grasps = 20) {
  PreprocessOptions o;
  o.grasps = grasps;
  o.compute_table_slots = false;
  return o;
}

Scene OneBox(const Vec3& size, const std::string& end_effector) {
  Scene s;
  AddPart(s, "box", MakeBox(-0.5 * size, 0.5 * size));
  AddRobots(s, end_effector);
  EXPECT_TRUE(Finish(s));
  return s;
}

// The grasps of `sub` that collide with it: every grasp's end effector (fingers open by
// `clearance_m` beyond the width, a vacuum gripper backed off by `standoff_m`) is checked in a
// collision world of its own against every part. Returns messages naming the colliding pairs.
std::vector<std::string> CollidingGrasps(const Project& project, const ProjectCheck& check,
                                         const Subassembly& sub, const std::vector<Grasp>& grasps,
                                         double clearance_m, double standoff_m) {
  CollisionWorld world;
  for (size_t k = 0; k < sub.parts.size(); ++k) {
    BodyDef part;
    part.name = project.parts[sub.parts[k]].name;
    part.group = 0;
    Shape mesh;
    mesh.type = Shape::Type::kMesh;
    mesh.mesh = check.parts[sub.parts[k]].mesh;
    part.shapes.push_back(mesh);
    part.X_WB = sub.X_AP[k];
    EXPECT_TRUE(world.AddBody(part));
  }
  world.SetGroupPairAllowed(0, 0, true);
  world.SetGroupPairAllowed(1, 1, true);
  for (size_t i = 0; i < grasps.size(); ++i) {
    const Grasp& g = grasps[i];
    const auto ee = LoadEndEffector(g.end_effector);
    EXPECT_TRUE(ee);
    Iso3 X_AP = Iso3::Identity();
    for (size_t k = 0; k < sub.parts.size(); ++k) {
      if (sub.parts[k] == g.part) X_AP = sub.X_AP[k];
    }
    Iso3 X_AG = X_AP * g.X_PG;
    const bool vacuum = g.kind == EndEffectorKind::kVacuum;
    if (vacuum) X_AG.translation() -= standoff_m * X_AG.linear().col(2);
    BodyDef gripper;
    gripper.name = "grasp" + std::to_string(i);
    gripper.group = 1;
    gripper.shapes = EndEffectorShapesAt(*ee, vacuum ? 0.0 : g.width_m + 2 * clearance_m);
    gripper.X_WB = X_AG * ee->X_FT.inverse();
    EXPECT_TRUE(world.AddBody(gripper));
  }
  CollisionRequest request;
  request.all_pairs = true;
  request.max_pairs = 1000;
  CollisionResult result;
  std::vector<std::string> hits;
  if (world.AnyCollision(request, &result)) {
    for (const ShapePair& pair : result.pairs) hits.push_back(world.Describe(pair));
  }
  return hits;
}

// Same for one grasp of a scene.
bool GraspCollides(const Scene& scene, const Subassembly& sub, const Grasp& g, const EndEffector&,
                   double opening_m, double standoff_m) {
  const auto hits = CollidingGrasps(scene.project, scene.check, sub, {g},
                                    0.5 * std::max(0.0, opening_m - g.width_m), standoff_m);
  for (const std::string& h : hits) ADD_FAILURE() << h;
  return !hits.empty();
}

// The full-pad grasps of a set (its first part; grasp_types_test.cpp tests the reduced ones).
std::vector<Grasp> FullPad(const std::vector<Grasp>& grasps) {
  std::vector<Grasp> out;
  for (const Grasp& g : grasps) {
    if (g.type == GraspType::kFullPad) out.push_back(g);
  }
  return out;
}

size_t Reduced(const std::vector<Grasp>& grasps) { return grasps.size() - FullPad(grasps).size(); }

double AngleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Outward normal of the face of the centred box with half sizes h that p lies on.
Vec3 BoxFaceNormal(const Vec3& p, const Vec3& h) {
  int axis = 0;
  (p.cwiseAbs() - h).cwiseAbs().minCoeff(&axis);
  Vec3 n = Vec3::Zero();
  n[axis] = p[axis] > 0 ? 1.0 : -1.0;
  EXPECT_NEAR(std::abs(p[axis]), h[axis], 1e-9) << "contact off the surface: " << p.transpose();
  EXPECT_TRUE((p.cwiseAbs() - h).maxCoeff() <= 1e-9) << "contact outside the box";
  return n;
}

TEST(TwoFinger, GraspsOnABoxAreAntipodalWithinTheStrokeAndFree) {
  const Vec3 size(0.04, 0.06, 0.10);  // 100 mm exceeds the 85 mm stroke
  const Scene s = OneBox(size, "robotiq_2f85");
  RunContext ctx(1);
  auto r = Preprocess(s.project, s.check, Quick(), ctx);
  ASSERT_TRUE(r) << r.error().message;
  const auto ee = LoadEndEffector("robotiq_2f85");
  ASSERT_TRUE(ee);
  const Subassembly& box = r->subassemblies.at(0);
  ASSERT_EQ(box.grasp_sets.size(), 1u);
  const GraspSet& set = box.grasp_sets[0];
  const std::vector<Grasp> full = FullPad(set.grasps);
  ASSERT_EQ(full.size(), 20u);
  EXPECT_LE(Reduced(set.grasps), 20u);
  const double alpha = std::atan(s.project.table.friction);
  const Vec3 pad_T = ee->X_FT.inverse() * ee->pad_center_F;
  const TwoFingerGraspOptions defaults;
  for (const Grasp& g : full) {
    EXPECT_EQ(g.part, 0);
    EXPECT_EQ(g.end_effector, "robotiq_2f85");
    EXPECT_EQ(g.kind, EndEffectorKind::kTwoFinger);
    EXPECT_GE(g.quality, 0.0);
    EXPECT_LE(g.quality, 1.0);
    // Within the stroke, with room for the clearance on both sides.
    EXPECT_LE(g.width_m, ee->stroke_m - 2 * defaults.clearance_m);
    EXPECT_GE(g.width_m, defaults.min_width_m);
    EXPECT_NEAR((g.contacts_P[0] - g.contacts_P[1]).norm(), g.width_m, 1e-9);
    // Antipodal: the closing axis (G's x, the catalog's closing axis) joins the contacts, which
    // lie on opposite faces, inside both friction cones.
    const Vec3 x_G = g.X_PG.linear().col(0);
    EXPECT_NEAR(((g.contacts_P[0] - g.contacts_P[1]) / g.width_m - x_G).norm(), 0.0, 1e-9);
    const Vec3 n0 = BoxFaceNormal(g.contacts_P[0], 0.5 * size);
    const Vec3 n1 = BoxFaceNormal(g.contacts_P[1], 0.5 * size);
    EXPECT_NEAR(n0.dot(n1), -1.0, 1e-12) << "contacts not on opposite faces";
    EXPECT_LE(AngleBetween(x_G, n0), alpha + 1e-9);
    EXPECT_LE(AngleBetween(-x_G, n1), alpha + 1e-9);
    EXPECT_NE(std::abs(n0.z()), 1.0) << "closed across the 100 mm side";
    // The pads' centre sits on the contact midpoint, or (a shallow grasp, contacts near the
    // fingertips) straight back from it along the approach axis by half the pad less 3 mm; the
    // pads touch enough.
    const Vec3 back = 0.5 * (g.contacts_P[0] + g.contacts_P[1]) - g.X_PG * pad_T;
    const double shallow = 0.5 * ee->pad_length_m - 0.003;
    const Vec3 approach = g.X_PG.linear().col(2);
    EXPECT_TRUE(back.norm() < 1e-9 || (std::abs(back.norm() - shallow) < 1e-9 &&
                                       back.normalized().dot(approach) > 1.0 - 1e-9))
        << "pad centre " << back.transpose() << " from the contact midpoint";
    EXPECT_GE(g.contact_area_m2, defaults.min_pad_contact_m2);
    // The gripper, open by the clearance, does not touch the box.
    EXPECT_FALSE(GraspCollides(s, box, g, *ee, g.width_m + 2 * defaults.clearance_m, 0.0));
  }
}

// 30 x 60 x 100 mm: only the two 60 x 100 faces hold a 40 mm disc. A cup centred on a face sits
// on the line through the centre of mass: the grasp a vacuum insertion needs (the paper's assembly
// box allows no moment); the sampler tries the middle of every flat face first, so both large
// faces' centres are among the grasps.
TEST(Vacuum, OnlyOnFacesLargeEnoughForTheCupAndTheirCentresFirst) {
  const Vec3 size(0.03, 0.06, 0.10);
  const Scene s = OneBox(size, "vacuum_cup");
  RunContext ctx(2);
  auto r = Preprocess(s.project, s.check, Quick(), ctx);
  ASSERT_TRUE(r) << r.error().message;
  const auto ee = LoadEndEffector("vacuum_cup");
  ASSERT_TRUE(ee);
  const Subassembly& box = r->subassemblies.at(0);
  const GraspSet& set = box.grasp_sets.at(0);
  ASSERT_EQ(set.grasps.size(), 20u);
  const double radius = 0.5 * ee->cup_diameter_m;
  bool plus = false, minus = false;
  int centred = 0;
  for (const Grasp& g : set.grasps) {
    EXPECT_EQ(g.kind, EndEffectorKind::kVacuum);
    const Vec3 z_G = g.X_PG.linear().col(2);  // cup axis, into the part
    const Vec3 p = g.X_PG.translation();
    EXPECT_NEAR(std::abs(z_G.x()), 1.0, 1e-9) << "cup not on a 60 x 100 face";
    EXPECT_NEAR(std::abs(p.x()), 0.5 * size.x(), 1e-9);
    EXPECT_LT(z_G.x() * p.x(), 0.0) << "cup axis must point into the part";
    // The whole disc lies on the face.
    EXPECT_LE(std::abs(p.y()), 0.5 * size.y() - radius + 1e-9);
    EXPECT_LE(std::abs(p.z()), 0.5 * size.z() - radius + 1e-9);
    plus = plus || p.x() > 0;
    minus = minus || p.x() < 0;
    EXPECT_FALSE(GraspCollides(s, box, g, *ee, 0.0, VacuumGraspOptions{}.standoff_m));
    if (std::abs(p.y()) < 1e-9 && std::abs(p.z()) < 1e-9) {
      ++centred;
      EXPECT_LT(z_G.cross(-p).norm(), 1e-9) << "a centred cup's axis passes through the COM";
    }
  }
  EXPECT_TRUE(plus && minus) << "grasps should spread over both large faces";
  EXPECT_EQ(centred, 2) << "both large faces' centres should be among the grasps";

  // A box whose faces are all narrower than the cup has no vacuum grasp at all.
  const Scene thin = OneBox(Vec3(0.03, 0.03, 0.2), "vacuum_cup");
  RunContext ctx2(2);
  auto none = Preprocess(thin.project, thin.check, Quick(), ctx2);
  ASSERT_TRUE(none) << none.error().message;
  EXPECT_TRUE(none->subassemblies[0].grasp_sets[0].grasps.empty());
  ASSERT_FALSE(none->warnings.empty());
  EXPECT_NE(none->warnings[0].find("no grasp"), std::string::npos);
}

TEST(Grasps, SpreadOverTheSurface) {
  // A long bar: the grasps should cover much of its length, with no two in one spot.
  const Scene s = OneBox(Vec3(0.03, 0.03, 0.3), "robotiq_2f85");
  RunContext ctx(3);
  auto r = Preprocess(s.project, s.check, Quick(20), ctx);
  ASSERT_TRUE(r) << r.error().message;
  const auto grasps = FullPad(r->subassemblies[0].grasp_sets[0].grasps);
  ASSERT_EQ(grasps.size(), 20u);
  double lo = 1.0, hi = -1.0, nearest = 1.0;
  for (size_t i = 0; i < grasps.size(); ++i) {
    const Vec3 c = 0.5 * (grasps[i].contacts_P[0] + grasps[i].contacts_P[1]);
    lo = std::min(lo, c.z());
    hi = std::max(hi, c.z());
    for (size_t j = 0; j < i; ++j) {
      const Vec3 d = 0.5 * (grasps[j].contacts_P[0] + grasps[j].contacts_P[1]);
      nearest = std::min(nearest, (c - d).norm() + AngleBetween(grasps[i].X_PG.linear().col(2),
                                                                grasps[j].X_PG.linear().col(2)));
    }
  }
  EXPECT_GT(hi - lo, 0.2) << "grasps cover only " << (hi - lo) << " m of the 0.3 m bar";
  EXPECT_GT(nearest, 1e-3) << "two grasps (nearly) coincide";
}

TEST(Grasps, SameSeedSameGrasps) {
  const Scene s = OneBox(Vec3(0.04, 0.05, 0.07), "robotiq_2f85");
  auto run = [&](std::uint64_t seed, bool parallel) {
    RunContext ctx(seed);
    PreprocessOptions o = Quick();
    o.parallel = parallel;
    auto r = Preprocess(s.project, s.check, o, ctx);
    EXPECT_TRUE(r);
    return r->subassemblies[0].grasp_sets[0].grasps;
  };
  const auto a = run(11, true), b = run(11, true), c = run(11, false), d = run(12, true);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  bool differs = a.size() != d.size();
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].X_PG.matrix() == b[i].X_PG.matrix()) << "grasp " << i;
    EXPECT_TRUE(a[i].X_PG.matrix() == c[i].X_PG.matrix()) << "grasp " << i << " (serial)";
    EXPECT_EQ(a[i].quality, b[i].quality);
    if (i < d.size()) differs = differs || !(a[i].X_PG.matrix() == d[i].X_PG.matrix());
  }
  EXPECT_TRUE(differs) << "another seed should give other grasps";
}

TEST(Subassemblies, TowerOfTwoBoxes) {
  // A 60 x 60 x 20 mm base with a 20 x 20 x 60 mm post standing on its centre.
  Scene s;
  AddPart(s, "base", MakeBox(Vec3(-0.03, -0.03, 0.0), Vec3(0.03, 0.03, 0.02)));
  Pose up;
  up.xyz = Vec3(0, 0, 0.02);
  AddPart(s, "post", MakeBox(Vec3(-0.01, -0.01, 0.0), Vec3(0.01, 0.01, 0.06)), up);
  AddStep(s, "tower", "post", "base");
  AddRobots(s, "robotiq_2f85");
  s.project.robots[1].end_effector = "vacuum_cup";
  ASSERT_TRUE(Finish(s));
  RunContext ctx(4);
  auto r = Preprocess(s.project, s.check, Quick(), ctx);
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->subassemblies.size(), 3u);
  EXPECT_EQ(r->end_effectors, (std::vector<std::string>{"robotiq_2f85", "vacuum_cup"}));
  const Subassembly* tower = r->Find("tower");
  ASSERT_NE(tower, nullptr);
  EXPECT_EQ(tower->parts, (std::vector<int>{0, 1}));
  const double m_base = 1000 * 0.06 * 0.06 * 0.02, m_post = 1000 * 0.02 * 0.02 * 0.06;
  EXPECT_NEAR(tower->mass_kg, m_base + m_post, 1e-9);
  EXPECT_NEAR(tower->com_A.z(), (m_base * 0.01 + m_post * 0.05) / (m_base + m_post), 1e-9);
  EXPECT_NEAR(tower->hull.volume_m3,
              0.06 * 0.06 * 0.02 + (0.06 * 0.06 + 0.02 * 0.02 + 0.06 * 0.02) * 0.06 / 3.0,
              1e-9);  // box plus the frustum from the base's top to the post's top
  // Rests on its base only among the axis faces; the top (20 x 20) holds the COM too.
  ASSERT_FALSE(tower->placements.empty());
  EXPECT_NEAR(tower->placements[0].normal_A.z(), -1.0, 1e-9);
  const auto two_finger = LoadEndEffector("robotiq_2f85");
  const auto vacuum = LoadEndEffector("vacuum_cup");
  ASSERT_TRUE(two_finger && vacuum);
  int on_post = 0, on_base = 0;
  for (const GraspSet& set : tower->grasp_sets) {
    EXPECT_FALSE(set.grasps.empty()) << set.end_effector;
    for (const Grasp& g : set.grasps) {
      (g.part == 1 ? on_post : on_base) += 1;
      if (g.kind == EndEffectorKind::kTwoFinger) {
        EXPECT_FALSE(GraspCollides(s, *tower, g, *two_finger, g.width_m + 2e-3, 0.0));
      } else {
        EXPECT_FALSE(GraspCollides(s, *tower, g, *vacuum, 0.0, 1e-3));
      }
    }
  }
  EXPECT_GT(on_post, 0);
  EXPECT_GT(on_base, 0);
  const Subassembly* post = r->Find("post");
  ASSERT_NE(post, nullptr);
  EXPECT_EQ(post->parts, (std::vector<int>{1}));
}

TEST(Preprocess, StopsWhenCancelledOrOutOfTime) {
  Scene s;
  AddPart(s, "round", MakeCylinder(0.02, 0.08, 4000));  // 16k triangles
  AddRobots(s, "robotiq_2f85");
  ASSERT_TRUE(Finish(s));
  {
    std::stop_source stop;
    stop.request_stop();
    RunContext ctx(0);
    ctx.set_stop_token(stop.get_token());
    auto r = Preprocess(s.project, s.check, Quick(), ctx);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kCancelled);
  }
  {
    RunContext ctx(0);
    ctx.set_deadline(RunContext::Clock::now());
    auto r = Preprocess(s.project, s.check, Quick(), ctx);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kTimeout);
  }
  {
    // Cancel while it samples a large grasp set: it must answer the stop (the latency depends on
    // the machine's load and is not asserted; a hang would meet ctest's timeout). A machine fast
    // enough to finish before the stop is asked again sooner.
    bool stopped_midway = false;
    for (int delay_ms : {100, 20, 2}) {
      std::stop_source stop;
      RunContext ctx(0);
      ctx.set_stop_token(stop.get_token());
      PreprocessOptions o = Quick(2000);
      Result<Preprocessed> r = Fail(ErrorCode::kInternal, "not run");
      std::thread worker([&] { r = Preprocess(s.project, s.check, o, ctx); });
      std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
      stop.request_stop();
      worker.join();
      if (r) continue;  // finished before the stop
      EXPECT_EQ(r.error().code, ErrorCode::kCancelled) << r.error().message;
      stopped_midway = true;
      break;
    }
    EXPECT_TRUE(stopped_midway) << "preprocessing finished within 2 ms every time: no stop tested";
  }
}

TEST(Preprocess, RejectsBadInput) {
  Scene s = OneBox(Vec3(0.05, 0.05, 0.05), "robotiq_2f85");
  RunContext ctx(0);
  PreprocessOptions o = Quick();
  o.friction = -1.0;
  auto r = Preprocess(s.project, s.check, o, ctx);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(r.error().message.find("friction"), std::string::npos);

  o = Quick();
  o.end_effectors = {"no_such_gripper"};
  r = Preprocess(s.project, s.check, o, ctx);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);

  Scene no_tree = s;
  no_tree.check.tree.reset();
  r = Preprocess(no_tree.project, no_tree.check, Quick(), ctx);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);

  Scene flat = s;
  for (Vec3& v : flat.check.parts[0].mesh.vertices) v.z() = 0.0;
  flat.check.parts[0].mass_kg = 1.0;
  r = Preprocess(flat.project, flat.check, Quick(), ctx);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput) << r.error().message;
  EXPECT_NE(r.error().message.find("'box'"), std::string::npos) << r.error().message;
}

class ExampleProjects : public ::testing::TestWithParam<std::string> {};

TEST_P(ExampleProjects, PreprocessGivesPlacementsGraspsAndReachableSlots) {
  const fs::path file = fs::path(WRAP_SOURCE_DIR) / "projects" / (GetParam() + ".json");
  const LoadedProject lp = LoadProject(file);
  // Only the Fabrica projects may be absent here (their meshes are in ../shared).
  if (!lp.ok() && GetParam().starts_with("fabrica") &&
      !fs::exists(fs::path(WRAP_SHARED_DIR) / "fabrica")) {
    GTEST_SKIP() << "the Fabrica meshes are not beside the repository";
  }
  ASSERT_TRUE(lp.ok()) << GetParam() << " does not validate";
  const Project& p = *lp.project;
  PreprocessOptions o;
  o.project_file = file;
  RunContext ctx(p.planner.seed);
  auto r = Preprocess(p, lp.check, o, ctx);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->subassemblies.size(), p.parts.size() + p.steps.size());
  EXPECT_GT(ctx.stage_times().at("grasp"), 0.0);
  for (const Subassembly& sub : r->subassemblies) {
    EXPECT_FALSE(sub.placements.empty()) << sub.name;
    size_t grasps = 0;
    for (const GraspSet& set : sub.grasp_sets) {
      EXPECT_LE(FullPad(set.grasps).size(), static_cast<size_t>(p.planner.grasps));
      EXPECT_LE(Reduced(set.grasps), static_cast<size_t>(p.planner.grasps));
      grasps += set.grasps.size();
    }
    EXPECT_GT(grasps, 0u) << sub.name;
  }
  // The root can be grasped by a full set of some end effector.
  size_t root_best = 0;
  for (const GraspSet& set : r->subassemblies[lp.check.tree->root].grasp_sets) {
    root_best = std::max(root_best, FullPad(set.grasps).size());
  }
  EXPECT_EQ(root_best, static_cast<size_t>(p.planner.grasps));
  // Slots: as many as asked, on the table, each reached by two robots (checked again here).
  const TableSlots& slots = r->table_slots;
  EXPECT_EQ(slots.slots.size(), static_cast<size_t>(o.table_slots.num_slots));
  for (const TableSlot& slot : slots.slots) {
    EXPECT_LE(std::abs(slot.p_W.x() - p.table.center_xy.x()), 0.5 * p.table.size.x());
    EXPECT_LE(std::abs(slot.p_W.y() - p.table.center_xy.y()), 0.5 * p.table.size.y());
    EXPECT_DOUBLE_EQ(slot.p_W.z(), p.table.height);
    EXPECT_GE(slot.robots.size(), 2u);
    for (int robot : slot.robots) {
      const Robot& rb = p.robots[robot];
      auto chain = LoadRobotModel(rb.model);
      auto ee = LoadEndEffector(rb.end_effector);
      ASSERT_TRUE(chain && ee);
      auto ur = UrAnalyticIk::FromChain(*chain);
      if (!ur) continue;  // numeric IK: trusted
      bool ok = false;
      for (int k = 0; k < 8 && !ok; ++k) {
        Iso3 X_WT = Iso3::Identity();
        X_WT.linear() = (Eigen::AngleAxisd(k * std::numbers::pi / 4, Vec3::UnitZ()) *
                         Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()))
                            .toRotationMatrix();
        X_WT.translation() = slot.p_W + Vec3(0, 0, o.table_slots.probe_height_m);
        ok = ur->SolveTcp(RobotBaseInWorld(p, rb).inverse() * X_WT, ee->X_FT).count > 0;
      }
      EXPECT_TRUE(ok) << rb.name << " at " << slot.p_W.transpose();
    }
  }
  // No grasp of any subassembly collides with it, checked independently; every placement holds
  // its COM above the support polygon.
  for (const Subassembly& sub : r->subassemblies) {
    for (const GraspSet& set : sub.grasp_sets) {
      for (const std::string& hit : CollidingGrasps(
               p, lp.check, sub, set.grasps, o.two_finger.clearance_m, o.vacuum.standoff_m)) {
        ADD_FAILURE() << sub.name << ": " << hit;
      }
    }
    for (const StablePlacement& pl : sub.placements) {
      const Vec3 com_T = pl.X_TA * sub.com_A;
      EXPECT_NEAR(com_T.head<2>().norm(), 0.0, 1e-9);
      EXPECT_GE(PolygonMargin(pl.support_T, Eigen::Vector2d::Zero()),
                o.placements.min_margin_m - 1e-12);
      for (const Vec3& v : sub.hull.mesh.vertices) {
        EXPECT_GE((pl.X_TA * v).z(), -1e-6) << sub.name << ": hull below the table";
      }
    }
  }
  // The JSON carries what the issue asks for.
  const auto doc = nlohmann::json::parse(PreprocessedToJson(p, *r));
  ASSERT_TRUE(doc.contains("subassemblies"));
  ASSERT_EQ(doc["subassemblies"].size(), r->subassemblies.size());
  for (const auto& sub : doc["subassemblies"]) {
    for (const char* key : {"name", "parts", "placements", "grasps"}) {
      EXPECT_TRUE(sub.contains(key)) << key;
    }
  }
  EXPECT_TRUE(doc["timings_s"].contains("total"));
}

INSTANTIATE_TEST_SUITE_P(Projects, ExampleProjects,
                         ::testing::Values("stool", "chair", "cross", "cross_openarm", "cube",
                                           "cube_2x2x3", "half_stool", "fabrica_beam",
                                           "fabrica_plumbers_block", "fabrica_car",
                                           "fabrica_gamepad", "fabrica_cooling_manifold"));

// The cooling manifold's pipes are held only by fingertips on the collar from above, where the
// elbow fits between the open fingers: 0 of ~1000 reduced candidates cleared the plate on seeds
// 2 and 5 before a part short of assembly grasps drew a second, larger pool. Every seed gives
// each pipe some.
TEST(ReducedGrasps, APartShortOfAssemblyGraspsDrawsAgain) {
  const fs::path file = fs::path(WRAP_SOURCE_DIR) / "projects" / "fabrica_cooling_manifold.json";
  const LoadedProject lp = LoadProject(file);
  if (!lp.ok() && !fs::exists(fs::path(WRAP_SHARED_DIR) / "fabrica")) {
    GTEST_SKIP() << "the Fabrica meshes are not beside the repository";
  }
  ASSERT_TRUE(lp.ok());
  for (std::uint64_t seed : {2u, 5u}) {
    PreprocessOptions o;
    o.project_file = file;
    RunContext ctx(seed);
    auto r = Preprocess(*lp.project, lp.check, o, ctx);
    ASSERT_TRUE(r) << r.error().message;
    for (const char* pipe : {"pipe0", "pipe4"}) {
      const Subassembly* sub = r->Find(pipe);
      ASSERT_NE(sub, nullptr);
      const GraspSet& set = sub->grasp_sets.front();
      const int clear = set.assembly_candidates_by_type[1] + set.assembly_candidates_by_type[2];
      EXPECT_GT(clear, 0) << pipe << ", seed " << seed;
      // The second draw: more reduced candidates than the first pass's pool gives.
      const int reduced = set.candidates_by_type[1] + set.candidates_by_type[2];
      EXPECT_GT(reduced, 4 * r->grasps_per_set * o.candidate_factor) << pipe << ", seed " << seed;
      int reduced_in_set = 0;
      for (const Grasp& g : set.grasps) reduced_in_set += g.type != GraspType::kFullPad;
      EXPECT_GT(reduced_in_set, 0) << pipe;
    }
  }
}

TEST(Placements, StoolLegRestsOnItsEndsAndItsSide) {
  const fs::path file = fs::path(WRAP_SOURCE_DIR) / "projects" / "stool.json";
  const LoadedProject lp = LoadProject(file);
  ASSERT_TRUE(lp.ok()) << "stool does not validate";
  RunContext ctx(0);
  auto r = Preprocess(*lp.project, lp.check, Quick(), ctx);
  ASSERT_TRUE(r) << r.error().message;
  const Subassembly* leg = r->Find("leg1");
  ASSERT_NE(leg, nullptr);
  ASSERT_EQ(leg->placements.size(), 3u);  // foot, peg end, side (one class of 48 facets)
  int sides = 0;
  for (const StablePlacement& pl : leg->placements) {
    if (std::abs(pl.normal_A.z()) < 1e-6) {
      ++sides;
      EXPECT_EQ(pl.equivalent_facets.size(), 48u);
    }
  }
  EXPECT_EQ(sides, 1);
}

}  // namespace
}  // namespace wrap
