// The GUI's Import of STEP files: a whole assembly becomes its parts in one undoable edit, a
// single solid one part; the scripted `import` takes STEP too. The STEP files are written in the
// test by the team's generator (OpenCASCADE): a build without it (WRAP_WITH_OCCT) has none of
// these tests.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "generator/step_designs.h"
#include "geometry/step_cache.h"
#include "gui/commands.h"
#include "gui/document.h"
#include "model/validate.h"
#include "test_build_config.h"

#if WRAP_TEST_WITH_OCCT
namespace wrap::gui {
namespace {

namespace fs = std::filesystem;

class StepImportGui : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) /
           ("wrap_gui_step_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "cad");
    ClearStepMemoryCache();
    auto ok = WriteStep(partgen::StepStoolSpec(), dir_ / "cad" / "stool.step");
    ASSERT_TRUE(ok.has_value()) << ok.error().message;
    StepDocumentSpec block;
    block.products.push_back({"block",
                              {{{.kind = StepPrimitive::Kind::kBox,
                                 .origin = Vec3::Zero(),
                                 .size = Vec3(0.05, 0.04, 0.03)}}},
                              std::array<double, 4>{0.1, 0.2, 0.3, 1.0}});
    ok = WriteStep(block, dir_ / "cad" / "block.stp");
    ASSERT_TRUE(ok.has_value()) << ok.error().message;
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
};

TEST_F(StepImportGui, AssemblyIsOneUndoableEdit) {
  Document doc(Project{}, dir_ / "project.json");
  auto parts = PrepareStepImport(doc.project(), doc.ResolvePath(), dir_ / "cad" / "stool.step");
  ASSERT_TRUE(parts.has_value()) << parts.error().message;
  ASSERT_EQ(parts->size(), 5u);
  EXPECT_EQ((*parts)[0].name, "seat");
  EXPECT_EQ((*parts)[0].mesh, "cad/stool.step") << "relative to the project";
  EXPECT_EQ((*parts)[4].solid, "leg");
  ASSERT_TRUE(doc.Execute(AddParts(*parts)));
  EXPECT_EQ(doc.project().parts.size(), 5u);
  ASSERT_TRUE(doc.Undo());
  EXPECT_TRUE(doc.project().parts.empty()) << "one undo removes the whole assembly";
  ASSERT_TRUE(doc.Redo());
  EXPECT_EQ(doc.project().parts.size(), 5u);
  // The parts load and rest on the table.
  const ProjectCheck check = ValidateProject(doc.project(), doc.ResolvePath());
  for (const Diagnostic& d : check.diagnostics.items) {
    if (d.path.starts_with("parts")) {
      EXPECT_NE(d.severity, Severity::kError) << Format(d);
      EXPECT_EQ(d.path.find("initial_pose"), std::string::npos) << Format(d);
    }
  }
  // A second import of the same assembly gets unique names.
  auto again = PrepareStepImport(doc.project(), doc.ResolvePath(), dir_ / "cad" / "stool.step");
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ((*again)[0].name, "seat_2");
  // AddParts refuses all of them when one name is taken.
  std::vector<Part> clash = *again;
  clash[2].name = "seat";
  const Project before = doc.project();
  EXPECT_FALSE(doc.Execute(AddParts(clash)));
  EXPECT_EQ(doc.project(), before);
}

TEST_F(StepImportGui, SingleSolidIsOnePart) {
  Document doc(Project{}, dir_ / "project.json");
  auto parts = PrepareStepImport(doc.project(), doc.ResolvePath(), dir_ / "cad" / "block.stp");
  ASSERT_TRUE(parts.has_value()) << parts.error().message;
  ASSERT_EQ(parts->size(), 1u);
  EXPECT_EQ((*parts)[0].name, "block");
  EXPECT_TRUE((*parts)[0].solid.empty()) << "the whole file";
  EXPECT_NEAR((*parts)[0].color[2], 0.3, 1e-6);
  EXPECT_NEAR((*parts)[0].initial_pose.xyz.z(), doc.project().table.height, 1e-9);
}

TEST_F(StepImportGui, BadFileFailsNamingIt) {
  Document doc(Project{}, dir_ / "project.json");
  const fs::path bad = dir_ / "cad" / "bad.step";
  { std::ofstream(bad) << "ISO-10303-21;\nHEADER;\n"; }
  auto parts = PrepareStepImport(doc.project(), doc.ResolvePath(), bad);
  ASSERT_FALSE(parts.has_value());
  EXPECT_NE(parts.error().message.find(bad.string()), std::string::npos) << parts.error().message;
  EXPECT_NE(parts.error().message.find("truncated"), std::string::npos) << parts.error().message;
}

// A file that crashes OpenCASCADE 7.6 (found by fuzz_step): the import fails naming it, the
// document and this process live on.
TEST_F(StepImportGui, FileThatCrashesOpenCascadeFailsAndTheDocumentLivesOn) {
  Document doc(Project{}, dir_ / "project.json");
  auto first = PrepareStepImport(doc.project(), doc.ResolvePath(), dir_ / "cad" / "block.stp");
  ASSERT_TRUE(first.has_value()) << first.error().message;
  ASSERT_TRUE(doc.Execute(AddParts(*first)));
  const Project before = doc.project();
  const fs::path crash = fs::path(WRAP_SOURCE_DIR) /
                         "tests/fuzz/regressions/step_crashes_occt/face_bound_of_wrong_type.step";
  auto parts = PrepareStepImport(doc.project(), doc.ResolvePath(), crash);
  ASSERT_FALSE(parts.has_value());
  EXPECT_NE(parts.error().message.find(crash.string()), std::string::npos)
      << parts.error().message;
  EXPECT_NE(parts.error().message.find("OpenCASCADE crashed on it"), std::string::npos)
      << parts.error().message;
  EXPECT_EQ(doc.project(), before);
  // The importer still works afterwards.
  auto again = PrepareStepImport(doc.project(), doc.ResolvePath(), dir_ / "cad" / "stool.step");
  EXPECT_TRUE(again.has_value());
}

}  // namespace
}  // namespace wrap::gui
#endif  // WRAP_TEST_WITH_OCCT
