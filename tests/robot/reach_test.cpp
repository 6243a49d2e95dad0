// The example projects' layouts with real kinematics: every part, where it starts on the table,
// can be grasped from above by at least two robots (IK only; collisions are the planner's job).
#include <gtest/gtest.h>

#include <filesystem>
#include <numbers>
#include <random>

#include "model/validate.h"
#include "robot/catalog.h"
#include "robot/ik.h"
#include "robot/kinematics.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

// True when `robot` reaches the TCP pose X_WT (analytic IK for UR arms, numeric otherwise).
bool Reaches(const Chain& chain, const EndEffector& ee, const Iso3& X_WB, const Iso3& X_WT,
             std::mt19937_64& rng) {
  const Iso3 X_BT = X_WB.inverse() * X_WT;
  if (auto ur = UrAnalyticIk::FromChain(chain)) return ur->SolveTcp(X_BT, ee.X_FT).count > 0;
  NumericIkRequest request;
  request.X_BT = X_BT;
  request.X_FT = ee.X_FT;
  NumericIkOptions options;
  options.restarts = 30;
  return SolveNumericIk(chain, request, rng, options).has_value();
}

class ExampleReach : public ::testing::TestWithParam<std::string> {};

TEST_P(ExampleReach, EveryPartCanBeGraspedFromAboveByTwoRobots) {
  const fs::path file = fs::path(WRAP_SOURCE_DIR) / "projects" / (GetParam() + ".json");
  const LoadedProject lp = LoadProject(file);
  // Only the Fabrica projects may be absent here (their meshes are in ../shared).
  if (!lp.ok() && GetParam().starts_with("fabrica") &&
      !fs::exists(fs::path(WRAP_SHARED_DIR) / "fabrica")) {
    GTEST_SKIP() << "the Fabrica meshes are not beside the repository";
  }
  ASSERT_TRUE(lp.ok()) << GetParam() << " does not validate";
  const Project& p = *lp.project;
  std::vector<Chain> chains;
  std::vector<EndEffector> effectors;
  for (const Robot& r : p.robots) {
    auto chain = LoadRobotModel(r.model);
    auto ee = LoadEndEffector(r.end_effector);
    ASSERT_TRUE(chain && ee) << r.name;
    chains.push_back(*chain);
    effectors.push_back(*ee);
  }
  std::mt19937_64 rng(1);
  for (size_t i = 0; i < p.parts.size(); ++i) {
    // TCP 1 cm below the top of the part's box (pads around the top; a cup on the top face).
    const Iso3 X_WP = ToIsometry(p.parts[i].initial_pose);
    Aabb box;
    box.min = Vec3::Constant(1e9);
    box.max = Vec3::Constant(-1e9);
    for (const Vec3& v : lp.check.parts[i].mesh.vertices) {
      box.min = box.min.cwiseMin(X_WP * v);
      box.max = box.max.cwiseMax(X_WP * v);
    }
    int reaching = 0;
    std::string who;
    for (size_t r = 0; r < p.robots.size(); ++r) {
      const bool vacuum = effectors[r].kind == EndEffectorKind::kVacuum;
      const Vec3 c((box.min.x() + box.max.x()) / 2, (box.min.y() + box.max.y()) / 2,
                   box.max.z() - (vacuum ? 0.0 : 0.01));
      bool ok = false;
      for (int k = 0; k < 12 && !ok; ++k) {
        Iso3 X_WT = Iso3::Identity();
        // Approach axis z points down; yaw about the vertical.
        X_WT.linear() = Eigen::AngleAxisd(k * std::numbers::pi / 6, Vec3::UnitZ()) *
                        Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()).toRotationMatrix();
        X_WT.translation() = c;
        ok = Reaches(chains[r], effectors[r], RobotBaseInWorld(p, p.robots[r]), X_WT, rng);
      }
      if (ok) {
        ++reaching;
        who += " " + p.robots[r].name;
      }
    }
    EXPECT_GE(reaching, 2) << GetParam() << ": part '" << p.parts[i].name
                           << "' is reachable from above by" << (who.empty() ? " none" : who);
  }
}

INSTANTIATE_TEST_SUITE_P(Projects, ExampleReach,
                         ::testing::Values("stool", "chair", "cross", "cross_openarm", "cube",
                                           "cube_2x2x3", "half_stool", "fabrica_beam",
                                           "fabrica_plumbers_block", "fabrica_car", "fabrica_gamepad",
                                           "fabrica_cooling_manifold"));

}  // namespace
}  // namespace wrap
