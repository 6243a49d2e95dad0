// The geometry's verdicts on hand-made scenes: contacts, insertion paths, free directions,
// overlaps at the start, and the messages validation prints for them.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mating/check.h"
#include "mating/contact_graph.h"
#include "mating/insertion.h"
#include "mating/start_layout.h"
#include "model/assembly.h"
#include "scenes.h"

namespace wrap {
namespace {

using test::CupAndPeg;
using test::Mm;
using test::Scene;

InsertionPath PegPath(const std::vector<int>& base, int peg, const Vec3& axis) {
  InsertionPath path;
  path.moved = {peg};
  path.base = base;
  path.axis_A = axis.normalized();
  return path;
}

bool Near(const Vec3& a, const Vec3& b) {
  return a.dot(b) > std::cos(4.0 * std::numbers::pi / 180);
}

TEST(Insertion, PegIntoBlindHoleHasOneFreeDirection) {
  Scene s;
  const std::vector<int> base = CupAndPeg(s, true);
  const int peg = static_cast<int>(s.names.size()) - 1;
  AssemblyGeometry g = s.Geometry();
  EXPECT_FALSE(SweepInsertion(g, PegPath(base, peg, -Vec3::UnitZ())).blocked);
  const ContactGraph contacts = ComputeContactGraph(g);
  const std::vector<Vec3> free =
      FreeAxes(g, PegPath(base, peg, -Vec3::UnitZ()), CandidateAxes(contacts, {peg}, base));
  ASSERT_EQ(free.size(), 1u) << FormatDirection(free.back());
  EXPECT_TRUE(Near(free[0], -Vec3::UnitZ()));
}

TEST(Insertion, PegThroughTubeHasTwoFreeDirections) {
  Scene s;
  const std::vector<int> base = CupAndPeg(s, false);
  const int peg = static_cast<int>(s.names.size()) - 1;
  AssemblyGeometry g = s.Geometry();
  const ContactGraph contacts = ComputeContactGraph(g);
  const std::vector<Vec3> free =
      FreeAxes(g, PegPath(base, peg, -Vec3::UnitZ()), CandidateAxes(contacts, {peg}, base));
  ASSERT_EQ(free.size(), 2u);
  EXPECT_TRUE(Near(free[0], -Vec3::UnitZ()));
  EXPECT_TRUE(Near(free[1], Vec3::UnitZ()));
}

TEST(Insertion, SidewaysThroughTheWallIsBlockedWhereItHits) {
  Scene s;
  const std::vector<int> base = CupAndPeg(s, true);
  const int peg = static_cast<int>(s.names.size()) - 1;
  AssemblyGeometry g = s.Geometry();
  const PathHit hit = SweepInsertion(g, PegPath(base, peg, Vec3::UnitX()));
  ASSERT_TRUE(hit.blocked);
  EXPECT_EQ(g.name(hit.base_part), "wall_xn");
  EXPECT_EQ(hit.moved_part, peg);
  // Coming in along +x from 30 mm, the peg meets the wall's far face 25 mm out, less the
  // 0.1 mm insets of both surfaces: exactly 24.8 mm.
  EXPECT_NEAR(hit.at_m, 24.8e-3, 1e-8);
  // Going out from the mating pose, the peg meets the same wall's near face at once, inside the
  // interference band: both surfaces inset by 0.25 mm there, 0.5 mm of travel.
  PathHit out;
  EXPECT_FALSE(IsPathFree(g, PegPath(base, peg, Vec3::UnitX()), &out));
  EXPECT_EQ(g.name(out.base_part), "wall_xn");
  EXPECT_NEAR(out.at_m, 0.5e-3, 1e-8);
  // Coming up from below through the bottom plate: blocked at once.
  const PathHit up = SweepInsertion(g, PegPath(base, peg, Vec3::UnitZ()));
  ASSERT_TRUE(up.blocked);
  EXPECT_EQ(g.name(up.base_part), "bottom");
}

TEST(Insertion, SnapFitBandAllowsTheFinalInterference) {
  Scene s;
  const std::vector<int> base = CupAndPeg(s, true);
  // A catch 0.3 mm proud on both sides of the peg, entering the walls in the last 0.8 mm.
  const int peg = static_cast<int>(s.names.size()) - 1;
  s.meshes[peg] = test::Merged(s.meshes[peg], BoxMesh(Mm(-10.3, -2, 24.2), Mm(10.3, 2, 25)));
  AssemblyGeometry g = s.Geometry();
  InsertionPath path = PegPath(base, peg, -Vec3::UnitZ());
  EXPECT_FALSE(SweepInsertion(g, path).blocked);  // 1 mm band, 0.5 mm allowed
  path.interference_depth_m = 0.1e-3;             // less than the catch's 0.3 mm
  const PathHit deep = SweepInsertion(g, path);
  ASSERT_TRUE(deep.blocked);
  EXPECT_LE(deep.at_m, 1e-3);
  path.interference_depth_m = 0.5e-3;
  path.interference_travel_m = 0.5e-3;  // the catch overlaps over its last 0.8 mm
  const PathHit early = SweepInsertion(g, path);
  ASSERT_TRUE(early.blocked);
  // Beyond the band the surfaces are inset by 0.1 mm: the catch's inset bottom (24.3 mm) meets
  // the walls' inset top (24.9 mm) 0.6 mm before the mating pose.
  EXPECT_NEAR(early.at_m, 0.6e-3, 1e-8);
}

TEST(Insertion, AWallThinnerThanAStepIsNotJumped) {
  // A 0.05 mm sheet comes down 30 mm through a 0.08 mm wall (no allowance: the meshes as they
  // are). Their surfaces cross only from 10.18 to 10.05 mm before the mating pose, between two
  // stations of a 0.2 mm grid from 30 mm (10.2 and 10.0).
  Scene s;
  const int wall = s.Add("wall", BoxMesh(Mm(-20, -20, 10.10), Mm(20, 20, 10.18)));
  const int sheet = s.Add("sheet", BoxMesh(Mm(-5, -5, 0), Mm(5, 5, 0.05)));
  AssemblyGeometry g = s.Geometry();
  InsertionPath path = PegPath({wall}, sheet, -Vec3::UnitZ());
  path.touch_depth_m = 0.0;
  path.interference_depth_m = 0.0;
  const PathHit in = SweepInsertion(g, path);
  ASSERT_TRUE(in.blocked);
  EXPECT_NEAR(in.at_m, 10.18e-3, 1e-8);
  PathHit out;
  EXPECT_FALSE(IsPathFree(g, path, &out));
  EXPECT_NEAR(out.at_m, 10.05e-3, 1e-8);
  path.length_m = 10.0e-3;  // stops short of it
  EXPECT_FALSE(SweepInsertion(g, path).blocked);
}

TEST(Insertion, TiltedAxis) {
  Iso3 X = Iso3::Identity();
  X.linear() = Eigen::AngleAxisd(std::numbers::pi / 6, Vec3::UnitX()).toRotationMatrix();
  Scene s;
  const std::vector<int> base = CupAndPeg(s, true, X);
  const int peg = static_cast<int>(s.names.size()) - 1;
  AssemblyGeometry g = s.Geometry();
  const Vec3 axis = X.linear() * -Vec3::UnitZ();
  EXPECT_FALSE(SweepInsertion(g, PegPath(base, peg, axis)).blocked);
  EXPECT_TRUE(SweepInsertion(g, PegPath(base, peg, -Vec3::UnitZ())).blocked);
  const ContactGraph contacts = ComputeContactGraph(g);
  const std::vector<Vec3> free =
      FreeAxes(g, PegPath(base, peg, axis), CandidateAxes(contacts, {peg}, base));
  ASSERT_EQ(free.size(), 1u);
  EXPECT_TRUE(Near(free[0], axis));  // found among the contact normals
}

TEST(Contacts, CupAndPegContactsAreTheFacesThatMeet) {
  Scene s;
  const std::vector<int> base = CupAndPeg(s, true);
  const int peg = static_cast<int>(s.names.size()) - 1;
  AssemblyGeometry g = s.Geometry();
  const ContactGraph contacts = ComputeContactGraph(g);
  // The peg touches the bottom and the four walls; each wall touches the bottom and its two
  // neighbours: 5 + 4 + 4 pairs.
  EXPECT_EQ(contacts.contacts.size(), 13u);
  EXPECT_EQ(contacts.Neighbours(peg), base);
  const Contact* wall = contacts.Find(peg, 1);  // wall_xn, 20 x 20 mm of shared face
  ASSERT_TRUE(wall);
  EXPECT_NEAR(wall->area_m2, 400e-6, 60e-6);
  ASSERT_FALSE(wall->normals.empty());
  EXPECT_EQ(wall->a, 1);
  EXPECT_TRUE(Near(wall->normals[0].n_A, -Vec3::UnitX()));  // out of the peg (b) into the wall
  const Contact* bottom = contacts.Find(0, peg);
  ASSERT_TRUE(bottom);
  EXPECT_NEAR(bottom->area_m2, 400e-6, 60e-6);
  EXPECT_TRUE(Near(bottom->normals[0].n_A, -Vec3::UnitZ()));
  EXPECT_NEAR(bottom->centroid_A.z(), 5e-3, 1e-4);
  EXPECT_EQ(bottom->distance_m, 0.0);
}

TEST(Contacts, PartsApartDoNotTouch) {
  Scene s;
  s.Add("a", BoxMesh(Mm(0, 0, 0), Mm(10, 10, 10)));
  s.Add("b", BoxMesh(Mm(22, 0, 0), Mm(30, 10, 10)));
  s.Add("c", BoxMesh(Mm(10.5, 0, 0), Mm(15, 10, 10)));  // 0.5 mm from a: touches (1 mm)
  AssemblyGeometry g = s.Geometry();
  const ContactGraph contacts = ComputeContactGraph(g);
  ASSERT_EQ(contacts.contacts.size(), 1u);
  EXPECT_NEAR(contacts.contacts[0].distance_m, 0.5e-3, 1e-9);
  const SetDistance d = DistanceBetween(g, {0}, {1});
  EXPECT_NEAR(d.distance_m, 12e-3, 1e-9);
}

TEST(StartLayout, OverlapsAreFoundWithTheirDepth) {
  Scene s;
  s.Add("a", BoxMesh(Mm(0, 0, 0), Mm(10, 10, 10)));
  s.Add("b", BoxMesh(Mm(0, 0, 0), Mm(10, 10, 10)));
  s.Add("c", BoxMesh(Mm(0, 0, 0), Mm(10, 10, 10)));
  AssemblyGeometry g = s.Geometry();
  auto at = [](double x, double y, double z) {
    Iso3 X = Iso3::Identity();
    X.translation() = Mm(x, y, z);
    return X;
  };
  // b sits 3 mm into a; c stands on a (touching, 0.05 mm in: tessellation).
  const std::vector<Iso3> X = {at(0, 0, 0), at(7, 0, 0), at(0, 0, 9.95)};
  const std::vector<StartOverlap> overlaps = StartOverlaps(g, X, 0.2e-3);
  ASSERT_EQ(overlaps.size(), 1u);
  EXPECT_EQ(overlaps[0].a, 0);
  EXPECT_EQ(overlaps[0].b, 1);
  EXPECT_NEAR(overlaps[0].depth_m, 3e-3, 0.3e-3);
  // A part swallowed whole by another: found although no surfaces meet.
  Scene t;
  t.Add("big", BoxMesh(Mm(0, 0, 0), Mm(30, 30, 30)));
  t.Add("small", BoxMesh(Mm(10, 10, 10), Mm(14, 14, 14)));
  AssemblyGeometry h = t.Geometry();
  const auto inside = StartOverlaps(h, {Iso3::Identity(), Iso3::Identity()}, 0.2e-3);
  ASSERT_EQ(inside.size(), 1u);
  EXPECT_NEAR(inside[0].depth_m, 14e-3, 0.5e-3);  // the far corner: 14 mm from the near faces
}

// A project over a Scene: part names, meshes as validation would have loaded them, one step.
struct SceneProject {
  Project project;
  ProjectCheck check;
  SceneProject(const Scene& s, std::vector<Step> steps) {
    for (size_t i = 0; i < s.names.size(); ++i) {
      Part part;
      part.name = s.names[i];
      part.mesh = s.names[i] + ".stl";
      part.initial_pose.xyz = Vec3(0.3 * static_cast<double>(i), 0.0, 0.75);
      project.parts.push_back(part);
      PartGeometry geo;
      geo.loaded = true;
      geo.mesh = s.meshes[i];
      check.parts.push_back(geo);
    }
    project.steps = std::move(steps);
    AssemblyTree tree;
    Diagnostics d;
    if (BuildAssemblyTree(project, "p.json", d, tree)) check.tree = tree;
  }
};

Step MakeStep(std::string name, std::string moved, std::string base, Vec3 axis) {
  Step step;
  step.name = std::move(name);
  step.inputs = {moved, base};
  step.mating.moved = moved;
  step.mating.base = base;
  step.mating.axis = axis;
  return step;
}

TEST(GeometryCheck, BlockedAxisIsAnErrorWithFreeDirections) {
  Scene s;
  s.Add("cup", BoxMesh(Mm(-15, -15, 0), Mm(15, 15, 5)));
  s.Add("peg", BoxMesh(Mm(-10, -10, 5), Mm(10, 10, 40)));
  s.meshes[0] = test::Merged(
      test::Merged(
          test::Merged(test::Merged(s.meshes[0], BoxMesh(Mm(-15, -15, 5), Mm(-10, 15, 25))),
                       BoxMesh(Mm(10, -15, 5), Mm(15, 15, 25))),
          BoxMesh(Mm(-10, -15, 5), Mm(10, -10, 25))),
      BoxMesh(Mm(-10, 10, 5), Mm(10, 15, 25)));
  SceneProject p(s, {MakeStep("cup+peg", "peg", "cup", Vec3::UnitX())});
  ASSERT_TRUE(p.check.tree);
  const GeometryReport r = CheckAssemblyGeometry(p.project, p.check, "p.json");
  ASSERT_EQ(r.diagnostics.error_count(), 1);
  const Diagnostic& d = r.diagnostics.items[0];
  EXPECT_EQ(d.path, "steps[0].mating.axis");
  EXPECT_NE(d.message.find("step 'cup+peg': 'peg' moving along [1, 0, 0] hits 'cup' 24."),
            std::string::npos)
      << d.message;
  EXPECT_NE(d.message.find("mm before its mating pose; free directions: [0, 0, -1]"),
            std::string::npos)
      << d.message;
  // The right axis: no error.
  p.project.steps[0].mating.axis = -Vec3::UnitZ();
  EXPECT_EQ(CheckAssemblyGeometry(p.project, p.check, "p.json").diagnostics.error_count(), 0);
}

TEST(GeometryCheck, InputsThatDoNotTouchAreAnError) {
  Scene s;
  s.Add("a", BoxMesh(Mm(0, 0, 0), Mm(10, 10, 10)));
  s.Add("b", BoxMesh(Mm(10, 0, 0), Mm(20, 10, 10)));
  s.Add("c", BoxMesh(Mm(32.3, 0, 0), Mm(40, 10, 10)));
  Step ab = MakeStep("ab", "b", "a", -Vec3::UnitX());
  Step abc = MakeStep("abc", "c", "ab", -Vec3::UnitX());
  abc.inputs = {"ab", "c"};
  SceneProject p(s, {ab, abc});
  ASSERT_TRUE(p.check.tree);
  const GeometryReport r = CheckAssemblyGeometry(p.project, p.check, "p.json");
  ASSERT_EQ(r.diagnostics.error_count(), 1);
  const Diagnostic& d = r.diagnostics.items[0];
  EXPECT_EQ(d.path, "steps[1].mating.base");
  EXPECT_NE(d.message.find("step 'abc': its inputs 'c' and 'ab' do not touch at the mating pose "
                           "(closest 12.3 mm, between 'c' and 'b'"),
            std::string::npos)
      << d.message;
  EXPECT_NE(d.message.find("'c' touches no other part"), std::string::npos) << d.message;
}

// A part whose mesh was not read (validation has said so) makes no step look wrong: the steps
// are not judged until every mesh is there.
TEST(GeometryCheck, AMissingMeshIsNotReportedAgainAsStepsThatDoNotTouch) {
  Scene s;
  s.Add("a", BoxMesh(Mm(0, 0, 0), Mm(10, 10, 10)));
  s.Add("b", BoxMesh(Mm(10, 0, 0), Mm(20, 10, 10)));
  SceneProject p(s, {MakeStep("ab", "b", "a", Vec3::UnitX())});
  ASSERT_TRUE(p.check.tree);
  p.check.parts[1] = PartGeometry{};  // its file was not found
  const GeometryReport r = CheckAssemblyGeometry(p.project, p.check, "p.json");
  EXPECT_EQ(r.diagnostics.error_count(), 0);
  EXPECT_TRUE(r.steps.empty());
}

TEST(GeometryCheck, OverlappingStartIsAnErrorNamingBothParts) {
  Scene s;
  s.Add("a", BoxMesh(Mm(0, 0, 0), Mm(10, 10, 10)));
  s.Add("b", BoxMesh(Mm(10, 0, 0), Mm(20, 10, 10)));
  SceneProject p(s, {MakeStep("ab", "b", "a", -Vec3::UnitX())});
  p.project.parts[1].initial_pose.xyz = p.project.parts[0].initial_pose.xyz + Mm(-4, 0, 0);
  const GeometryReport r = CheckAssemblyGeometry(p.project, p.check, "p.json");
  ASSERT_EQ(r.diagnostics.error_count(), 1);
  const Diagnostic& d = r.diagnostics.items[0];
  EXPECT_EQ(d.path, "parts[1].initial_pose");
  EXPECT_NE(d.message.find("part 'b' overlaps part 'a' by 4.0 mm where they start"),
            std::string::npos)
      << d.message;
}

}  // namespace
}  // namespace wrap
