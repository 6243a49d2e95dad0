// Projects whose part meshes are STEP files: validation reads them (a solid per part, the whole
// file without one) through the tessellation cache beside the project; bad STEP files and
// fields are reported with the field's path; PartsFromStep builds a project's parts from an
// assembly. The STEP files are written in the test by the team's generator (OpenCASCADE).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/file_io.h"
#include "generator/step_designs.h"
#include "geometry/step_cache.h"
#include "model/project_io.h"
#include "model/step_parts.h"
#include "model/validate.h"
#include "test_build_config.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

class StepProjectTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) /
           ("wrap_step_project_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ClearStepMemoryCache();
#if WRAP_TEST_WITH_OCCT
    auto ok = WriteStep(partgen::StepStoolSpec(), dir_ / "stool.step");
    ASSERT_TRUE(ok.has_value()) << ok.error().message;
#endif  // WRAP_TEST_WITH_OCCT
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// The stool_step example with its mesh paths pointing at the test's STEP file.
  Project StoolProject() {
    ProjectParse parse =
        ReadProjectFile(fs::path(WRAP_SOURCE_DIR) / "projects" / "stool_step.json");
    EXPECT_TRUE(parse.project.has_value());
    Project p = *parse.project;
    for (Part& part : p.parts) part.mesh = "stool.step";
    return p;
  }
  fs::path File() const { return dir_ / "project.json"; }

  static bool HasDiagnostic(const ProjectCheck& check, const std::string& path,
                            const std::string& phrase, Severity severity = Severity::kError) {
    for (const Diagnostic& d : check.diagnostics.items) {
      if (d.severity == severity && d.path == path && d.message.find(phrase) != std::string::npos) {
        return true;
      }
    }
    return false;
  }
  static std::string All(const ProjectCheck& check) {
    std::string s;
    for (const Diagnostic& d : check.diagnostics.items) s += Format(d) + "\n";
    return s;
  }

  fs::path dir_;
};

// The tests that read the STEP file SetUp writes: a build with OpenCASCADE only (WRAP_WITH_OCCT).
#if WRAP_TEST_WITH_OCCT
TEST_F(StepProjectTest, PartsPickTheirSolidsAndValidate) {
  const Project p = StoolProject();
  const ProjectCheck check = ValidateProject(p, File());
  EXPECT_FALSE(check.diagnostics.has_errors()) << All(check);
  ASSERT_EQ(check.parts.size(), 5u);
  const partgen::StepStoolDesign d;
  for (size_t i = 0; i < 5; ++i) {
    const PartGeometry& g = check.parts[i];
    ASSERT_TRUE(g.loaded) << i;
    EXPECT_TRUE(g.topology.closed());
    EXPECT_GT(g.mass_kg, 0.0);
  }
  // The legs share one mesh: the same vertices for all four.
  EXPECT_EQ(check.parts[1].mesh.vertices, check.parts[4].mesh.vertices);
  const double leg_volume = std::numbers::pi * (d.leg_radius * d.leg_radius * d.leg_length +
                                                d.peg_radius * d.peg_radius * d.peg_length);
  EXPECT_NEAR(check.parts[1].mass_properties.volume_m3, leg_volume, 0.005 * leg_volume);
  EXPECT_NEAR(check.parts[1].aabb.max.z(), d.leg_length + d.peg_length, 1e-6);
  // Tessellations are cached beside the project.
  const fs::path cache = StepCacheDirFor(File());
  ASSERT_TRUE(fs::is_directory(cache));
  EXPECT_EQ(std::distance(fs::directory_iterator(cache), fs::directory_iterator()), 1);
}

