// Grasp-set selection for one subassembly and end effector: filtering its parts' candidates
// against the other parts, the mating partner and the table, scoring them, and spreading the
// picks in tiers by farthest-point order.
#include "grasp/detail/grasp_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace wrap::detail {

namespace {

double AngleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Placements (most stable first) in which a grasp that clears the table counts as pickable.
constexpr int kPickPlacements = 3;

// A vacuum grasp of a moved input is an assembly grasp only when the cup pushes within this
// angle's cosine (15 degrees) of the insertion direction.
constexpr double kVacuumPushCos = 0.966;

// Distance of point c from the line through x along unit u [m].
double LineDistance(const Vec3& c, const Vec3& x, const Vec3& u) {
  return (c - x - (c - x).dot(u) * u).norm();
}

// Farthest-point order of up to n more items from `among` (indices into x, a, quality): the
// item farthest (position, plus approach angle times rot_scale) from those already `chosen` and
// picked so far, mildly weighted by quality; with nothing chosen yet, the best quality first.
// Items that coincide with a chosen one are never picked. Ties go to the lower index:
// deterministic. Stops early (short) when ctx says so.
std::vector<int> FarthestPointOrder(const std::vector<Vec3>& x, const std::vector<Vec3>& a,
                                    const std::vector<double>& quality,
                                    const std::vector<int>& among, const std::vector<int>& chosen,
                                    int n, double rot_scale, const RunContext& ctx) {
  const int m = static_cast<int>(among.size());
  std::vector<int> order;
  if (m == 0 || n <= 0) return order;
  std::vector<double> min_dist(m, std::numeric_limits<double>::infinity());
  std::vector<char> taken(m, 0);
  auto account = [&](int item) {
    for (int i = 0; i < m; ++i) {
      if (taken[i]) continue;
      const int k = among[i];
      const double ang = rot_scale * AngleBetween(a[k], a[item]);
      min_dist[i] = std::min(min_dist[i], std::sqrt((x[k] - x[item]).squaredNorm() + ang * ang));
    }
  };
  for (int c : chosen) account(c);
  auto pick_next = [&]() {
    int next = -1;
    double best = -1.0;
    for (int i = 0; i < m; ++i) {
      if (taken[i] || min_dist[i] < 1e-9) continue;
      const double q = quality[among[i]];
      const double score = std::isinf(min_dist[i]) ? q : min_dist[i] * (0.75 + 0.25 * q);
      if (score > best) {
        best = score;
        next = i;
      }
    }
    return next;
  };
  int next = pick_next();
  while (next >= 0 && static_cast<int>(order.size()) < n) {
    if (order.size() % 16 == 15 && ctx.ShouldStop()) break;
    order.push_back(among[next]);
    taken[next] = 1;
    account(among[next]);
    next = pick_next();
  }
  return order;
}

// The candidates of a subassembly that clear its other parts, with what the selection weighs:
// parallel vectors, one entry per kept candidate.
struct ScoredCandidates {
  std::vector<const GraspCandidate*> kept;
  std::vector<Vec3> x;  // Centre in A.
  std::vector<Vec3> a;  // Approach direction in A.
  std::vector<double> quality;
  std::vector<char> clear_of_partner;
  std::vector<char> pickable_at_rest;
};

// Drops the candidates of subassembly s's parts that hit another of its parts and scores the
// rest: quality (slack, pad fraction, nearness of the closing line or cup axis to the COM),
// clearance of the partner at the mating pose, and clearance of the table at rest. False when
// ctx says stop.
bool ScoreCandidates(const Subassembly& sub, int s, int e, const EndEffector& ee,
                     const std::vector<std::vector<GraspCandidate>>& candidates, int num_ee,
                     const SelectionScene& scene, GripperCollision& local,
                     const PreprocessOptions& options, const RunContext& ctx,
                     ScoredCandidates& out) {
  const double diag = sub.aabb_A.size().norm();
  const double length = std::max(1e-6, 0.5 * diag);
  int checked = 0;
  for (size_t k = 0; k < sub.parts.size(); ++k) {
    const int p = sub.parts[k];
    std::vector<int> others;
    for (int o : sub.parts) {
      if (o != p) others.push_back(o);
    }
    const Iso3& X_AP_k = sub.X_AP[k];
    for (const GraspCandidate& c : candidates[p * num_ee + e]) {
      if (++checked % 32 == 0 && ctx.ShouldStop()) return false;
      Iso3 X_AT = X_AP_k * c.grasp.X_PG;
      double opening = 0.0;
      if (ee.kind == EndEffectorKind::kVacuum) {
        X_AT.translation() -= options.vacuum.standoff_m * (X_AP_k.linear() * c.approach_P);
      } else {
        opening = c.grasp.width_m + 2.0 * options.two_finger.clearance_m;
      }
      if (!others.empty()) {
        local.EnableOnly(others);
        if (local.Collides(e, X_AT, opening)) continue;
      }
      bool clear = true;
      if (!scene.partner[s].empty()) {
        local.EnableOnly(scene.partner[s]);
        clear = !local.Collides(e, X_AT, opening);
      }
      if (clear && ee.kind == EndEffectorKind::kVacuum && scene.insertion[s]) {
        clear = (X_AP_k.linear() * c.approach_P).dot(*scene.insertion[s]) >= kVacuumPushCos;
      }
      bool pickable = false;
      const int only_table[1] = {scene.table_body};
      local.EnableOnly(only_table);
      for (const Iso3& X_TA : scene.rest_frames[s]) {
        if (!local.Collides(e, X_TA * X_AT, opening)) {
          pickable = true;
          break;
        }
      }
      const Vec3 x_A = X_AP_k * c.center_P;
      const Vec3 axis_A = X_AP_k.linear() * c.axis_P;
      const double com_term = std::exp(-LineDistance(sub.com_A, x_A, axis_A) / length);
      out.kept.push_back(&c);
      out.x.push_back(x_A);
      out.a.push_back(X_AP_k.linear() * c.approach_P);
      out.clear_of_partner.push_back(clear ? 1 : 0);
      out.pickable_at_rest.push_back(pickable ? 1 : 0);
      out.quality.push_back(ee.kind == EndEffectorKind::kVacuum
                                ? (c.slack + com_term) / 2.0
                                : (c.slack + c.pad_fraction + com_term) / 3.0);
    }
  }
  return true;
}

// Picks up to n of the scored candidates whose `reduced` flag (not full-pad) is as asked, in
// tiers (assembly and pick, assembly only, pick only, neither), each pick spread away from every
// grasp already `chosen` (`rot_scale`: metres per radian of approach angle), and interleaves the
// assembly and the other half. Returns indices into `kept`; adds them to `chosen`.
std::vector<int> SpreadTiers(const ScoredCandidates& scored, bool reduced, int n, double rot_scale,
                             std::vector<int>& chosen, const RunContext& ctx) {
  // Spread picks among a subset of the candidates (indices into `kept`), away from every grasp
  // already in the set.
  auto spread = [&](const std::vector<int>& among, int want) {
    std::vector<int> picked =
        FarthestPointOrder(scored.x, scored.a, scored.quality, among, chosen, want, rot_scale, ctx);
    chosen.insert(chosen.end(), picked.begin(), picked.end());
    return picked;
  };
  // Tiers: assembly and pick, assembly only, pick only, neither.
  std::vector<int> tier[4];
  for (int i = 0; i < static_cast<int>(scored.kept.size()); ++i) {
    if ((scored.kept[i]->grasp.type != GraspType::kFullPad) != reduced) continue;
    tier[(scored.clear_of_partner[i] ? 0 : 2) + (scored.pickable_at_rest[i] ? 0 : 1)].push_back(i);
  }
  auto take = [&](std::vector<int>& list, int from_tier, int quota) {
    const int want = quota - static_cast<int>(list.size());
    if (want <= 0) return;
    for (int i : spread(tier[from_tier], want)) list.push_back(i);
  };
  std::vector<int> first, second;
  take(first, 0, (n + 1) / 2);
  take(first, 1, (n + 1) / 2);
  take(second, 2, n - static_cast<int>(first.size()));
  take(second, 3, n - static_cast<int>(first.size()));
  // Too few assembly grasps: the other half takes up the slack from what is left.
  if (static_cast<int>(first.size() + second.size()) < n) {
    std::vector<int> left;
    for (int t : {0, 1}) {
      for (int i : tier[t]) {
        if (std::find(first.begin(), first.end(), i) == first.end()) left.push_back(i);
      }
    }
    tier[0] = left;
    take(second, 0, n - static_cast<int>(first.size()));
  }
  std::vector<int> order;
  for (size_t k = 0; k < std::max(first.size(), second.size()); ++k) {
    for (const std::vector<int>* list : {&first, &second}) {
      if (k < list->size()) order.push_back((*list)[k]);
    }
  }
  return order;
}

// The set: up to n full-pad grasps (SpreadTiers), then up to n reduced ones, spread away from
// the full-pad grasps too. The full-pad part is what it was before reduced grasps existed, so
// plans that find their grasps there do not change; the planner's widening reaches the rest.
GraspSet SpreadGrasps(const ScoredCandidates& scored, const EndEffector& ee, int n,
                      double rot_scale, const RunContext& ctx) {
  std::vector<int> chosen;
  std::vector<int> order = SpreadTiers(scored, false, n, rot_scale, chosen, ctx);
  const std::vector<int> reduced = SpreadTiers(scored, true, n, rot_scale, chosen, ctx);
  order.insert(order.end(), reduced.begin(), reduced.end());
  GraspSet set;
  set.end_effector = ee.name;
  set.kind = ee.kind;
  set.candidates = static_cast<int>(scored.kept.size());
  for (size_t i = 0; i < scored.kept.size(); ++i) {
    const int type = static_cast<int>(scored.kept[i]->grasp.type);
    ++set.candidates_by_type[type];
    if (scored.clear_of_partner[i]) ++set.assembly_candidates_by_type[type];
  }
  for (int i : order) {
    Grasp g = scored.kept[i]->grasp;
    g.quality = scored.quality[i];
    set.grasps.push_back(std::move(g));
  }
  return set;
}

}  // namespace

