#include "motion/ompl_adapter.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/ScopedState.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/datastructures/NearestNeighborsLinear.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

namespace wrap {

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

Eigen::VectorXd ToVector(const ob::State* s, int dim) {
  const auto* v = s->as<ob::RealVectorStateSpace::StateType>();
  Eigen::VectorXd q(dim);
  for (int i = 0; i < dim; ++i) q[i] = v->values[i];
  return q;
}

// Uniform sampling from our own seeded generator (OMPL's global seed is process-wide).
class SeededSampler : public ob::RealVectorStateSampler {
 public:
  SeededSampler(const ob::StateSpace* space, std::uint64_t seed)
      : ob::RealVectorStateSampler(space) {
    rng_.setLocalSeed(static_cast<std::uint_fast32_t>(seed ^ (seed >> 32)));
  }
};

// Dense straight-line checks at the query's resolution (max-norm in joint space).
class DenseMotionValidator : public ob::MotionValidator {
 public:
  DenseMotionValidator(const ob::SpaceInformationPtr& si, const PathQuery& query, int dim,
                       long long* checks)
      : ob::MotionValidator(si), query_(query), dim_(dim), checks_(checks) {}

  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    const bool ok = StraightMotionValid(query_, ToVector(s1, dim_), ToVector(s2, dim_), checks_);
    ok ? ++valid_ : ++invalid_;
    return ok;
  }

  bool checkMotion(const ob::State* s1, const ob::State* s2,
                   std::pair<ob::State*, double>& last_valid) const override {
    const Eigen::VectorXd a = ToVector(s1, dim_);
    const Eigen::VectorXd b = ToVector(s2, dim_);
    const int steps =
        std::max(1, static_cast<int>(std::ceil((b - a).cwiseAbs().maxCoeff() / query_.resolution)));
    for (int k = 1; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      ++*checks_;
      if (!query_.valid(a + t * (b - a))) {
        const double t_ok = static_cast<double>(k - 1) / steps;
        if (last_valid.first != nullptr) {
          auto* v = last_valid.first->as<ob::RealVectorStateSpace::StateType>();
          for (int i = 0; i < dim_; ++i) v->values[i] = a[i] + t_ok * (b[i] - a[i]);
        }
        last_valid.second = t_ok;
        ++invalid_;
        return false;
      }
    }
    ++valid_;
    return true;
  }

 private:
  const PathQuery& query_;
  int dim_;
  long long* checks_;
};

// Point at arc-length parameter s along a polyline with cumulative lengths `cum`.
Eigen::VectorXd PointAt(const std::vector<Eigen::VectorXd>& path, const std::vector<double>& cum,
                        double s, size_t* segment) {
  size_t i = std::upper_bound(cum.begin(), cum.end(), s) - cum.begin();
  i = std::clamp<size_t>(i, 1, path.size() - 1);
  const double len = cum[i] - cum[i - 1];
  const double t = len > 0.0 ? (s - cum[i - 1]) / len : 0.0;
  *segment = i - 1;
  return path[i - 1] + std::clamp(t, 0.0, 1.0) * (path[i] - path[i - 1]);
}

std::vector<double> Cumulative(const std::vector<Eigen::VectorXd>& path) {
  std::vector<double> cum(path.size(), 0.0);
  for (size_t i = 1; i < path.size(); ++i) cum[i] = cum[i - 1] + (path[i] - path[i - 1]).norm();
  return cum;
}

// Every piece valid at the query's resolution.
bool PathValid(const PathQuery& query, const std::vector<Eigen::VectorXd>& path,
               long long* checks) {
  for (size_t i = 1; i < path.size(); ++i) {
    if (!StraightMotionValid(query, path[i - 1], path[i], checks)) return false;
  }
  return true;
}

void Shortcut(const PathQuery& query, std::vector<Eigen::VectorXd>& path, long long* checks) {
  // Greedy first: from each waypoint, straight to the farthest later one it sees. Few checks
  // succeed (each success is a full check of the new piece at the fine resolution), and it takes
  // most of what random shortcuts would.
  for (size_t i = 0; i + 2 < path.size(); ++i) {
    if (query.stop && query.stop()) return;
    for (size_t j = path.size() - 1; j >= i + 2; --j) {
      if (StraightMotionValid(query, path[i], path[j], checks)) {
        path.erase(path.begin() + static_cast<long>(i) + 1, path.begin() + static_cast<long>(j));
        break;
      }
    }
  }
  std::mt19937_64 rng(query.seed ^ 0x5c0ffee);
  for (int attempt = 0; attempt < query.shortcut_attempts && path.size() > 2; ++attempt) {
    if (query.stop && query.stop()) break;
    const std::vector<double> cum = Cumulative(path);
    const double total = cum.back();
    if (total <= 0.0) break;
    std::uniform_real_distribution<double> u(0.0, total);
    double s1 = u(rng);
    double s2 = u(rng);
    if (s1 > s2) std::swap(s1, s2);
    size_t i1 = 0;
    size_t i2 = 0;
    const Eigen::VectorXd p1 = PointAt(path, cum, s1, &i1);
    const Eigen::VectorXd p2 = PointAt(path, cum, s2, &i2);
    if (i1 == i2) continue;  // same straight piece: nothing to gain
    if (!StraightMotionValid(query, p1, p2, checks)) continue;
    std::vector<Eigen::VectorXd> shorter(path.begin(), path.begin() + i1 + 1);
    shorter.push_back(p1);
    shorter.push_back(p2);
    shorter.insert(shorter.end(), path.begin() + i2 + 1, path.end());
    path = std::move(shorter);
  }
  // Drop waypoints whose neighbours see each other, and duplicates.
  for (size_t i = 1; i + 1 < path.size();) {
    if ((path[i] - path[i - 1]).cwiseAbs().maxCoeff() < 1e-9 ||
        StraightMotionValid(query, path[i - 1], path[i + 1], checks)) {
      path.erase(path.begin() + i);
    } else {
      ++i;
    }
  }
}

}  // namespace