TEST_F(StepProjectTest, AReopenReadsTheCacheInsteadOfTessellating) {
  const Project p = StoolProject();
  const ProjectCheck first = ValidateProject(p, File());
  ASSERT_FALSE(first.diagnostics.has_errors()) << All(first);
  ClearStepMemoryCache();  // as a new process would start
  auto load = LoadStep(dir_ / "stool.step",
                       {.tessellation = p.tessellation, .cache_dir = StepCacheDirFor(File())});
  ASSERT_TRUE(load.has_value());
  EXPECT_EQ(load->source, StepSource::kDiskCache);
  const ProjectCheck again = ValidateProject(p, File());
  EXPECT_EQ(again.parts[0].mesh.vertices, first.parts[0].mesh.vertices);
}

TEST_F(StepProjectTest, WholeFileWithoutSolid) {
  Project p = StoolProject();
  p.parts.resize(1);
  p.steps.clear();
  p.parts[0].solid.clear();  // the whole stool as one part
  const ProjectCheck check = ValidateProject(p, File());
  ASSERT_TRUE(check.parts[0].loaded) << All(check);
  const partgen::StepStoolDesign d;
  EXPECT_NEAR(check.parts[0].aabb.max.z(), d.leg_length + d.seat_thickness, 1e-6);
  EXPECT_NEAR(check.parts[0].aabb.size().x(), d.seat_side, 1e-6);
}

TEST_F(StepProjectTest, BadFieldsAreNamedByPath) {
  Project p = StoolProject();
  p.parts[1].solid = "stool_leg";
  p.parts[2].scale = 0.001;
  p.parts[3].mesh = (fs::path(WRAP_SOURCE_DIR) / "assets/parts/stool/leg.stl").string();
  p.parts[3].solid = "leg";
  const ProjectCheck check = ValidateProject(p, File());
  EXPECT_TRUE(HasDiagnostic(check, "parts[1].mesh", "no solid or part 'stool_leg'")) << All(check);
  EXPECT_TRUE(HasDiagnostic(check, "parts[1].mesh", "'seat', 'leg'")) << All(check);
  EXPECT_TRUE(
      HasDiagnostic(check, "parts[2].scale", "STEP files come in metres", Severity::kWarning))
      << All(check);
  EXPECT_TRUE(HasDiagnostic(check, "parts[3].solid", "is not one")) << All(check);

  Project q = StoolProject();
  q.tessellation.linear_deflection_m = 0.0;
  const ProjectCheck bad = ValidateProject(q, File());
  EXPECT_TRUE(HasDiagnostic(bad, "tessellation.linear_deflection_m", "between")) << All(bad);
}

TEST_F(StepProjectTest, DamagedStepFileIsAnErrorNamingFileAndField) {
  auto text = ReadFile(dir_ / "stool.step");
  ASSERT_TRUE(text.has_value());
  ASSERT_TRUE(WriteFileAtomic(dir_ / "stool.step", text->substr(0, text->size() / 3)).has_value());
  const ProjectCheck check = ValidateProject(StoolProject(), File());
  EXPECT_TRUE(HasDiagnostic(check, "parts[0].mesh", "truncated")) << All(check);
  EXPECT_TRUE(HasDiagnostic(check, "parts[0].mesh", (dir_ / "stool.step").string())) << All(check);
}
#endif  // WRAP_TEST_WITH_OCCT

TEST_F(StepProjectTest, TessellationFieldRoundTrips) {
  Project p = StoolProject();
  p.tessellation = {.linear_deflection_m = 2e-4, .angular_deflection_rad = 0.3};
  const std::string text = SerializeProject(p);
  EXPECT_NE(text.find("\"tessellation\""), std::string::npos);
  EXPECT_NE(text.find("\"solid\": \"leg\""), std::string::npos);
  const ProjectParse again = ParseProject(text, "again.json");
  ASSERT_TRUE(again.project.has_value());
  EXPECT_EQ(again.project->parts[1].solid, "leg");
  EXPECT_DOUBLE_EQ(again.project->tessellation.linear_deflection_m, 2e-4);
  EXPECT_NEAR(again.project->tessellation.angular_deflection_rad, 0.3, 1e-12);
  // The default is not written.
  EXPECT_EQ(SerializeProject(StoolProject()).find("tessellation"), std::string::npos);
}

