// Tests of STEP import: files built in the test with OpenCASCADE itself (WriteStep: boxes, a
// cylinder, a sphere, a peg-and-hole assembly with four instances of one leg, millimetres and
// inches), imported back and checked for names, counts, poses, volumes, colours and closedness;
// bad files; the tessellation cache; LoadMeshFile. Those exist only in a build with OpenCASCADE
// (WRAP_WITH_OCCT); a build without it has StepUnavailableWithoutOpenCascade instead.
#include "geometry/step_import.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "core/file_io.h"
#include "geometry/mesh_file.h"
#include "geometry/step_cache.h"
#include "test_build_config.h"

namespace wrap {
namespace {

namespace fs = std::filesystem;
using Kind = StepPrimitive::Kind;

class StepImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("wrap_step_" + std::to_string(::getpid()) + "_" +
                                             info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ClearStepMemoryCache();
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path WriteSpec(const StepDocumentSpec& spec, const std::string& name) {
    const fs::path path = dir_ / name;
    auto ok = WriteStep(spec, path);
    EXPECT_TRUE(ok.has_value()) << ok.error().message;
    return path;
  }
  fs::path WriteText(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    EXPECT_TRUE(WriteFileAtomic(path, text).has_value());
    return path;
  }
  std::string Text(const fs::path& path) {
    auto text = ReadFile(path);
    EXPECT_TRUE(text.has_value());
    return text.value_or("");
  }

  fs::path dir_;
};

void ExpectError(const Result<StepAssembly>& a, ErrorCode code, const fs::path& file,
                 const std::vector<std::string>& phrases) {
  ASSERT_FALSE(a.has_value()) << "expected an error for " << file;
  EXPECT_EQ(a.error().code, code) << a.error().message;
  EXPECT_NE(a.error().message.find(file.string()), std::string::npos) << a.error().message;
  for (const std::string& p : phrases) {
    EXPECT_NE(a.error().message.find(p), std::string::npos)
        << "'" << p << "' in " << a.error().message;
  }
}

// Files written by OpenCASCADE and imported back: a build with it only (WRAP_WITH_OCCT).
#if WRAP_TEST_WITH_OCCT
constexpr double kPoseTol = 1e-6;     // [m]
constexpr double kVolumeRel = 0.005;  // 0.5%

StepPrimitive Box(const Vec3& lo, const Vec3& size) {
  return {.kind = Kind::kBox, .origin = lo, .size = size};
}
StepPrimitive Cylinder(const Vec3& base, double r, double h, bool subtract = false) {
  return {.kind = Kind::kCylinder, .subtract = subtract, .origin = base, .radius = r, .height = h};
}

StepDocumentSpec OneProduct(const std::string& name, std::vector<StepPrimitive> solid,
                            const std::string& unit = "MM") {
  StepDocumentSpec spec;
  spec.unit = unit;
  spec.products.push_back({name, {std::move(solid)}, std::nullopt});
  return spec;
}

double Volume(const TriangleMesh& mesh) { return ComputeMassProperties(mesh).volume_m3; }

// The peg-and-hole assembly: a plate with four round blind pockets from below and four
// instances of one leg (a body with a peg on top), the plate coloured, rotated legs included.
struct PegAndHole {
  double side = 0.2, thickness = 0.02, offset = 0.07, pocket_r = 0.01, pocket_depth = 0.012;
  double leg_r = 0.0125, leg_h = 0.15, peg_r = 0.0095, peg_h = 0.011;

