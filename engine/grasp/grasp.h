// Grasps: how an end effector holds a part (paper §IV-B "Preprocessing", grasp sets G_A).
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/pose.h"
#include "grasp/grasp_type.h"
#include "model/project.h"

namespace wrap {

/// One grasp of a subassembly: a grasp on one of its parts. Frames: P the part, G the grasp
/// frame, which is the end effector's TCP frame T while it holds the part (z the approach, into
/// the part; two-finger: the catalog's closing axis, x for the Robotiq 2F-85, y for the OpenArm
/// hand, along the line through both contacts; vacuum: z along the cup axis). In a subassembly A
/// the grasp frame is X_AG = X_AP * X_PG: a grasp carries over to every subassembly that contains
/// its part.
struct Grasp {
  int part = -1;             ///< Index into Project::parts of the held part.
  std::string end_effector;  ///< Catalog end-effector name, e.g. "robotiq_2f85".
  EndEffectorKind kind = EndEffectorKind::kTwoFinger;  ///< Two-finger or vacuum.
  Iso3 X_PG = Iso3::Identity();                        ///< Grasp (TCP) frame in the part frame.
  /// Score in [0, 1], higher is better. Two-finger: mean of the friction-cone slack (1 when the
  /// closing line is along both surface normals, 0 at the cone's edge), the smaller pad contact
  /// as a fraction of the pad, and exp(-d / L) for the distance d of the subassembly's centre of
  /// mass from the closing line (L: half the subassembly's box diagonal). Vacuum: mean of the
  /// flatness slack (1 - largest normal deviation under the cup / allowed deviation) and
  /// exp(-d / L) with d the COM's distance from the cup axis.
  double quality = 0.0;
  /// Two-finger: distance between the two contacts, the width the fingers close to [m] (for
  /// drawing the fingers); vacuum: 0.
  double width_m = 0.0;
  /// Contact points in P [m]: two-finger the two fingers' contacts, the one on the +closing-axis
  /// side first; vacuum the cup centre twice.
  std::array<Vec3, 2> contacts_P = {Vec3::Zero(), Vec3::Zero()};
  /// Two-finger: the smaller of the two pads' contact areas; vacuum: the cup disc [m^2].
  double contact_area_m2 = 0.0;
  GraspType type = GraspType::kFullPad;  ///< Full-pad, partial-pad or fingertip.
  /// The grasp's torque limits as fractions of the end effector's adopted box, per axis of G
  /// (GraspTorqueScale: 1 for full-pad and vacuum grasps). Its box: GraspLimits.
  Vec3 torque_scale = Vec3::Ones();
};

/// The contact patch of a reduced two-finger grasp, as the sampler measured it on the smaller
/// of the two pads.
struct PadPatch {
  double area_m2 = 0.0;   ///< Touching area [m^2].
  double width_m = 0.0;   ///< Extent across the pad's width (normal to the approach) [m].
  double length_m = 0.0;  ///< Extent along the pad's length (along the approach) [m].
};

/// The physical model of a reduced grasp's limits (docs/algorithms.md "Grasp types"), as
/// fractions of the adopted box, which holds for any contact of at least `full_area_m2` (a
/// square patch of that area is the reference): forces keep their bounds (Coulomb friction
/// mu * grip force does not depend on the contact area; the push along the closing axis is the
/// grip itself); the torque about the closing axis (torsional friction) scales with the patch's
/// radius, sqrt(area / full_area); the torque about the pad's width axis with the patch's length
/// and the torque about the approach axis with its width (the pressure moment over the patch),
/// each over the reference square's side. All capped at 1. `closing_G`, `approach_G`: the
/// end effector's axes in G (unit, along G's axes). Returns the scale per axis of G.
Vec3 GraspTorqueScale(const PadPatch& patch, double full_area_m2, const Vec3& closing_G,
                      const Vec3& approach_G);

/// The wrench limits of grasp `g` given the holding robot's limits `limits`: the two-finger box's
/// torques scaled by g.torque_scale; the vacuum boxes as they are. The one place a grasp's box
/// is made (planner, validator, motion, simulation).
WrenchLimits GraspLimits(const WrenchLimits& limits, const Vec3& torque_scale);
inline WrenchLimits GraspLimits(const WrenchLimits& limits, const Grasp& g) {
  return GraspLimits(limits, g.torque_scale);
}

/// The grasps of one subassembly for one end effector, spread over its surface: ordered by
/// farthest-point selection, so every prefix is itself spread (the planner's widening takes the
/// first k). Full-pad grasps first, then the reduced ones (partial-pad, fingertip).
struct GraspSet {
  std::string end_effector;                            ///< Catalog end-effector name.
  EndEffectorKind kind = EndEffectorKind::kTwoFinger;  ///< Its kind.
  /// At most the requested set size of full-pad grasps, then at most as many reduced ones.
  std::vector<Grasp> grasps;
  int candidates = 0;  ///< Collision-free candidates the set was selected from (statistics).
  /// Of them, per GraspType (index: the enum's value).
  std::array<int, kGraspTypes> candidates_by_type = {0, 0, 0};
  /// Of them, per GraspType, those whose gripper clears the mating partner at the mating pose
  /// (the assembly grasps the set's tiers put first).
  std::array<int, kGraspTypes> assembly_candidates_by_type = {0, 0, 0};
};

/// Options of the two-finger antipodal sampler.
struct TwoFingerGraspOptions {
  /// Least contact between each finger pad and the part [m^2]. Default 1 cm^2 (the Robotiq pad
  /// is 22 x 37.5 mm; a 25 mm round leg gives ~3.5 cm^2).
  double min_pad_contact_m2 = 1e-4;
  /// Pad compliance: surface within this distance of the pad's plane touches it [m]. Default 1 mm.
  double contact_tolerance_m = 1e-3;
  /// The fingers are checked for collision this much wider than the part on each side: the
  /// opening the gripper approaches with [m]. Default 1 mm.
  double clearance_m = 1e-3;
  /// Narrowest part width grasped [m]. Default 2 mm.
  double min_width_m = 2e-3;
  /// Approach directions tried about each contact pair's closing line. Default 8.
  int approach_samples = 8;
  /// Rays across the pad's width and along its length for the contact test. Default 4 x 6.
  int pad_rays_width = 4;
  int pad_rays_length = 6;
  /// Reduced grasps (partial-pad and fingertip), sampled after the full-pad ones and added to
  /// each set after them (so the planner's widening reaches them last). Default true.
  bool reduced = true;
  /// ... for the parts that need them: those whose own full-pad candidates that clear the
  /// mating partner at the mating pose number fewer than this share of the grasp set (a wheel,
  /// a short collar, a button, a slide that leaves the gripper little room). 0: none; 1 or more:
  /// every part whose full-pad assembly grasps cannot fill the set. Default 0.25 (16 of 64): with
  /// fewer, the few that clear the partner rarely also reach from the table and leave IK room
  /// at the mating pose (the gamepad's slide: 4-10 of 256, task plans for 1 seed of 3).
  double reduced_below_share = 0.25;
  /// Least contact of a reduced grasp on each pad [m^2]. Default 0.2 cm^2: a patch of about
  /// 4.5 x 4.5 mm, at least two cells of the reduced pass's pad grid; below it the pad meets
  /// an edge or a point, where no contact patch (and no torque capacity) can be relied on.
  double min_reduced_contact_m2 = 2e-5;
  /// Fingertip grasps: how far the pads' tips reach past the contacts [m]. Default 1.5 mm.
  double fingertip_reach_m = 1.5e-3;
  /// Rays across the pad's width and along its length in the reduced pass (finer: the patches
  /// are small). Default 8 x 8.
  int reduced_rays_width = 8;
  int reduced_rays_length = 8;
};

/// How many full-pad assembly candidates a part needs to go without reduced grasps, for sets of
/// `grasps_per_set` (TwoFingerGraspOptions::reduced_below_share of it, rounded up; 0 for none).
int ReducedGraspThreshold(const TwoFingerGraspOptions& options, int grasps_per_set);

/// Options of the vacuum sampler.
struct VacuumGraspOptions {
  /// Every point of the cup disc must lie within this distance of the tangent plane [m].
  /// Default 0.5 mm.
  double flatness_tolerance_m = 5e-4;
  /// ... with a surface normal within this angle of the cup axis [rad]. Default 10 degrees.
  double max_normal_deviation_rad = 0.1745;
  /// Fraction of the disc's test points that must be supported: the minimum support area as a
  /// fraction of the cup's. Default 1 (the whole disc rests on the patch).
  double min_support_fraction = 1.0;
  /// The gripper is checked for collision this far back from the surface along the cup axis
  /// (the cup lip touches the part by construction) [m]. Default 1 mm.
  double standoff_m = 1e-3;
  /// Rotations about the cup axis tried for a collision-free gripper body. Default 4.
  int yaw_samples = 4;
  /// Test points of the disc: the centre, a ring at r/2, and the corners of a polygon around the
  /// rim (circumscribing the disc). Default 6 on the inner ring, 12 on the rim.
  int inner_ring_points = 6;
  int rim_points = 12;
};

}  // namespace wrap