bool StraightMotionValid(const PathQuery& query, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                         long long* checks) {
  const double span = (b - a).cwiseAbs().maxCoeff();
  const int steps = std::max(1, static_cast<int>(std::ceil(span / query.resolution)));
  // Ends first, then coarse to fine: a collision in the middle is found early.
  std::vector<char> seen(steps + 1, 0);
  auto check = [&](int k) {
    if (seen[k]) return true;
    seen[k] = 1;
    if (checks) ++*checks;
    return query.valid(a + (static_cast<double>(k) / steps) * (b - a));
  };
  if (!check(0) || !check(steps)) return false;
  int stride = 1;
  while (stride * 2 < steps) stride *= 2;
  for (; stride >= 1; stride /= 2) {
    for (int k = stride; k < steps; k += stride) {
      if (!check(k)) return false;
    }
  }
  return true;
}

namespace {

// The query's start to its goal (or one of its other goals): the straight motion when it is
// valid, else RRT-Connect within the work budget; every piece valid at the final resolution, not
// shortcut.
PathAnswer Connect(const PathQuery& query) {
  PathAnswer out;
  const int dim = static_cast<int>(query.start.size());
  if (!query.valid(query.start)) {
    out.why = "the start configuration is in collision";
    return out;
  }
  ++out.checks;
  // The goals that are free (the given one first).
  std::vector<Eigen::VectorXd> goals;
  std::vector<int> goal_ids;
  for (size_t k = 0; k <= query.other_goals.size(); ++k) {
    const Eigen::VectorXd& g = k == 0 ? query.goal : query.other_goals[k - 1];
    ++out.checks;
    if (query.valid(g)) {
      goals.push_back(g);
      goal_ids.push_back(static_cast<int>(k));
    }
  }
  if (goals.empty()) {
    out.why = "the goal configuration is in collision";
    return out;
  }
  PathQuery fine = query;
  if (query.final_resolution > 0.0) fine.resolution = query.final_resolution;
  for (size_t k = 0; k < goals.size(); ++k) {
    if (StraightMotionValid(fine, query.start, goals[k], &out.checks)) {
      out.solved = true;
      out.path = {query.start, goals[k]};
      out.goal_index = goal_ids[k];
      return out;
    }
  }
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  auto space = std::make_shared<ob::RealVectorStateSpace>(dim);
  ob::RealVectorBounds bounds(dim);
  for (int i = 0; i < dim; ++i) {
    bounds.setLow(i, query.lower[i]);
    bounds.setHigh(i, query.upper[i]);
  }
  space->setBounds(bounds);
  const std::uint64_t seed = query.seed;
  space->setStateSamplerAllocator([seed](const ob::StateSpace* s) -> ob::StateSamplerPtr {
    return std::make_shared<SeededSampler>(s, seed);
  });
  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([&query, dim, &out](const ob::State* s) {
    ++out.checks;
    return query.valid(ToVector(s, dim));
  });
  si->setMotionValidator(std::make_shared<DenseMotionValidator>(si, query, dim, &out.checks));
  si->setup();
  ob::ScopedState<> start(space);
  for (int i = 0; i < dim; ++i) start[i] = query.start[i];
  auto goal_states = std::make_shared<ob::GoalStates>(si);
  for (const Eigen::VectorXd& g : goals) {
    ob::ScopedState<> goal(space);
    for (int i = 0; i < dim; ++i) goal[i] = g[i];
    goal_states->addState(goal);
  }
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  pdef->addStartState(start);
  pdef->setGoal(goal_states);
  auto planner = std::make_shared<og::RRTConnect>(si);
  planner->setNearestNeighbors<ompl::NearestNeighborsLinear>();
  // Short extensions: a long one through clutter is nearly always trapped.
  planner->setRange(query.range_per_sqrt_dim * std::sqrt(static_cast<double>(dim)));
  planner->setProblemDefinition(pdef);
  planner->setup();
  // The budget is work (validity checks), not time: a loaded machine slows the search, it does
  // not change what it finds. Cancellation and the run's deadline come through query.stop.
  ob::PlannerTerminationCondition ptc(
      [&] { return out.checks >= query.max_checks || (query.stop && query.stop()); });
  std::uint64_t attempt_seed = seed;
  while (true) {
    const ob::PlannerStatus status = planner->solve(ptc);
    if (status != ob::PlannerStatus::EXACT_SOLUTION) {
      out.timed_out = !(query.stop && query.stop());
      out.why = out.timed_out ? "RRT-Connect found no path within its budget of " +
                                    std::to_string(query.max_checks) + " collision checks"
                              : "stopped (cancelled or past the time limit)";
      return out;
    }
    const auto* path = pdef->getSolutionPath()->as<og::PathGeometric>();
    out.path.clear();
    for (size_t i = 0; i < path->getStateCount(); ++i) {
      out.path.push_back(ToVector(path->getState(i), dim));
    }
    out.path.front() = query.start;
    size_t reached = 0;
    for (size_t k = 1; k < goals.size(); ++k) {
      if ((goals[k] - out.path.back()).squaredNorm() <
          (goals[reached] - out.path.back()).squaredNorm()) {
        reached = k;
      }
    }
    out.path.back() = goals[reached];
    out.goal_index = goal_ids[reached];
    if (PathValid(fine, out.path, &out.checks)) break;
    // It grazes something between the states RRT-Connect checked: search again.
    attempt_seed = attempt_seed * 6364136223846793005ULL + 1442695040888963407ULL;
    space->setStateSamplerAllocator([attempt_seed](const ob::StateSpace* s) -> ob::StateSamplerPtr {
      return std::make_shared<SeededSampler>(s, attempt_seed);
    });
    planner->clear();
    pdef->clearSolutionPaths();
  }
  out.solved = true;
  return out;
}

bool Same(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).cwiseAbs().maxCoeff() < 1e-9;
}

