// Free paths: the robots that move, in their composite joint space, from where they are to their
// goals (RRT-Connect and shortcutting through ompl_adapter.h, within a work budget that doubles
// per effort level), reused from the cache where the query and the scene are the same.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "motion/segments_internal.h"

namespace wrap::detail {

std::vector<SoleLoad> SegmentBuilder::SoleLoads(const std::vector<int>& robots) const {
  std::vector<SoleLoad> out;
  for (int r : robots) {
    if (std::optional<SoleLoad> l = SoleLoadOf(w_, state_, r)) out.push_back(*l);
  }
  return out;
}

bool SegmentBuilder::MoveOpening(int robot, double wanted) {
  const double now = opening_[robot];
  opening_[robot] = wanted;
  if (wanted == now) return true;
  if (!SetScene(opening_)) return false;
  if (!scene_->Collides(std::vector<int>{robot})) return true;
  opening_[robot] = now;
  if (!SetScene(opening_)) return false;
  if (scene_->Collides(std::vector<int>{robot})) opening_[robot] = wanted;
  return true;
}

bool SegmentBuilder::Free(int action, bool main, const std::vector<int>& robots,
                          const std::vector<JointVector>& goals, const std::vector<int>& objects,
                          const std::vector<JointVector>* others, int* reached) {
  if (reached) *reached = 0;
  if (others && others->empty()) others = nullptr;
  FreeRequest req;
  req.action = action;
  req.main = main;
  req.others = others;
  for (size_t i = 0; i < robots.size(); ++i) {
    if (!Same(cur_[robots[i]], goals[i])) {
      req.movers.push_back(robots[i]);
      req.targets.push_back(goals[i]);
    }
  }
  if (req.movers.empty()) return true;
  req.index = free_index_++;
  ReportFree(req);
  const int index = req.index;
  if (cache_.free_paths.size() <= static_cast<size_t>(index)) cache_.free_paths.resize(index + 1);
  GeoSegment seg;
  seg.kind = SegmentKind::kFree;
  seg.action = action;
  seg.main = main;
  seg.objects = objects;
  seg.openings = opening_;
  const std::vector<double> scene_key = SceneKey();
  if (ReuseFree(req, scene_key, seg, reached)) return true;
  if (!SetScene(opening_)) return false;
  std::vector<std::vector<JointVector>> path;
  PathAnswer answer = FreeQuery(req, req.movers, req.targets, &path);
  if (answer.solved && reached) *reached = answer.goal_index;
  if (!answer.solved && answer.timed_out && ctx_.Logs("motion.diag") && req.movers.size() == 1) {
    DiagnoseFree(req);
  }
  std::vector<int> who = req.movers;
  if (!answer.solved && answer.timed_out && effort_ > 0 && !ctx_.ShouldStop()) {
    StepAside(req, answer, path, who);
  }
  if (!answer.solved) {
    if (ctx_.cancelled()) cancelled_ = true;
    std::string names;
    for (int r : req.movers) names += (names.empty() ? "" : ", ") + Name(r);
    return Fail(action, SegmentKind::kFree, answer.timed_out,
                "no collision-free path for " + names + " toward action " +
                    std::to_string(action + 1) + ": " + answer.why);
  }
  seg.robots = who;
  seg.waypoints = std::move(path);
  seg.free_index = index;
  cache_.free_paths[index] = {seg.robots, seg.waypoints, scene_key};
  Push(std::move(seg));
  return true;
}

void SegmentBuilder::ReportFree(const FreeRequest& req) {
  std::string names;
  for (int r : req.movers) names += (names.empty() ? "" : ", ") + Name(r);
  ctx_.Progress(
      "motion", static_cast<double>(req.action) / std::max<size_t>(1, plan_.actions.size()),
      "action " + std::to_string(req.action + 1) + "/" + std::to_string(plan_.actions.size()) +
          ": free path " + std::to_string(req.index + 1) + " for " + names);
}

bool SegmentBuilder::ReuseFree(const FreeRequest& req, const std::vector<double>& scene_key,
                               GeoSegment& seg, int* reached) {
  const MotionCache::Path& c = cache_.free_paths[req.index];
  if (c.waypoints.empty() || c.scene != scene_key) return false;
  // Reuse a path solved at a lower effort when it is the same query in the same scene.
  const std::vector<int>& movers = req.movers;
  const std::vector<JointVector>* others = req.others;
  bool same = true;
  int end = 0;
  for (size_t i = 0; i < movers.size() && same; ++i) {
    const auto it = std::find(c.robots.begin(), c.robots.end(), movers[i]);
    same = it != c.robots.end();
    if (same) {
      const size_t j = static_cast<size_t>(it - c.robots.begin());
      same = Same(c.waypoints.front()[j], cur_[movers[i]]) &&
             Same(c.waypoints.back()[j], req.targets[i]);
      if (!same && others && movers.size() == 1 && Same(c.waypoints.front()[j], cur_[movers[i]])) {
        for (size_t k = 0; k < others->size() && !same; ++k) {
          same = Same(c.waypoints.back()[j], (*others)[k]);
          end = static_cast<int>(k) + 1;
        }
      }
    }
  }
  if (!same) return false;
  if (ctx_.Logs("motion")) {
    ctx_.Log("motion", StrFormat("free: action %d: reused path %d", req.action + 1, req.index));
  }
  if (reached) *reached = end;
  seg.robots = c.robots;
  seg.waypoints = c.waypoints;
  seg.free_index = req.index;
  Push(std::move(seg));
  return true;
}

PathQuery SegmentBuilder::FreeQueryBounds(const FreeRequest& req, const std::vector<int>& who,
                                          const std::vector<JointVector>& to) const {
  PathQuery query;
  int dim = 0;
  for (int r : who) dim += static_cast<int>(w_.robots[r].chain.joints.size());
  query.lower.resize(dim);
  query.upper.resize(dim);
  query.start.resize(dim);
  query.goal.resize(dim);
  int k = 0;
  for (size_t i = 0; i < who.size(); ++i) {
    const Chain& chain = w_.robots[who[i]].chain;
    for (size_t j = 0; j < chain.joints.size(); ++j, ++k) {
      query.start[k] = cur_[who[i]][j];
      query.goal[k] = to[i][j];
      // Samples within half a turn beyond the ends (joints of +-2 pi would wrap in vain).
      const double lo = std::min(query.start[k], query.goal[k]) - M_PI;
      const double hi = std::max(query.start[k], query.goal[k]) + M_PI;
      query.lower[k] = std::max(chain.joints[j].lower, lo);
      query.upper[k] = std::min(chain.joints[j].upper, hi);
    }
  }
  if (req.others && who.size() == 1) {
    for (const JointVector& g : *req.others) {
      query.other_goals.push_back(g);
      query.lower = query.lower.cwiseMin(g);
      query.upper = query.upper.cwiseMax(g);
    }
  }
  return query;
}

std::vector<JointVector> SegmentBuilder::SplitComposite(const std::vector<int>& who,
                                                        const Eigen::VectorXd& x) const {
  std::vector<JointVector> qs(who.size());
  int o = 0;
  for (size_t i = 0; i < who.size(); ++i) {
    const int n = static_cast<int>(w_.robots[who[i]].chain.joints.size());
    qs[i] = x.segment(o, n);
    o += n;
  }
  return qs;
}

PathAnswer SegmentBuilder::FreeQuery(const FreeRequest& req, const std::vector<int>& who,
                                     const std::vector<JointVector>& to,
                                     std::vector<std::vector<JointVector>>* path) {
  const int action = req.action;
  PathQuery query = FreeQueryBounds(req, who, to);
  // Objects carried by one robot: their weight on the gripper stays within the limits' share
  // (or the worse of the two ends' loads).
  const std::vector<SoleLoad> loads = SoleLoads(who);
  std::vector<std::pair<size_t, double>> load_bound;  // (index in who, largest ratio)
  for (const SoleLoad& load : loads) {
    const size_t i =
        static_cast<size_t>(std::find(who.begin(), who.end(), load.robot) - who.begin());
    load_bound.push_back({i, std::max({opt_.transport_load_max, LoadRatio(load, cur_[who[i]]),
                                       LoadRatio(load, to[i])}) +
                                 1e-9});
  }
  for (size_t l = 0; l < loads.size() && ctx_.Logs("motion"); ++l) {
    ctx_.Log("motion", StrFormat("load: action %d %s: up to %.2f of its limits", action + 1,
                                 Name(loads[l].robot).c_str(), load_bound[l].second));
  }
  query.valid = [&](const Eigen::VectorXd& x) {
    const std::vector<JointVector> qs = SplitComposite(who, x);
    for (size_t l = 0; l < loads.size(); ++l) {
      if (LoadRatio(loads[l], qs[load_bound[l].first]) > load_bound[l].second) return false;
    }
    for (size_t i = 0; i < who.size(); ++i) scene_->SetRobot(who[i], qs[i]);
    return !scene_->Collides(who);
  };
  query.resolution = opt_.resolution_rad;
  query.max_checks = opt_.segment_checks << effort_;
  query.seed =
      Mix(seed_, static_cast<std::uint64_t>(req.index) * 2 + (who.size() > req.movers.size()));
  if (auto it = cache_.reseed.find(req.index); it != cache_.reseed.end()) {
    query.seed = Mix(query.seed, 0x7265736565640000ULL + static_cast<std::uint64_t>(it->second));
  }
  query.stop = [this] { return ctx_.ShouldStop(); };
  query.shortcut_attempts = opt_.shortcut_attempts;
  // Where the direct search fails, through the movers' home (the 7-DoF arms' starts and goals
  // beside parts and other hands often both reach it while RRT-Connect's trees miss each other).
  Eigen::VectorXd home(query.start.size());
  bool homes = true;
  for (size_t i = 0, o = 0; i < who.size() && homes; ++i) {
    const JointVector& h = w_.robots[who[i]].home;
    homes = h.size() == static_cast<long>(w_.robots[who[i]].chain.joints.size());
    if (homes) home.segment(static_cast<long>(o), h.size()) = h;
    o += static_cast<size_t>(h.size());
  }
  if (homes) query.via = {home};
  query.via_name = who.size() == 1 ? "its home" : "their homes";
  const auto t_query = std::chrono::steady_clock::now();
  query.final_resolution = query.resolution / kRefine;
  const PathAnswer answer = PlanPath(query);
  const std::string hit = DescribeFreeFailure(action, who, to, answer);
  for (size_t i = 0; i < who.size(); ++i) scene_->SetRobot(who[i], cur_[who[i]]);
  if (ctx_.Logs("motion")) {
    ctx_.Log(
        "motion",
        StrFormat("free: action %d robots %zu: %s%s, %lld checks, %.2f s, %zu waypoints",
                  action + 1, who.size(), answer.solved ? "solved" : answer.why.c_str(),
                  hit.c_str(), answer.checks,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t_query).count(),
                  answer.path.size()));
  }
  if (answer.solved) {
    for (const Eigen::VectorXd& x : answer.path) path->push_back(SplitComposite(who, x));
  }
  return answer;
}