#if WRAP_TEST_WITH_OCCT
TEST_F(StepProjectTest, PartsFromStepRestOnTheTableWithFileNamesPosesAndColours) {
  auto assembly = ImportStep(dir_ / "stool.step");
  ASSERT_TRUE(assembly.has_value()) << assembly.error().message;
  Project p = StoolProject();
  p.parts.clear();
  p.steps.clear();
  p.parts.push_back(StoolProject().parts[0]);  // "seat" is taken: the new one is "seat_2"
  const std::vector<Part> parts = PartsFromStep(*assembly, p, {.mesh = "stool.step"});
  ASSERT_EQ(parts.size(), 5u);
  EXPECT_EQ(parts[0].name, "seat_2");
  EXPECT_EQ(parts[0].solid, "seat");
  for (int i = 1; i <= 4; ++i) {
    EXPECT_EQ(parts[static_cast<size_t>(i)].name, "leg_" + std::to_string(i));
    EXPECT_EQ(parts[static_cast<size_t>(i)].solid, "leg");
    EXPECT_EQ(parts[static_cast<size_t>(i)].mesh, "stool.step");
  }
  const partgen::StepStoolDesign d;
  EXPECT_LT((parts[0].assembled_pose.xyz - Vec3(0, 0, d.leg_length)).norm(), 1e-9);
  EXPECT_LT((parts[3].assembled_pose.xyz - Vec3(-d.leg_offset, -d.leg_offset, 0)).norm(), 1e-9);
  EXPECT_NEAR(parts[0].color[0], 0.949, 1e-6);
  EXPECT_NEAR(parts[1].color[2], 0.655, 1e-6);
  // Every part rests on the table, within it, without overlapping another.
  p.parts.erase(p.parts.begin());
  p.parts.insert(p.parts.end(), parts.begin(), parts.end());
  const ProjectCheck check = ValidateProject(p, File());
  std::vector<Aabb> boxes;
  for (size_t i = 0; i < check.parts.size(); ++i) {
    ASSERT_TRUE(check.parts[i].loaded) << All(check);
    Aabb box{Vec3::Constant(1e9), Vec3::Constant(-1e9)};
    const Iso3 X = ToIsometry(p.parts[i].initial_pose);
    for (const Vec3& v : check.parts[i].mesh.vertices) {
      box.min = box.min.cwiseMin(X * v);
      box.max = box.max.cwiseMax(X * v);
    }
    EXPECT_NEAR(box.min.z(), p.table.height, 1e-6) << p.parts[i].name;
    EXPECT_GE(box.min.x(), -p.table.size.x() / 2) << p.parts[i].name;
    EXPECT_LE(box.max.y(), p.table.size.y() / 2) << p.parts[i].name;
    for (const Robot& r : p.robots) {  // clear of the robots' bases
      const Vec3 base = RobotBaseInWorld(p, r).translation();
      const Vec3 nearest = base.cwiseMax(box.min).cwiseMin(box.max);
      EXPECT_GT((nearest - base).head<2>().norm(), 0.1) << p.parts[i].name << " on " << r.name;
    }
    for (const Aabb& other : boxes) {
      const bool apart = (box.min.head<2>().array() >= other.max.head<2>().array()).any() ||
                         (other.min.head<2>().array() >= box.max.head<2>().array()).any();
      EXPECT_TRUE(apart) << p.parts[i].name << " overlaps another part";
    }
    boxes.push_back(box);
  }
  for (const Diagnostic& d2 : check.diagnostics.items) {
    EXPECT_EQ(d2.path.find("initial_pose"), std::string::npos) << Format(d2);
  }
}
#endif  // WRAP_TEST_WITH_OCCT

}  // namespace
}  // namespace wrap
