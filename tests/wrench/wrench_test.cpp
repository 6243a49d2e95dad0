// Hand-computed cases of the wrench check (paper §IV-A): table support and friction, bracing,
// vacuum assembly vs transport limits, compression-only connections, lambda, utilisations, the
// other gates, reasons, the cache and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "wrench/wrench.h"

namespace wrap {
namespace {

constexpr double kG = 9.81;
constexpr double kMu = 0.4;
constexpr double kInf = std::numeric_limits<double>::infinity();

Iso3 At(const Vec3& p, const Mat3& R = Mat3::Identity()) {
  Iso3 X = Iso3::Identity();
  X.linear() = R;
  X.translation() = p;
  return X;
}

Mat3 RotX(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }
Mat3 RotY(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }

WrenchBounds Box(double f, double m) {
  WrenchBox box{Vec3::Constant(f), Vec3::Constant(m)};
  return BoundsFromBox(box);
}

// A 1 kg block, 0.25 m square and 0.1 m tall, resting on a table whose top is z = 0.
StepConfiguration BlockOnTable(int pyramid_edges = 4) {
  StepConfiguration c;
  c.bodies.push_back({"block", 1.0, Vec3(0, 0, 0.05)});
  WrenchTableSupport table;
  table.body = 0;
  table.p_WV = {Vec3(0.125, 0.125, 0), Vec3(-0.125, 0.125, 0), Vec3(-0.125, -0.125, 0),
                Vec3(0.125, -0.125, 0)};
  table.friction = kMu;
  table.pyramid_edges = pyramid_edges;
  c.tables.push_back(table);
  return c;
}

// The block pressed by an unmodelled moved part along `axis` at `contact`.
MatingLoad Press(const Vec3& axis, const Vec3& contact, double force, double transverse = 0.0) {
  MatingLoad m;
  m.moved = -1;
  m.base = 0;
  m.axis_W = axis;
  m.p_WContact = contact;
  m.force_N = force;
  m.transverse_fraction = transverse;
  return m;
}

WrenchCheck MustCheck(const StepConfiguration& c, const WrenchQuery& q = {},
                      const WrenchOptions& o = {}) {
  Result<WrenchCheck> r = CheckWrench(c, q, o);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  return r ? *r : WrenchCheck{};
}

const SupportLoad& Load(const WrenchCheck& check, SupportKind kind, int index) {
  for (const SupportLoad& s : check.supports) {
    if (s.kind == kind && s.index == index) return s;
  }
  static const SupportLoad kMissing{};
  ADD_FAILURE() << "support not reported";
  return kMissing;
}

TEST(WrenchTable, BlockPressedFromAboveIsSupported) {
  StepConfiguration c = BlockOnTable();
  c.mating = Press(-Vec3::UnitZ(), Vec3(0, 0, 0.1), 10.0);
  const WrenchCheck check = MustCheck(c);
  EXPECT_TRUE(check.feasible);
  EXPECT_EQ(check.vertex_count, 1);
  EXPECT_EQ(check.worst_vertex_label, "nominal");
  // Only the (unlimited) table carries the load, with no friction.
  EXPECT_DOUBLE_EQ(check.utilisation, 0.0);
  EXPECT_NEAR(Load(check, SupportKind::kTable, 0).utilisation, 0.0, 1e-12);
  EXPECT_TRUE(check.reason.empty());
}

TEST(WrenchTable, PulledUpFromAboveIsNotSupported) {
  // The sign convention: the base is pushed along the axis; +z pulls the block off the table.
  StepConfiguration c = BlockOnTable();
  c.mating = Press(Vec3::UnitZ(), Vec3(0, 0, 0.1), 20.0);
  const WrenchCheck check = MustCheck(c);
  EXPECT_FALSE(check.feasible);
  EXPECT_TRUE(std::isinf(check.utilisation));
  EXPECT_NE(check.reason.find("'block'"), std::string::npos) << check.reason;
}

TEST(WrenchTable, SidewaysPushThresholdIsMuMg) {
  // A sideways press along +x low on the block: friction holds up to mu m g.
  const double threshold = kMu * 1.0 * kG;
  for (double factor : {0.5, 0.99, 1.01}) {
    StepConfiguration c = BlockOnTable();
    c.mating = Press(Vec3::UnitX(), Vec3(-0.1, 0, 0.02), factor * threshold);
    const WrenchCheck check = MustCheck(c);
    EXPECT_EQ(check.feasible, factor < 1.0) << factor;
    if (factor < 1.0) {
      // Friction used by the table's resultant: F / (mu m g).
      EXPECT_NEAR(Load(check, SupportKind::kTable, 0).utilisation, factor, 1e-9);
    } else {
      EXPECT_NE(check.reason.find("slides"), std::string::npos) << check.reason;
      EXPECT_NE(check.reason.find("table under 'block'"), std::string::npos) << check.reason;
    }
  }
}

// The worst transverse vertex of a press from above pushes along a diagonal with magnitude
// sqrt(2) tau F; an 8-edge pyramid is exact along diagonals: sideways > mu (m g + F) fails.
TEST(WrenchTable, PressWithTransverseThresholdIsMuTimesNormal) {
  const double F = 10.0;
  const double tau_star = kMu * (kG + F) / (std::sqrt(2.0) * F);
  for (double factor : {0.99, 1.01}) {
    StepConfiguration c = BlockOnTable(8);
    c.mating = Press(-Vec3::UnitZ(), Vec3(0, 0, 0.1), F, factor * tau_star);
    const WrenchCheck check = MustCheck(c);
    EXPECT_EQ(check.vertex_count, 4);
    EXPECT_EQ(check.feasible, factor < 1.0) << factor;
    if (factor < 1.0) {
      EXPECT_NEAR(Load(check, SupportKind::kTable, 0).utilisation, factor, 1e-9);
    } else {
      EXPECT_EQ(check.failing_vertex_count, 4);
      EXPECT_NE(check.reason.find("slides"), std::string::npos) << check.reason;
      EXPECT_NE(check.reason.find("vertex 1/4 (transverse +x -y)"), std::string::npos)
          << check.reason;
    }
  }
}

// A 4-edge pyramid (the default) is the inscribed diamond |fx| + |fy| <= mu N: conservative
// along the diagonals, so the diagonal corner fails at half the sideways force per component.
TEST(WrenchTable, FourEdgePyramidIsConservativeAlongDiagonals) {
  const double F = 10.0;
  const double tau_star = kMu * (kG + F) / (2.0 * F);
  for (double factor : {0.99, 1.01}) {
    StepConfiguration c = BlockOnTable(4);
    c.mating = Press(-Vec3::UnitZ(), Vec3(0, 0, 0.1), F, factor * tau_star);
    EXPECT_EQ(MustCheck(c).feasible, factor < 1.0) << factor;
  }
}

// Beyond friction a two-finger gripper at the block's centre braces it: it pushes down (more
// normal force, more friction) and sideways, each force component up to 5 N. Diagonal capacity:
// mu (m g + F + 5) + 5 sqrt(2).
TEST(WrenchTable, GripperBracesWithinItsLimits) {
  const double F = 10.0;
  const double limit = 5.0;
  const double tau_star = (kMu * (kG + F + limit) + limit * std::sqrt(2.0)) / (std::sqrt(2.0) * F);
  const double tau_friction = kMu * (kG + F) / (std::sqrt(2.0) * F);
  ASSERT_GT(0.99 * tau_star, tau_friction);
  for (double factor : {0.99, 1.01}) {
    StepConfiguration c = BlockOnTable(8);
    c.mating = Press(-Vec3::UnitZ(), Vec3(0, 0, 0.1), F, factor * tau_star);
    WrenchGripper g;
    g.name = "r1";
    g.body = 0;
    g.X_WG = At(Vec3(0, 0, 0.05));
    g.assembly_limits = g.transport_limits = Box(limit, 10.0);
    c.grippers.push_back(g);
    const WrenchCheck braced = MustCheck(c);
    EXPECT_EQ(braced.feasible, factor < 1.0) << factor;
    if (factor < 1.0) {
      // Nearly every force component is needed: utilisation just under 1.
      EXPECT_GT(braced.utilisation, 0.95);
      EXPECT_LE(braced.utilisation, 1.0);
      EXPECT_NEAR(Load(braced, SupportKind::kGripper, 0).utilisation, braced.utilisation, 1e-9);
    }
    c.grippers.clear();
    EXPECT_FALSE(MustCheck(c).feasible) << "without the brace " << factor;
  }
}

// Vacuum cup holding a 0.5 kg part from the side (cup axis z_G = +x_W), centre of mass at the
// cup: gravity is transverse to the cup.
StepConfiguration VacuumFromSide() {
  StepConfiguration c;
  c.bodies.push_back({"seat", 0.5, Vec3(0.3, 0.2, 1.0)});
  c.grippers.push_back(MakeGripper("r1", 0, At(Vec3(0.3, 0.2, 1.0), RotY(std::numbers::pi / 2)),
                                   EndEffectorKind::kVacuum, WrenchLimits{}));
  return c;
}

TEST(WrenchVacuum, TransportTakesTransverseForceAssemblyDoesNot) {
  StepConfiguration c = VacuumFromSide();
  WrenchQuery transport;
  transport.gate = WrenchGate::kTransport;
  transport.accel_margin_mps2 = 0.0;
  const WrenchCheck carried = MustCheck(c, transport);
  EXPECT_TRUE(carried.feasible);
  // x_G = -z_W: holding up 0.5 g N is -4.905 N along x_G against the 67.4 N transport limit.
  EXPECT_NEAR(carried.utilisation, 0.5 * kG / 67.4, 1e-12);
  EXPECT_EQ(Load(carried, SupportKind::kGripper, 0).component, 0);

  // Assembly: the cup already holds the weight before the parts touch (as in transport); only
  // what the insertion adds must lie in the assembly box (F_z alone).
  WrenchQuery gravity;
  gravity.gate = WrenchGate::kAssembly;
  gravity.mode = MatingWrenchMode::kGravityOnly;
  const WrenchCheck held = MustCheck(c, gravity);
  EXPECT_TRUE(held.feasible) << held.reason;
  EXPECT_NEAR(held.utilisation, 0.5 * kG / 67.4, 1e-9);

  // A post held by a two-finger gripper below the seat; the seat is pressed down onto it.
  c.bodies.push_back({"post", 0.2, Vec3(0.3, 0.2, 0.9)});
  c.grippers.push_back(
      MakeGripper("r2", 1, At(Vec3(0.3, 0.2, 0.9)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
  MatingLoad m;
  m.moved = 0;
  m.base = 1;
  m.axis_W = -Vec3::UnitZ();  // Across the cup's axis: the cup would have to push sideways.
  m.p_WContact = Vec3(0.3, 0.2, 0.95);
  m.force_N = 10.0;
  c.mating = m;
  const WrenchCheck across = MustCheck(c);
  EXPECT_FALSE(across.feasible);
  EXPECT_EQ(across.reason,
            "assembly (nominal): the vacuum gripper 'r1' on 'seat' would need 10 N along x in "
            "assembly mode (limit 0)");
  ASSERT_FALSE(across.shortfalls.empty());
  EXPECT_EQ(across.shortfalls[0].kind, ShortfallKind::kGripperLimit);
  EXPECT_NEAR(across.shortfalls[0].needed, 10.0, 1e-9);  // x_G = -z_W

  // Along the cup's axis (+x_W = z_G) the push is allowed: 10 N of its 110 N, beside the weight
  // held along x_G (4.9 N of 67.4 N).
  c.mating->axis_W = Vec3::UnitX();
  c.mating->p_WContact = Vec3(0.35, 0.2, 1.0);  // On the cup's axis: no moment.
  const WrenchCheck along = MustCheck(c);
  EXPECT_TRUE(along.feasible) << along.reason;
  EXPECT_NEAR(Load(along, SupportKind::kGripper, 0).utilisation, 10.0 / 110.0, 1e-9);
}

TEST(WrenchVacuum, TransportWithAccelerationMargin) {
  // Cup from above (z_G = -z_W) carrying 0.5 kg: 8 acceleration vertices of +-2 m/s^2.
  StepConfiguration c;
  c.bodies.push_back({"seat", 0.5, Vec3(0, 0, 1.0)});
  c.grippers.push_back(MakeGripper("r1", 0, At(Vec3(0, 0, 1.0), RotX(std::numbers::pi)),
                                   EndEffectorKind::kVacuum, WrenchLimits{}));
  WrenchQuery q;
  q.gate = WrenchGate::kTransport;
  q.accel_margin_mps2 = 2.0;
  const WrenchCheck check = MustCheck(c, q);
  EXPECT_TRUE(check.feasible);
  EXPECT_EQ(check.vertex_count, 8);
  // Worst: accelerating up, 0.5 (g + 2) N along z against 110 N.
  EXPECT_NEAR(check.utilisation, 0.5 * (kG + 2.0) / 110.0, 1e-12);
  EXPECT_TRUE(check.worst_vertex_label.ends_with("+z")) << check.worst_vertex_label;
}

// Inserting a part held by a vacuum cup from above: the axial push is fine in assembly mode, a
// transverse component is not.
// A peg on a vacuum cup mated into a seat held by fingers, in the air.
StepConfiguration CupPegIntoHeldSeat(double transverse) {
  StepConfiguration c;
  c.bodies.push_back({"peg", 0.5, Vec3(0, 0, 0.2)});
  c.bodies.push_back({"seat", 1.0, Vec3(0, 0, 0.05)});
  c.grippers.push_back(MakeGripper("r1", 0, At(Vec3(0, 0, 0.25), RotX(std::numbers::pi)),
                                   EndEffectorKind::kVacuum, WrenchLimits{}));
  c.grippers.push_back(
      MakeGripper("r2", 1, At(Vec3(0, 0, 0.05)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
  MatingLoad m;
  m.moved = 0;
  m.base = 1;
  m.axis_W = -Vec3::UnitZ();
  m.p_WContact = Vec3(0, 0, 0.1);
  m.force_N = 10.0;
  m.transverse_fraction = transverse;
  c.mating = m;
  return c;
}

TEST(WrenchVacuum, AssemblyModeRejectsTransverseMatingForce) {
  StepConfiguration c = CupPegIntoHeldSeat(0.0);
  const WrenchCheck axial = MustCheck(c);
  EXPECT_TRUE(axial.feasible) << axial.reason;
  // The cup pushes the peg down with F - m g = 10 - 4.905 N (z_G points down) of its 110 N.
  EXPECT_NEAR(Load(axial, SupportKind::kGripper, 0).utilisation, (10.0 - 0.5 * kG) / 110.0, 1e-12);

  c.mating->transverse_fraction = 0.1;
  const WrenchCheck transverse = MustCheck(c);
  EXPECT_FALSE(transverse.feasible);
  EXPECT_EQ(transverse.vertex_count, 4);
  EXPECT_EQ(transverse.failing_vertex_count, 4);
  EXPECT_NE(transverse.reason.find("assembly: vertex 1/4 (transverse +x -y): the vacuum gripper "
                                   "'r1' on 'peg' would need 1 N along"),
            std::string::npos)
      << transverse.reason;
  EXPECT_NE(transverse.reason.find("in assembly mode (limit 0)"), std::string::npos);
  EXPECT_NE(transverse.reason.find("(3 more of the 4 vertices fail)"), std::string::npos);
}

// A search needs a yes or no: with first_failure_suffices the check stops at the first failing
// vertex, gives the same verdict and explains that vertex; the next check starts there. A check
// that passes still asks every vertex, each only up to a load factor of 1: its utilisation is
// reported as 1, the reference's is the least (below 1).
TEST(WrenchVacuum, FirstFailureSufficesGivesTheSameVerdictWithFewerLps) {
  StepConfiguration c = CupPegIntoHeldSeat(0.0);
  c.mating->transverse_fraction = 0.1;
  WrenchChecker full(WrenchOptions{});
  WrenchChecker first(WrenchOptions{.first_failure_suffices = true});
  const Result<WrenchCheck> all = full.Check(c, {});
  const Result<WrenchCheck> one = first.Check(c, {});
  ASSERT_TRUE(all && one);
  EXPECT_FALSE(all->feasible);
  EXPECT_FALSE(one->feasible);
  EXPECT_EQ(all->failing_vertex_count, 4);
  EXPECT_EQ(one->failing_vertex_count, 1);
  EXPECT_EQ(one->worst_vertex, 0);
  EXPECT_NE(one->reason.find("assembly: vertex 1/4 (transverse +x -y): the vacuum gripper 'r1' on "
                             "'peg' would need 1 N along"),
            std::string::npos)
      << one->reason;
  EXPECT_EQ(one->reason.find("more of the"), std::string::npos) << one->reason;
  EXPECT_LT(first.lp_solves(), full.lp_solves());

  // The axial insertion passes: every vertex is asked, the verdict as without the option.
  c.mating->transverse_fraction = 0.0;
  const std::uint64_t before = first.lp_solves();
  const Result<WrenchCheck> pass = first.Check(c, {});
  const Result<WrenchCheck> reference = full.Check(c, {});
  ASSERT_TRUE(pass && reference);
  EXPECT_TRUE(pass->feasible);
  EXPECT_TRUE(reference->feasible);
  EXPECT_EQ(pass->utilisation, 1.0);
  EXPECT_LT(reference->utilisation, 1.0);
  EXPECT_EQ(first.lp_solves() - before, static_cast<std::uint64_t>(reference->vertex_count) + 1);
}

// top (held) -- compression-only connection -- bottom <- peg inserted along the axis. The
// connection frame's z points from top into bottom (down): top pressing bottom down is
// compression, top pulling it up is tension.
StepConfiguration ConnectionStack(const Vec3& axis, bool compression_only) {
  StepConfiguration c;
  c.bodies.push_back({"top", 0.2, Vec3(0, 0, 0.6)});
  c.bodies.push_back({"bottom", 0.1, Vec3(0, 0, 0.45)});
  c.bodies.push_back({"peg", 0.1, Vec3(0, 0, 0.3)});
  const WrenchBox box = Project{}.connection_limits;
  c.connections.push_back({0, 1, At(Vec3(0, 0, 0.5), RotX(std::numbers::pi)),
                           compression_only ? CompressionOnlyZ(box) : BoundsFromBox(box), ""});
  c.grippers.push_back(
      MakeGripper("r1", 0, At(Vec3(0, 0, 0.6)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
  c.grippers.push_back(
      MakeGripper("r2", 2, At(Vec3(0, 0, 0.3)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
  MatingLoad m;
  m.moved = 2;
  m.base = 1;
  m.axis_W = axis;
  m.p_WContact = Vec3(0, 0, 0.4);
  m.force_N = 10.0;
  c.mating = m;
  return c;
}

TEST(WrenchConnection, CompressionOnlyHoldsCompression) {
  const WrenchCheck check = MustCheck(ConnectionStack(Vec3::UnitZ(), true));
  EXPECT_TRUE(check.feasible) << check.reason;
  // Bottom: +10 N up from the peg, 0.981 N down: the connection presses 9.019 N of 200 N.
  EXPECT_NEAR(Load(check, SupportKind::kConnection, 0).utilisation, (10.0 - 0.1 * kG) / 200.0,
              1e-12);
  EXPECT_EQ(Load(check, SupportKind::kConnection, 0).component, 2);
  // Peg gripper pushes 10 N + its weight: the largest utilisation of the step, of 50 N.
  EXPECT_NEAR(check.utilisation, (10.0 + 0.1 * kG) / 50.0, 1e-12);
  EXPECT_NEAR(Load(check, SupportKind::kGripper, 1).utilisation, (10.0 + 0.1 * kG) / 50.0, 1e-12);
  // Top gripper: the top's weight plus the connection's push, 9.019 - 1.962 N up.
  EXPECT_NEAR(Load(check, SupportKind::kGripper, 0).utilisation, (10.0 - 0.3 * kG) / 50.0, 1e-12);
}

TEST(WrenchConnection, CompressionOnlyFailsInTension) {
  const WrenchCheck tension = MustCheck(ConnectionStack(-Vec3::UnitZ(), true));
  EXPECT_FALSE(tension.feasible);
  EXPECT_NE(tension.reason.find("the connection between 'top' and 'bottom' would need 11 N "
                                "along -z (limit 0: it takes compression only)"),
            std::string::npos)
      << tension.reason;
  ASSERT_FALSE(tension.shortfalls.empty());
  EXPECT_EQ(tension.shortfalls[0].kind, ShortfallKind::kConnectionLimit);
  EXPECT_NEAR(tension.shortfalls[0].needed, -(10.0 + 0.1 * kG), 1e-9);
  // A two-sided connection takes the same tension.
  EXPECT_TRUE(MustCheck(ConnectionStack(-Vec3::UnitZ(), false)).feasible);
}

TEST(WrenchModes, LambdaZeroEqualsGravityOnly) {
  for (bool compression_only : {true, false}) {
    StepConfiguration c = ConnectionStack(-Vec3::UnitZ(), compression_only);
    c.mating->transverse_fraction = 0.2;
    c.mating->offset_m = 0.01;
    WrenchQuery zero;
    zero.lambda = 0.0;
    WrenchQuery gravity;
    gravity.mode = MatingWrenchMode::kGravityOnly;
    const WrenchCheck a = MustCheck(c, zero);
    const WrenchCheck b = MustCheck(c, gravity);
    EXPECT_EQ(a.feasible, b.feasible);
    EXPECT_EQ(a.utilisation, b.utilisation);
    EXPECT_EQ(a.vertex_count, 1);
    EXPECT_EQ(a.vertex_count, b.vertex_count);
    EXPECT_EQ(a.reason, b.reason);
    ASSERT_EQ(a.supports.size(), b.supports.size());
    for (std::size_t i = 0; i < a.supports.size(); ++i) {
      EXPECT_EQ(a.supports[i].utilisation, b.supports[i].utilisation);
      EXPECT_EQ(a.supports[i].component, b.supports[i].component);
    }
  }
  // And lambda scales: at lambda = 0.5 the tension is 5 + 0.981 N.
  WrenchQuery half;
  half.lambda = 0.5;
  const WrenchCheck h = MustCheck(ConnectionStack(-Vec3::UnitZ(), true), half);
  ASSERT_FALSE(h.shortfalls.empty());
  EXPECT_NEAR(h.shortfalls[0].needed, -(5.0 + 0.1 * kG), 1e-9);
}

TEST(WrenchModes, NoneAlwaysPasses) {
  StepConfiguration c = BlockOnTable();
  c.mating = Press(Vec3::UnitZ(), Vec3(0, 0, 0.1), 100.0);
  WrenchQuery q;
  q.mode = MatingWrenchMode::kNone;
  const WrenchCheck check = MustCheck(c, q);
  EXPECT_TRUE(check.feasible);
  EXPECT_EQ(check.vertex_count, 0);
}

TEST(WrenchUtilisation, SingleGripperWithOffsetCentreOfMass) {
  // 1 kg held by a two-finger gripper 0.1 m from its centre of mass along x: Fz = 9.81 N of 50,
  // My = 0.981 N m of 4.5.
  StepConfiguration c;
  c.bodies.push_back({"leg", 1.0, Vec3(0.1, 0, 1.0)});
  c.grippers.push_back(
      MakeGripper("r1", 0, At(Vec3(0, 0, 1.0)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
  WrenchQuery q;
  q.gate = WrenchGate::kRelease;
  const WrenchCheck check = MustCheck(c, q);
  EXPECT_TRUE(check.feasible);
  EXPECT_NEAR(check.utilisation, 0.981 / 4.5, 1e-12);
  const SupportLoad& load = Load(check, SupportKind::kGripper, 0);
  EXPECT_NEAR(load.utilisation, 0.981 / 4.5, 1e-12);
  EXPECT_EQ(load.component, 4);
}

TEST(WrenchUtilisation, TwoGrippersShareEvenly) {
  // Minimising the largest utilisation splits the weight: 4.905 N of 50 N each.
  StepConfiguration c;
  c.bodies.push_back({"seat", 1.0, Vec3(0, 0, 1.0)});
  for (double x : {-0.1, 0.1}) {
    c.grippers.push_back(
        MakeGripper("r", 0, At(Vec3(x, 0, 1.0)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
  }
  WrenchQuery q;
  q.gate = WrenchGate::kRelease;
  const WrenchCheck check = MustCheck(c, q);
  EXPECT_TRUE(check.feasible);
  EXPECT_NEAR(check.utilisation, kG / 2.0 / 50.0, 1e-12);
  EXPECT_NEAR(Load(check, SupportKind::kGripper, 0).utilisation, kG / 2.0 / 50.0, 1e-12);
  EXPECT_NEAR(Load(check, SupportKind::kGripper, 1).utilisation, kG / 2.0 / 50.0, 1e-12);
}

TEST(WrenchUtilisation, ScrewTorqueAgainstMzLimit) {
  // Screwing with torque T about the axis: the moved part's gripper reacts T (limit Mz 3 N m).
  for (double torque : {2.9, 3.1}) {
    StepConfiguration c;
    c.bodies.push_back({"leg", 0.0, Vec3(0, 0, 0.2)});
    c.bodies.push_back({"seat", 0.0, Vec3(0, 0, 0.0)});
    c.grippers.push_back(
        MakeGripper("r1", 0, At(Vec3(0, 0, 0.2)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
    WrenchGripper fixed;
    fixed.body = 1;
    fixed.assembly_limits = fixed.transport_limits = UnboundedWrench();
    c.grippers.push_back(fixed);
    MatingLoad m;
    m.moved = 0;
    m.base = 1;
    m.axis_W = -Vec3::UnitZ();
    m.p_WContact = Vec3(0, 0, 0.1);
    m.force_N = 0.0;
    m.torque_Nm = torque;
    c.mating = m;
    const WrenchCheck check = MustCheck(c);
    EXPECT_EQ(check.feasible, torque < 3.0);
    EXPECT_NEAR(Load(check, SupportKind::kGripper, 0).utilisation, torque / 3.0, 1e-12);
    EXPECT_EQ(Load(check, SupportKind::kGripper, 0).component, 5);
    // The unlimited holder of the seat counts 0.
    EXPECT_EQ(Load(check, SupportKind::kGripper, 1).utilisation, 0.0);
  }
}

TEST(WrenchGates, RestNeedsCentreOfMassOverThePolygon) {
  StepConfiguration c = BlockOnTable();
  WrenchQuery q;
  q.gate = WrenchGate::kRest;
  // A gripper is ignored while resting.
  c.grippers.push_back(
      MakeGripper("r1", 0, At(Vec3(0, 0, 0.05)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
  const WrenchCheck stable = MustCheck(c, q);
  EXPECT_TRUE(stable.feasible);
  EXPECT_EQ(stable.supports.size(), 1u);
  c.bodies[0].p_WBcm = Vec3(0.15, 0, 0.05);  // Outside the 0.25 m square.
  const WrenchCheck tips = MustCheck(c, q);
  EXPECT_FALSE(tips.feasible);
  EXPECT_NE(tips.reason.find("it tips"), std::string::npos) << tips.reason;
}

TEST(WrenchGates, ReleaseWithRemainingSupports) {
  // Two grippers hold a 1 kg seat; releasing one leaves the other to take the moment.
  StepConfiguration c;
  c.bodies.push_back({"seat", 1.0, Vec3(0, 0, 1.0)});
  c.grippers.push_back(
      MakeGripper("r1", 0, At(Vec3(-0.6, 0, 1.0)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
  c.grippers.push_back(
      MakeGripper("r2", 0, At(Vec3(0.6, 0, 1.0)), EndEffectorKind::kTwoFinger, WrenchLimits{}));
  WrenchQuery q;
  q.gate = WrenchGate::kRelease;
  EXPECT_TRUE(MustCheck(c, q).feasible);
  c.grippers.pop_back();  // r2 lets go: 9.81 N at 0.6 m = 5.9 N m > 4.5 N m.
  const WrenchCheck check = MustCheck(c, q);
  EXPECT_FALSE(check.feasible);
  EXPECT_NE(check.reason.find("release (gravity): the two-finger gripper 'r1' on 'seat' would "
                              "need 5.89 N m about -y (limit 4.5)"),
            std::string::npos)
      << check.reason;
}

TEST(WrenchGates, TransportIgnoresTheTable) {
  StepConfiguration c = BlockOnTable();
  WrenchQuery q;
  q.gate = WrenchGate::kTransport;
  const WrenchCheck check = MustCheck(c, q);
  EXPECT_FALSE(check.feasible);
  EXPECT_NE(check.reason.find("nothing balances 'block'"), std::string::npos) << check.reason;
  EXPECT_TRUE(check.supports.empty());
}

TEST(WrenchVertices, CountsLabelsAndSigns) {
  StepConfiguration c;
  c.bodies.push_back({"peg", 0.0, Vec3(0, 0, 0.2)});
  c.bodies.push_back({"seat", 0.0, Vec3(0, 0, 0.0)});
  MatingLoad m;
  m.moved = 0;
  m.base = 1;
  m.axis_W = -Vec3::UnitZ();
  m.p_WContact = Vec3(0, 0, 0.1);
  m.force_N = 10.0;
  c.mating = m;
  Result<std::vector<WrenchVertex>> nominal = UncertaintyVertices(c, {});
  ASSERT_TRUE(nominal);
  ASSERT_EQ(nominal->size(), 1u);
  // The base is pushed along the axis, the moved body back.
  EXPECT_TRUE((*nominal)[0].w_ext_W[1].head<3>().isApprox(Vec3(0, 0, -10)));
  EXPECT_TRUE((*nominal)[0].w_ext_W[0].head<3>().isApprox(Vec3(0, 0, 10)));

  c.mating->transverse_fraction = 0.1;
  c.mating->offset_m = 0.005;
  Result<std::vector<WrenchVertex>> all = UncertaintyVertices(c, {});
  ASSERT_TRUE(all);
  ASSERT_EQ(all->size(), 16u);
  EXPECT_EQ((*all)[0].label, "transverse +x -y, offset +x -y");
  EXPECT_EQ((*all)[15].label, "transverse -x +y, offset -x +y");
  for (const WrenchVertex& v : *all) {
    // Action and reaction: the mating wrench sums to zero over the two bodies.
    EXPECT_LT((v.w_ext_W[0] + v.w_ext_W[1]).norm(), 1e-12);
    EXPECT_NEAR(v.w_ext_W[1].head<2>().cwiseAbs().maxCoeff(), 1.0, 1e-12);
  }
  // Moment of the first vertex about O = 0: force (1, -1, -10) at (0.005, -0.005, 0.1).
  const Vec3 expected = Vec3(0.005, -0.005, 0.1).cross(Vec3(1, -1, -10));
  EXPECT_TRUE((*all)[0].w_ext_W[1].tail<3>().isApprox(expected));
}

TEST(WrenchInput, MalformedConfigurationsAreInvalidInput) {
  StepConfiguration c = BlockOnTable();
  c.tables[0].body = 3;
  Result<WrenchCheck> r = CheckWrench(c);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(r.error().message.find("tables[0].body"), std::string::npos);

  c = BlockOnTable();
  WrenchGripper g;
  g.assembly_limits = Box(5, 1);
  g.transport_limits = Box(5, 1);
  g.transport_limits.lower[2] = 1.0;  // Does not contain 0.
  c.grippers.push_back(g);
  r = CheckWrench(c);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);

  c = BlockOnTable();
  c.bodies[0].mass_kg = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(CheckWrench(c));
  c = BlockOnTable();
  c.tables[0].pyramid_edges = 3;
  EXPECT_FALSE(CheckWrench(c));
  c = BlockOnTable();
  WrenchQuery q;
  q.lambda = -1.0;
  EXPECT_FALSE(CheckWrench(c, q));
}

TEST(WrenchInput, OneSidedLimits) {
  // A cup that pushes freely (no upper bound along z_G) but pulls at most 10 N.
  StepConfiguration c;
  c.bodies.push_back({"plate", 2.0, Vec3(0, 0, 1.0)});
  WrenchGripper cup;
  cup.name = "r1";
  cup.kind = EndEffectorKind::kVacuum;
  cup.X_WG = At(Vec3(0, 0, 1.0), RotX(std::numbers::pi));  // z_G down, into the plate.
  cup.assembly_limits = Box(0, 0);
  cup.assembly_limits.lower[2] = -10.0;
  cup.assembly_limits.upper[2] = kInf;
  cup.transport_limits = cup.assembly_limits;
  c.grippers.push_back(cup);
  WrenchQuery q;
  q.gate = WrenchGate::kRelease;
  // Holding 19.6 N up is a pull (-z_G): over the 10 N limit.
  const WrenchCheck hang = MustCheck(c, q);
  EXPECT_FALSE(hang.feasible);
  EXPECT_NEAR(hang.utilisation, 2.0 * kG / 10.0, 1e-9);
  // Gravity reversed (pressing into the cup) is free: utilisation 0.
  c.gravity_W = Vec3(0, 0, kG);
  const WrenchCheck push = MustCheck(c, q);
  EXPECT_TRUE(push.feasible);
  EXPECT_EQ(push.utilisation, 0.0);
}

StepConfiguration TwoGrippersAndTable() {
  StepConfiguration c = BlockOnTable(8);
  c.bodies[0].name = "seat";
  // Dyadic x, y coordinates: shifting by whole metres keeps relative positions bit-identical.
  c.bodies.push_back({"leg", 0.3, Vec3(0.03125, 0.015625, 0.25)});
  c.grippers.push_back(MakeGripper("r1", 1, At(Vec3(0.03125, 0.015625, 0.3), RotX(0.1)),
                                   EndEffectorKind::kTwoFinger, WrenchLimits{}));
  c.grippers.push_back(MakeGripper("r2", 0, At(Vec3(0.125, 0.0, 0.05), RotY(0.2)),
                                   EndEffectorKind::kVacuum, WrenchLimits{}));
  MatingLoad m;
  m.moved = 1;
  m.base = 0;
  m.axis_W = -Vec3::UnitZ();
  m.p_WContact = Vec3(0, 0, 0.1);
  m.force_N = 10.0;
  m.transverse_fraction = 0.3;
  m.offset_m = 0.005;
  c.mating = m;
  return c;
}

TEST(WrenchDeterminism, RepeatedCallsAndCacheGiveIdenticalAnswers) {
  for (double transverse : {0.3, 5.0}) {  // Feasible, then not (50 N > 39.7 N on the leg).
    StepConfiguration c = TwoGrippersAndTable();
    c.mating->transverse_fraction = transverse;
    WrenchChecker checker;
    Result<WrenchCheck> first = checker.Check(c);
    ASSERT_TRUE(first);
    EXPECT_EQ(first->feasible, transverse < 1.0) << first->reason;
    auto same = [&](const WrenchCheck& a, const WrenchCheck& b) {
      EXPECT_EQ(a.feasible, b.feasible);
      EXPECT_EQ(a.utilisation, b.utilisation);
      EXPECT_EQ(a.worst_vertex, b.worst_vertex);
      EXPECT_EQ(a.reason, b.reason);
      ASSERT_EQ(a.supports.size(), b.supports.size());
      for (std::size_t i = 0; i < a.supports.size(); ++i) {
        EXPECT_EQ(a.supports[i].utilisation, b.supports[i].utilisation);
        EXPECT_EQ(a.supports[i].vertex, b.supports[i].vertex);
      }
    };
    for (int i = 0; i < 3; ++i) same(*first, *checker.Check(c));
    WrenchChecker other;
    same(*first, *other.Check(c));
    same(*first, *checker.CheckCached(c));
    same(*first, *checker.CheckCached(c));
    EXPECT_EQ(checker.cache_hits(), 1u);
    same(*first, *checker.CheckCached(42, c));
    same(*first, *checker.CheckCached(42, c));
    EXPECT_EQ(checker.cache_hits(), 2u);
  }
}

TEST(WrenchCache, TranslatedCopyHitsAndChangesMiss) {
  StepConfiguration c = TwoGrippersAndTable();
  WrenchChecker checker;
  ASSERT_TRUE(checker.CheckCached(c));
  // Shift everything by a power of two: relative positions are bit-identical.
  StepConfiguration moved = c;
  const Vec3 shift(4.0, -2.0, 0.0);
  for (WrenchBody& b : moved.bodies) b.p_WBcm += shift;
  for (WrenchGripper& g : moved.grippers) g.X_WG.translation() += shift;
  for (Vec3& v : moved.tables[0].p_WV) v += shift;
  moved.mating->p_WContact += shift;
  ASSERT_TRUE(checker.CheckCached(moved));
  EXPECT_EQ(checker.cache_hits(), 1u);
  // Any change of the question is a miss.
  StepConfiguration heavier = c;
  heavier.bodies[1].mass_kg += 0.1;
  ASSERT_TRUE(checker.CheckCached(heavier));
  WrenchQuery q;
  q.lambda = 0.5;
  ASSERT_TRUE(checker.CheckCached(c, q));
  EXPECT_EQ(checker.cache_hits(), 1u);
  EXPECT_EQ(checker.cache_misses(), 3u);
  checker.ClearCache();
  ASSERT_TRUE(checker.CheckCached(c));
  EXPECT_EQ(checker.cache_misses(), 1u);
}

TEST(WrenchBackends, ClpGivesTheSameAnswerOnTheHandCases) {
  WrenchOptions clp;
  clp.backend = WrenchLpBackend::kClp;
  const StepConfiguration configs[] = {TwoGrippersAndTable(), ConnectionStack(Vec3::UnitZ(), true),
                                       ConnectionStack(-Vec3::UnitZ(), true), VacuumFromSide()};
  for (const StepConfiguration& c : configs) {
    const WrenchCheck a = MustCheck(c);
    const WrenchCheck b = MustCheck(c, {}, clp);
    EXPECT_EQ(a.feasible, b.feasible);
    if (std::isinf(a.utilisation)) {
      EXPECT_TRUE(std::isinf(b.utilisation));
    } else {
      EXPECT_NEAR(a.utilisation, b.utilisation, 1e-7 * (1.0 + a.utilisation));
    }
  }
}

// The whole configuration turned by R about the world origin (gravity stays down).
StepConfiguration Turned(const StepConfiguration& c, const Mat3& R) {
  StepConfiguration out = c;
  for (WrenchBody& b : out.bodies) b.p_WBcm = R * b.p_WBcm;
  for (WrenchGripper& g : out.grippers) {
    g.X_WG.translation() = R * g.X_WG.translation();
    g.X_WG.linear() = R * g.X_WG.linear();
  }
  if (out.mating) {
    out.mating->axis_W = R * out.mating->axis_W;
    out.mating->p_WContact = R * out.mating->p_WContact;
  }
  return out;
}

// A cup takes no transverse force while mating (paper's vacuum table), so a transverse mating
// bound fails in every orientation of the pair, and the relaxation says so without gravity.
TEST(WrenchRelaxation, CupUnderTransverseMatingFailsInEveryOrientation) {
  const StepConfiguration c = CupPegIntoHeldSeat(0.1);
  ASSERT_TRUE(HeldThenMated(c));
  const StepConfiguration relaxed = MatingIncrementRelaxation(c);
  EXPECT_EQ(relaxed.gravity_W, Vec3::Zero());
  EXPECT_NEAR(relaxed.mating->transverse_fraction, 0.1 / std::numbers::sqrt2, 1e-15);
  // Transport boxes widened to the difference of two wrenches within them: 2x a symmetric box.
  EXPECT_EQ(relaxed.grippers[0].transport_limits.upper, 2.0 * c.grippers[0].transport_limits.upper);
  EXPECT_EQ(relaxed.grippers[0].assembly_limits, c.grippers[0].assembly_limits);
  EXPECT_FALSE(MustCheck(relaxed).feasible);
  for (const Mat3& R : {Mat3(Mat3::Identity()), RotX(std::numbers::pi / 2), RotY(0.7),
                        RotX(std::numbers::pi), Mat3(RotY(-1.2) * RotX(0.4))}) {
    EXPECT_FALSE(MustCheck(Turned(c, R)).feasible);
  }
  // Along the axis alone it holds, and so does the relaxation.
  EXPECT_TRUE(MustCheck(CupPegIntoHeldSeat(0.0)).feasible);
  EXPECT_TRUE(MustCheck(MatingIncrementRelaxation(CupPegIntoHeldSeat(0.0))).feasible);
}

// The relaxation is necessary: over random pairs in the air (cups and fingers, masses, grasp
// points, transverse and offset bounds, tilted axes) and random orientations, whenever the full
// check holds in some orientation, the relaxation holds.
TEST(WrenchRelaxation, NeverRefusesWhatSomeOrientationHolds) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int held = 0, refused_by_relaxation = 0;
  for (int trial = 0; trial < 150; ++trial) {
    StepConfiguration c;
    c.bodies.push_back(
        {"moved", 0.2 + 0.8 * (u(rng) + 1.0), Vec3(0.05 * u(rng), 0.05 * u(rng), 0.15)});
    c.bodies.push_back({"base", 0.5 + (u(rng) + 1.0), Vec3(0.05 * u(rng), 0.05 * u(rng), 0.0)});
    for (int b = 0; b < 2; ++b) {
      const bool cup = b == 0 || u(rng) > 0.3;
      const Mat3 R = Eigen::AngleAxisd(0.2 * u(rng), Vec3(u(rng), u(rng), 0.0).normalized())
                         .toRotationMatrix() *
                     (b == 0 ? RotX(std::numbers::pi) : Mat3(Mat3::Identity()));
      const Vec3 p = c.bodies[b].p_WBcm + Vec3(0.04 * u(rng), 0.04 * u(rng), b == 0 ? 0.05 : -0.05);
      c.grippers.push_back(MakeGripper("r" + std::to_string(b), b, At(p, R),
                                       cup ? EndEffectorKind::kVacuum : EndEffectorKind::kTwoFinger,
                                       WrenchLimits{}));
    }
    MatingLoad m;
    m.moved = 0;
    m.base = 1;
    // Mostly along the cup's z (what a cup can push), sometimes tilted off it.
    m.axis_W = (c.grippers[0].X_WG.linear().col(2) +
                (u(rng) > 0.0 ? Vec3::Zero() : Vec3(0.2 * u(rng), 0.2 * u(rng), 0.0)))
                   .normalized();
    // On the cup's line mostly (a cup takes no moment while mating), sometimes off it.
    m.p_WContact = c.grippers[0].X_WG.translation() + 0.07 * m.axis_W +
                   (u(rng) > 0.0 ? Vec3::Zero() : Vec3(0.01 * u(rng), 0.01 * u(rng), 0.0));
    m.force_N = 5.0 + 10.0 * (u(rng) + 1.0);
    m.transverse_fraction = u(rng) > 0.0 ? 0.0 : 0.1 * (u(rng) + 1.0);
    m.offset_m = u(rng) > 0.0 ? 0.0 : 0.005 * (u(rng) + 1.0);
    c.mating = m;
    ASSERT_TRUE(HeldThenMated(c));
    const bool relaxed = MustCheck(MatingIncrementRelaxation(c)).feasible;
    for (int k = 0; k < 4; ++k) {
      const Mat3 R = Eigen::AngleAxisd((k == 0 ? 0.0 : 0.8) * u(rng),
                                       Vec3(u(rng), u(rng), u(rng)).normalized())
                         .toRotationMatrix();
      const bool full = MustCheck(Turned(c, R)).feasible;
      held += full ? 1 : 0;
      if (full) {
        EXPECT_TRUE(relaxed) << "trial " << trial << " orientation " << k;
      }
    }
    refused_by_relaxation += relaxed ? 0 : 1;
  }
  // Both verdicts occur, so the property was exercised.
  EXPECT_GT(held, 0);
  EXPECT_GT(refused_by_relaxation, 0);
}

}  // namespace
}  // namespace wrap