// A leg to or from a hub gets this share of the query's budget: an open hub is reached within a
// few thousand checks where it is reached at all (cross_openarm: 4k and 23k of 200k), so a
// failed leg costs a quarter of the direct search, not all of it again.
constexpr long long kHubLegShare = 4;

// Where RRT-Connect's two trees did not meet within the budget: start -> hub -> goal, each leg
// within a share of the budget of its own. A start and a goal in pockets (a hand beside a part,
// between two arms) often both reach an open configuration (the robots' home) while the trees
// grown from the pockets miss each other.
void ConnectViaHubs(const PathQuery& query, PathAnswer& out) {
  const bool stopped_before = query.stop && query.stop();
  bool tried = false;
  for (size_t h = 0; h < query.via.size() && !stopped_before; ++h) {
    const Eigen::VectorXd& hub = query.via[h];
    if (Same(hub, query.start) || Same(hub, query.goal)) continue;  // the direct search again
    tried = true;
    PathQuery leg = query;
    leg.via.clear();
    leg.lower = query.lower.cwiseMin(hub);
    leg.upper = query.upper.cwiseMax(hub);
    leg.goal = hub;
    leg.other_goals.clear();
    leg.max_checks = std::max<long long>(1, query.max_checks / kHubLegShare);
    leg.seed = query.seed * 6364136223846793005ULL + 2 * h + 1;
    PathAnswer to_hub = Connect(leg);
    out.checks += to_hub.checks;
    PathAnswer from_hub;
    if (to_hub.solved) {
      leg.start = hub;
      leg.goal = query.goal;
      leg.other_goals = query.other_goals;
      leg.seed = query.seed * 6364136223846793005ULL + 2 * h + 2;
      from_hub = Connect(leg);
      out.checks += from_hub.checks;
    }
    if (query.stop && query.stop()) {
      out.timed_out = false;
      out.why = "stopped (cancelled or past the time limit)";
      return;
    }
    if (!from_hub.solved) continue;
    out.path = std::move(to_hub.path);
    out.path.insert(out.path.end(), from_hub.path.begin() + 1, from_hub.path.end());
    out.goal_index = from_hub.goal_index;
    out.solved = true;
    out.timed_out = false;
    out.why.clear();
    return;
  }
  if (tried && out.timed_out) out.why += ", nor through " + query.via_name;
}

}  // namespace

PathAnswer PlanPath(const PathQuery& query) {
  PathAnswer out = Connect(query);
  if (!out.solved && out.timed_out) ConnectViaHubs(query, out);
  if (!out.solved) return out;
  PathQuery fine = query;
  if (query.final_resolution > 0.0) fine.resolution = query.final_resolution;
  Shortcut(fine, out.path, &out.checks);
  return out;
}

}  // namespace wrap
