// The STEP importer's child process (geometry/detail/step_isolation.h): what the child returns
// comes back whole, and a child that crashes, exits early or throws becomes an error naming the
// file while this process lives on. With OpenCASCADE: a file that crashes OpenCASCADE 7.6
// (found by fuzz_step) is refused, and the child's import equals the in-process one.
#include "geometry/detail/step_isolation.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>

#include "geometry/step_import.h"
#include "test_build_config.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;

const fs::path kRepo = WRAP_SOURCE_DIR;

StepAssembly SmallAssembly() {
  StepAssembly a;
  a.unit = "millimetre";
  a.metres_per_unit = 1e-3;
  StepSolid s;
  s.name = "leg";
  s.product = "LEG";
  s.entity = "#12 MANIFOLD_SOLID_BREP";
  s.mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  s.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  a.solids.push_back(s);
  StepInstance i;
  i.name = "leg_2";
  i.solid = 0;
  i.X_AS.translation() = Vec3(0.1, -0.2, 0.3);
  i.color = std::array<double, 4>{0.25, 0.5, 0.75, 1.0};
  a.instances.push_back(i);
  a.warnings.push_back("product 'bolt' has no solid");
  return a;
}

std::string Message(const Result<StepAssembly>& r) { return r ? "(no error)" : r.error().message; }

TEST(StepIsolation, TheChildsAssemblyComesBackWhole) {
  std::mutex held;
  auto r = detail::ImportInChild(
      "a.step", [] { return Result<StepAssembly>(SmallAssembly()); }, held);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  const StepAssembly want = SmallAssembly();
  EXPECT_EQ(r->unit, want.unit);
  ASSERT_EQ(r->solids.size(), 1u);
  EXPECT_EQ(r->solids[0].name, "leg");
  EXPECT_EQ(r->solids[0].entity, want.solids[0].entity);
  EXPECT_EQ(r->solids[0].mesh.vertices, want.solids[0].mesh.vertices);
  EXPECT_EQ(r->solids[0].mesh.triangles, want.solids[0].mesh.triangles);
  ASSERT_EQ(r->instances.size(), 1u);
  EXPECT_EQ(r->instances[0].name, "leg_2");
  EXPECT_TRUE(r->instances[0].X_AS.isApprox(want.instances[0].X_AS, 0.0));
  EXPECT_EQ(r->instances[0].color, want.instances[0].color);
  EXPECT_EQ(r->warnings, want.warnings);
  // The lock taken around the fork is free again here.
  EXPECT_TRUE(held.try_lock());
  held.unlock();
}

TEST(StepIsolation, TheChildsErrorComesBackAsItWas) {
  std::mutex held;
  auto r = detail::ImportInChild(
      "b.step",
      [] { return Result<StepAssembly>(Fail(ErrorCode::kIo, "cannot read 'b.step': no such")); },
      held);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kIo);
  EXPECT_EQ(r.error().message, "cannot read 'b.step': no such");
}

TEST(StepIsolation, TheChildInheritsTheLockHeldAroundTheFork) {
  std::mutex held;
  auto r = detail::ImportInChild(
      "c.step",
      [&held] {
        return Result<StepAssembly>(Fail(ErrorCode::kInternal, held.try_lock() ? "free" : "held"));
      },
      held);
  EXPECT_EQ(Message(r), "held");
}

TEST(StepIsolation, AChildThatAbortsBecomesAnErrorNamingTheFile) {
  std::mutex held;
  auto r = detail::ImportInChild(
      "damaged.step", []() -> Result<StepAssembly> { std::abort(); }, held);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(r.error().message.rfind("cannot read STEP file 'damaged.step': OpenCASCADE crashed on "
                                    "it (SIGABRT",
                                    0),
            0u)
      << r.error().message;
  EXPECT_NE(r.error().message.find("export it again"), std::string::npos) << r.error().message;
}

TEST(StepIsolation, AChildThatExitsBeforeAnsweringBecomesAnError) {
  std::mutex held;
  auto r = detail::ImportInChild(
      "e.step", []() -> Result<StepAssembly> { std::_Exit(7); }, held);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(r.error().message.find("crashed on it (exit status 7)"), std::string::npos)
      << r.error().message;
}

TEST(StepIsolation, AnExceptionInTheChildBecomesAnError) {
  std::mutex held;
  auto r = detail::ImportInChild(
      "f.step", []() -> Result<StepAssembly> { throw std::runtime_error("bad alloc of sorts"); },
      held);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(r.error().message,
            "cannot read STEP file 'f.step': the importer failed (bad alloc of sorts)");
}

#if WRAP_TEST_WITH_OCCT
// OpenCASCADE 7.6.3 dereferences a face bound whose bound is not a loop
// (StepShape_FaceBound::Bound during the transfer); found by fuzz_step.
TEST(StepIsolation, AFileThatCrashesOpenCascadeIsRefusedAndWeLiveOn) {
  const fs::path file =
      kRepo / "tests/fuzz/regressions/step_crashes_occt/face_bound_of_wrong_type.step";
  auto r = ImportStep(file);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(r.error().message.find("'" + file.string() + "'"), std::string::npos)
      << r.error().message;
  EXPECT_NE(r.error().message.find("OpenCASCADE crashed on it"), std::string::npos)
      << r.error().message;
}

TEST(StepIsolation, TheChildsImportEqualsTheInProcessOne) {
  const fs::path file = kRepo / "assets/parts/step/stool.step";
  ASSERT_TRUE(fs::exists(file)) << file;
  auto child = ImportStep(file);
  auto here = ImportStepInProcess(file);
  ASSERT_TRUE(child.has_value()) << child.error().message;
  ASSERT_TRUE(here.has_value()) << here.error().message;
  ASSERT_EQ(child->solids.size(), here->solids.size());
  for (size_t k = 0; k < here->solids.size(); ++k) {
    EXPECT_EQ(child->solids[k].name, here->solids[k].name);
    EXPECT_EQ(child->solids[k].mesh.vertices, here->solids[k].mesh.vertices);
    EXPECT_EQ(child->solids[k].mesh.triangles, here->solids[k].mesh.triangles);
  }
  ASSERT_EQ(child->instances.size(), here->instances.size());
  for (size_t k = 0; k < here->instances.size(); ++k) {
    EXPECT_EQ(child->instances[k].name, here->instances[k].name);
    EXPECT_TRUE(child->instances[k].X_AS.isApprox(here->instances[k].X_AS, 0.0));
    EXPECT_EQ(child->instances[k].color, here->instances[k].color);
  }
  EXPECT_EQ(child->unit, here->unit);
  EXPECT_EQ(child->warnings, here->warnings);
}
#endif  // WRAP_TEST_WITH_OCCT

}  // namespace
}  // namespace wrap
