// ImportUrdf on small URDFs written by the test: a 3-joint arm with every geometry kind, fixed
// joints folded, package:// meshes, the UR5e joint origins, and broken files with their errors.
#include "robot/urdf_import.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "geometry/mesh.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

Iso3 Translation(double x, double y, double z) {
  Iso3 X = Iso3::Identity();
  X.translation() = Vec3(x, y, z);
  return X;
}

class UrdfImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) /
           ("wrap_urdf_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path Write(const fs::path& rel, const std::string& text) {
    const fs::path p = dir_ / rel;
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
    return p;
  }

  // An ASCII STL box from the origin to `size` (in the file's units).
  void WriteStlBox(const fs::path& rel, const Vec3& size) {
    std::string s = "solid box\n";
    auto v = [&](int k) {
      return Vec3((k & 1) ? size.x() : 0, (k & 2) ? size.y() : 0, (k & 4) ? size.z() : 0);
    };
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
      for (const auto& tri : {std::array<int, 3>{q[0], q[1], q[2]}, {q[0], q[2], q[3]}}) {
        s += "facet normal 0 0 0\nouter loop\n";
        for (int k : tri) {
          const Vec3 p = v(k);
          s += "vertex " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " +
               std::to_string(p.z()) + "\n";
        }
        s += "endloop\nendfacet\n";
      }
    }
    s += "endsolid box\n";
    Write(rel, s);
  }

  fs::path dir_;
};

constexpr const char* kToyArm = R"(<?xml version="1.0"?>
<robot name="toy3">
  <link name="base_link">
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="base"/>
  <joint name="base_link-base" type="fixed">
    <parent link="base_link"/><child link="base"/><origin rpy="0 0 3.14159265358979"/>
  </joint>
  <link name="link1">
    <collision name="column"><origin xyz="0 0 0.15"/>
      <geometry><cylinder radius="0.05" length="0.3"/></geometry></collision>
    <visual><geometry><sphere radius="0.01"/></geometry></visual>
  </link>
  <joint name="joint1" type="revolute">
    <parent link="base_link"/><child link="link1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 2"/>
    <limit lower="-2.5" upper="2.5" velocity="1.5" effort="40"/>
  </joint>
  <link name="link2">
    <collision><origin xyz="0.2 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><cylinder radius="0.04" length="0.4"/></geometry></collision>
    <collision><origin xyz="0.4 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <joint name="joint2" type="continuous">
    <parent link="link1"/><child link="link2"/>
    <origin xyz="0 0 0.3" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <link name="link2_mount">
    <collision><geometry><box size="0.02 0.04 0.06"/></geometry></collision>
  </link>
  <joint name="mount" type="fixed">
    <parent link="link2"/><child link="link2_mount"/><origin xyz="0.4 0 0.05"/>
  </joint>
  <link name="link3">
    <collision><geometry>
      <mesh filename="package://toy_description/meshes/finger.stl" scale="0.001 0.001 0.002"/>
    </geometry></collision>
  </link>
  <joint name="joint3" type="prismatic">
    <parent link="link2_mount"/><child link="link3"/>
    <origin xyz="0.05 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" velocity="0.25" effort="100"/>
  </joint>
  <link name="tool0"/>
  <joint name="flange" type="fixed">
    <parent link="link3"/><child link="tool0"/>
    <origin xyz="0 0 0.07" rpy="0 0 1.5707963267948966"/>
  </joint>
</robot>
)";

