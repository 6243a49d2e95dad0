#include "grasp/preprocess.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <random>

#include "grasp/detail/grasp_sampler.h"
#include "grasp/detail/gripper_collision.h"
#include "geometry/mesh_query.h"
#include "grasp/detail/parallel.h"
#include "robot/catalog.h"

namespace wrap {

namespace {

using detail::GraspCandidate;
using Clock = std::chrono::steady_clock;

// SplitMix64 of a and b: independent seeds for the tasks of one run.
std::uint64_t MixSeed(std::uint64_t a, std::uint64_t b) {
  std::uint64_t z = a + 0x9E3779B97F4A7C15ull * (b + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

Error Stopped(const RunContext& ctx, const std::string& where) {
  return Error{ctx.cancelled() ? ErrorCode::kCancelled : ErrorCode::kTimeout,
               "preprocess: " + std::string(ctx.cancelled() ? "cancelled" : "time limit reached") +
                   " during " + where};
}

double AngleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

bool SameMesh(const TriangleMesh& a, const TriangleMesh& b) {
  return a.vertices == b.vertices && a.triangles == b.triangles;
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

// Times the phases of the preprocessing and reports the next one as progress.
class Lap {
 public:
  Lap(StageTimes& times, const RunContext& ctx)
      : times_(times), ctx_(ctx), last_(Clock::now()), start_(last_) {
    Report();
  }
  void operator()(const std::string& key) {
    const auto now = Clock::now();
    times_[key] += std::chrono::duration<double>(now - last_).count();
    last_ = now;
    ++done_;
    Report();
  }
  void Total() { times_["total"] = std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  void Report() const {
    static constexpr const char* kPhases[] = {
        "subassemblies",     "convex hulls",
        "stable placements", "table slots (IK over the table)",
        "grasp candidates",  "grasp selection"};
    constexpr int n = static_cast<int>(std::size(kPhases));
    if (done_ >= n) return;
    ctx_.Progress("preprocess", static_cast<double>(done_) / n,
                  std::to_string(done_ + 1) + "/" + std::to_string(n) + ": " + kPhases[done_]);
  }
  StageTimes& times_;
  const RunContext& ctx_;
  Clock::time_point last_, start_;
  int done_ = 0;
};

Result<Preprocessed> Run(const Project& project, const ProjectCheck& check,
                         const PreprocessOptions& options, RunContext& ctx) {
  Preprocessed out;
  Lap lap(out.times, ctx);
  out.grasps_per_set = options.grasps > 0 ? options.grasps : project.planner.grasps;
  if (out.grasps_per_set <= 0) {
    return Fail(ErrorCode::kInvalidInput,
                "preprocess: grasp-set size must be positive (planner.grasps is " +
                    std::to_string(project.planner.grasps) + ")");
  }
  out.friction = options.friction.value_or(project.table.friction);
  if (!(out.friction > 0.0) || !std::isfinite(out.friction)) {
    return Fail(ErrorCode::kInvalidInput, "preprocess: friction coefficient must be positive");
  }
  out.seed = ctx.rng()();

  // Subassemblies: parts in final relative poses, mass and COM.
  auto subs = BuildSubassemblies(project, check);
  if (!subs) return std::unexpected(subs.error());
  out.subassemblies = std::move(*subs);
  const int num_parts = static_cast<int>(project.parts.size());
  const int num_subs = static_cast<int>(out.subassemblies.size());

  // End effectors: the options' or those of the robots, in robot order.
  std::vector<std::string> names = options.end_effectors;
  if (names.empty()) {
    for (const Robot& r : project.robots) {
      if (std::find(names.begin(), names.end(), r.end_effector) == names.end()) {
        names.push_back(r.end_effector);
      }
    }
  }
  std::vector<EndEffector> effectors;
  for (const std::string& name : names) {
    auto ee = LoadEndEffector(name);
    if (!ee) return Fail(ee.error().code, "preprocess: " + ee.error().message);
    effectors.push_back(std::move(*ee));
  }
  out.end_effectors = names;
  const int num_ee = static_cast<int>(effectors.size());
  lap("subassemblies");

  // Parts with identical meshes (the same file: legs, arms, cube blocks) share their hull,
  // raycaster and grasp candidates, which are all in the part frame: `same[p]` is the first.
  std::vector<int> same(num_parts);
  for (int p = 0; p < num_parts; ++p) {
    same[p] = p;
    for (int q = 0; q < p; ++q) {
      if (same[q] == q && SameMesh(check.parts[p].mesh, check.parts[q].mesh)) {
        same[p] = q;
        break;
      }
    }
  }
  std::vector<int> unique_parts;
  for (int p = 0; p < num_parts; ++p) {
    if (same[p] == p) unique_parts.push_back(p);
  }
  const int num_unique = static_cast<int>(unique_parts.size());

  // Convex hulls: each part's, then each subassembly's from its parts' hull vertices.
  std::vector<Result<ConvexHull>> part_hulls(num_parts, Fail(ErrorCode::kInternal, ""));
  detail::ParallelFor(num_unique, options.parallel, [&](int u) {
    if (ctx.ShouldStop()) return;
    const int p = unique_parts[u];
    part_hulls[p] = ComputeConvexHull(check.parts[p].mesh, options.hull);
  });
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "convex hulls"));
  for (int p = 0; p < num_parts; ++p) {
    if (same[p] != p) part_hulls[p] = part_hulls[same[p]];
    if (!part_hulls[p]) {
      return Fail(part_hulls[p].error().code, "preprocess: part '" + project.parts[p].name +
                                                  "': " + part_hulls[p].error().message);
    }
  }
  std::vector<Error> errors(num_subs);
  detail::ParallelFor(num_subs, options.parallel, [&](int s) {
    if (ctx.ShouldStop()) return;
    Subassembly& sub = out.subassemblies[s];
    std::vector<Vec3> points;
    for (size_t k = 0; k < sub.parts.size(); ++k) {
      for (const Vec3& v : part_hulls[sub.parts[k]]->mesh.vertices)
        points.push_back(sub.X_AP[k] * v);
    }
    auto hull = ComputeConvexHull(points, options.hull);
    if (!hull) {
      errors[s] = hull.error();
      return;
    }
    sub.hull = std::move(*hull);
  });
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "convex hulls"));
  for (int s = 0; s < num_subs; ++s) {
    if (!errors[s].message.empty()) {
      return Fail(errors[s].code, "preprocess: subassembly '" + out.subassemblies[s].name +
                                      "': " + errors[s].message);
    }
  }
  lap("hulls");

  // Stable placements.
  detail::ParallelFor(num_subs, options.parallel, [&](int s) {
    if (ctx.ShouldStop()) return;
    Subassembly& sub = out.subassemblies[s];
    sub.placements = ComputeStablePlacements(sub.hull, sub.com_A, options.placements);
  });
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "stable placements"));
  lap("placements");

