// The cell scene and its MJCF, without GL: the model compiles in MuJoCo, has the bodies, joints
// and mocap parts it should, and MuJoCo's kinematics agree with ours.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <numbers>
#include <string>

#include "geometry/step_import.h"
#include "robot/home.h"
#include "robot/kinematics.h"
#include "sim/mjcf.h"
#include "sim/mujoco_model.h"
#include "sim/scene.h"
#include "test_build_config.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

struct Loaded {
  LoadedProject project;
  CellScene scene;
};

Loaded Load(const std::string& name) {
  const fs::path file = fs::path(WRAP_SOURCE_DIR) / "projects" / (name + ".json");
  Loaded l;
  l.project = LoadProject(file);
  EXPECT_TRUE(l.project.ok()) << name;
  if (!l.project.ok()) return l;
  auto scene = BuildCellScene(*l.project.project, l.project.check, file);
  EXPECT_TRUE(scene.has_value()) << (scene ? "" : scene.error().message);
  if (scene) l.scene = std::move(*scene);
  return l;
}

Iso3 BodyPose(const mjModel* m, const mjData* d, const std::string& name) {
  const int id = mj_name2id(m, mjOBJ_BODY, name.c_str());
  EXPECT_GE(id, 0) << name;
  Iso3 X = Iso3::Identity();
  if (id < 0) return X;
  for (int r = 0; r < 3; ++r) {
    X.translation()[r] = d->xpos[3 * id + r];
    for (int c = 0; c < 3; ++c) X.linear()(r, c) = d->xmat[9 * id + 3 * r + c];
  }
  return X;
}

void ExpectNear(const Iso3& a, const Iso3& b, double tol, const std::string& what) {
  EXPECT_LT((a.translation() - b.translation()).norm(), tol) << what;
  EXPECT_LT((a.linear() - b.linear()).norm(), 1e-6) << what;
}

TEST(CellScene, StoolHasRobotsPartsAndSteps) {
  const Loaded l = Load("stool");
  const CellScene& s = l.scene;
  ASSERT_EQ(s.robots.size(), 4u);
  ASSERT_EQ(s.parts.size(), 5u);
  EXPECT_EQ(s.steps.size(), 4u);
  // The four legs come from one file: one shared mesh.
  EXPECT_EQ(s.parts[1].mesh.get(), s.parts[2].mesh.get());
  for (const SceneRobot& r : s.robots) {
    EXPECT_TRUE(WithinLimits(r.chain, r.home)) << r.name;
    EXPECT_EQ(r.pedestal_radius_m, 0.0) << r.name << " stands on the table";
  }
}

#if WRAP_TEST_WITH_OCCT
// Parts from one STEP file share a mesh only when they use the same solid of it (a build with
// OpenCASCADE only: WRAP_WITH_OCCT).
TEST(CellScene, StepPartsShareMeshesBySolid) {
  const Loaded l = Load("stool_step");
  const CellScene& s = l.scene;
  ASSERT_EQ(s.parts.size(), 5u);
  EXPECT_EQ(s.parts[1].mesh.get(), s.parts[4].mesh.get()) << "the legs: one solid";
  EXPECT_NE(s.parts[0].mesh.get(), s.parts[1].mesh.get()) << "the seat is another solid";
  EXPECT_NEAR(ComputeAabb(*s.parts[1].mesh).size().z(), 0.199, 1e-6);
  EXPECT_NEAR(ComputeAabb(*s.parts[0].mesh).size().x(), 0.240, 1e-6);
}
#endif  // WRAP_TEST_WITH_OCCT

TEST(CellScene, HomeFacesTheTableWithTheToolDown) {
  const Loaded l = Load("stool");
  for (const SceneRobot& r : l.scene.robots) {
    const Iso3 X_WF = FlangePose(r.chain, r.X_WB, r.home);
    // Tool straight down, above the table, nearer the centre than the base is.
    EXPECT_LT(X_WF.linear().col(2).z(), -0.99) << r.name;
    EXPECT_GT(X_WF.translation().z(), l.scene.table.top_center.z() + 0.3) << r.name;
    const Vec3 base = r.X_WB.translation();
    EXPECT_LT(X_WF.translation().head<2>().norm(), base.head<2>().norm()) << r.name;
  }
  for (const char* model : {"ur5e", "ur10e", "openarm"}) {
    auto chain = LoadRobotModel(model);
    ASSERT_TRUE(chain.has_value());
    EXPECT_TRUE(WithinLimits(*chain, HomeConfiguration(*chain))) << model;
  }
}