TEST_F(UrdfImportTest, ThreeJointArm) {
  const fs::path urdf = Write("toy_description/urdf/toy3.urdf", kToyArm);
  WriteStlBox("toy_description/meshes/finger.stl", Vec3(10, 10, 20));  // mm
  auto chain = ImportUrdf(urdf);
  ASSERT_TRUE(chain) << chain.error().message;
  EXPECT_EQ(chain->name, "toy3");
  ASSERT_EQ(chain->dof(), 3);
  ASSERT_EQ(chain->links.size(), 4u);
  EXPECT_EQ(chain->links[0].name, "base_link");
  EXPECT_EQ(chain->links[3].name, "link3");

  const Joint& j1 = chain->joints[0];
  EXPECT_EQ(j1.name, "joint1");
  EXPECT_EQ(j1.type, Joint::Type::kRevolute);
  EXPECT_TRUE(j1.X_PJ.isApprox(Translation(0, 0, 0.1)));
  EXPECT_TRUE(j1.axis.isApprox(Vec3::UnitZ()));  // normalised
  EXPECT_DOUBLE_EQ(j1.lower, -2.5);
  EXPECT_DOUBLE_EQ(j1.upper, 2.5);
  EXPECT_DOUBLE_EQ(j1.max_velocity, 1.5);
  EXPECT_DOUBLE_EQ(j1.max_effort, 40.0);
  EXPECT_DOUBLE_EQ(j1.max_acceleration, 5.0);

  const Joint& j2 = chain->joints[1];
  EXPECT_EQ(j2.type, Joint::Type::kRevolute);  // continuous
  EXPECT_DOUBLE_EQ(j2.lower, -2 * kPi);
  EXPECT_DOUBLE_EQ(j2.upper, 2 * kPi);
  EXPECT_DOUBLE_EQ(j2.max_velocity, 1.0);  // none given: the default
  EXPECT_TRUE(j2.X_PJ.translation().isApprox(Vec3(0, 0, 0.3)));
  EXPECT_TRUE(j2.X_PJ.linear().isApprox(
      Eigen::AngleAxisd(kPi / 2, Vec3::UnitX()).toRotationMatrix(), 1e-12));

  // The fixed 'mount' folds into joint3's origin.
  const Joint& j3 = chain->joints[2];
  EXPECT_EQ(j3.type, Joint::Type::kPrismatic);
  EXPECT_TRUE(j3.X_PJ.translation().isApprox(Vec3(0.45, 0, 0.05)));
  EXPECT_TRUE(j3.axis.isApprox(Vec3::UnitX()));
  EXPECT_DOUBLE_EQ(j3.lower, 0.0);
  EXPECT_DOUBLE_EQ(j3.upper, 0.2);
  EXPECT_DOUBLE_EQ(j3.max_velocity, 0.25);
  EXPECT_DOUBLE_EQ(j3.max_effort, 100.0);

  // The flange: tool0 in link3.
  EXPECT_TRUE(chain->X_LF.translation().isApprox(Vec3(0, 0, 0.07)));
  EXPECT_TRUE(chain->X_LF.linear().isApprox(
      Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()).toRotationMatrix(), 1e-12));

  // Collision shapes in the chain link frames.
  ASSERT_EQ(chain->links[0].collision.size(), 1u);
  const Shape& base = chain->links[0].collision[0];
  EXPECT_EQ(base.type, Shape::Type::kBox);
  EXPECT_TRUE(base.X_LS.translation().isApprox(Vec3(0, 0, 0.05)));
  EXPECT_TRUE(base.half_extents.isApprox(Vec3(0.1, 0.1, 0.05)));

  ASSERT_EQ(chain->links[1].collision.size(), 1u);
  const Shape& column = chain->links[1].collision[0];
  EXPECT_EQ(column.type, Shape::Type::kCylinder);
  EXPECT_EQ(column.name, "link1/column");
  EXPECT_DOUBLE_EQ(column.radius, 0.05);
  EXPECT_TRUE(column.p0.isZero(1e-12));
  EXPECT_TRUE(column.p1.isApprox(Vec3(0, 0, 0.3)));
  ASSERT_EQ(chain->links[1].visual.size(), 1u);
  EXPECT_EQ(chain->links[1].visual[0].type, Shape::Type::kSphere);

  ASSERT_EQ(chain->links[2].collision.size(), 3u);  // cylinder, sphere, folded mount box
  const Shape& arm = chain->links[2].collision[0];
  EXPECT_EQ(arm.type, Shape::Type::kCylinder);
  EXPECT_TRUE(arm.p0.isZero(1e-12));
  EXPECT_TRUE(arm.p1.isApprox(Vec3(0.4, 0, 0), 1e-12));
  EXPECT_EQ(chain->links[2].collision[1].type, Shape::Type::kSphere);
  EXPECT_TRUE(chain->links[2].collision[1].p0.isApprox(Vec3(0.4, 0, 0)));
  const Shape& mount = chain->links[2].collision[2];
  EXPECT_EQ(mount.type, Shape::Type::kBox);
  EXPECT_EQ(mount.name, "link2_mount/collision0");
  EXPECT_TRUE(mount.X_LS.translation().isApprox(Vec3(0.4, 0, 0.05)));
  EXPECT_TRUE(mount.half_extents.isApprox(Vec3(0.01, 0.02, 0.03)));

  ASSERT_EQ(chain->links[3].collision.size(), 1u);
  const Shape& finger = chain->links[3].collision[0];
  EXPECT_EQ(finger.type, Shape::Type::kMesh);
  EXPECT_EQ(finger.mesh.triangles.size(), 12u);
  const Aabb box = ComputeAabb(finger.mesh);  // 10 x 10 x 20 mm at scale (1e-3, 1e-3, 2e-3)
  EXPECT_TRUE(box.min.isZero(1e-9));
  EXPECT_TRUE(box.max.isApprox(Vec3(0.01, 0.01, 0.04), 1e-9));

  // Without visuals; with a package folder given explicitly.
  UrdfImportOptions opt;
  opt.import_visual = false;
  opt.continuous_range_rad = kPi;
  opt.package_paths["toy_description"] = dir_ / "toy_description";
  auto again = ImportUrdf(urdf, opt);
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_TRUE(again->links[1].visual.empty());
  EXPECT_DOUBLE_EQ(again->joints[1].upper, kPi);

  // A shorter chain: tip link2.
  opt.tip = "link2";
  auto shorter = ImportUrdf(urdf, opt);
  ASSERT_TRUE(shorter) << shorter.error().message;
  EXPECT_EQ(shorter->dof(), 2);
  EXPECT_TRUE(shorter->X_LF.isApprox(Iso3::Identity()));
}