SelectionScene BuildSelectionScene(const Project& project, const ProjectCheck& check,
                                   const std::vector<Subassembly>& subs,
                                   const std::vector<Iso3>& X_AP, int table_body) {
  const int num_subs = static_cast<int>(subs.size());
  SelectionScene scene;
  scene.table_body = table_body;
  // Rest frames in which grasps must clear the table: a part's initial pose (as a rest frame:
  // rotation kept, lowest hull point at z = 0), and each subassembly's most stable placements.
  scene.rest_frames.resize(num_subs);
  for (int s = 0; s < num_subs; ++s) {
    const Subassembly& sub = subs[s];
    if (sub.parts.size() == 1) {
      const int p = sub.parts[0];
      Iso3 X = ToIsometry(project.parts[p].initial_pose) * X_AP[p].inverse();
      double low = std::numeric_limits<double>::infinity();
      for (const Vec3& v : sub.hull.mesh.vertices) low = std::min(low, (X * v).z());
      X.translation().z() -= low;
      scene.rest_frames[s].push_back(X);
    }
    for (int k = 0; k < std::min<int>(kPickPlacements, sub.placements.size()); ++k) {
      scene.rest_frames[s].push_back(sub.placements[k].X_TA);
    }
  }

  // The partner of each subassembly at its mating: the parts of the other input of the step
  // that consumes it (none for the root). A moved input also has its insertion direction.
  scene.partner.resize(num_subs);
  scene.insertion.resize(num_subs);
  if (check.tree) {
    for (const AssemblyNode& n : check.tree->nodes) {
      if (n.inputs.size() != 2 || n.step < 0) continue;
      scene.partner[n.inputs[0]] = subs[n.inputs[1]].parts;
      scene.partner[n.inputs[1]] = subs[n.inputs[0]].parts;
      const Mating& mating = project.steps[n.step].mating;
      for (int input : n.inputs) {
        if (check.tree->nodes[input].name == mating.moved && mating.axis.norm() > 0.0) {
          scene.insertion[input] = mating.axis.normalized();
        }
      }
    }
  }
  return scene;
}

std::optional<GraspSet> SelectGraspSet(const Subassembly& sub, int s, int e, const EndEffector& ee,
                                       const std::vector<std::vector<GraspCandidate>>& candidates,
                                       int num_ee, const SelectionScene& scene,
                                       const GripperCollision& world,
                                       const PreprocessOptions& options, int grasps_per_set,
                                       const RunContext& ctx) {
  GripperCollision local = world;
  ScoredCandidates scored;
  if (!ScoreCandidates(sub, s, e, ee, candidates, num_ee, scene, local, options, ctx, scored)) {
    return std::nullopt;
  }
  const double diag = sub.aabb_A.size().norm();
  return SpreadGrasps(scored, ee, grasps_per_set, 0.1 * diag, ctx);
}

}  // namespace wrap::detail