TEST(CellScene, PedestalsUnderRaisedBases) {
  const Loaded l = Load("cross_openarm");
  ASSERT_EQ(l.scene.robots.size(), 4u);
  for (const SceneRobot& r : l.scene.robots) {
    EXPECT_GT(r.pedestal_radius_m, 0.05) << r.name;
    EXPECT_DOUBLE_EQ(r.pedestal_bottom_z, 0.75) << r.name << ": from the table top";
  }
  const Loaded husky = Load("half_stool");
  ASSERT_EQ(husky.scene.mobile_bases.size(), 1u);
  for (const SceneRobot& r : husky.scene.robots) {
    EXPECT_TRUE(r.mounted);
    EXPECT_EQ(r.pedestal_radius_m, 0.0) << r.name << " is on the Husky";
  }
}

TEST(CellScene, GoalRestsOnTheTableAndExplodes) {
  const Loaded l = Load("cross");
  const CellScene& s = l.scene;
  auto goal = GoalState(s);
  auto exploded = GoalState(s, GoalOptions{0.5});
  ASSERT_TRUE(goal && exploded);
  auto parts_box = [&](const SceneState& st) {
    Aabb box{Vec3::Constant(1e9), Vec3::Constant(-1e9)};
    for (size_t i = 0; i < s.parts.size(); ++i) {
      for (const Vec3& v : s.parts[i].mesh->vertices) {
        box.min = box.min.cwiseMin(st.X_WP[i] * v);
        box.max = box.max.cwiseMax(st.X_WP[i] * v);
      }
    }
    return box;
  };
  const Aabb a = parts_box(*goal);
  const Aabb e = parts_box(*exploded);
  EXPECT_NEAR(a.min.z(), s.table.top_center.z(), 1e-9);
  EXPECT_NEAR(e.min.z(), s.table.top_center.z(), 1e-9);
  EXPECT_NEAR(0.5 * (a.min.x() + a.max.x()), s.table.top_center.x(), 1e-9);
  // The cross explodes along all six axes: larger in every direction.
  for (int k = 0; k < 3; ++k) EXPECT_GT(e.size()[k], a.size()[k] + 0.05) << "axis " << k;
  // Relative poses of the assembled goal are the project's assembled poses.
  const Iso3 X_01 = goal->X_WP[0].inverse() * goal->X_WP[1];
  ExpectNear(X_01, s.parts[0].X_AP.inverse() * s.parts[1].X_AP, 1e-9, "assembled pose");
  EXPECT_FALSE(GoalState(s, GoalOptions{-1.0}).has_value());
}

TEST(Mjcf, CompilesWithBodiesJointsAndMocapParts) {
  const Loaded l = Load("stool");
  const CellScene& s = l.scene;
  const SceneState state = InitialState(s);
  auto doc = BuildCellMjcf(s, state);
  ASSERT_TRUE(doc.has_value()) << doc.error().message;
  EXPECT_TRUE(doc->warnings.empty());
  auto cell = CellModel::Compile(*doc);
  ASSERT_TRUE(cell.has_value()) << cell.error().message;
  const mjModel* m = cell->model();

  int bodies = 1 + 1;  // world, table
  int joints = 0;
  int two_finger = 0;
  for (const SceneRobot& r : s.robots) {
    bodies += r.chain.dof() + 1 + 1;  // links, end effector
    joints += r.chain.dof();
    if (r.end_effector.kind == EndEffectorKind::kTwoFinger) {
      bodies += 2;
      joints += 2;
      ++two_finger;
    }
  }
  bodies += static_cast<int>(s.parts.size());
  EXPECT_EQ(two_finger, 2);
  EXPECT_EQ(m->nbody, bodies);
  EXPECT_EQ(m->njnt, joints);
  EXPECT_EQ(m->nmocap, static_cast<int>(s.parts.size()));
  EXPECT_EQ(m->nmesh, 2) << "seat and one shared leg mesh";
  EXPECT_EQ(cell->num_robots(), 4);
  EXPECT_EQ(cell->num_parts(), 5);
  EXPECT_EQ(m->vis.global.offwidth, 640);
  // Keyframe "state" holds the state: the first robot's first joint at home.
  ASSERT_EQ(m->nkey, 1);
  EXPECT_NEAR(m->key_qpos[0], s.robots[0].home[0], 1e-6);
  EXPECT_NEAR(m->key_mpos[2], state.X_WP[0].translation().z(), 1e-6);
  for (int g = 0; g < m->ngeom; ++g) {
    EXPECT_EQ(m->geom_contype[g], 0);
    EXPECT_EQ(m->geom_conaffinity[g], 0);
  }
}