std::string SegmentBuilder::DescribeFreeFailure(int action, const std::vector<int>& who,
                                                const std::vector<JointVector>& to,
                                                const PathAnswer& answer) {
  std::string hit;
  if (!ctx_.Logs("motion") || answer.solved || answer.timed_out) return hit;
  const bool at_start = answer.why.find("start") != std::string::npos;
  for (size_t i = 0; i < who.size(); ++i) scene_->SetRobot(who[i], at_start ? cur_[who[i]] : to[i]);
  CollisionResult res;
  if (scene_->cell().InCollision(&res)) hit = " (" + scene_->cell().Describe(res.first) + ")";
  if (at_start) {
    for (int r : who) {
      std::string line =
          StrFormat("free: start of %s: opening %.4f, holds %d; keyframes:", Name(r).c_str(),
                    opening_[r], state_.held[r]);
      for (int j = std::max(0, action - 3); j <= action; ++j) {
        line += StrFormat(" %d:%s", j + 1,
                          Same(plan_.actions[j].keyframe.q[r], cur_[r]) ? "same" : "differs");
      }
      ctx_.Log("motion", line);
    }
  }
  return hit;
}

void SegmentBuilder::DiagnoseFree(const FreeRequest& req) {
  const std::vector<int>& movers = req.movers;
  const std::vector<JointVector>& targets = req.targets;
  // Diagnosis: is the start or the goal cut off from the robot's home?
  const JointVector saved = cur_[movers[0]];
  std::vector<std::vector<JointVector>> p1, p2;
  const PathAnswer a1 = FreeQuery(req, movers, {w_.robots[movers[0]].home}, &p1);
  cur_[movers[0]] = targets[0];
  scene_->SetRobot(movers[0], targets[0]);
  const PathAnswer a2 = FreeQuery(req, movers, {w_.robots[movers[0]].home}, &p2);
  cur_[movers[0]] = saved;
  scene_->SetRobot(movers[0], saved);
  // What the goal's neighbourhood hits.
  std::map<std::string, int> hits;
  {
    std::mt19937_64 g(7);
    std::uniform_real_distribution<double> u(-0.05, 0.05);
    for (int t = 0; t < 64; ++t) {
      JointVector x = targets[0];
      for (int j = 0; j < x.size(); ++j) x[j] += u(g);
      scene_->SetRobot(movers[0], x);
      CollisionResult res;
      if (scene_->cell().InCollision(&res)) {
        const CollisionWorld& cw = scene_->cell().world();
        ++hits[cw.body_name(res.first.body_a) + " ~ " + cw.body_name(res.first.body_b)];
      }
    }
    scene_->SetRobot(movers[0], saved);
  }
  std::string near;
  for (const auto& [k, v] : hits) near += " " + k + " x" + std::to_string(v);
  ctx_.Log("motion.diag",
           StrFormat("action %d %s (%s, holds %d): start->home %s, goal->home %s;%s",
                     req.action + 1, Name(movers[0]).c_str(), req.main ? "main" : "return",
                     state_.held[movers[0]], a1.solved ? "yes" : a1.why.c_str(),
                     a2.solved ? "yes" : a2.why.c_str(), near.c_str()));
}

void SegmentBuilder::StepAside(const FreeRequest& req, PathAnswer& answer,
                               std::vector<std::vector<JointVector>>& path, std::vector<int>& who) {
  const std::vector<int>& movers = req.movers;
  // The idle robots (free, not in this segment) may step aside and come back.
  std::vector<int> all = movers;
  std::vector<JointVector> to = req.targets;
  for (int r = 0; r < static_cast<int>(w_.robots.size()); ++r) {
    if (state_.held[r] < 0 && released_[r] < 0 &&
        std::find(movers.begin(), movers.end(), r) == movers.end()) {
      all.push_back(r);
      to.push_back(cur_[r]);
    }
  }
  if (all.size() <= movers.size()) return;
  std::vector<size_t> order(all.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return all[x] < all[y]; });
  std::vector<int> sorted;
  std::vector<JointVector> sorted_to;
  for (size_t k : order) {
    sorted.push_back(all[k]);
    sorted_to.push_back(to[k]);
  }
  answer = FreeQuery(req, sorted, sorted_to, &path);
  who = sorted;
}
}  // namespace wrap::detail