// The UR5e joint origins of the fact sheet (ur_macro.xacro) put the flange where the DH model
// does at q = 0: the rpy and origin handling agree with the DH table.
TEST_F(UrdfImportTest, Ur5eOriginsMatchDh) {
  const fs::path urdf = Write("ur5e.urdf", R"(<robot name="ur5e">
  <link name="base_link_inertia"/><link name="shoulder_link"/><link name="upper_arm_link"/>
  <link name="forearm_link"/><link name="wrist_1_link"/><link name="wrist_2_link"/>
  <link name="wrist_3_link"/>
  <joint name="shoulder_pan_joint" type="revolute"><parent link="base_link_inertia"/>
    <child link="shoulder_link"/><origin xyz="0 0 0.1625" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-6.283185" upper="6.283185" velocity="3.14" effort="150"/></joint>
  <joint name="shoulder_lift_joint" type="revolute"><parent link="shoulder_link"/>
    <child link="upper_arm_link"/><origin xyz="0 0 0" rpy="1.570796327 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-6.283185" upper="6.283185" velocity="3.14" effort="150"/></joint>
  <joint name="elbow_joint" type="revolute"><parent link="upper_arm_link"/>
    <child link="forearm_link"/><origin xyz="-0.425 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3.14159" upper="3.14159" velocity="3.14" effort="150"/></joint>
  <joint name="wrist_1_joint" type="revolute"><parent link="forearm_link"/>
    <child link="wrist_1_link"/><origin xyz="-0.3922 0 0.1333" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-6.283185" upper="6.283185" velocity="3.14" effort="28"/></joint>
  <joint name="wrist_2_joint" type="revolute"><parent link="wrist_1_link"/>
    <child link="wrist_2_link"/><origin xyz="0 -0.0997 0" rpy="1.570796327 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-6.283185" upper="6.283185" velocity="3.14" effort="28"/>
  </joint>
  <joint name="wrist_3_joint" type="revolute"><parent link="wrist_2_link"/>
    <child link="wrist_3_link"/>
    <origin xyz="0 0.0996 0" rpy="1.570796327 3.141592653589793 3.141592653589793"/>
    <axis xyz="0 0 1"/><limit lower="-6.283185" upper="6.283185" velocity="3.14" effort="28"/>
  </joint>
</robot>)");
  auto chain = ImportUrdf(urdf);
  ASSERT_TRUE(chain) << chain.error().message;
  ASSERT_EQ(chain->dof(), 6);
  Iso3 X = Iso3::Identity();
  for (const Joint& j : chain->joints) X = X * j.X_PJ;  // q = 0
  X = X * chain->X_LF;
  EXPECT_TRUE(X.translation().isApprox(Vec3(-0.8172, -0.2329, 0.0628), 1e-6))
      << X.translation().transpose();
}

