// Physics verification of a plan (paper §V-B, table "simulation success"): the plan's timed
// trajectories run in MuJoCo 2.2 on the physics variant of the cell's MJCF (sim/mjcf.h). Parts
// are free bodies on the table under gravity and friction; each robot's TCP is a mocap body
// driven kinematically along its trajectory (forward kinematics at every step: the arm is not
// simulated, so joint tracking errors and arm dynamics are not part of the verdict); a grasped
// part is welded to the TCP from the grasp to the release; during an insertion the project's
// mating wrench acts on the two inputs at their interface as an external wrench; a made
// connection is welded. The weld forces give each gripper's wrench in its grasp frame, compared
// with its limits as a utilisation.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/result.h"
#include "core/run_context.h"
#include "model/project.h"
#include "model/validate.h"
#include "sim/scene.h"
#include "task/plan.h"

namespace wrap {

/// Options of SimulatePlan, with their defaults.
struct SimOptions {
  double timestep_s = 0.001;         ///< Integration step [s].
  double settle_s = 1.0;             ///< Simulated after the last action [s].
  double drift_tolerance_m = 0.03;   ///< A part this far from where the plan has it: "no support".
  double drift_tolerance_rad = 0.3;  ///< ... or turned this far from it [rad].
  double misalign_tolerance_m = 0.01;   ///< Mated or final relative pose error: "misalignment".
  double misalign_tolerance_rad = 0.1;  ///< ... in rotation [rad].
  double force_scale = 1.0;             ///< Lambda on the applied mating wrench (>= 0).
  /// A gripper limit of 0 (vacuum: no lateral force while mating) is taken as this small bound
  /// when computing utilisation, so that measurement noise does not count as a violation [N].
  double zero_limit_force_N = 1.0;
  double zero_limit_torque_Nm = 0.05;  ///< Same for torques [N m].
  int sample_every = 5;                ///< Measure wrenches and drift every this many steps.
  /// A gripper's wrench is judged averaged over this long [s] (its last measurements): a
  /// kinematic robot's acceleration steps where its trajectory's pieces meet, and MuJoCo's weld
  /// answers a step with a spike of one or two samples (a carried chair's gripper: 53% -> 103%
  /// -> 85% within 20 ms) that no gripper's pads would feel. 0: every sample alone.
  double average_s = 0.02;
  /// Judge collisions (robots with robots, robots with parts they neither hold nor are grasping
  /// or releasing, held parts with anything but their mating partner during its insertion, a
  /// held part into the table). Only with trajectories: a keyframe replay is not collision-free
  /// by construction, so its collisions are never judged.
  bool check_collisions = true;
  /// Contacts no deeper than this do not count [m]: every robot shape is shrunk by it (two robots
  /// may overlap by twice it), a held part may sink this far into the table.
  double collision_tolerance_m = 0.002;
  /// Collisions are checked after a joint moved this much since the last check [rad] ...
  double collision_resolution_rad = 0.01;
  /// ... or a part this much [m], or an action happened.
  double collision_resolution_m = 0.002;
  /// Called with the simulated cell every `frame_interval_s` of simulated time (from t = 0 and
  /// once more at the end) when set, e.g. to record a video: robots at their driven joints,
  /// parts where MuJoCo has them. Never called with GL: drawing is the caller's business.
  std::function<void(double t_s, const SceneState& state)> on_frame;
  double frame_interval_s = 0.1;  ///< [s] > 0.
  /// When set, the physics model is also written here (cell.xml and meshes, sim/mjcf.h
  /// WriteMjcf), e.g. to open it in MuJoCo's `simulate`.
  std::filesystem::path mjcf_dir;
};

/// Peak utilisations (1 = 100% of the limit) by phase and end-effector type; -1 where no gripper
/// of that type held anything in that phase.
struct SimUtilisation {
  double two_finger_transport = -1.0;  ///< Two-finger grippers carrying or holding.
  double two_finger_insertion = -1.0;  ///< Two-finger grippers during insertions.
  double vacuum_transport = -1.0;      ///< Vacuum grippers carrying or holding.
  double vacuum_insertion = -1.0;      ///< Vacuum grippers during insertions.
  /// Made connections: the wrench through the weld of each made connection against its limits
  /// (T_pq, a box in the connection frame: origin at the interface, z along the insertion axis).
  /// Reported, not a failure.
  double connection = -1.0;
  /// The table's support: the largest friction use |F_t| / (mu F_n) of a part nobody holds, over
  /// the resultant of its contacts with the table carrying more than 0.05 N (1: sliding).
  /// Reported, not a failure (a part that slides is caught as "no support").
  double table_friction = -1.0;
};

/// What happened to one action of the plan.
struct SimActionStatus {
  std::string type;              ///< "pick", "place", ...
  std::string status;            ///< "completed", "failed" or "not reached".
  double peak_utilisation = -1;  ///< Highest utilisation of its robots while it ran; -1 none.
};

/// Why a plan failed in simulation.
struct SimFailure {
  int action = -1;  ///< Index of the action blamed.
  /// "no support", "slip", "vacuum limit", "collision", "misalignment".
  std::string reason;
  std::string detail;  ///< In words: which part or robot, the numbers seen.
  double t_s = 0.0;    ///< Simulated time it was detected [s].
};

/// The verdict of a simulation.
struct SimReport {
  bool success = false;                  ///< The plan ran to the end with no failure.
  int tasks_completed = 0;               ///< Actions completed before the failure.
  int tasks_total = 0;                   ///< Actions of the plan.
  std::vector<SimActionStatus> actions;  ///< One per plan action.
  SimUtilisation peak;                   ///< Peak utilisations.
  std::optional<SimFailure> failure;     ///< Null when it holds.
  double final_position_error_m = 0.0;   ///< Worst part position error in the final assembly [m].
  double final_angle_error_rad = 0.0;    ///< Worst part rotation error in it [rad].
  double simulated_s = 0.0;              ///< Simulated time [s].
  long long steps = 0;                   ///< Integration steps.
  std::string driving = "kinematic TCP mocap";  ///< How the robots are driven.
  /// "trajectories" (the plan's timed motion) or "keyframes" (a plan without motion: its
  /// keyframes replayed one action at a time, straight in joint space; see `notes`).
  std::string motion = "trajectories";
  bool collisions_judged = false;  ///< Collisions were checked during the run.
  long long collision_checks = 0;  ///< Moments checked for collisions.
  /// Measurements in which a gripper beyond its limits as MuJoCo's rigid welds split its
  /// object's load was judged by the best split among the object's supports instead (its other
  /// grippers, its table contacts: an LP, see sim_measure.cpp BestSplit). 0 when none.
  long long split_measurements = 0;
  std::vector<std::string> notes;     ///< What the run approximated (keyframe replay).
  std::vector<std::string> warnings;  ///< MuJoCo warnings, approximated meshes.
};

/// Simulates `plan` of `project` (validated: `check` holds its meshes and tree; `project_file`
/// resolves URDFs). A plan with trajectories runs them; a plan without (`wrap plan --task-only`)
/// replays its keyframes (report.motion "keyframes": one action at a time, robots straight in
/// joint space between keyframes within their velocity and acceleration limits, a lift after a
/// pick, a descent before a place, the insertion from the approach keyframe; robots that share an
/// object follow the first holder's TCP; collisions are not judged). Fails with kInvalidInput when
/// the plan does not fit the cell (the message starts with the plan's JSON path, e.g.
/// "trajectories: ..." or "actions[3]: ..."; callers prefix the plan file), kInternal with MuJoCo's
/// message when MuJoCo raises an error (never exits), kCancelled when `ctx` stops. A plan that
/// fails in simulation is a SimReport with success false, not an error.
[[nodiscard]] Result<SimReport> SimulatePlan(const Project& project, const ProjectCheck& check,
                                             const std::filesystem::path& project_file,
                                             const Plan& plan, const SimOptions& options,
                                             RunContext& ctx);

/// The report as JSON text (2-space indent, final newline): success, tasks, actions, peak
/// utilisations in percent (null where absent), failure {action, reason, detail, t_s} or null.
std::string SerializeSimReport(const SimReport& report);

}  // namespace wrap