TEST(Mjcf, WrittenFilesLoadFromDisk) {
  const Loaded l = Load("stool");
  auto doc = BuildCellMjcf(l.scene, InitialState(l.scene));
  ASSERT_TRUE(doc.has_value());
  const fs::path dir = fs::temp_directory_path() / ("wrap_mjcf_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  ASSERT_TRUE(WriteMjcf(*doc, dir).has_value());
  InstallMujocoHandlers();
  char error[1000] = "";
  mjModel* m = mj_loadXML((dir / "cell.xml").c_str(), nullptr, error, sizeof error);
  ASSERT_NE(m, nullptr) << error;
  EXPECT_EQ(m->nmocap, 5);
  mj_deleteModel(m);
}

TEST(Mjcf, MujocoKinematicsMatchOurs) {
  for (const char* project : {"stool", "cross_openarm", "half_stool"}) {
    const Loaded l = Load(project);
    const CellScene& s = l.scene;
    SceneState state = InitialState(s);
    auto doc = BuildCellMjcf(s, state);
    ASSERT_TRUE(doc.has_value()) << doc.error().message;
    auto cell = CellModel::Compile(*doc);
    ASSERT_TRUE(cell.has_value()) << cell.error().message;
    auto data = cell->MakeData();
    ASSERT_TRUE(data);
    // A configuration away from home, a half-open gripper, a part moved.
    std::mt19937_64 rng(7);
    for (size_t r = 0; r < s.robots.size(); ++r) {
      state.q[r] = RandomConfiguration(s.robots[r].chain, rng);
      state.opening_m[r] = 0.5 * s.robots[r].end_effector.stroke_m;
    }
    state.X_WP[0].pretranslate(Vec3(0.01, 0.02, 0.03));
    ASSERT_TRUE(cell->Apply(state, data.get()));
    const mjModel* m = cell->model();
    for (size_t r = 0; r < s.robots.size(); ++r) {
      const SceneRobot& robot = s.robots[r];
      std::vector<Iso3> X_WL(robot.chain.links.size());
      ForwardKinematics(robot.chain, robot.X_WB, state.q[r], X_WL);
      const std::string prefix = "robot:" + robot.name + "/";
      for (size_t i = 0; i < X_WL.size(); ++i) {
        ExpectNear(BodyPose(m, data.get(), prefix + "link" + std::to_string(i)), X_WL[i], 1e-6,
                   std::string(project) + " " + robot.name + " link " + std::to_string(i));
      }
      const Iso3 X_WF = FlangePose(robot.chain, robot.X_WB, state.q[r]);
      ExpectNear(BodyPose(m, data.get(), prefix + "ee"), X_WF, 1e-6, "flange");
      // The fingers where EndEffectorShapesAt puts them at this opening.
      const EndEffector& ee = robot.end_effector;
      if (ee.kind != EndEffectorKind::kTwoFinger) continue;
      const std::vector<Shape> shapes = EndEffectorShapesAt(ee, state.opening_m[r]);
      const char* names[2] = {"finger_pos", "finger_neg"};
      for (int k = 0; k < 2; ++k) {
        const Vec3 expected = X_WF * shapes[ee.finger_shapes[k]].X_LS.translation();
        const Vec3 actual = BodyPose(m, data.get(), prefix + names[k]).translation();
        EXPECT_LT((actual - expected).norm(), 1e-6) << robot.name << " " << names[k];
      }
    }
    const Iso3 part = BodyPose(m, data.get(), "part:" + s.parts[0].name);
    ExpectNear(part, state.X_WP[0], 1e-6, "mocap part");
  }
}

TEST(Mjcf, PedestalsAndMobileBasesAreDrawn) {
  const Loaded l = Load("cross_openarm");
  auto doc = BuildCellMjcf(l.scene, InitialState(l.scene));
  ASSERT_TRUE(doc.has_value());
  auto cell = CellModel::Compile(*doc);
  ASSERT_TRUE(cell.has_value()) << cell.error().message;
  const int pedestal = mj_name2id(cell->model(), mjOBJ_GEOM, "robot:openarm_a/pedestal");
  ASSERT_GE(pedestal, 0);
  EXPECT_EQ(cell->model()->geom_type[pedestal], mjGEOM_CYLINDER);
  // Half the height of the 15 cm pedestal.
  EXPECT_NEAR(cell->model()->geom_size[3 * pedestal + 1], 0.075, 1e-6);

  const Loaded h = Load("half_stool");
  auto hdoc = BuildCellMjcf(h.scene, InitialState(h.scene));
  ASSERT_TRUE(hdoc.has_value());
  auto hcell = CellModel::Compile(*hdoc);
  ASSERT_TRUE(hcell.has_value()) << hcell.error().message;
  EXPECT_GE(mj_name2id(hcell->model(), mjOBJ_BODY, "base:husky"), 0);
}

TEST(Mjcf, FlatMeshIsDrawnAsItsBoxWithAWarning) {
  const Loaded l = Load("stool");
  CellScene s = l.scene;
  Shape flat;
  flat.type = Shape::Type::kMesh;
  flat.name = "flat";
  flat.mesh.vertices = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0, 0.1, 0)};
  flat.mesh.triangles = {Eigen::Vector3i(0, 1, 2)};
  s.robots[0].chain.links[2].visual.push_back(flat);
  // A part with a flat mesh too (validation only warns about open meshes).
  s.parts[0].mesh = std::make_shared<const TriangleMesh>(flat.mesh);
  auto doc = BuildCellMjcf(s, InitialState(s));
  ASSERT_TRUE(doc.has_value());
  ASSERT_EQ(doc->warnings.size(), 2u);
  for (const std::string& w : doc->warnings) {
    EXPECT_NE(w.find("bounding box"), std::string::npos) << w;
  }
  auto cell = CellModel::Compile(*doc);
  ASSERT_TRUE(cell.has_value()) << cell.error().message;
  EXPECT_EQ(cell->num_parts(), 5);
}