// Writes `xml` and imports it, expecting a failure with `code` and `phrase` in the message.
#define EXPECT_IMPORT_FAILS(urdf, options, code_, phrase)                                \
  do {                                                                                   \
    auto r_ = ImportUrdf(urdf, options);                                                 \
    ASSERT_FALSE(r_) << "imported although broken";                                      \
    EXPECT_EQ(r_.error().code, code_) << r_.error().message;                             \
    EXPECT_NE(r_.error().message.find(phrase), std::string::npos) << r_.error().message; \
  } while (0)

constexpr const char* kLinkAB = R"(<link name="a"/><link name="b"/>)";

TEST_F(UrdfImportTest, FloatingJointIsRejected) {
  const fs::path urdf = Write("floating.urdf", std::string(R"(<robot name="f">)") + kLinkAB +
                                                   R"(<link name="world"/>
    <joint name="float" type="floating"><parent link="world"/><child link="a"/></joint>
    <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
      <limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>)");
  EXPECT_IMPORT_FAILS(urdf, UrdfImportOptions{}, ErrorCode::kInvalidInput, "joint 'float'");
  EXPECT_IMPORT_FAILS(urdf, UrdfImportOptions{}, ErrorCode::kInvalidInput, "floating");
  // Starting the chain below the floating joint works.
  UrdfImportOptions opt;
  opt.root = "a";
  EXPECT_TRUE(ImportUrdf(urdf, opt));
}

TEST_F(UrdfImportTest, TooManyJointsIsRejected) {
  std::string text = R"(<robot name="snake"><link name="l0"/>)";
  for (int i = 1; i <= 12; ++i) {
    const std::string n = std::to_string(i);
    const std::string p = std::to_string(i - 1);
    text += "<link name=\"l" + n + "\"/><joint name=\"j" + n +
            "\" type=\"revolute\"><parent link=\"l" + p + "\"/><child link=\"l" + n +
            "\"/><limit lower=\"-1\" upper=\"1\" velocity=\"1\" effort=\"1\"/></joint>";
  }
  text += "</robot>";
  EXPECT_IMPORT_FAILS(Write("snake.urdf", text), UrdfImportOptions{}, ErrorCode::kInvalidInput,
                      "has 12 movable joints; at most 10");
}

TEST_F(UrdfImportTest, PlanarJointIsRejected) {
  const fs::path urdf = Write("planar.urdf", std::string(R"(<robot name="p">)") + kLinkAB + R"(
    <joint name="slide" type="planar"><parent link="a"/><child link="b"/></joint></robot>)");
  EXPECT_IMPORT_FAILS(urdf, UrdfImportOptions{}, ErrorCode::kInvalidInput,
                      "joint 'slide' is planar");
}

TEST_F(UrdfImportTest, TwoLeavesNeedATip) {
  const fs::path urdf = Write("two.urdf", R"(<robot name="two">
    <link name="torso"/><link name="left_hand"/><link name="right_hand"/>
    <joint name="l" type="revolute"><parent link="torso"/><child link="left_hand"/>
      <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
    <joint name="r" type="revolute"><parent link="torso"/><child link="right_hand"/>
      <limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>)");
  EXPECT_IMPORT_FAILS(urdf, UrdfImportOptions{}, ErrorCode::kInvalidInput,
                      "[left_hand, right_hand]");
  EXPECT_IMPORT_FAILS(urdf, UrdfImportOptions{}, ErrorCode::kInvalidInput, "no tip named");
  UrdfImportOptions opt;
  opt.tip = "right_hand";
  auto chain = ImportUrdf(urdf, opt);
  ASSERT_TRUE(chain) << chain.error().message;
  EXPECT_EQ(chain->dof(), 1);
  EXPECT_EQ(chain->joints[0].name, "r");
  opt.tip = "nose";
  EXPECT_IMPORT_FAILS(urdf, opt, ErrorCode::kInvalidInput, "tip link 'nose' not found");
  opt.tip = "torso";
  EXPECT_IMPORT_FAILS(urdf, opt, ErrorCode::kInvalidInput, "no revolute");
  opt.tip = "left_hand";
  opt.root = "right_hand";
  EXPECT_IMPORT_FAILS(urdf, opt, ErrorCode::kInvalidInput, "is not below root link");
}

TEST_F(UrdfImportTest, MalformedXmlCarriesUrdfdomMessage) {
  const fs::path urdf = Write("bad.urdf", R"(<robot name="x"><link name="a"></robot>)");
  EXPECT_IMPORT_FAILS(urdf, UrdfImportOptions{}, ErrorCode::kInvalidInput, "urdfdom: ");
  EXPECT_IMPORT_FAILS(urdf, UrdfImportOptions{}, ErrorCode::kInvalidInput, "bad.urdf");
  const fs::path no_robot = Write("norobot.urdf", "<foo/>");
  EXPECT_IMPORT_FAILS(no_robot, UrdfImportOptions{}, ErrorCode::kInvalidInput, "'robot'");
}