  // Table positions the robots reach.
  if (options.compute_table_slots) {
    TableSlotOptions slot_options = options.table_slots;
    slot_options.parallel = slot_options.parallel && options.parallel;
    auto slots = ComputeTableSlots(project, options.project_file, slot_options,
                                   MixSeed(out.seed, 0x51075), ctx);
    if (!slots) return std::unexpected(slots.error());
    out.table_slots = std::move(*slots);
  }
  lap("table_slots");

  // Grasp candidates per part and end effector, each checked against its own part.
  std::vector<const TriangleMesh*> meshes;
  std::vector<Iso3> X_AP;
  for (int p = 0; p < num_parts; ++p) {
    meshes.push_back(&check.parts[p].mesh);
    X_AP.push_back(ToIsometry(project.parts[p].assembled_pose));
  }
  // The table as one more body: its top is the plane z = 0 of this frame, wide enough for any
  // part (grasps are tested against it in the rest frame of a placement).
  const TriangleMesh table_box = BoxMesh(Vec3(-5.0, -5.0, -0.1), Vec3(5.0, 5.0, 0.0));
  const int table_body = num_parts;
  meshes.push_back(&table_box);
  X_AP.push_back(Iso3::Identity());
  // The collision world (FCL's trees, built serially) alongside the parts' raycasters.
  Result<detail::GripperCollision> world = Fail(ErrorCode::kInternal, "not built");
  std::vector<std::unique_ptr<MeshQuery>> rays(num_parts);
  detail::ParallelFor(num_unique + 1, options.parallel, [&](int task) {
    if (task == 0) {
      world = detail::GripperCollision::Build(meshes, X_AP, effectors, ctx);
    } else if (!ctx.ShouldStop()) {
      const int p = unique_parts[task - 1];
      rays[p] = std::make_unique<MeshQuery>(check.parts[p].mesh);
    }
  });
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "grasp sampling"));
  if (!world) return Fail(world.error().code, "preprocess: " + world.error().message);
  const int pool = std::max(out.grasps_per_set * std::max(1, options.candidate_factor), 8);
  const int max_samples = pool * std::max(1, options.sample_factor);
  std::vector<std::vector<GraspCandidate>> candidates(num_parts * num_ee);
  detail::ParallelFor(num_unique * num_ee, options.parallel, [&](int task) {
    const int p = unique_parts[task / num_ee], e = task % num_ee;
    detail::GripperCollision local = *world;
    const int only[1] = {p};
    local.EnableOnly(only);
    std::mt19937_64 rng(MixSeed(out.seed, static_cast<std::uint64_t>(task) + 1));
    detail::SamplerInput in;
    in.part = rays[p].get();
    in.part_index = p;
    in.X_AP = X_AP[p];
    in.ee = &effectors[e];
    in.ee_index = e;
    in.friction = out.friction;
    in.wanted = pool;
    in.max_samples = max_samples;
    candidates[p * num_ee + e] =
        effectors[e].kind == EndEffectorKind::kVacuum
            ? detail::SampleVacuum(in, options.vacuum, local, rng, ctx)
            : detail::SampleTwoFinger(in, options.two_finger, local, rng, ctx);
  });
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "grasp sampling"));
  for (int p = 0; p < num_parts; ++p) {
    if (same[p] == p) continue;
    for (int e = 0; e < num_ee; ++e) {
      candidates[p * num_ee + e] = candidates[same[p] * num_ee + e];
      for (GraspCandidate& c : candidates[p * num_ee + e]) c.grasp.part = p;
    }
  }
  lap("grasp_candidates");

  // Rest frames in which grasps must clear the table: a part's initial pose (as a rest frame:
  // rotation kept, lowest hull point at z = 0), and each subassembly's most stable placements.
  std::vector<std::vector<Iso3>> rest_frames(num_subs);
  for (int s = 0; s < num_subs; ++s) {
    const Subassembly& sub = out.subassemblies[s];
    if (sub.parts.size() == 1) {
      const int p = sub.parts[0];
      Iso3 X = ToIsometry(project.parts[p].initial_pose) * X_AP[p].inverse();
      double low = std::numeric_limits<double>::infinity();
      for (const Vec3& v : sub.hull.mesh.vertices) low = std::min(low, (X * v).z());
      X.translation().z() -= low;
      rest_frames[s].push_back(X);
    }
    for (int k = 0; k < std::min<int>(kPickPlacements, sub.placements.size()); ++k) {
      rest_frames[s].push_back(sub.placements[k].X_TA);
    }
  }

  // The partner of each subassembly at its mating: the parts of the other input of the step
  // that consumes it (none for the root).
  // A moved input also has its insertion direction: a vacuum cup inserts it only when it pushes
  // along that direction (its assembly box allows force along the cup axis alone).
  std::vector<std::vector<int>> partner(num_subs);
  std::vector<std::optional<Vec3>> insertion(num_subs);
  if (check.tree) {
    for (const AssemblyNode& n : check.tree->nodes) {
      if (n.inputs.size() != 2 || n.step < 0) continue;
      partner[n.inputs[0]] = out.subassemblies[n.inputs[1]].parts;
      partner[n.inputs[1]] = out.subassemblies[n.inputs[0]].parts;
      const Mating& mating = project.steps[n.step].mating;
      for (int input : n.inputs) {
        if (check.tree->nodes[input].name == mating.moved && mating.axis.norm() > 0.0) {
          insertion[input] = mating.axis.normalized();
        }
      }
    }
  }

  // Per subassembly and end effector: drop candidates that hit another part, score, spread.
  // Half of each set (every other grasp, from the first) are assembly grasps: the gripper clears
  // the partner input at the mating pose, so the inserting and the holding robot have grasps
  // that work there whatever else the random candidates favour. Within each half, grasps that
  // can take the subassembly from the table come first: the gripper clears the table top where
  // the subassembly rests in its initial pose (a part) or one of its most stable placements.
  for (Subassembly& sub : out.subassemblies) sub.grasp_sets.resize(num_ee);
  detail::ParallelFor(num_subs * num_ee, options.parallel, [&](int task) {
    const int s = task / num_ee, e = task % num_ee;
    Subassembly& sub = out.subassemblies[s];
    const EndEffector& ee = effectors[e];
    detail::GripperCollision local = *world;
    const double diag = sub.aabb_A.size().norm();
    const double length = std::max(1e-6, 0.5 * diag);
    std::vector<const GraspCandidate*> kept;
    std::vector<Vec3> x, a;
    std::vector<double> quality;
    std::vector<char> clear_of_partner, pickable_at_rest;
    int checked = 0;
    for (size_t k = 0; k < sub.parts.size(); ++k) {
      const int p = sub.parts[k];
      std::vector<int> others;
      for (int o : sub.parts) {
        if (o != p) others.push_back(o);
      }
      const Iso3& X_AP_k = sub.X_AP[k];
      for (const GraspCandidate& c : candidates[p * num_ee + e]) {
        if (++checked % 32 == 0 && ctx.ShouldStop()) return;
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
        if (!partner[s].empty()) {
          local.EnableOnly(partner[s]);
          clear = !local.Collides(e, X_AT, opening);
        }
        if (clear && ee.kind == EndEffectorKind::kVacuum && insertion[s]) {
          clear = (X_AP_k.linear() * c.approach_P).dot(*insertion[s]) >= kVacuumPushCos;
        }
        bool pickable = false;
        const int only_table[1] = {table_body};
        local.EnableOnly(only_table);
        for (const Iso3& X_TA : rest_frames[s]) {
          if (!local.Collides(e, X_TA * X_AT, opening)) {
            pickable = true;
            break;
          }
        }
        const Vec3 x_A = X_AP_k * c.center_P;
        const Vec3 axis_A = X_AP_k.linear() * c.axis_P;
        const double com_term = std::exp(-LineDistance(sub.com_A, x_A, axis_A) / length);
        kept.push_back(&c);
        x.push_back(x_A);
        a.push_back(X_AP_k.linear() * c.approach_P);
        clear_of_partner.push_back(clear ? 1 : 0);
        pickable_at_rest.push_back(pickable ? 1 : 0);
        quality.push_back(ee.kind == EndEffectorKind::kVacuum
                              ? (c.slack + com_term) / 2.0
                              : (c.slack + c.pad_fraction + com_term) / 3.0);
      }
    }
    // Spread picks among a subset of the candidates (indices into `kept`), away from every grasp
    // already in the set.
    std::vector<int> chosen;
    auto spread = [&](const std::vector<int>& among, int n) {
      std::vector<int> picked =
          FarthestPointOrder(x, a, quality, among, chosen, n, 0.1 * diag, ctx);
      chosen.insert(chosen.end(), picked.begin(), picked.end());
      return picked;
    };
    // Tiers: assembly and pick, assembly only, pick only, neither.
    std::vector<int> tier[4];
    for (int i = 0; i < static_cast<int>(kept.size()); ++i) {
      tier[(clear_of_partner[i] ? 0 : 2) + (pickable_at_rest[i] ? 0 : 1)].push_back(i);
    }
    const int n = out.grasps_per_set;
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
    GraspSet set;
    set.end_effector = ee.name;
    set.kind = ee.kind;
    set.candidates = static_cast<int>(kept.size());
    for (size_t k = 0; k < std::max(first.size(), second.size()); ++k) {
      for (const std::vector<int>* list : {&first, &second}) {
        if (k >= list->size()) continue;
        const int i = (*list)[k];
        Grasp g = kept[i]->grasp;
        g.quality = quality[i];
        set.grasps.push_back(std::move(g));
      }
    }
    sub.grasp_sets[e] = std::move(set);
  });
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "grasp selection"));
  lap("grasp_sets");

  for (const Subassembly& sub : out.subassemblies) {
    if (sub.placements.empty()) {
      out.warnings.push_back("subassembly '" + sub.name +
                             "': no stable placement (it cannot be set down on the table)");
    }
    int total = 0;
    for (const GraspSet& set : sub.grasp_sets) total += static_cast<int>(set.grasps.size());
    if (total == 0 && num_ee > 0) {
      out.warnings.push_back("subassembly '" + sub.name + "': no grasp for any end effector");
    }
  }
  lap.Total();
  return out;
}

}  // namespace

const Subassembly* Preprocessed::Find(const std::string& name) const {
  for (const Subassembly& s : subassemblies) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

Result<Preprocessed> Preprocess(const Project& project, const ProjectCheck& check,
                                const PreprocessOptions& options, RunContext& ctx) {
  ScopedStageTimer timer(ctx, "grasp");
  // The catch barrier of this stage: anything thrown below (allocation, TBB) becomes an Error.
  try {
    return Run(project, check, options, ctx);
  } catch (const std::exception& e) {
    return Fail(ErrorCode::kInternal, std::string("preprocess: unexpected exception: ") + e.what());
  }
}

}  // namespace wrap
