// Rendering a cell to files: a list of shots (scene states with captions) drawn from one camera
// into PNG files, a captioned contact sheet and optionally a video. The front door of headless
// rendering; `wrap render` fills a RenderJob and calls RunRenderJob.
//
// Where the shots come from: without a plan, StillShots gives the initial scene and the
// assembled (and exploded) goal. With a plan, PlanShots draws its keyframes: the plan's timeline
// is its keyframes in order (the initial one, then each action's approach, if any, and its
// keyframe), with the keyframe index as time until plans are retimed; FrameTimes picks along it.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/result.h"
#include "render/gl_context.h"
#include "sim/mjcf.h"
#include "sim/scene.h"
#include "task/plan.h"

namespace wrap::render {

/// One image to draw.
struct Shot {
  SceneState state;         ///< What the cell looks like.
  std::string caption;      ///< Under the snapshot on the contact sheet, e.g. "t = 3.2 s: pick".
  std::string file_name;    ///< PNG file name in the output folder, e.g. "initial.png".
  double duration_s = 1.0;  ///< How long the video shows it [s].
};

/// The camera of a job: unset fields are chosen to frame every shot (SceneBounds of all
/// states), from the default direction.
struct CameraRequest {
  std::optional<double> azimuth_deg;  ///< [deg]; default 105 (from the -y side, between the robots
                                      ///< of the example cells).
  std::optional<double> elevation_deg;  ///< [deg] in [-90, 90]; default -40 (looking down).
  std::optional<double> distance_m;     ///< [m] > 0; default: the framing distance.
};

/// Default camera direction of RunRenderJob.
inline constexpr double kDefaultAzimuthDeg = 105.0;
inline constexpr double kDefaultElevationDeg = -40.0;

/// Everything a render run needs besides the scene.
struct RenderJob {
  std::filesystem::path out_dir;                 ///< Created if missing.
  int width = 960;                               ///< Image width [px], in [16, 8192].
  int height = 720;                              ///< Image height [px], in [16, 8192].
  GlBackend backend = GlBackend::kEgl;           ///< Offscreen GL platform.
  CameraRequest camera;                          ///< Camera; automatic framing by default.
  bool shadows = true;                           ///< Draw shadows.
  std::vector<Shot> shots;                       ///< At least one.
  bool contact_sheet = true;                     ///< Also write the captioned grid.
  std::string sheet_file = "contact_sheet.png";  ///< Its file name in out_dir.
  std::string title;                             ///< Title line of the sheet (empty: none).
  std::filesystem::path video;                   ///< MP4 to encode through ffmpeg (empty: none).
};

/// What a render run did.
struct RenderReport {
  std::vector<std::filesystem::path> written;  ///< Every file written, in order.
  std::string gl;                              ///< The GL context used.
  CameraView camera;                           ///< The camera every shot was drawn from.
  double mean_frame_ms = 0.0;         ///< Mean time per rendered shot [ms] (incl. read-back).
  std::vector<std::string> warnings;  ///< E.g. shapes drawn approximately.
};

/// Checks a job's options before anything is loaded or drawn: size in [16, 8192], camera
/// elevation in [-90, 90] and distance > 0, finite values, a plain sheet file name. Fails with
/// kInvalidInput naming the option.
Result<void> CheckRenderOptions(const RenderJob& job);

/// CheckRenderOptions, plus at least one shot and plain file names.
Result<void> CheckRenderJob(const RenderJob& job);

/// Creates `dir` if missing and checks that a file can be written in it. Fails with kIo naming
/// the folder and the system's reason.
Result<void> PrepareOutputDirectory(const std::filesystem::path& dir);

/// Draws every shot of `job` into out_dir, then the contact sheet and the video. Fails with
/// kInvalidInput (bad job, GL backend unavailable, ffmpeg missing for a video), kIo (cannot
/// write) or kInternal (MuJoCo or GL failure); files already written stay.
Result<RenderReport> RunRenderJob(const CellScene& scene, const RenderJob& job);

/// Options of StillShots.
struct StillShotOptions {
  bool initial = true;   ///< The initial scene ("initial.png").
  bool goal = true;      ///< The assembled goal ("goal.png").
  double explode = 0.0;  ///< > 0: also the exploded goal ("goal_exploded.png"), see GoalOptions.
};

/// The shots of a scene without a plan. Fails with kInvalidInput for a bad explode factor or
/// when nothing is selected.
Result<std::vector<Shot>> StillShots(const CellScene& scene, const StillShotOptions& options);

/// The times of the frames to draw along a timeline of `duration_s`: `at_s` when given (each in
/// [0, duration], in the order given), else `frames` times evenly from 0 to the end (one frame:
/// t = 0). Fails with kInvalidInput for frames < 1, a time outside the timeline or not finite.
Result<std::vector<double>> FrameTimes(double duration_s, int frames,
                                       const std::vector<double>& at_s);

/// One keyframe of a plan's timeline.
struct PlanTimelineEntry {
  int action = -1;        ///< Index into Plan::actions; -1 for the initial keyframe.
  bool approach = false;  ///< The action's approach keyframe (assemble), not its keyframe.
};

/// The plan's keyframes in order: the initial one, then per action its approach (if any) and
/// its keyframe. Entry k is time k of the timeline.
std::vector<PlanTimelineEntry> PlanTimeline(const Plan& plan);

/// The scene state at every entry of PlanTimeline. A keyframe becomes a state by its robots'
/// joints and its objects' poses (each part P of object A at X_WA * X_AP); a robot that holds
/// something (replaying the actions: pick, add_grasp and a handover's receiver take hold; place,
/// release and a handover's giver let go, after their keyframe) closes its fingers to the
/// grasp's width, the others are fully open. `tree` is the project's DAG (ProjectCheck::tree).
/// Fails with kInvalidInput naming the keyframe when a joint vector does not fit its robot's
/// chain, an object is not a node of `tree`, or a part is in no object or in two; check the plan
/// with CheckPlanMatchesProject first for messages that name the file and the field.
Result<std::vector<SceneState>> PlanStates(const CellScene& scene, const AssemblyTree& tree,
                                           const Plan& plan);

/// The scene at time t [s] of a plan with motion (trajectories): robots from their timed
/// trajectories with their fingers' openings, resting objects where their last keyframe left them,
/// held objects with their first holder's TCP (the actions take effect at their end_s). Fails with
/// kInvalidInput when the plan has no trajectories or they do not fit the cell.
Result<SceneState> MotionState(const CellScene& scene, const AssemblyTree& tree, const Plan& plan,
                               double t);

/// Options of PlanShots.
struct PlanShotOptions {
  /// >= 1: this many frames evenly along the timeline: with motion, evenly in time from 0 to the
  /// makespan (MotionState); without, frame k of N showing keyframe round(k (K - 1) / (N - 1)) of
  /// K; negative: every keyframe once; 0 is refused.
  int frames = -1;
  /// Keyframe indices to draw, in this order (whole numbers in [0, K - 1]); when given they
  /// replace `frames`.
  std::vector<double> at;
};

/// The shots of a plan: by default one per keyframe, named "plan_KKK_TYPE.png" (KKK the
/// keyframe's index on the timeline, zero-padded; TYPE "initial", the action type, or the type
/// and "_approach"), captioned with the action in words; with `frames` or `at`, "frame_NNN.png"
/// per frame. Fails with kInvalidInput as PlanStates, or for frames or keyframe indices that do
/// not fit the timeline (messages name --frames and --at).
Result<std::vector<Shot>> PlanShots(const CellScene& scene, const AssemblyTree& tree,
                                    const Plan& plan, const PlanShotOptions& options);

}  // namespace wrap::render