TEST_F(UrdfImportTest, MissingFileIsIo) {
  EXPECT_IMPORT_FAILS(dir_ / "nowhere.urdf", UrdfImportOptions{}, ErrorCode::kIo, "not found");
}

TEST_F(UrdfImportTest, ClosedLoopIsRejected) {
  const fs::path urdf = Write("loop.urdf", R"(<robot name="loop">
    <link name="a"/><link name="b"/><link name="c"/>
    <joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
    <joint name="ac" type="fixed"><parent link="a"/><child link="c"/></joint>
    <joint name="bc" type="fixed"><parent link="b"/><child link="c"/></joint></robot>)");
  EXPECT_IMPORT_FAILS(urdf, UrdfImportOptions{}, ErrorCode::kInvalidInput, "closed loop");
  EXPECT_IMPORT_FAILS(urdf, UrdfImportOptions{}, ErrorCode::kInvalidInput, "link 'c'");
  // A ring with no root: urdfdom's own message.
  const fs::path ring = Write("ring.urdf", R"(<robot name="ring">
    <link name="a"/><link name="b"/>
    <joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
    <joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint></robot>)");
  EXPECT_IMPORT_FAILS(ring, UrdfImportOptions{}, ErrorCode::kInvalidInput, "root link");
}

TEST_F(UrdfImportTest, DroppedElementsAndBadGeometryAreErrors) {
  // urdfdom skips a <capsule> with a logged error; the import must not lose it silently.
  const fs::path capsule = Write("capsule.urdf", R"(<robot name="c">
    <link name="a"><collision><geometry><capsule radius="0.1" length="0.2"/></geometry>
    </collision></link><link name="b"/>
    <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
      <limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>)");
  EXPECT_IMPORT_FAILS(capsule, UrdfImportOptions{}, ErrorCode::kInvalidInput, "capsule");

  const fs::path zero = Write("zero.urdf", R"(<robot name="z">
    <link name="a"><collision><geometry><box size="0.1 0 0.1"/></geometry></collision></link>
    <link name="b"/>
    <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
      <limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>)");
  EXPECT_IMPORT_FAILS(zero, UrdfImportOptions{}, ErrorCode::kInvalidInput, "link 'a' collision 0");

  const fs::path limits = Write("limits.urdf", R"(<robot name="l"><link name="a"/><link name="b"/>
    <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
      <limit lower="1" upper="-1" velocity="1" effort="1"/></joint></robot>)");
  EXPECT_IMPORT_FAILS(limits, UrdfImportOptions{}, ErrorCode::kInvalidInput, "joint 'j'");
}

TEST_F(UrdfImportTest, MeshPathsResolveOrFailClearly) {
  auto arm = [](const std::string& uri) {
    return R"(<robot name="m"><link name="a"/><link name="b"><collision><geometry>
      <mesh filename=")" +
           uri + R"("/></geometry></collision></link>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
        <limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>)";
  };
  WriteStlBox("meshes/b.stl", Vec3(0.1, 0.1, 0.1));
  // Relative to the URDF's folder.
  auto ok = ImportUrdf(Write("rel.urdf", arm("meshes/b.stl")));
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->links[1].collision[0].mesh.triangles.size(), 12u);
  // file:// URI.
  ok = ImportUrdf(Write("abs.urdf", arm("file://" + (dir_ / "meshes/b.stl").string())));
  ASSERT_TRUE(ok) << ok.error().message;

  EXPECT_IMPORT_FAILS(Write("pkg.urdf", arm("package://nope/meshes/b2.stl")), UrdfImportOptions{},
                      ErrorCode::kInvalidInput, "package 'nope' not found");
  EXPECT_IMPORT_FAILS(Write("missing.urdf", arm("meshes/none.stl")), UrdfImportOptions{},
                      ErrorCode::kIo, "link 'b' collision 0");
  EXPECT_IMPORT_FAILS(Write("http.urdf", arm("http://example.com/b.stl")), UrdfImportOptions{},
                      ErrorCode::kInvalidInput, "only package://");
}

}  // namespace
}  // namespace wrap
