// Straight Cartesian moves: the robots' TCPs follow given paths (lines, slerps), tracked sample by
// sample by IK on the start's branch, thinned to the fewest waypoints that keep one arm on its
// line, and checked for collisions along straight joint motion between the waypoints.

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "motion/segments_internal.h"
#include "robot/ik.h"
#include "robot/kinematics.h"

namespace wrap::detail {

std::vector<std::vector<JointVector>> SegmentBuilder::Track(
    const std::vector<int>& robots, const std::vector<JointVector>& q0,
    const std::vector<std::function<Iso3(double)>>& targets, int steps,
    const std::vector<JointVector>* goals, double tolerance_m) {
  std::vector<std::vector<JointVector>> out(steps + 1, std::vector<JointVector>(robots.size()));
  NumericIkOptions ik;
  ik.restarts = 0;
  ik.max_iterations = 100;
  ik.position_tolerance_m = tolerance_m;
  ik.rotation_tolerance_rad = 10.0 * tolerance_m;
  for (size_t i = 0; i < robots.size(); ++i) {
    const TaskRobot& r = w_.robots[robots[i]];
    JointVector q = q0[i];
    out[0][i] = q;
    // UR arms: the closed form on the start's branch (continuous away from singularities).
    const int branch = r.ur ? r.ur->BranchOf(r.chain, q) : -1;
    for (int k = 1; k <= steps; ++k) {
      const double s = static_cast<double>(k) / steps;
      const Iso3 X_BT = r.X_BW * targets[i](s);
      JointVector next;
      if (branch >= 0) {
        UrIkOptions options;
        options.q6_if_singular = q[5];
        const UrIkSolutions sols = r.ur->SolveTcp(X_BT, r.end_effector.X_FT, options);
        for (int c = 0; c < sols.count; ++c) {
          if (sols.branch[c] == branch) next = NearestEquivalent(r.chain, sols.q[c], q);
        }
        if (next.size() == 0) return {};
      } else {
        NumericIkRequest req;
        req.X_BT = X_BT;
        req.X_FT = r.end_effector.X_FT;
        // From the last sample, and from it nudged away from the joint limits (an arm stuck at a
        // limit finds the way round through its redundancy).
        JointVector centred = q;
        for (int j = 0; j < q.size(); ++j) {
          centred[j] += 0.15 * (0.5 * (r.chain.joints[j].lower + r.chain.joints[j].upper) - q[j]);
        }
        req.seeds = {q, centred};
        // A redundant arm drifts toward its goal joints where it has a choice.
        req.reference = goals ? JointVector(q0[i] + s * ((*goals)[i] - q0[i])) : q;
        auto sol = SolveNumericIk(r.chain, req, rng_, ik);
        if (!sol) {
          if (ctx_.Logs("motion")) {
            ctx_.Log("motion", StrFormat("track: %s step %d/%d: %s", r.name.c_str(), k, steps,
                                         sol.error().message.c_str()));
          }
          return {};
        }
        next = sol->q;
      }
      if ((next - q).cwiseAbs().maxCoeff() > kMaxTrackJump) {
        if (ctx_.Logs("motion")) {
          ctx_.Log("motion", StrFormat("track: %s step %d/%d: jump %.3f", r.name.c_str(), k, steps,
                                       (next - q).cwiseAbs().maxCoeff()));
        }
        return {};
      }
      q = next;
      out[k][i] = q;
    }
  }
  return Simplify(robots, std::move(out), std::min(tolerance_m, kTrackTolerance));
}

std::vector<std::function<Iso3(double)>> SegmentBuilder::ShiftedTcps(
    const std::vector<int>& robots, const std::vector<JointVector>& q, const Vec3& offset) const {
  std::vector<std::function<Iso3(double)>> targets;
  for (size_t i = 0; i < robots.size(); ++i) {
    targets.push_back([X0 = Tcp(robots[i], q[i]), offset](double s) {
      Iso3 X = X0;
      X.translation() += s * offset;
      return X;
    });
  }
  return targets;
}

std::vector<std::vector<JointVector>> SegmentBuilder::Simplify(
    const std::vector<int>& robots, std::vector<std::vector<JointVector>> path,
    double tolerance_m) const {
  // Arms that hold one object together keep every sample: where two grippers leave their
  // lines differently they pull on the object against each other (MuJoCo saw 50 N inside a
  // cross's base carried with 0.2 mm of tolerance, more than stop and go costs).
  if (path.size() <= 2 || robots.size() > 1) return path;
  // One arm may leave its Cartesian line by the tolerance (half a millimetre unless said).
  const double tol_m = tolerance_m;
  const double tol_rad = 10.0 * tolerance_m;
  std::vector<std::vector<Iso3>> X(path.size(), std::vector<Iso3>(robots.size()));
  for (size_t k = 0; k < path.size(); ++k) {
    for (size_t i = 0; i < robots.size(); ++i) X[k][i] = Tcp(robots[i], path[k][i]);
  }
  // The straight joint motion from a to b passes within the tolerance of every sample between.
  auto covers = [&](size_t a, size_t b) {
    for (size_t m = a + 1; m < b; ++m) {
      const double f = static_cast<double>(m - a) / static_cast<double>(b - a);
      for (size_t i = 0; i < robots.size(); ++i) {
        const Iso3 Xl = Tcp(robots[i], path[a][i] + f * (path[b][i] - path[a][i]));
        if ((Xl.translation() - X[m][i].translation()).norm() > tol_m) return false;
        if (Eigen::AngleAxisd(Xl.linear().transpose() * X[m][i].linear()).angle() > tol_rad) {
          return false;
        }
      }
    }
    return true;
  };
  std::vector<std::vector<JointVector>> out = {path.front()};
  size_t a = 0;
  while (a + 1 < path.size()) {
    size_t b = a + 1;
    while (b + 1 < path.size() && covers(a, b + 1)) ++b;
    out.push_back(path[b]);
    a = b;
  }
  return out;
}

bool SegmentBuilder::PathClear(const std::vector<int>& robots,
                               const std::vector<std::vector<JointVector>>& waypoints) {
  for (size_t k = 0; k < waypoints.size(); ++k) {
    const size_t prev = k == 0 ? 0 : k - 1;
    double span = 0.0;
    for (size_t i = 0; i < robots.size(); ++i) {
      span = std::max(span, (waypoints[k][i] - waypoints[prev][i]).cwiseAbs().maxCoeff());
    }
    const int steps =
        std::max(1, static_cast<int>(std::ceil(span * kRefine / opt_.resolution_rad)));
    for (int s = (k == 0 ? steps : 1); s <= steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      for (size_t i = 0; i < robots.size(); ++i) {
        scene_->SetRobot(robots[i],
                         waypoints[prev][i] + t * (waypoints[k][i] - waypoints[prev][i]));
      }
      if (scene_->Collides(robots)) {
        CollisionResult hit;
        scene_->cell().InCollision(&hit);
        const CollisionWorld& cw = scene_->cell().world();
        last_hit_ = "'" + cw.body_name(hit.first.body_a) + "' hits '" +
                    cw.body_name(hit.first.body_b) + "'";
        // The failure record's picture: the robots where they hit, the parts as set.
        last_hit_scene_ = CellNow();
        for (size_t i = 0; i < robots.size(); ++i) {
          last_hit_scene_.q[robots[i]] =
              waypoints[prev][i] + t * (waypoints[k][i] - waypoints[prev][i]);
        }
        last_hit_scene_.bodies = {cw.body_name(hit.first.body_a), cw.body_name(hit.first.body_b)};
        return false;
      }
    }
  }
  return true;
}

bool SegmentBuilder::Tight(int robot, const JointVector& q) {
  // A few small joint perturbations, the same every time.
  std::mt19937_64 g(0x7469676874);
  std::uniform_real_distribution<double> u(-kTightRad, kTightRad);
  int bad = 0;
  for (int t = 0; t < kTightSamples; ++t) {
    JointVector x = q;
    for (int j = 0; j < x.size(); ++j) x[j] += u(g);
    scene_->SetRobot(robot, x);
    bad += scene_->Collides(std::span<const int>(&robot, 1));
  }
  scene_->SetRobot(robot, q);
  return bad > kTightSamples / 8;
}

}  // namespace wrap::detail
