// The segment builder's scene and record: the collision scene set from the builder's state, the
// key of the scene a cached free path was solved in, the failure record with the cell at it, and
// the segments recorded in order with the world boxes they sweep.

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "motion/segments_internal.h"

namespace wrap::detail {

Result<void> SegmentBuilder::SetScene(const std::vector<double>& openings,
                                      const std::vector<std::pair<int, int>>& mating,
                                      const std::vector<int>& table_ok,
                                      const std::vector<std::pair<int, int>>& gripper_ok) {
  // Objects still where they were picked from touch the table until they are lifted.
  std::vector<int> on_table = table_ok;
  on_table.insert(on_table.end(), grounded_.begin(), grounded_.end());
  return scene_->Set(state_, openings, cur_, mating, on_table, gripper_ok);
}

bool SegmentBuilder::Fail(int action, SegmentKind kind, bool suspend, const std::string& message,
                          int blame) {
  if (failure_) {
    failure_->action = action;
    failure_->blame = blame >= 0 ? blame : action;
    failure_->segment = std::string(ToString(kind));
    failure_->suspend = suspend;
    failure_->message = message;
    // The collision the message names, where it happened; else the cell where the segment
    // starts.
    const bool named = !last_hit_.empty() && message.find(last_hit_) != std::string::npos &&
                       !last_hit_scene_.q.empty();
    failure_->scene = named ? last_hit_scene_ : CellNow();
  }
  return false;
}

FailureScene SegmentBuilder::CellNow() {
  FailureScene scene;
  scene.q = cur_;
  scene.X_WP.resize(w_.num_parts);
  for (int p = 0; p < w_.num_parts; ++p) scene.X_WP[p] = scene_->cell().object_pose(p);
  return scene;
}

void SegmentBuilder::Push(GeoSegment seg) {
  if (seg.openings.empty()) seg.openings = opening_;
  for (size_t i = 0; i < seg.robots.size() && !seg.waypoints.empty(); ++i) {
    const int r = seg.robots[i];
    if ((seg.waypoints.front()[i] - cur_[r]).cwiseAbs().maxCoeff() > 1e-6 && !jump_) {
      // A bug, not a plan that has no motion: the trajectory would jump.
      jump_ = true;
      Fail(seg.action, seg.kind, false,
           "internal: the " + std::string(ToString(seg.kind)) + " segment of " + Name(r) +
               " does not start where the robot is");
    }
  }
  Sweep(seg);
  for (size_t i = 0; i < seg.robots.size(); ++i) cur_[seg.robots[i]] = seg.waypoints.back()[i];
  out_.push_back(std::move(seg));
}

void SegmentBuilder::PushSkill(SegmentKind kind, int action, bool main, std::vector<int> robots,
                               std::vector<int> objects,
                               std::vector<std::vector<JointVector>> waypoints, double length_m,
                               double speed_mps) {
  GeoSegment seg;
  seg.kind = kind;
  seg.action = action;
  seg.main = main;
  seg.robots = std::move(robots);
  seg.objects = std::move(objects);
  seg.waypoints = std::move(waypoints);
  seg.skill_length_m = length_m;
  seg.skill_speed_mps = speed_mps;
  Push(std::move(seg));
}

void SegmentBuilder::PushSkill(SegmentKind kind, int action, bool main, int robot, int object,
                               const std::vector<JointVector>& waypoints, double length_m,
                               double speed_mps) {
  std::vector<std::vector<JointVector>> composite;
  for (const JointVector& q : waypoints) composite.push_back({q});
  PushSkill(kind, action, main, {robot}, {object}, std::move(composite), length_m, speed_mps);
}

void SegmentBuilder::Sweep(GeoSegment& seg) {
  // Samples no farther apart than kSweepStep in the sum of joint changes: with links at most
  // kLever from their joints, a body point between two samples lies within kSweepMargin of one.
  // Per body: its whole sweep, then the sweeps of runs of kChunk samples.
  constexpr double kSweepStep = 0.03;  // [rad]
  constexpr double kLever = 1.5;       // [m]
  constexpr double kSweepMargin = 0.5 * kSweepStep * kLever + 0.01;
  constexpr int kChunk = 6;
  if (!SetScene(seg.openings)) return;
  std::vector<std::vector<Aabb>> sweep;  // per body: [0] all, then chunks
  std::vector<double> sweep_u;           // per chunk: the path parameter of its first sample
  std::vector<Aabb> sample;
  int count = 0;
  double u = 0.0;  // the path parameter of the sample
  auto merge = [](Aabb& into, const Aabb& b) {
    into.min = into.min.cwiseMin(b.min);
    into.max = into.max.cwiseMax(b.max);
  };
  auto add = [&] {
    sample.clear();
    for (int r : seg.robots) scene_->AppendBoxes(r, sample);
    for (int node : seg.objects) {
      if (state_.objects.count(node)) scene_->AppendObjectBoxes(node, sample);
    }
    if (sweep.size() != sample.size()) {  // first sample (or a body appeared: start over)
      sweep.assign(sample.size(), {});
      for (size_t b = 0; b < sample.size(); ++b) sweep[b] = {sample[b], sample[b]};
      sweep_u = {0.0};  // (from the start: the samples before a restart are not kept)
      count = 1;
      return;
    }
    const bool fresh = count % kChunk == 0;
    if (fresh) sweep_u.push_back(u);
    for (size_t b = 0; b < sample.size(); ++b) {
      merge(sweep[b][0], sample[b]);
      if (fresh) {
        sweep[b].push_back(sample[b]);
      } else {
        merge(sweep[b].back(), sample[b]);
      }
    }
    ++count;
  };
  const auto& wp = seg.waypoints;
  for (size_t i = 0; i < seg.robots.size(); ++i) scene_->SetRobot(seg.robots[i], wp[0][i]);
  add();
  for (size_t k = 1; k < wp.size(); ++k) {
    double l1 = 0.0;
    for (size_t i = 0; i < seg.robots.size(); ++i) l1 += (wp[k][i] - wp[k - 1][i]).cwiseAbs().sum();
    const int steps = std::max(1, static_cast<int>(std::ceil(l1 / kSweepStep)));
    for (int s = 1; s <= steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      u = static_cast<double>(k - 1) + t;
      for (size_t i = 0; i < seg.robots.size(); ++i) {
        scene_->SetRobot(seg.robots[i], wp[k - 1][i] + t * (wp[k][i] - wp[k - 1][i]));
      }
      add();
    }
  }
  for (auto& boxes : sweep) {
    for (Aabb& b : boxes) {
      b.min.array() -= kSweepMargin;
      b.max.array() += kSweepMargin;
    }
  }
  seg.sweep = std::move(sweep);
  seg.sweep_u = std::move(sweep_u);
}

std::vector<double> SegmentBuilder::SceneKey() const {
  std::vector<double> key;
  for (const JointVector& q : cur_) key.insert(key.end(), q.data(), q.data() + q.size());
  key.insert(key.end(), opening_.begin(), opening_.end());
  for (int r : released_) key.push_back(r);
  for (const auto& [node, o] : state_.objects) {
    key.push_back(node);
    key.push_back(o.resting ? 1.0 : 0.0);
    const Eigen::Matrix4d m = o.X_WA.matrix();
    key.insert(key.end(), m.data(), m.data() + 12);
  }
  for (size_t r = 0; r < state_.held.size(); ++r) {
    key.push_back(state_.held[r]);
    if (state_.held[r] >= 0 && r < state_.grasp.size()) {
      key.push_back(state_.grasp[r].subassembly);
      key.push_back(state_.grasp[r].index);
    }
  }
  return key;
}

BuilderCheckpoint SegmentBuilder::Save() const {
  return {out_.size(), cur_, opening_, free_index_};
}

void SegmentBuilder::Restore(const BuilderCheckpoint& saved) {
  out_.resize(saved.out);
  cur_ = saved.cur;
  opening_ = saved.opening;
}

}  // namespace wrap::detail
