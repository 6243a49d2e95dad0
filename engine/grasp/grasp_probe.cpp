#include "grasp/grasp_probe.h"

#include <optional>
#include <random>

#include "geometry/mesh_query.h"
#include "grasp/detail/grasp_sampler.h"
#include "grasp/detail/gripper_collision.h"
#include "robot/catalog.h"

namespace wrap {

struct GraspProbe::Impl {
  std::vector<EndEffector> effectors;
  std::vector<Iso3> X_AP;
  std::optional<detail::GripperCollision> world;
  std::vector<std::vector<detail::GraspCandidate>> candidates;  // part * num_ee + ee
  std::vector<std::vector<Grasp>> grasps;                       // same order
  // For the reduced candidates, sampled on first use: each part's surface, the options, and
  // the candidates (part * num_ee + ee; none yet when empty).
  std::vector<std::unique_ptr<MeshQuery>> queries;
  GraspProbeOptions options;
  std::vector<std::optional<std::vector<Grasp>>> reduced;
};

GraspProbe::GraspProbe() : impl_(std::make_unique<Impl>()) {}
GraspProbe::~GraspProbe() = default;
GraspProbe::GraspProbe(GraspProbe&&) noexcept = default;
GraspProbe& GraspProbe::operator=(GraspProbe&&) noexcept = default;

Result<GraspProbe> GraspProbe::Build(std::span<const TriangleMesh* const> meshes,
                                     std::span<const Iso3> X_AP,
                                     std::span<const std::string> end_effectors,
                                     const GraspProbeOptions& options, const RunContext& ctx) {
  GraspProbe probe;
  Impl& impl = *probe.impl_;
  for (const std::string& name : end_effectors) {
    auto ee = LoadEndEffector(name);
    if (!ee) return Fail(ErrorCode::kInvalidInput, ee.error().message);
    impl.effectors.push_back(std::move(*ee));
  }
  impl.X_AP.assign(X_AP.begin(), X_AP.end());
  auto world = detail::GripperCollision::Build(meshes, X_AP, impl.effectors, ctx);
  if (!world) return std::unexpected(world.error());
  impl.world.emplace(std::move(*world));
  const int num_parts = static_cast<int>(meshes.size());
  const int num_ee = static_cast<int>(impl.effectors.size());
  impl.candidates.resize(num_parts * num_ee);
  impl.grasps.resize(num_parts * num_ee);
  impl.options = options;
  impl.reduced.resize(num_parts * num_ee);
  for (int p = 0; p < num_parts; ++p) {
    impl.queries.push_back(std::make_unique<MeshQuery>(*meshes[p]));
    const MeshQuery& query = *impl.queries.back();
    const int only[1] = {p};
    impl.world->EnableOnly(only);
    for (int e = 0; e < num_ee; ++e) {
      std::mt19937_64 rng(options.seed * 1000003ULL + static_cast<std::uint64_t>(p * num_ee + e));
      detail::SamplerInput in;
      in.part = &query;
      in.part_index = p;
      in.X_AP = X_AP[p];
      in.ee = &impl.effectors[e];
      in.ee_index = e;
      in.friction = options.friction;
      in.wanted = options.candidates;
      in.max_samples = options.candidates * options.sample_factor;
      auto& out = impl.candidates[p * num_ee + e];
      out = impl.effectors[e].kind == EndEffectorKind::kVacuum
                ? detail::SampleVacuum(in, options.vacuum, *impl.world, rng, ctx)
                : detail::SampleTwoFinger(in, options.two_finger, *impl.world, rng, ctx);
      for (const detail::GraspCandidate& c : out) impl.grasps[p * num_ee + e].push_back(c.grasp);
    }
  }
  return probe;
}

const std::vector<Grasp>& GraspProbe::candidates(int part, int ee) const {
  return impl_->grasps[part * static_cast<int>(impl_->effectors.size()) + ee];
}

namespace {

int CountClear(detail::GripperCollision& world, const Iso3& X_AP, int ee,
               const std::vector<Grasp>& grasps, std::span<const int> others) {
  world.EnableOnly(others);
  int clear = 0;
  for (const Grasp& g : grasps) {
    const double opening = g.kind == EndEffectorKind::kVacuum ? 0.0 : g.width_m + 2e-3;
    if (!world.Collides(ee, X_AP * g.X_PG, opening)) ++clear;
  }
  return clear;
}

}  // namespace

int GraspProbe::ReducedClearOf(int part, int ee, std::span<const int> others) {
  Impl& impl = *impl_;
  if (impl.effectors[ee].kind != EndEffectorKind::kTwoFinger) return 0;
  std::optional<std::vector<Grasp>>& reduced =
      impl.reduced[part * static_cast<int>(impl.effectors.size()) + ee];
  if (!reduced) {
    const int only[1] = {part};
    impl.world->EnableOnly(only);
    // A generator of its own, and the preprocessing's larger pool for a part short of grasps.
    std::mt19937_64 rng(impl.options.seed * 1000003ULL + 0x5eedULL +
                        static_cast<std::uint64_t>(part * impl.effectors.size() + ee));
    detail::SamplerInput in;
    in.part = impl.queries[part].get();
    in.part_index = part;
    in.X_AP = impl.X_AP[part];
    in.ee = &impl.effectors[ee];
    in.ee_index = ee;
    in.friction = impl.options.friction;
    in.wanted = detail::kShortReducedPoolFactor * impl.options.candidates;
    in.max_samples =
        detail::kShortReducedPoolFactor / 4 * impl.options.candidates * impl.options.sample_factor;
    RunContext quiet(impl.options.seed);
    reduced.emplace();
    for (const detail::GraspCandidate& c :
         detail::SampleTwoFingerReduced(in, impl.options.two_finger, *impl.world, rng, quiet)) {
      reduced->push_back(c.grasp);
    }
  }
  return CountClear(*impl.world, impl.X_AP[part], ee, *reduced, others);
}

int GraspProbe::ClearOf(int part, int ee, std::span<const int> others) {
  Impl& impl = *impl_;
  return CountClear(*impl.world, impl.X_AP[part], ee, candidates(part, ee), others);
}

}  // namespace wrap