  StepDocumentSpec Spec(const std::string& unit) const {
    StepDocumentSpec spec;
    spec.name = "peg_and_hole";
    spec.unit = unit;
    std::vector<StepPrimitive> plate = {
        Box(Vec3(-side / 2, -side / 2, 0), Vec3(side, side, thickness))};
    for (const Vec3& c : Corners()) {
      plate.push_back(Cylinder(Vec3(c.x(), c.y(), -0.001), pocket_r, pocket_depth + 0.001, true));
    }
    spec.products.push_back({"plate", {plate}, std::array<double, 4>{0.9, 0.5, 0.1, 1.0}});
    spec.products.push_back({"leg",
                             {{Cylinder(Vec3::Zero(), leg_r, leg_h),
                               Cylinder(Vec3(0, 0, leg_h - 0.001), peg_r, peg_h + 0.001)}},
                             std::array<double, 4>{0.2, 0.4, 0.6, 1.0}});
    spec.instances.push_back({"top", 0, PlatePose()});
    for (int i = 0; i < 4; ++i) spec.instances.push_back({LegName(i), 1, LegPose(i)});
    return spec;
  }
  std::vector<Vec3> Corners() const {
    return {{offset, offset, 0}, {-offset, offset, 0}, {-offset, -offset, 0}, {offset, -offset, 0}};
  }
  static std::string LegName(int i) { return "leg_" + std::to_string(i + 1); }
  Iso3 PlatePose() const {
    Iso3 X = Iso3::Identity();
    X.translation() = Vec3(0, 0, leg_h);
    return X;
  }
  Iso3 LegPose(int i) const {  // each leg turned about its axis by a different angle
    Iso3 X = Iso3::Identity();
    X.linear() = Eigen::AngleAxisd(0.4 * i, Vec3::UnitZ()).toRotationMatrix();
    X.translation() = Corners()[static_cast<size_t>(i)];
    return X;
  }
  double PlateVolume() const {
    return side * side * thickness - 4 * std::numbers::pi * pocket_r * pocket_r * pocket_depth;
  }
  double LegVolume() const {
    return std::numbers::pi * (leg_r * leg_r * leg_h + peg_r * peg_r * peg_h);
  }
};

void ExpectPegAndHole(const StepAssembly& a, const PegAndHole& d) {
  ASSERT_EQ(a.solids.size(), 2u);
  ASSERT_EQ(a.instances.size(), 5u);
  EXPECT_EQ(a.solids[0].name, "plate");
  EXPECT_EQ(a.solids[1].name, "leg");
  EXPECT_EQ(a.instances[0].name, "top");
  EXPECT_EQ(a.instances[0].solid, 0);
  EXPECT_TRUE(a.instances[0].X_AS.isApprox(d.PlatePose(), kPoseTol));
  for (int i = 0; i < 4; ++i) {
    const StepInstance& leg = a.instances[static_cast<size_t>(i) + 1];
    EXPECT_EQ(leg.name, PegAndHole::LegName(i));
    EXPECT_EQ(leg.solid, 1) << "the four legs share one mesh";
    EXPECT_LE((leg.X_AS.translation() - d.LegPose(i).translation()).norm(), kPoseTol);
    EXPECT_LE((leg.X_AS.linear() - d.LegPose(i).linear()).norm(), 1e-9);
    ASSERT_TRUE(leg.color.has_value());
    EXPECT_NEAR((*leg.color)[2], 0.6, 1e-6);
  }
  ASSERT_TRUE(a.instances[0].color.has_value());
  EXPECT_NEAR((*a.instances[0].color)[0], 0.9, 1e-6);
  EXPECT_NEAR(Volume(a.solids[0].mesh), d.PlateVolume(), kVolumeRel * d.PlateVolume());
  EXPECT_NEAR(Volume(a.solids[1].mesh), d.LegVolume(), kVolumeRel * d.LegVolume());
  for (const StepSolid& s : a.solids) {
    EXPECT_TRUE(AnalyzeTopology(s.mesh).closed()) << s.name;
    EXPECT_NE(s.entity.find('#'), std::string::npos) << s.name << ": " << s.entity;
  }
  // The leg's frame is at its foot, the plate's at its underside, both as designed.
  const Aabb leg = ComputeAabb(a.solids[1].mesh);
  EXPECT_NEAR(leg.min.z(), 0.0, kPoseTol);
  EXPECT_NEAR(leg.max.z(), d.leg_h + d.peg_h, kPoseTol);
  const Aabb plate = ComputeAabb(a.solids[0].mesh);
  EXPECT_NEAR(plate.min.x(), -d.side / 2, kPoseTol);
  EXPECT_NEAR(plate.max.z(), d.thickness, kPoseTol);
}

TEST_F(StepImportTest, BoxInMillimetres) {
  StepDocumentSpec spec =
      OneProduct("block", {Box(Vec3(-0.02, -0.015, 0), Vec3(0.04, 0.03, 0.02))});
  spec.products[0].color = std::array<double, 4>{0.25, 0.5, 0.75, 1.0};
  const fs::path file = WriteSpec(spec, "block.step");
  ASSERT_NE(Text(file).find("SI_UNIT(.MILLI.,.METRE.)"), std::string::npos);
  auto a = ImportStep(file);
  ASSERT_TRUE(a.has_value()) << a.error().message;
  EXPECT_EQ(a->unit, "millimetre");
  ASSERT_EQ(a->solids.size(), 1u);
  ASSERT_EQ(a->instances.size(), 1u);
  EXPECT_EQ(a->solids[0].name, "block");
  EXPECT_EQ(a->instances[0].name, "block");
  EXPECT_TRUE(a->instances[0].X_AS.isApprox(Iso3::Identity()));
  const TriangleMesh& mesh = a->solids[0].mesh;
  EXPECT_EQ(mesh.vertices.size(), 8u);
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_TRUE(AnalyzeTopology(mesh).closed());
  EXPECT_NEAR(Volume(mesh), 0.04 * 0.03 * 0.02, 1e-12);
  const Aabb box = ComputeAabb(mesh);
  EXPECT_LE((box.min - Vec3(-0.02, -0.015, 0)).norm(), 1e-9);
  EXPECT_LE((box.max - Vec3(0.02, 0.015, 0.02)).norm(), 1e-9);
  ASSERT_TRUE(a->instances[0].color.has_value());
  EXPECT_NEAR((*a->instances[0].color)[1], 0.5, 1e-6);
}

TEST_F(StepImportTest, CylinderVolumeAndDeflection) {
  const double r = 0.025, h = 0.05;  // a 5 cm part
  const fs::path file = WriteSpec(OneProduct("can", {Cylinder(Vec3::Zero(), r, h)}), "can.stp");
  auto a = ImportStep(file);
  ASSERT_TRUE(a.has_value()) << a.error().message;
  const TriangleMesh& mesh = a->solids[0].mesh;
  EXPECT_TRUE(AnalyzeTopology(mesh).closed());
  EXPECT_NEAR(Volume(mesh), std::numbers::pi * r * r * h,
              kVolumeRel * std::numbers::pi * r * r * h);
  EXPECT_LT(mesh.triangles.size(), 20000u);
  // Every vertex on the surface; every triangle centre within 0.1 mm of it.
  for (const Vec3& v : mesh.vertices) {
    const double radial = std::hypot(v.x(), v.y());
    EXPECT_TRUE(std::abs(radial - r) < 1e-6 || std::abs(v.z()) < 1e-9 ||
                std::abs(v.z() - h) < 1e-9);
  }
  double worst = 0.0;
  for (const auto& t : mesh.triangles) {
    const Vec3 c = (mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3.0;
    const bool cap = std::abs(c.z()) < 1e-9 || std::abs(c.z() - h) < 1e-9;
    if (!cap) worst = std::max(worst, r - std::hypot(c.x(), c.y()));
  }
  EXPECT_LT(worst, 1e-4);
}

TEST_F(StepImportTest, SphereOfFiveCentimetresStaysWithinATenthOfAMillimetre) {
  const double r = 0.025;
  const fs::path file =
      WriteSpec(OneProduct("ball", {{.kind = Kind::kSphere, .origin = Vec3(0, 0, r), .radius = r}}),
                "ball.step");
  auto a = ImportStep(file);
  ASSERT_TRUE(a.has_value()) << a.error().message;
  const TriangleMesh& mesh = a->solids[0].mesh;
  EXPECT_TRUE(AnalyzeTopology(mesh).closed());
  EXPECT_LT(mesh.triangles.size(), 20000u);
  double worst = 0.0;
  for (const auto& t : mesh.triangles) {
    const Vec3 c = (mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3.0;
    worst = std::max(worst, r - (c - Vec3(0, 0, r)).norm());
  }
  EXPECT_LT(worst, 1e-4);
  const double volume = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  EXPECT_NEAR(Volume(mesh), volume, kVolumeRel * volume);
  // A coarser tessellation gives fewer triangles.
  auto coarse = ImportStep(file, {.linear_deflection_m = 1e-3, .angular_deflection_rad = 0.5});
  ASSERT_TRUE(coarse.has_value()) << coarse.error().message;
  EXPECT_LT(coarse->triangles(), a->triangles() / 4);
}

TEST_F(StepImportTest, PegAndHoleAssemblyInMillimetres) {
  const PegAndHole design;
  const fs::path file = WriteSpec(design.Spec("MM"), "peg_and_hole.step");
  auto a = ImportStep(file);
  ASSERT_TRUE(a.has_value()) << a.error().message;
  ExpectPegAndHole(*a, design);
  // The whole file in one mesh: every instance in place.
  const TriangleMesh merged = MergedInstances(*a);
  const double total = design.PlateVolume() + 4 * design.LegVolume();
  EXPECT_NEAR(Volume(merged), total, kVolumeRel * total);
  EXPECT_NEAR(ComputeAabb(merged).max.z(), design.leg_h + design.thickness, kPoseTol);
}

TEST_F(StepImportTest, PegAndHoleAssemblyInInchesComesInMetres) {
  const PegAndHole design;
  const fs::path inches = WriteSpec(design.Spec("INCH"), "peg_and_hole_in.step");
  const std::string text = Text(inches);
  ASSERT_NE(text.find("CONVERSION_BASED_UNIT('INCH'"), std::string::npos);
  auto a = ImportStep(inches);
  ASSERT_TRUE(a.has_value()) << a.error().message;
  EXPECT_EQ(a->unit, "INCH");
  ExpectPegAndHole(*a, design);
  // The numbers in the file are inches: the plate's 0.2 m side is 7.874 in.
  EXPECT_NE(text.find("7.87"), std::string::npos);
}

TEST_F(StepImportTest, MultiSolidProductGivesOneSolidEach) {
  StepDocumentSpec spec;
  spec.products.push_back({"pair",
                           {{Box(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01))},
                            {Box(Vec3(0.03, 0, 0), Vec3(0.02, 0.01, 0.01))}},
                           std::nullopt});
  const fs::path file = WriteSpec(spec, "pair.step");
  auto a = ImportStep(file);
  ASSERT_TRUE(a.has_value()) << a.error().message;
  ASSERT_EQ(a->solids.size(), 2u);
  ASSERT_EQ(a->instances.size(), 2u);
  EXPECT_EQ(a->solids[0].name, "pair.1");
  EXPECT_EQ(a->solids[1].name, "pair.2");
  auto second = FindStepSolid(*a, "pair.2", file.string());
  ASSERT_TRUE(second.has_value()) << second.error().message;
  EXPECT_NEAR(Volume(*second), 2e-6, 1e-12);
  auto missing = FindStepSolid(*a, "pair.3", file.string());
  ASSERT_FALSE(missing.has_value());
  EXPECT_NE(missing.error().message.find("'pair.1', 'pair.2'"), std::string::npos)
      << missing.error().message;
}

TEST_F(StepImportTest, DeterministicAcrossImports) {
  const fs::path file = WriteSpec(PegAndHole().Spec("MM"), "peg_and_hole.step");
  auto a = ImportStep(file);
  auto b = ImportStep(file);
  ASSERT_TRUE(a && b);
  for (size_t s = 0; s < a->solids.size(); ++s) {
    EXPECT_EQ(a->solids[s].mesh.vertices, b->solids[s].mesh.vertices);
    EXPECT_EQ(a->solids[s].mesh.triangles, b->solids[s].mesh.triangles);
  }
  // The writer too: the same spec, the same bytes (without colours: OpenCASCADE writes those in
  // an order of its own, which may change from run to run).
  StepDocumentSpec plain = PegAndHole().Spec("MM");
  for (StepProductSpec& p : plain.products) p.color.reset();
  const fs::path one = WriteSpec(plain, "one.step");
  const fs::path two = WriteSpec(plain, "two.step");
  EXPECT_EQ(Text(one), Text(two));
}

TEST_F(StepImportTest, ConcurrentImportsAgree) {
  const fs::path file = WriteSpec(PegAndHole().Spec("MM"), "peg_and_hole.step");
  std::vector<Result<StepAssembly>> results(3, Fail(ErrorCode::kInternal, "not run"));
  std::vector<std::thread> threads;
  for (auto& r : results) threads.emplace_back([&r, &file] { r = ImportStep(file); });
  for (auto& t : threads) t.join();
  for (const auto& r : results) {
    ASSERT_TRUE(r.has_value()) << r.error().message;
    EXPECT_EQ(r->triangles(), results[0]->triangles());
  }
}
#endif  // WRAP_TEST_WITH_OCCT

// ---- Bad input --------------------------------------------------------------------------------

TEST_F(StepImportTest, NotAStepFile) {
  const fs::path stl = WriteText("part.step", "solid part\nendsolid part\n");
  ExpectError(ImportStep(stl), ErrorCode::kInvalidInput, stl, {"is not a STEP file", "STL"});
  const fs::path xml = WriteText("part.stp", "<?xml version=\"1.0\"?><iso_10303_28/>");
  ExpectError(ImportStep(xml), ErrorCode::kInvalidInput, xml, {"is not a STEP file", "XML"});
  const fs::path empty = WriteText("empty.step", "");
  ExpectError(ImportStep(empty), ErrorCode::kInvalidInput, empty, {"empty"});
  ExpectError(ImportStep(dir_ / "missing.step"), ErrorCode::kIo, dir_ / "missing.step",
              {"not found"});
  ExpectError(ImportStep(dir_), ErrorCode::kIo, dir_, {"not a regular file"});
}

#if WRAP_TEST_WITH_OCCT
TEST_F(StepImportTest, TruncatedFile) {
  const std::string text = Text(WriteSpec(PegAndHole().Spec("MM"), "whole.step"));
  for (const double keep : {0.1, 0.5, 0.97}) {
    const fs::path cut =
        WriteText("cut.step", text.substr(0, static_cast<size_t>(keep * text.size())));
    ExpectError(ImportStep(cut), ErrorCode::kInvalidInput, cut, {"truncated"});
  }
  // Cut in the middle but with the end marker put back: the entities left refer to ones cut off.
  const fs::path spliced =
      WriteText("spliced.step", text.substr(0, text.size() / 2) + "\nENDSEC;\nEND-ISO-10303-21;\n");
  ExpectError(ImportStep(spliced), ErrorCode::kInvalidInput, spliced,
              {"is damaged: entity #", "which the file does not define"});
  // A record that does not parse, its references intact: the parser names the line.
  std::string garbled = text;
  const size_t point = garbled.find("CARTESIAN_POINT(");
  ASSERT_NE(point, std::string::npos);
  garbled.replace(point, 16, "CARTESIAN_POINT((");
  const fs::path unparsed = WriteText("garbled.step", garbled);
  ExpectError(ImportStep(unparsed), ErrorCode::kInvalidInput, unparsed,
              {"Line ", "near entity #", "syntax"});
}

TEST_F(StepImportTest, FileWithoutSolids) {
  const fs::path points = WriteText("points.step",
                                    "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n"
                                    "FILE_NAME('p','',(''),(''),'','','');\n"
                                    "FILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n"
                                    "#1=CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\n"
                                    "END-ISO-10303-21;\n");
  auto a = ImportStep(points);
  ASSERT_FALSE(a.has_value());
  EXPECT_EQ(a.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(a.error().message.find(points.string()), std::string::npos) << a.error().message;
}

// References that form a cycle (an edge that is its own edge; a loop through two entities) or
// name an entity the file lacks are refused before OpenCASCADE, which followed such an edge until
// the stack overflowed (found by fuzz_step).
// A '#' inside a string or comment is not a reference.
TEST_F(StepImportTest, BrokenEntityReferencesAreRefused) {
  const std::string head =
      "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('#1 in a string'),'2;1');\n"
      "FILE_NAME('p','',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\n"
      "DATA;\n#1=CARTESIAN_POINT('it''s #2; not a reference',(0.,0.,0.));\n/* #3 -> #3 */\n";
  const std::string tail = "ENDSEC;\nEND-ISO-10303-21;\n";
  const fs::path self = WriteText(
      "self.step", head + "#2=VERTEX_POINT('',#1);\n#3=ORIENTED_EDGE('',*,*,#3,.T.);\n" + tail);
  ExpectError(ImportStep(self), ErrorCode::kInvalidInput, self, {"cycle (#3 -> #3)"});
  const fs::path loop = WriteText(
      "loop.step", head +
                       "#2=EDGE_LOOP('',(#4));\n#3=VERTEX_POINT('',#1);\n"
                       "#4=ORIENTED_EDGE('',*,*,#5,.T.);\n#5=ORIENTED_EDGE('',*,*,#4,.F.);\n" +
                       tail);
  ExpectError(ImportStep(loop), ErrorCode::kInvalidInput, loop, {"cycle (#4 -> #5 -> #4)"});
  const fs::path dangling = WriteText(
      "dangling.step", head + "#2=VERTEX_POINT('',#1);\n#3=ORIENTED_EDGE('',*,*,#9,.T.);\n" + tail);
  ExpectError(ImportStep(dangling), ErrorCode::kInvalidInput, dangling,
              {"entity #3 refers to #9, which the file does not define"});
  // Without a cycle the same text goes on to OpenCASCADE (and has no solid).
  const fs::path fine = WriteText("fine.step", head + "#2=VERTEX_POINT('',#1);\n" + tail);
  auto a = ImportStep(fine);
  ASSERT_FALSE(a.has_value());
  EXPECT_EQ(a.error().message.find("cycle"), std::string::npos) << a.error().message;
}

TEST_F(StepImportTest, SolidThatDoesNotMeshClosed) {
  std::string text =
      Text(WriteSpec(OneProduct("box", {Box(Vec3::Zero(), Vec3(0.01, 0.02, 0.03))}), "box.step"));
  // Drop one face from the box's closed shell: an open "solid".
  const std::regex shell(R"(CLOSED_SHELL\(\s*'[^']*'\s*,\s*\(\s*(#\d+)\s*,)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(text, m, shell));
  text.replace(static_cast<size_t>(m.position(1)), m.length(1) + 1, "");
  const fs::path open = WriteText("open.step", text);
  ExpectError(ImportStep(open), ErrorCode::kInvalidInput, open,
              {"solid 'box'", "CLOSED_SHELL", "does not mesh closed"});
}

TEST_F(StepImportTest, OpenSurfaceModelIsSkippedWithAWarning) {
  std::string text = Text(WriteSpec(PegAndHole().Spec("MM"), "peg_and_hole.step"));
  // The plate (the first solid) as a surface model of an open shell: one face dropped.
  const std::regex brep(R"((#\d+) = ADVANCED_BREP_SHAPE_REPRESENTATION)");
  const std::regex solid(R"((#\d+) = MANIFOLD_SOLID_BREP\('',(#\d+)\);)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(text, m, brep));
  text.replace(static_cast<size_t>(m.position(0)), m.length(0),
               m.str(1) + " = MANIFOLD_SURFACE_SHAPE_REPRESENTATION");
  ASSERT_TRUE(std::regex_search(text, m, solid));
  const std::string shell = m.str(2);
  text.replace(static_cast<size_t>(m.position(0)), m.length(0),
               m.str(1) + " = SHELL_BASED_SURFACE_MODEL(''," + "(" + shell + "));");
  const std::regex closed(shell + R"( = CLOSED_SHELL\(\s*'[^']*'\s*,\s*\(\s*(#\d+)\s*,)");
  ASSERT_TRUE(std::regex_search(text, m, closed));
  text.replace(static_cast<size_t>(m.position(1)), m.length(1) + 1, "");
  const std::string closed_shell = shell + " = CLOSED_SHELL(";
  const size_t at = text.find(closed_shell);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, closed_shell.size(), shell + " = OPEN_SHELL(");
  const fs::path file = WriteText("surface.step", text);
  auto a = ImportStep(file);
  ASSERT_TRUE(a.has_value()) << a.error().message;
  ASSERT_EQ(a->instances.size(), 4u) << "the four legs; the plate is skipped";
  EXPECT_EQ(a->instances[0].name, "leg_1");
  ASSERT_EQ(a->warnings.size(), 1u);
  EXPECT_NE(a->warnings[0].find("'plate'"), std::string::npos) << a->warnings[0];
  EXPECT_NE(a->warnings[0].find("OPEN_SHELL"), std::string::npos) << a->warnings[0];
}

TEST_F(StepImportTest, FileWithoutLengthUnit) {
  std::string text =
      Text(WriteSpec(OneProduct("box", {Box(Vec3::Zero(), Vec3(0.01, 0.01, 0.01))}), "box.step"));
  const std::string unit = "LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.)";
  const size_t at = text.find(unit);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, unit.size(), "NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT()");
  const fs::path unitless = WriteText("unitless.step", text);
  ExpectError(ImportStep(unitless), ErrorCode::kInvalidInput, unitless,
              {"length unit", "representation context #"});
}

TEST_F(StepImportTest, DeflectionsOutOfRange) {
  const fs::path file = WriteText("x.step", "ISO-10303-21;\nEND-ISO-10303-21;\n");
  ExpectError(ImportStep(file, {.linear_deflection_m = 0.0}), ErrorCode::kInvalidInput, file,
              {"linear deflection"});
  ExpectError(ImportStep(file, {.angular_deflection_rad = 3.0}), ErrorCode::kInvalidInput, file,
              {"angular deflection"});
}
#else
// A build without OpenCASCADE refuses STEP files, saying why.
TEST_F(StepImportTest, StepUnavailableWithoutOpenCascade) {
  const fs::path file = WriteText("x.step", "ISO-10303-21;\nEND-ISO-10303-21;\n");
  ExpectError(ImportStep(file), ErrorCode::kInvalidInput, file, {"STEP is unavailable"});
  auto mesh = LoadMeshFile(file);
  ASSERT_FALSE(mesh.has_value());
  EXPECT_NE(mesh.error().message.find("STEP is unavailable"), std::string::npos);
}
#endif  // WRAP_TEST_WITH_OCCT

// ---- The cache and LoadMeshFile ---------------------------------------------------------------

#if WRAP_TEST_WITH_OCCT
TEST_F(StepImportTest, CacheServesAReopenWithoutRemeshing) {
  const fs::path file = WriteSpec(PegAndHole().Spec("MM"), "peg_and_hole.step");
  const StepLoadOptions options{.cache_dir = dir_ / ".wrap-cache" / "step"};
  auto first = LoadStep(file, options);
  ASSERT_TRUE(first.has_value()) << first.error().message;
  EXPECT_EQ(first->source, StepSource::kImported);
  EXPECT_TRUE(first->cache_problem.empty()) << first->cache_problem;
  ASSERT_TRUE(fs::is_regular_file(first->cache_file));
  auto again = LoadStep(file, options);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->source, StepSource::kMemory);
  ClearStepMemoryCache();  // a new process
  auto reopened = LoadStep(file, options);
  ASSERT_TRUE(reopened.has_value()) << reopened.error().message;
  EXPECT_EQ(reopened->source, StepSource::kDiskCache);
  const StepAssembly& x = *first->assembly;
  const StepAssembly& y = *reopened->assembly;
  ASSERT_EQ(x.solids.size(), y.solids.size());
  ASSERT_EQ(x.instances.size(), y.instances.size());
  for (size_t i = 0; i < x.solids.size(); ++i) {
    EXPECT_EQ(x.solids[i].name, y.solids[i].name);
    EXPECT_EQ(x.solids[i].entity, y.solids[i].entity);
    EXPECT_EQ(x.solids[i].mesh.vertices, y.solids[i].mesh.vertices);
    EXPECT_EQ(x.solids[i].mesh.triangles, y.solids[i].mesh.triangles);
  }
  for (size_t i = 0; i < x.instances.size(); ++i) {
    EXPECT_EQ(x.instances[i].name, y.instances[i].name);
    EXPECT_TRUE(x.instances[i].X_AS.isApprox(y.instances[i].X_AS, 0.0));
    EXPECT_EQ(x.instances[i].color, y.instances[i].color);
  }
  ExpectPegAndHole(y, PegAndHole());
  // Other deflections are another entry.
  ClearStepMemoryCache();
  auto finer = LoadStep(
      file, {.tessellation = {.linear_deflection_m = 1e-5}, .cache_dir = options.cache_dir});
  ASSERT_TRUE(finer.has_value());
  EXPECT_EQ(finer->source, StepSource::kImported);
  EXPECT_GT(finer->assembly->triangles(), x.triangles());
}

TEST_F(StepImportTest, DamagedOrStaleCacheIsReplaced) {
  const fs::path file = WriteSpec(PegAndHole().Spec("MM"), "peg_and_hole.step");
  const StepLoadOptions options{.cache_dir = dir_ / "cache"};
  auto first = LoadStep(file, options);
  ASSERT_TRUE(first.has_value());
  const std::string bytes = Text(first->cache_file);
  for (const std::string& damaged : {bytes.substr(0, bytes.size() / 2), std::string("junk"),
                                     bytes.substr(0, 100) + "X" + bytes.substr(101)}) {
    ClearStepMemoryCache();
    ASSERT_TRUE(WriteFileAtomic(first->cache_file, damaged).has_value());
    auto load = LoadStep(file, options);
    ASSERT_TRUE(load.has_value()) << load.error().message;
    EXPECT_EQ(load->source, StepSource::kImported);
    EXPECT_EQ(Text(first->cache_file), bytes) << "rewritten";
  }
  // A changed file is a new key: not served from the old entry.
  ClearStepMemoryCache();
  const fs::path changed = WriteSpec(OneProduct("box", {Box(Vec3::Zero(), Vec3(0.01, 0.01, 0.01))}),
                                     "peg_and_hole.step");
  auto load = LoadStep(changed, options);
  ASSERT_TRUE(load.has_value());
  EXPECT_EQ(load->source, StepSource::kImported);
  EXPECT_EQ(load->assembly->instances.size(), 1u);
}

TEST_F(StepImportTest, UnwritableCacheStillImports) {
  const fs::path file =
      WriteSpec(OneProduct("box", {Box(Vec3::Zero(), Vec3(0.01, 0.01, 0.01))}), "box.step");
  const fs::path blocked = WriteText("not_a_folder", "x");  // a file where the folder would be
  auto load = LoadStep(file, {.cache_dir = blocked / "step"});
  ASSERT_TRUE(load.has_value()) << load.error().message;
  EXPECT_FALSE(load->cache_problem.empty());
  EXPECT_EQ(Text(blocked), "x");
}

TEST_F(StepImportTest, LoadMeshFilePicksASolidOrTheWholeFile) {
  const PegAndHole d;
  const fs::path file = WriteSpec(d.Spec("MM"), "peg_and_hole.step");
  auto leg = LoadMeshFile(file, {.solid = "leg"});
  ASSERT_TRUE(leg.has_value()) << leg.error().message;
  EXPECT_NEAR(Volume(leg->mesh), d.LegVolume(), kVolumeRel * d.LegVolume());
  auto by_instance = LoadMeshFile(file, {.solid = "leg_3"});  // an instance: its solid
  ASSERT_TRUE(by_instance.has_value());
  EXPECT_EQ(by_instance->mesh.vertices, leg->mesh.vertices);
  auto whole = LoadMeshFile(file, {.scale = 2.0});
  ASSERT_TRUE(whole.has_value());
  const double total = 8.0 * (d.PlateVolume() + 4 * d.LegVolume());
  EXPECT_NEAR(Volume(whole->mesh), total, kVolumeRel * total);
  EXPECT_TRUE(whole->warnings.empty());
  auto missing = LoadMeshFile(file, {.solid = "seat"});
  ASSERT_FALSE(missing.has_value());
  EXPECT_NE(missing.error().message.find("no solid or part 'seat'"), std::string::npos);
  EXPECT_NE(missing.error().message.find("'plate', 'leg'"), std::string::npos);
  const fs::path stl = WriteText("tri.stl", "solid t\nendsolid t\n");
  auto refused = LoadMeshFile(stl, {.solid = "leg"});
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("not a STEP file"), std::string::npos);
}
#endif  // WRAP_TEST_WITH_OCCT

// The tests' view of the build (WRAP_TEST_WITH_OCCT, from the option WRAP_WITH_OCCT) is the
// library's.
TEST(StepFiles, ImportIsAvailableExactlyInABuildWithOpenCascade) {
  EXPECT_EQ(StepImportAvailable(), WRAP_TEST_WITH_OCCT != 0);
}

TEST(StepFiles, LooksLikeStepByNameOrHeader) {
  EXPECT_TRUE(LooksLikeStep("a/b/model.STEP"));
  EXPECT_TRUE(LooksLikeStep("model.stp"));
  EXPECT_TRUE(LooksLikeStep("model.p21"));
  EXPECT_FALSE(LooksLikeStep("model.stl"));
  const fs::path renamed =
      fs::path(::testing::TempDir()) / ("wrap_step_renamed_" + std::to_string(::getpid()) + ".dat");
  ASSERT_TRUE(WriteFileAtomic(renamed, "ISO-10303-21;\nHEADER;\n").has_value());
  EXPECT_TRUE(LooksLikeStep(renamed));
  fs::remove(renamed);
}

}  // namespace
}  // namespace wrap
