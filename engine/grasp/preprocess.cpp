// The preprocessing stage in phases: subassemblies and end effectors, convex hulls, stable
// placements, table slots, grasp candidates per part (parts with the same mesh share them), and
// the grasp sets per subassembly (detail/grasp_selection.h), each phase timed and reported.
#include "grasp/preprocess.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <iterator>
#include <memory>
#include <optional>
#include <random>

#include "geometry/mesh_query.h"
#include "grasp/detail/grasp_sampler.h"
#include "grasp/detail/grasp_selection.h"
#include "grasp/detail/gripper_collision.h"
#include "grasp/detail/parallel.h"
#include "robot/catalog.h"

namespace wrap {

namespace {

using detail::GraspCandidate;
using Clock = std::chrono::steady_clock;

// A part with reduced grasps and fewer than this many candidates (of any type) clear of its
// partner at the mating pose draws reduced candidates a second time, kShortReducedPoolFactor
// times the full-pad pool (4 times round 0's samples).
constexpr int kLeastAssemblyGrasps = 8;

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

bool SameMesh(const TriangleMesh& a, const TriangleMesh& b) {
  return a.vertices == b.vertices && a.triangles == b.triangles;
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

// The end effectors to sample for: the options' or those of the robots, in robot order; their
// names into `names`.
Result<std::vector<EndEffector>> LoadEffectors(const Project& project,
                                               const PreprocessOptions& options,
                                               std::vector<std::string>& names) {
  names = options.end_effectors;
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
  return effectors;
}

// Parts with identical meshes (the same file: legs, arms, cube blocks) share their hull,
// raycaster and grasp candidates, which are all in the part frame.
struct SharedMeshes {
  std::vector<int> same;    // Per part: the first part with its mesh.
  std::vector<int> unique;  // The parts that are their own `same`, in order.
};

SharedMeshes FindSharedMeshes(const ProjectCheck& check, int num_parts) {
  SharedMeshes m;
  m.same.resize(num_parts);
  for (int p = 0; p < num_parts; ++p) {
    m.same[p] = p;
    for (int q = 0; q < p; ++q) {
      if (m.same[q] == q && SameMesh(check.parts[p].mesh, check.parts[q].mesh)) {
        m.same[p] = q;
        break;
      }
    }
  }
  for (int p = 0; p < num_parts; ++p) {
    if (m.same[p] == p) m.unique.push_back(p);
  }
  return m;
}

// Convex hulls: each part's, then each subassembly's from its parts' hull vertices.
Result<void> ComputeHulls(const Project& project, const ProjectCheck& check,
                          const PreprocessOptions& options, const SharedMeshes& shared,
                          std::vector<Subassembly>& subs, const RunContext& ctx) {
  const int num_parts = static_cast<int>(project.parts.size());
  const int num_subs = static_cast<int>(subs.size());
  const int num_unique = static_cast<int>(shared.unique.size());
  std::vector<Result<ConvexHull>> part_hulls(num_parts, Fail(ErrorCode::kInternal, ""));
  detail::ParallelFor(num_unique, options.parallel, [&](int u) {
    if (ctx.ShouldStop()) return;
    const int p = shared.unique[u];
    part_hulls[p] = ComputeConvexHull(check.parts[p].mesh, options.hull);
  });
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "convex hulls"));
  for (int p = 0; p < num_parts; ++p) {
    if (shared.same[p] != p) part_hulls[p] = part_hulls[shared.same[p]];
    if (!part_hulls[p]) {
      return Fail(part_hulls[p].error().code, "preprocess: part '" + project.parts[p].name +
                                                  "': " + part_hulls[p].error().message);
    }
  }
  std::vector<Error> errors(num_subs);
  detail::ParallelFor(num_subs, options.parallel, [&](int s) {
    if (ctx.ShouldStop()) return;
    Subassembly& sub = subs[s];
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
      return Fail(errors[s].code,
                  "preprocess: subassembly '" + subs[s].name + "': " + errors[s].message);
    }
  }
  return {};
}

// The grasp candidates of every part and end effector, and the collision world they were
// checked in.
struct SampledCandidates {
  std::vector<Iso3> X_AP;  // Assembled pose of each part, then the table's (identity).
  int table_body = -1;     // The table's index among the world's parts.
  std::optional<detail::GripperCollision> world;
  std::vector<std::unique_ptr<MeshQuery>> rays;         // Per unique part (shared.unique).
  std::vector<std::vector<GraspCandidate>> candidates;  // Index part * num_ee + end effector.
  int pool = 0;         // Candidates wanted per part and end effector.
  int max_samples = 0;  // Samples tried for them.
};

// The sampler's input for unique part `p` and end effector `e`.
detail::SamplerInput SamplerInputFor(const SampledCandidates& sampled,
                                     const std::vector<EndEffector>& effectors,
                                     const Preprocessed& out, int p, int e) {
  detail::SamplerInput in;
  in.part = sampled.rays[p].get();
  in.part_index = p;
  in.X_AP = sampled.X_AP[p];
  in.ee = &effectors[e];
  in.ee_index = e;
  in.friction = out.friction;
  in.wanted = sampled.pool;
  in.max_samples = sampled.max_samples;
  return in;
}

// The parts that share a unique part's mesh get its candidates (their own part index).
void CopyToSharedMeshes(const SharedMeshes& shared, int num_ee, SampledCandidates& sampled) {
  for (int p = 0; p < static_cast<int>(shared.same.size()); ++p) {
    if (shared.same[p] == p) continue;
    for (int e = 0; e < num_ee; ++e) {
      std::vector<GraspCandidate>& dst = sampled.candidates[p * num_ee + e];
      dst = sampled.candidates[shared.same[p] * num_ee + e];
      for (GraspCandidate& c : dst) c.grasp.part = p;
    }
  }
}

// Grasp candidates per part and end effector, each checked against its own part.
Result<SampledCandidates> SampleCandidates(const Project& project, const ProjectCheck& check,
                                           const PreprocessOptions& options,
                                           const std::vector<EndEffector>& effectors,
                                           const SharedMeshes& shared, const Preprocessed& out,
                                           const RunContext& ctx) {
  const int num_parts = static_cast<int>(project.parts.size());
  const int num_ee = static_cast<int>(effectors.size());
  const int num_unique = static_cast<int>(shared.unique.size());
  SampledCandidates sampled;
  std::vector<const TriangleMesh*> meshes;
  std::vector<Iso3>& X_AP = sampled.X_AP;
  for (int p = 0; p < num_parts; ++p) {
    meshes.push_back(&check.parts[p].mesh);
    X_AP.push_back(ToIsometry(project.parts[p].assembled_pose));
  }
  // The table as one more body: its top is the plane z = 0 of this frame, wide enough for any
  // part (grasps are tested against it in the rest frame of a placement).
  const TriangleMesh table_box = BoxMesh(Vec3(-5.0, -5.0, -0.1), Vec3(5.0, 5.0, 0.0));
  sampled.table_body = num_parts;
  meshes.push_back(&table_box);
  X_AP.push_back(Iso3::Identity());
  // The collision world (FCL's trees, built serially) alongside the parts' raycasters.
  Result<detail::GripperCollision> world = Fail(ErrorCode::kInternal, "not built");
  std::vector<std::unique_ptr<MeshQuery>>& rays = sampled.rays;
  rays.resize(num_parts);
  detail::ParallelFor(num_unique + 1, options.parallel, [&](int task) {
    if (task == 0) {
      world = detail::GripperCollision::Build(meshes, X_AP, effectors, ctx);
    } else if (!ctx.ShouldStop()) {
      const int p = shared.unique[task - 1];
      rays[p] = std::make_unique<MeshQuery>(check.parts[p].mesh);
    }
  });
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "grasp sampling"));
  if (!world) return Fail(world.error().code, "preprocess: " + world.error().message);
  sampled.pool = std::max(out.grasps_per_set * std::max(1, options.candidate_factor), 8);
  sampled.max_samples = sampled.pool * std::max(1, options.sample_factor);
  sampled.world = std::move(*world);
  std::vector<std::vector<GraspCandidate>>& candidates = sampled.candidates;
  candidates.resize(num_parts * num_ee);
  detail::ParallelFor(num_unique * num_ee, options.parallel, [&](int task) {
    const int p = shared.unique[task / num_ee], e = task % num_ee;
    detail::GripperCollision local = *sampled.world;
    const int only[1] = {p};
    local.EnableOnly(only);
    std::mt19937_64 rng(MixSeed(out.seed, static_cast<std::uint64_t>(task) + 1));
    const detail::SamplerInput in = SamplerInputFor(sampled, effectors, out, p, e);
    candidates[p * num_ee + e] =
        effectors[e].kind == EndEffectorKind::kVacuum
            ? detail::SampleVacuum(in, options.vacuum, local, rng, ctx)
            : detail::SampleTwoFinger(in, options.two_finger, local, rng, ctx);
  });
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "grasp sampling"));
  CopyToSharedMeshes(shared, num_ee, sampled);
  return sampled;
}

