// The two grasp samplers on one part (paper §IV-B): antipodal two-finger grasps and vacuum
// grasps, each checked against the part itself. Subassemblies filter and select from them.
#pragma once

#include <random>
#include <vector>

#include "core/run_context.h"
#include "grasp/detail/gripper_collision.h"
#include "geometry/mesh_query.h"
#include "grasp/grasp.h"
#include "robot/catalog.h"

namespace wrap::detail {

/// A grasp found on a part, before a subassembly scores and selects it.
struct GraspCandidate {
  Grasp grasp;                      ///< part, end effector, X_PG, width, contacts, area.
  Vec3 center_P = Vec3::Zero();     ///< Contact midpoint (two-finger) or cup centre, in P [m].
  Vec3 axis_P = Vec3::UnitX();      ///< Closing line (two-finger) or cup axis, unit, in P.
  Vec3 approach_P = Vec3::UnitZ();  ///< Approach direction of the gripper (G's z), in P.
  double slack = 0.0;         ///< Friction-cone (two-finger) or flatness (vacuum) slack in [0, 1].
  double pad_fraction = 0.0;  ///< Two-finger: smaller pad contact / pad area, in [0, 1].
};

/// What one sampling run needs: the part (its raycaster and index into the collision world),
/// where it sits in A, and the end effector.
struct SamplerInput {
  const MeshQuery* part = nullptr;  ///< The part's surface, in P.
  int part_index = -1;                  ///< Index into Project::parts (and the world's parts).
  Iso3 X_AP = Iso3::Identity();         ///< Its assembled pose.
  const EndEffector* ee = nullptr;      ///< The end effector.
  int ee_index = 0;                     ///< Its index in the collision world.
  double friction = 0.5;                ///< Pad friction coefficient (two-finger).
  int wanted = 0;                       ///< Stop after this many candidates.
  int max_samples = 0;                  ///< ... or after this many surface samples.
};

/// Antipodal sampling: a surface point, a closing line inside its friction cone, the exit point
/// of that line within the stroke and inside its friction cone, pads touching both sides over the
/// minimum area, and an approach direction about the line for which the open gripper does not
/// touch the part (`world` must have exactly this part enabled). Stops early when ctx says so.
std::vector<GraspCandidate> SampleTwoFinger(const SamplerInput& in,
                                            const TwoFingerGraspOptions& options,
                                            GripperCollision& world, std::mt19937_64& rng,
                                            const RunContext& ctx);

/// The pool of a reduced draw for a part short of grasps, as a multiple of the full-pad pool
/// (with a quarter of that multiple times the samples): their features are small (a collar, a
/// button). Preprocessing's second draw and GraspProbe::ReducedClearOf both use it.
inline constexpr int kShortReducedPoolFactor = 16;

/// Reduced two-finger sampling (partial-pad and fingertip grasps, grasp.h GraspType): as
/// SampleTwoFinger, on a finer pad grid, trying first the approach straight down in the
/// assembly's frame, with the pads centred on the contacts touching less than
/// options.min_pad_contact_m2 (partial-pad), pulled back so that their tips stand 3 mm past the
/// contacts touching less than that, or pulled back to options.fingertip_reach_m past them with
/// any contact (fingertip); at least options.min_reduced_contact_m2 on each pad. Each grasp has
/// its torque scale (GraspTorqueScale).
std::vector<GraspCandidate> SampleTwoFingerReduced(const SamplerInput& in,
                                                   const TwoFingerGraspOptions& options,
                                                   GripperCollision& world, std::mt19937_64& rng,
                                                   const RunContext& ctx);

/// Vacuum sampling: a surface point whose cup disc rests on a flat patch (every test point of
/// the disc on the tangent plane within the tolerance, normals aligned), cup axis along the
/// normal, and a rotation about it for which the gripper, backed off by the standoff, does not
/// touch the part.
std::vector<GraspCandidate> SampleVacuum(const SamplerInput& in, const VacuumGraspOptions& options,
                                         GripperCollision& world, std::mt19937_64& rng,
                                         const RunContext& ctx);

}  // namespace wrap::detail