TEST(Mjcf, MismatchedStateIsRejected) {
  const Loaded l = Load("stool");
  SceneState state = InitialState(l.scene);
  state.X_WP.pop_back();
  auto doc = BuildCellMjcf(l.scene, state);
  ASSERT_FALSE(doc.has_value());
  EXPECT_EQ(doc.error().code, ErrorCode::kInvalidInput);
  auto good = BuildCellMjcf(l.scene, InitialState(l.scene));
  auto cell = CellModel::Compile(*good);
  ASSERT_TRUE(cell.has_value());
  auto data = cell->MakeData();
  EXPECT_FALSE(cell->Apply(state, data.get()).has_value());
}

TEST(MujocoAdapter, CompilerErrorsAndFatalErrorsBecomeResults) {
  MjcfDocument bad;
  bad.xml = "<mujoco><worldbody><geom type='box' size='-1 1 1'/></worldbody></mujoco>";
  auto cell = CellModel::Compile(bad);
  ASSERT_FALSE(cell.has_value());
  EXPECT_EQ(cell.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(cell.error().message.find("MuJoCo"), std::string::npos);

  // mju_error exits the process by default; here it comes back as an Error.
  const fs::path log = fs::current_path() / "MUJOCO_LOG.TXT";
  const bool log_before = fs::exists(log);
  auto r = RunGuarded("test", [] { mju_error("deliberate failure"); });
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kInternal);
  EXPECT_NE(r.error().message.find("deliberate failure"), std::string::npos);
  mju_warning("deliberate warning");
  const std::vector<std::string> warnings = TakeMujocoWarnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("deliberate warning"), std::string::npos);
  EXPECT_EQ(fs::exists(log), log_before) << "no MUJOCO_LOG.TXT written";
}

TEST(FrameBox, EveryCornerIsInView) {
  const Aabb box{Vec3(-0.6, -0.5, 0.7), Vec3(0.6, 0.5, 1.5)};
  const double fovy = 40.0;
  const double aspect = 4.0 / 3.0;
  for (double az : {0.0, 90.0, 150.0, 270.0}) {
    for (double el : {-10.0, -40.0, -89.0}) {
      const CameraView v = FrameBox(box, az, el, fovy, aspect);
      const double a = az * std::numbers::pi / 180, e = el * std::numbers::pi / 180;
      const Vec3 fwd(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
      const Vec3 up(-std::sin(e) * std::cos(a), -std::sin(e) * std::sin(a), std::cos(e));
      const Vec3 right = fwd.cross(up);
      const Vec3 eye = v.lookat - v.distance_m * fwd;
      const double tv = std::tan(fovy / 2 * std::numbers::pi / 180), th = tv * aspect;
      double umax = 0, vmax = 0;
      for (int i = 0; i < 8; ++i) {
        const Vec3 c((i & 1) ? box.max.x() : box.min.x(), (i & 2) ? box.max.y() : box.min.y(),
                     (i & 4) ? box.max.z() : box.min.z());
        const Vec3 o = c - eye;
        const double depth = o.dot(fwd);
        ASSERT_GT(depth, 0.0);
        umax = std::max(umax, std::abs(o.dot(right)) / (depth * th));
        vmax = std::max(vmax, std::abs(o.dot(up)) / (depth * tv));
      }
      EXPECT_LE(umax, 1.0) << az << " " << el;
      EXPECT_LE(vmax, 1.0) << az << " " << el;
      EXPECT_GT(std::max(umax, vmax), 0.85) << "tight: " << az << " " << el;
    }
  }
}

}  // namespace
}  // namespace wrap