// Whether part `p` needs reduced grasps for two-finger end effector `e`: its own subassembly's
// full-pad candidates that clear the mating partner at the mating pose are fewer than
// ReducedGraspThreshold (a short collar, a button, a wheel whose rim the fingers
// would enter). Parts with enough full-pad grasps get none: the reduced pass is most of
// preprocessing's time where it runs.
bool NeedsReducedGrasps(const Preprocessed& out, int p, int e, int below) {
  for (const Subassembly& sub : out.subassemblies) {
    if (sub.parts.size() != 1 || sub.parts.front() != p) continue;
    const GraspSet& set = sub.grasp_sets[e];
    return set.assembly_candidates_by_type[static_cast<int>(GraspType::kFullPad)] < below;
  }
  return false;
}

// Whether part `p` is still short of assembly grasps for end effector `e` after its reduced
// grasps were added: fewer than `least` of its candidates of any type clear its partner at the
// mating pose (a pipe whose collar fingertips reach from above only where the elbow fits between
// the fingers: 0-6 of ~1000 reduced candidates, depending on the seed).
bool ShortOfAssemblyGrasps(const Preprocessed& out, int p, int e, int least) {
  for (const Subassembly& sub : out.subassemblies) {
    if (sub.parts.size() != 1 || sub.parts.front() != p) continue;
    const auto& by_type = sub.grasp_sets[e].assembly_candidates_by_type;
    return by_type[0] + by_type[1] + by_type[2] < least;
  }
  return false;
}

