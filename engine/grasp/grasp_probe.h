// Grasps of parts that sit among other parts, before any project exists: what assembly planning
// by disassembly asks ("can a gripper hold this part where it is assembled, clear of the rest?").
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/pose.h"
#include "core/result.h"
#include "core/run_context.h"
#include "geometry/mesh.h"
#include "grasp/grasp.h"

namespace wrap {

/// Options of GraspProbe::Build.
struct GraspProbeOptions {
  int candidates = 64;          ///< Grasp candidates sampled per part and end effector.
  int sample_factor = 30;       ///< Surface samples per candidate wanted before giving up.
  double friction = 0.4;        ///< Pad friction coefficient (the antipodal cone).
  std::uint64_t seed = 0;       ///< Same seed, same candidates.
  TwoFingerGraspOptions two_finger;
  VacuumGraspOptions vacuum;
};

/// Grasp candidates of each part alone (every part at its pose X_AP in a frame A), and the
/// question which of them stay clear of a set of other parts. Not thread-safe.
class GraspProbe {
 public:
  /// Samples the candidates of every part for every end effector (catalog names). Fails with
  /// kInvalidInput for an unknown end effector or a mesh the collision world rejects.
  static Result<GraspProbe> Build(std::span<const TriangleMesh* const> meshes,
                                  std::span<const Iso3> X_AP,
                                  std::span<const std::string> end_effectors,
                                  const GraspProbeOptions& options, const RunContext& ctx);
  ~GraspProbe();
  GraspProbe(GraspProbe&&) noexcept;
  GraspProbe& operator=(GraspProbe&&) noexcept;

  /// The candidates of `part` for end effector `ee` (index into the names given to Build).
  const std::vector<Grasp>& candidates(int part, int ee) const;

  /// How many candidates of `part` for `ee` leave the open gripper clear of every part in
  /// `others` (all at their poses X_AP).
  int ClearOf(int part, int ee, std::span<const int> others);

  /// The same for the reduced (partial-pad, fingertip) candidates of `part` for two-finger
  /// `ee`, sampled on first use with a pool 16 times `candidates` (a wheel held by its tire's
  /// edge, a pipe by its collar); 0 for other end effectors.
  int ReducedClearOf(int part, int ee, std::span<const int> others);

 private:
  GraspProbe();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wrap
