// Assembly sequences by disassembly on hand-made assemblies of boxes (millimetres): a peg in a
// blind hole, a stack, a slider that can only leave sideways, a ring interlocked with a post,
// a plate that must be the base.
#include <gtest/gtest.h>

#include "../mating/scenes.h"
#include "authoring/sequence.h"
#include "grasp/grasp_probe.h"
#include "mating/contact_graph.h"

namespace wrap {
namespace {

using test::Merged;
using test::Mm;
using test::Scene;

ProposedSequence Sequence(const Scene& s, bool with_grasps = false) {
  AssemblyGeometry g = s.Geometry();
  const ContactGraph contacts = ComputeContactGraph(g);
  std::optional<GraspProbe> probe;
  if (with_grasps) {
    std::vector<const TriangleMesh*> meshes;
    for (const TriangleMesh& m : s.meshes) meshes.push_back(&m);
    const std::string ees[1] = {"robotiq_2f85"};
    RunContext ctx(0);
    auto built = GraspProbe::Build(meshes, s.poses, ees, GraspProbeOptions{}, ctx);
    EXPECT_TRUE(built) << built.error().message;
    if (built) probe.emplace(std::move(*built));
  }
  return ProposeSequence(g, contacts, probe ? &*probe : nullptr);
}

bool IsAxis(const Vec3& a, const Vec3& b) { return a.dot(b) > 0.999; }

TEST(Sequence, PegIntoBlindHoleComesDownIntoTheCup) {
  Scene s;
  TriangleMesh cup = BoxMesh(Mm(-15, -15, 0), Mm(15, 15, 5));
  cup = Merged(cup, BoxMesh(Mm(-15, -15, 5), Mm(-10, 15, 25)));
  cup = Merged(cup, BoxMesh(Mm(10, -15, 5), Mm(15, 15, 25)));
  cup = Merged(cup, BoxMesh(Mm(-10, -15, 5), Mm(10, -10, 25)));
  cup = Merged(cup, BoxMesh(Mm(-10, 10, 5), Mm(10, 15, 25)));
  s.Add("cup", cup);
  s.Add("peg", BoxMesh(Mm(-10, -10, 5), Mm(10, 10, 40)));
  const ProposedSequence seq = Sequence(s);
  ASSERT_TRUE(seq.ok());
  ASSERT_EQ(seq.steps.size(), 1u);
  EXPECT_EQ(seq.steps[0].moved, std::vector<int>{1});
  EXPECT_EQ(seq.steps[0].base, std::vector<int>{0});
  EXPECT_TRUE(IsAxis(seq.steps[0].axis_A, -Vec3::UnitZ()));
}

TEST(Sequence, StackIsBuiltBottomUp) {
  Scene s;
  s.Add("middle", BoxMesh(Mm(0, 0, 20), Mm(30, 30, 40)));
  s.Add("top", BoxMesh(Mm(5, 5, 40), Mm(25, 25, 50)));
  s.Add("bottom", BoxMesh(Mm(-10, -10, 0), Mm(40, 40, 20)));
  const ProposedSequence seq = Sequence(s);
  ASSERT_TRUE(seq.ok());
  ASSERT_EQ(seq.steps.size(), 2u);
  EXPECT_EQ(seq.steps[0].moved, std::vector<int>{0});  // middle onto bottom
  EXPECT_EQ(seq.steps[0].base, std::vector<int>{2});
  EXPECT_EQ(seq.steps[1].moved, std::vector<int>{1});  // then top onto both
  EXPECT_TRUE(IsAxis(seq.steps[0].axis_A, -Vec3::UnitZ()));
  EXPECT_TRUE(IsAxis(seq.steps[1].axis_A, -Vec3::UnitZ()));
}

TEST(Sequence, SliderThatCanOnlyLeaveSideways) {
  Scene s;
  // A housing open only towards +x, and the slider that fills it.
  TriangleMesh housing = BoxMesh(Mm(0, 0, 0), Mm(40, 30, 5));
  housing = Merged(housing, BoxMesh(Mm(0, 0, 25), Mm(40, 30, 30)));
  housing = Merged(housing, BoxMesh(Mm(0, 0, 5), Mm(5, 30, 25)));
  housing = Merged(housing, BoxMesh(Mm(5, 0, 5), Mm(40, 5, 25)));
  housing = Merged(housing, BoxMesh(Mm(5, 25, 5), Mm(40, 30, 25)));
  s.Add("housing", housing);
  s.Add("slider", BoxMesh(Mm(5, 5, 5), Mm(40, 25, 25)));
  const ProposedSequence seq = Sequence(s);
  ASSERT_TRUE(seq.ok());
  ASSERT_EQ(seq.steps.size(), 1u);
  // Whichever is moved, the relative motion is along x: the slider comes in along -x.
  const ProposedStep& step = seq.steps[0];
  const Vec3 slider_in = step.moved == std::vector<int>{1} ? step.axis_A : Vec3(-step.axis_A);
  EXPECT_TRUE(IsAxis(slider_in, -Vec3::UnitX())) << step.why;
}

TEST(Sequence, InterlockedRingAndPostAreReportedNotLooped) {
  Scene s;
  TriangleMesh post = BoxMesh(Mm(-20, -20, 0), Mm(20, 20, 5));
  post = Merged(post, BoxMesh(Mm(-3, -3, 5), Mm(3, 3, 25)));
  post = Merged(post, BoxMesh(Mm(-20, -20, 25), Mm(20, 20, 30)));
  TriangleMesh ring = BoxMesh(Mm(-12, -12, 10), Mm(-3, 12, 20));
  ring = Merged(ring, BoxMesh(Mm(3, -12, 10), Mm(12, 12, 20)));
  ring = Merged(ring, BoxMesh(Mm(-3, -12, 10), Mm(3, -3, 20)));
  ring = Merged(ring, BoxMesh(Mm(-3, 3, 10), Mm(3, 12, 20)));
  s.Add("post", post);
  s.Add("ring", ring);
  const ProposedSequence seq = Sequence(s);
  EXPECT_FALSE(seq.ok());
  EXPECT_EQ(seq.interlocked, (std::vector<int>{0, 1}));
}

TEST(Sequence, PlateWithPegsIsTheBase) {
  Scene s;
  s.Add("peg_a", BoxMesh(Mm(10, 10, 5), Mm(20, 20, 40)));
  TriangleMesh plate = BoxMesh(Mm(0, 0, 0), Mm(100, 30, 5));
  s.Add("peg_b", BoxMesh(Mm(80, 10, 5), Mm(90, 20, 40)));
  s.Add("plate", plate);
  const ProposedSequence seq = Sequence(s, true);
  ASSERT_TRUE(seq.ok());
  ASSERT_EQ(seq.steps.size(), 2u);
  // Whatever the roles, the plate is in the first step, and the pegs come onto it.
  const ProposedStep& first = seq.steps[0];
  const bool plate_first = first.base == std::vector<int>{2} || first.moved == std::vector<int>{2};
  EXPECT_TRUE(plate_first) << first.why;
  EXPECT_GT(first.moved_grasps, 0) << first.why;
}

// A collar 6 mm tall on a plate: no full-pad grasp holds it (a pad needs 1 cm^2 of its 16 mm
// wide faces), but fingertips on its upper edge clear the plate where mated. It stays the moved
// input; before reduced grasps counted, the roles swapped to the plate lowered onto the collar
// (the Fabrica car's body onto a wheel, which the planner could not support).
TEST(Sequence, APartHeldOnlyByItsFingertipsKeepsTheMovedRole) {
  Scene s;
  s.Add("plate", BoxMesh(Mm(-30, -30, 0), Mm(30, 30, 4)));
  s.Add("collar", BoxMesh(Mm(-8, -8, 4), Mm(8, 8, 10)));
  const ProposedSequence seq = Sequence(s, true);
  ASSERT_TRUE(seq.ok());
  ASSERT_EQ(seq.steps.size(), 1u);
  const ProposedStep& step = seq.steps[0];
  EXPECT_EQ(step.moved, std::vector<int>{1}) << step.why;
  EXPECT_EQ(step.base, std::vector<int>{0}) << step.why;
  EXPECT_FALSE(step.swapped) << step.why;
  EXPECT_GT(step.moved_grasps, 0) << step.why;
  EXPECT_TRUE(IsAxis(step.axis_A, -Vec3::UnitZ())) << step.why;
}

}  // namespace
}  // namespace wrap