// The parts (index part * num_ee + end effector) whose two-finger candidates get reduced ones
// in round `round`: 0, the parts that need them (NeedsReducedGrasps); 1, those of them still
// short of assembly grasps (ShortOfAssemblyGrasps). A part needs them when any part sharing its
// mesh does; the mask is set on the mesh's unique part.
std::vector<char> ReducedRoundParts(const PreprocessOptions& options,
                                    const std::vector<EndEffector>& effectors,
                                    const SharedMeshes& shared, const Preprocessed& out,
                                    const std::vector<char>& before, int round) {
  const int num_parts = static_cast<int>(shared.same.size());
  const int num_ee = static_cast<int>(effectors.size());
  const int threshold = ReducedGraspThreshold(options.two_finger, out.grasps_per_set);
  std::vector<char> needs(num_parts * num_ee, 0);
  for (int p = 0; p < num_parts; ++p) {
    for (int e = 0; e < num_ee; ++e) {
      if (effectors[e].kind != EndEffectorKind::kTwoFinger) continue;
      const bool take = round == 0 ? NeedsReducedGrasps(out, p, e, threshold)
                                   : before[p * num_ee + e] &&
                                         ShortOfAssemblyGrasps(out, p, e, kLeastAssemblyGrasps);
      if (take) needs[shared.same[p] * num_ee + e] = 1;
    }
  }
  return needs;
}

// Adds reduced (partial-pad, fingertip) candidates to the two-finger candidates of the unique
// parts marked in `needs` (ReducedRoundParts), with a generator of each round's own and a pool
// of 4 times the full-pad one in round 0, kShortReducedPoolFactor times it in round 1. Returns the
// parts that got them (every part sharing a marked mesh).
std::vector<char> AddReducedCandidates(const PreprocessOptions& options,
                                       const std::vector<EndEffector>& effectors,
                                       const SharedMeshes& shared, const Preprocessed& out,
                                       std::vector<char> needs, int round,
                                       SampledCandidates& sampled, const RunContext& ctx) {
  const int num_parts = static_cast<int>(shared.same.size());
  const int num_ee = static_cast<int>(effectors.size());
  const int num_unique = static_cast<int>(shared.unique.size());
  detail::ParallelFor(num_unique * num_ee, options.parallel, [&](int task) {
    const int p = shared.unique[task / num_ee], e = task % num_ee;
    if (!needs[p * num_ee + e] || ctx.ShouldStop()) return;
    detail::GripperCollision local = *sampled.world;
    const int only[1] = {p};
    local.EnableOnly(only);
    // A generator of their own: the full-pad candidates (and round 0's) stay as they were.
    const std::uint64_t salt = round == 0 ? 0x9e3779b97f4a7c15ULL : 0xc2b2ae3d27d4eb4fULL;
    std::mt19937_64 rng(MixSeed(out.seed, salt ^ (static_cast<std::uint64_t>(task) + 1)));
    // A larger pool: the features only reduced grasps hold are small (a collar, a button).
    const int factor = round == 0 ? 4 : detail::kShortReducedPoolFactor;
    detail::SamplerInput in = SamplerInputFor(sampled, effectors, out, p, e);
    in.wanted = factor * sampled.pool;
    in.max_samples = factor / 4 * sampled.max_samples;
    std::vector<GraspCandidate> reduced =
        detail::SampleTwoFingerReduced(in, options.two_finger, local, rng, ctx);
    std::vector<GraspCandidate>& mine = sampled.candidates[p * num_ee + e];
    mine.insert(mine.end(), std::make_move_iterator(reduced.begin()),
                std::make_move_iterator(reduced.end()));
  });
  for (int p = 0; p < num_parts; ++p) {
    for (int e = 0; e < num_ee; ++e) needs[p * num_ee + e] = needs[shared.same[p] * num_ee + e];
  }
  CopyToSharedMeshes(shared, num_ee, sampled);
  return needs;
}

