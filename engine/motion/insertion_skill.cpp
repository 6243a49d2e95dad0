// The insertion skill: the moved input's straight move along its mating axis into the base, the
// slide start further back where the approach keyframe sits in a pocket, the hover above the
// table for an input lowered onto a resting base, and the check that the thinned move keeps the
// moved input within the overlap the geometry allows (an insertion with no clearance).

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "motion/segments_internal.h"

namespace wrap::detail {

bool SegmentBuilder::LongerSlideFree(int step, double extra) {
  if (step < w_.num_parts || !w_.check || !w_.check->tree) return true;
  if (!geometry_) geometry_.emplace(AssemblyGeometry::FromProject(*w_.project, *w_.check));
  InsertionPath path =
      StepInsertionPath(*w_.project, *w_.check->tree, w_.tree->nodes[step].step, -1);
  path.length_m += extra;
  return IsPathFree(*geometry_, path);
}

void SegmentBuilder::SlideStart(int action, Keyframe& goal) {
  const PlanAction& a = plan_.actions[action];
  if (a.type != ActionType::kAssemble || !a.approach || a.objects.size() < 2) return;
  const int m_node = a.objects[0], b_node = a.objects[1];
  const std::vector<int> holders = state_.Holders(m_node);
  if (holders.empty()) return;
  const int h0 = holders[0];
  const bool clear = KeyframeAccepts(h0, goal.q[h0], goal, {});
  if (clear && !Tight(h0, goal.q[h0])) return;  // clear, with room around it
  if (!clear && !KeyframeAccepts(h0, goal.q[h0], goal, {{m_node, b_node}})) return;  // not that
  Vec3 u = Tcp(h0, goal.q[h0]).translation() - Tcp(h0, a.keyframe.q[h0]).translation();
  if (u.norm() < 1e-6) return;
  u.normalize();
  std::vector<JointVector> q0;
  for (int r : holders) q0.push_back(goal.q[r]);
  // Further back along the insertion line: the first start that is clear with room around it
  // (a free path hardly reaches a start in a pocket, e.g. a long bolt still near its hole);
  // else the first clear one when the approach keyframe touches the base.
  std::optional<Keyframe> first_clear;
  double first_extra = 0.0;
  for (double extra : {0.01, 0.02, 0.04, 0.06, 0.09, 0.12}) {
    if (a.objects.size() >= 3 && !LongerSlideFree(a.objects[2], extra)) break;
    const int steps = std::max(2, static_cast<int>(std::ceil(extra / opt_.cartesian_step_m)));
    const auto path = Track(holders, q0, ShiftedTcps(holders, q0, extra * u), steps);
    if (path.empty()) continue;
    Keyframe pre = goal;
    for (size_t k = 0; k < holders.size(); ++k) pre.q[holders[k]] = path.back()[k];
    for (PlanObject& o : pre.objects) {
      if (o.node == m_node) o.X_WA.translation() += extra * u;
    }
    if (!KeyframeAccepts(h0, pre.q[h0], pre, {})) continue;
    if (!Tight(h0, pre.q[h0])) {
      if (ctx_.Logs("motion")) {
        ctx_.Log("motion",
                 StrFormat("slide: action %d: %s %s %s at the approach; the slide starts %.0f mm "
                           "further back",
                           action + 1, NodeName(m_node).c_str(), clear ? "is close to" : "touches",
                           NodeName(b_node).c_str(), 1000.0 * extra));
      }
      goal = std::move(pre);
      return;
    }
    if (!clear && !first_clear) {
      first_clear = std::move(pre);
      first_extra = extra;
    }
  }
  if (first_clear) {
    if (ctx_.Logs("motion")) {
      ctx_.Log("motion",
               StrFormat("slide: action %d: %s touches %s at the approach; the slide starts "
                         "%.0f mm further back (still tight)",
                         action + 1, NodeName(m_node).c_str(), NodeName(b_node).c_str(),
                         1000.0 * first_extra));
    }
    goal = std::move(*first_clear);
  }
}

bool SegmentBuilder::HoverAbove(int action, Keyframe& goal, std::vector<int>& holders,
                                std::vector<std::vector<JointVector>>& descent, double* length) {
  // An input this close above the table top touches it [m].
  constexpr double kTouch = 2e-3;
  const PlanAction& a = plan_.actions[action];
  if (a.objects.size() < 2) return true;
  const int m_node = a.objects[0], b_node = a.objects[1];
  const PlanObject* mo = FindObject(goal, m_node);
  if (mo == nullptr || LowestPoint(w_, m_node, mo->X_WA) > w_.table_top + kTouch) return true;
  holders = state_.Holders(m_node);
  if (holders.empty()) return true;
  // The scene at the goal: the objects where the keyframe has them, every robot at its joints.
  PlanState at = state_;
  for (const PlanObject& o : goal.objects) {
    if (auto it = at.objects.find(o.node); it != at.objects.end()) it->second.X_WA = o.X_WA;
  }
  std::vector<JointVector> q0;
  for (int r : holders) q0.push_back(goal.q[r]);
  // Straight down onto the table; else down and forward along the slide (from above and behind
  // its start), where the space above the start is taken.
  std::vector<Vec3> dirs = {Vec3::UnitZ()};
  Vec3 back = Tcp(holders[0], goal.q[holders[0]]).translation() -
              Tcp(holders[0], a.keyframe.q[holders[0]]).translation();
  back.z() = 0.0;
  if (back.norm() > 1e-6) dirs.push_back((Vec3::UnitZ() + back.normalized()).normalized());
  std::string why = "no IK solution along the line";
  for (const Vec3& dir : dirs) {
    for (double d : {opt_.skills.lift_m, 2 * opt_.skills.lift_m, opt_.skills.lift_m / 2}) {
      const double len = d / dir.z();
      auto path = Track(holders, q0, ShiftedTcps(holders, q0, len * dir),
                        std::max(2, static_cast<int>(std::ceil(len / opt_.cartesian_step_m))));
      if (path.empty()) continue;
      Keyframe top = goal;
      for (size_t k = 0; k < holders.size(); ++k) top.q[holders[k]] = path.back()[k];
      for (PlanObject& o : top.objects) {
        if (o.node == m_node) o.X_WA.translation() += len * dir;
      }
      if (!KeyframeAccepts(holders[0], top.q[holders[0]], top, {})) {
        why = "the pose " + std::to_string(static_cast<int>(std::lround(d * 1000))) +
              " mm above it collides";
        continue;
      }
      // The way down may touch the table and the base (the slide's contacts).
      if (!scene_->Set(at, opening_, goal.q, {{m_node, b_node}}, {m_node})) return false;
      if (!PathClear(holders, path)) {
        why = last_hit_;
        continue;
      }
      if (ctx_.Logs("motion")) {
        ctx_.Log("motion",
                 StrFormat("hover: action %d: %s touches the table at the insertion's start; it "
                           "is lowered %.0f mm onto it",
                           action + 1, NodeName(m_node).c_str(), 1000.0 * d));
      }
      descent.assign(path.rbegin(), path.rend());
      *length = len;
      goal = std::move(top);
      return true;
    }
  }
  return Fail(action, SegmentKind::kDescend, false,
              "the holders of " + NodeName(m_node) +
                  " cannot lower it straight onto the table where its insertion starts: " + why);
}

// Whether the moved input of action i's insertion stays within the overlap the geometry allows
// of its base along `path` (the first inserter's waypoints, straight joint motion between them:
// as the trajectory check will see it), sampled every millimetre of the TCP's travel.
bool SegmentBuilder::InsertionWithinOverlap(int i, const std::vector<int>& inserters,
                                            const std::vector<std::vector<JointVector>>& path) {
  const PlanAction& a = plan_.actions[i];
  const Keyframe& K = a.keyframe;
  const int m_node = a.objects[0], b_node = a.objects[1];
  if (a.objects.size() < 3 || a.objects[2] < w_.num_parts || !w_.check) return true;
  const PlanObject* m_obj = nullptr;
  const PlanObject* b_obj = nullptr;
  for (const PlanObject& o : K.objects) {
    if (o.node == m_node) m_obj = &o;
    if (o.node == b_node) b_obj = &o;
  }
  if (!m_obj || !b_obj) return true;
  if (!geometry_) geometry_.emplace(AssemblyGeometry::FromProject(*w_.project, *w_.check));
  const StepInterface& st = w_.interface(a.objects[2]);
  const int r0 = inserters[0];
  const Iso3 X_TM = Tcp(r0, K.q[r0]).inverse() * m_obj->X_WA;  // M in the TCP's frame
  std::vector<Iso3> X(w_.num_parts, Iso3::Identity());
  for (int p : w_.tree->nodes[b_node].parts) X[p] = b_obj->X_WA * w_.X_AP[p];
  const double touch = w_.project->geometry.touch_depth_m;
  for (size_t k = 1; k < path.size(); ++k) {
    const JointVector& qa = path[k - 1][0];
    const JointVector& qb = path[k][0];
    const double travel = (Tcp(r0, qb).translation() - Tcp(r0, qa).translation()).norm();
    const int n = std::clamp(static_cast<int>(std::ceil(travel / 1e-3)), 1, 64);
    for (int j = 1; j <= n; ++j) {
      const Iso3 X_WM = Tcp(r0, qa + (static_cast<double>(j) / n) * (qb - qa)) * X_TM;
      for (int p : w_.tree->nodes[m_node].parts) X[p] = X_WM * w_.X_AP[p];
      const double back = -(b_obj->X_WA.inverse() * X_WM).translation().dot(st.axis_A);
      const double allowed = AllowedOverlap(st.mating->interference_travel_m,
                                            st.mating->interference_depth_m, touch, back);
      if (OverlapBeyond(*geometry_, w_.tree->nodes[m_node].parts, w_.tree->nodes[b_node].parts, X,
                        allowed)) {
        return false;
      }
    }
  }
  return true;
}

bool SegmentBuilder::Insert(int i) {
  const PlanAction& a = plan_.actions[i];
  const Keyframe& K = a.keyframe;
  const int m_node = a.objects[0];
  const int b_node = a.objects[1];
  std::vector<int> inserters = state_.Holders(m_node);
  std::vector<JointVector> q0;
  std::vector<std::function<Iso3(double)>> targets;
  double len = 0.0;
  for (int r : inserters) {
    q0.push_back(cur_[r]);
    const Iso3 Xa = Tcp(r, cur_[r]);
    const Iso3 Xb = Tcp(r, K.q[r]);
    len = std::max(len, (Xb.translation() - Xa.translation()).norm());
    targets.push_back([Xa, Xb](double s) {
      Iso3 X = Xa;
      X.translation() = (1 - s) * Xa.translation() + s * Xb.translation();
      return X;
    });
  }
  const int steps = std::max(2, static_cast<int>(std::ceil(len / opt_.cartesian_step_m)));
  std::vector<JointVector> goals;
  for (int r : inserters) goals.push_back(K.q[r]);
  // The line tracked to the usual tolerance, ending at the keyframe's joints (or another IK
  // solution of its pose that the keyframe accepts).
  const auto track = [&](double tolerance_m) {
    auto path = Track(inserters, q0, targets, steps, &goals, tolerance_m);
    bool ok = !path.empty();
    for (size_t k = 0; ok && k < inserters.size(); ++k) {
      const int r = inserters[k];
      if ((path.back()[k] - K.q[r]).cwiseAbs().maxCoeff() > kMaxSnap) {
        ok = KeyframeAccepts(r, path.back()[k], K, {{m_node, b_node}});
        if (ok) Rebranch(r, i, false, K.q[r], path.back()[k]);
      }
      if (ok) path.back()[k] = K.q[r];
    }
    if (!ok) path.clear();
    return path;
  };
  auto path = track(kTrackTolerance);
  // A moved input that slides along its base with no clearance leaves no room for the line's
  // usual tolerance: tracked and thinned again within a fraction of the touch depth.
  if (!path.empty() && !InsertionWithinOverlap(i, inserters, path)) {
    path = track(
        std::max(kInsertLineShare * w_.project->geometry.touch_depth_m, kMinInsertLineTolerance));
  }
  bool ok = !path.empty();
  if (ok) {
    if (!SetScene(opening_, {{m_node, b_node}}, {m_node})) return false;
    ok = PathClear(inserters, path);
  }
  if (!ok) {
    return Fail(i, SegmentKind::kInsert, false,
                "the insertion of " + NodeName(m_node) + " into " + NodeName(b_node) +
                    " is not a collision-free straight move: " + last_hit_);
  }
  PushSkill(SegmentKind::kInsert, i, true, inserters, {m_node, b_node}, std::move(path), len,
            opt_.insert_speed_mps);
  return true;
}

}  // namespace wrap::detail
