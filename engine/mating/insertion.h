// Insertion paths: the moved input's straight path along the insertion axis into its mating pose,
// swept against the base input's meshes, and the directions along which that path is free.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/pose.h"
#include "mating/assembly_geometry.h"
#include "mating/contact_graph.h"

namespace wrap {

/// One insertion to judge: the moved parts travel along `axis_A` into their mating pose
/// (X_BM times their assembled poses) from `length_m` back along the axis.
struct InsertionPath {
  std::vector<int> moved;               ///< Parts of the moved input.
  std::vector<int> base;                ///< Parts of the base input.
  Iso3 X_BM = Iso3::Identity();         ///< Mating pose of the moved input relative to its
                                        ///< assembled pose (a symmetric final pose; identity).
  Vec3 axis_A = Vec3::UnitZ();          ///< Unit direction the moved input travels, frame A.
  double length_m = 0.03;               ///< Path length back from the mating pose [m].
  double interference_travel_m = 1e-3;  ///< Final travel where interference is allowed [m].
  double interference_depth_m = 5e-4;   ///< Overlap allowed there [m].
  double touch_depth_m = 2e-4;          ///< Overlap read as touching elsewhere [m].
};

/// Where a path is blocked.
struct PathHit {
  bool blocked = false;  ///< True when the moved input overlaps the base beyond the allowance.
  double at_m = 0.0;     ///< Distance before the mating pose where it does (first met coming in
                         ///< by SweepInsertion, first met going out by IsPathFree) [m].
  int moved_part = -1;   ///< The moved input's part that overlaps.
  int base_part = -1;    ///< The base input's part it overlaps.
};

/// Statistics of the sweeps (for benchmarks and tests).
struct SweepStats {
  int part_pairs = 0;            ///< Pairs of a moved and a base part swept (per range of s).
  long long box_tests = 0;       ///< Pairs of tree boxes whose travel interval was computed.
  long long triangle_tests = 0;  ///< Pairs of triangles whose travel interval was computed.
};

/// The overlap allowed between a moved input and its base `s_m` back from the mating pose: the
/// interference band's (the larger of interference_depth_m and touch_depth_m) within the last
/// interference_travel_m, touch_depth_m elsewhere. The one rule of the sweeps, the trajectory
/// check and the insertion skill.
double AllowedOverlap(double interference_travel_m, double interference_depth_m,
                      double touch_depth_m, double s_m);

/// The moved input's pose (frame A) `s_m` back along the path from its mating pose, for part p.
Iso3 PathPose(const AssemblyGeometry& geometry, const InsertionPath& path, int part, double s_m);

/// Sweeps the path inward, from `length_m` back to the mating pose, with the real meshes
/// (surfaces moved inward by half the allowed overlap): the exact continuous test of a
/// translation (SweepContact), so nothing is stepped over, however thin, and `at_m` is exact.
/// Returns the first overlap met coming in, or not blocked.
PathHit SweepInsertion(AssemblyGeometry& geometry, const InsertionPath& path,
                       SweepStats* stats = nullptr);

/// True when the path is free; `hit` gets the overlap nearest the mating pose (the first met
/// going out). The same exact sweep as SweepInsertion.
bool IsPathFree(AssemblyGeometry& geometry, const InsertionPath& path, PathHit* hit = nullptr,
                SweepStats* stats = nullptr);

/// Candidate insertion axes for a step: the assembly frame's six axes, the contact normals
/// between the inputs (into the base), and `sphere` directions spread over the sphere; without
/// duplicates (within 3 degrees), in that order.
std::vector<Vec3> CandidateAxes(const ContactGraph& contacts, const std::vector<int>& moved,
                                const std::vector<int>& base, int sphere = 64);

/// The candidate axes along which `path` (with its axis replaced) is free, in candidate order.
std::vector<Vec3> FreeAxes(AssemblyGeometry& geometry, InsertionPath path,
                           const std::vector<Vec3>& candidates, SweepStats* stats = nullptr);

/// A pair of parts that overlap.
struct PartOverlap {
  int part_a = -1;  ///< Of the first set.
  int part_b = -1;  ///< Of the second set.
};

/// The first pair (a of `set_a`, b of `set_b`, in order) whose solids overlap by more than
/// `allowed_m` with every part p at X[p] (the surfaces inset by half of it; FCL's exact test), or
/// none. The pose test behind the checks that replay a plan (the plan validator's own sweep, the
/// trajectory check, the simulation), each with its own poses.
std::optional<PartOverlap> OverlapBeyond(AssemblyGeometry& geometry, const std::vector<int>& set_a,
                                         const std::vector<int>& set_b, const std::vector<Iso3>& X,
                                         double allowed_m);

/// How natural an insertion axis is, higher is better: from above (the moved input comes down,
/// gravity helps) before level before from below, axis-aligned before oblique. Orders the free
/// directions in messages and the choices of authoring.
double AxisPreference(const Vec3& axis);

/// "[0, 0, -1]" or "[0.71, 0, -0.71]": a direction for messages (two decimals, no "-0").
std::string FormatDirection(const Vec3& d);

}  // namespace wrap