// What the planner should know: subassemblies that cannot be set down or grasped.
void AddWarnings(int num_ee, Preprocessed& out) {
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
}

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
  auto effectors = LoadEffectors(project, options, out.end_effectors);
  if (!effectors) return std::unexpected(effectors.error());
  const int num_ee = static_cast<int>(effectors->size());
  lap("subassemblies");

  const SharedMeshes shared = FindSharedMeshes(check, num_parts);
  if (auto hulls = ComputeHulls(project, check, options, shared, out.subassemblies, ctx); !hulls) {
    return std::unexpected(hulls.error());
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

  auto sampled = SampleCandidates(project, check, options, *effectors, shared, out, ctx);
  if (!sampled) return std::unexpected(sampled.error());
  lap("grasp_candidates");

  // Per subassembly and end effector: drop candidates that hit another part, score, spread
  // (detail/grasp_selection.h). Half of each set (every other grasp, from the first) are
  // assembly grasps: the gripper clears the partner input at the mating pose, so the inserting
  // and the holding robot have grasps that work there whatever else the random candidates
  // favour. Within each half, grasps that can take the subassembly from the table come first:
  // the gripper clears the table top where the subassembly rests in its initial pose (a part)
  // or one of its most stable placements.
  const detail::SelectionScene scene = detail::BuildSelectionScene(
      project, check, out.subassemblies, sampled->X_AP, sampled->table_body);
  for (Subassembly& sub : out.subassemblies) sub.grasp_sets.resize(num_ee);
  const auto select = [&](const std::vector<char>& which) {
    detail::ParallelFor(num_subs * num_ee, options.parallel, [&](int task) {
      const int s = task / num_ee, e = task % num_ee;
      if (!which[task]) return;
      Subassembly& sub = out.subassemblies[s];
      std::optional<GraspSet> set =
          detail::SelectGraspSet(sub, s, e, (*effectors)[e], sampled->candidates, num_ee, scene,
                                 *sampled->world, options, out.grasps_per_set, ctx);
      if (set) sub.grasp_sets[e] = std::move(*set);
    });
  };
  select(std::vector<char>(num_subs * num_ee, 1));
  if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "grasp selection"));
  lap("grasp_sets");

  // Reduced grasps for the parts whose full-pad grasps leave too few that clear their partner;
  // the sets of every subassembly holding such a part are selected again with them. A part
  // still short of assembly grasps after that draws again from a pool four times as large.
  if (options.two_finger.reduced) {
    std::vector<char> got(num_parts * num_ee, 0);
    for (int round = 0; round < 2; ++round) {
      std::vector<char> needs = ReducedRoundParts(options, *effectors, shared, out, got, round);
      if (std::ranges::none_of(needs, [](char c) { return c != 0; })) break;
      needs = AddReducedCandidates(options, *effectors, shared, out, std::move(needs), round,
                                   *sampled, ctx);
      if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "reduced grasp sampling"));
      std::vector<char> again(num_subs * num_ee, 0);
      for (int s = 0; s < num_subs; ++s) {
        for (int p : out.subassemblies[s].parts) {
          for (int e = 0; e < num_ee; ++e) again[s * num_ee + e] |= needs[p * num_ee + e];
        }
      }
      for (size_t k = 0; k < got.size(); ++k) got[k] |= needs[k];
      select(again);
      if (ctx.ShouldStop()) return std::unexpected(Stopped(ctx, "grasp selection"));
    }
    lap("reduced_grasps");
  }

  AddWarnings(num_ee, out);
  lap.Total();
  return out;
}

}  // namespace

int ReducedGraspThreshold(const TwoFingerGraspOptions& options, int grasps_per_set) {
  if (options.reduced_below_share <= 0.0) return 0;
  return static_cast<int>(std::ceil(options.reduced_below_share * grasps_per_set));
}

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
