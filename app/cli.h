// The command-line face of Wrap: one function per subcommand, dispatched by RunCli.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace wrap::cli {

/// Runs `wrap` with `args` (without the program name), printing to `out` and `err`. Returns the
/// process exit code: 0 success, 1 no plan / verification failed, 2 bad input, 3 internal error.
int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// `wrap validate PROJECT`: every problem, one per line; exit 0 valid (warnings allowed), 2 not.
int Validate(const std::string& project, bool quiet, std::ostream& out, std::ostream& err);

/// `wrap info PROJECT`: parts with mass and size, the DAG as a tree, robots and end effectors.
int Info(const std::string& project, std::ostream& out, std::ostream& err);

/// Arguments of `wrap preprocess`.
struct PreprocessArgs {
  std::string project;                ///< Project file.
  std::string output;                 ///< JSON file to write (atomically); empty: none.
  int grasps = 0;                     ///< Grasp-set size; 0: the project's planner.grasps.
  int slots = -1;                     ///< Table slots; negative: the default.
  std::optional<std::uint64_t> seed;  ///< Random seed; absent: the project's planner.seed.
};

/// `wrap preprocess PROJECT [-o FILE.json]`: per subassembly its parts, stable placements and
/// grasps per end effector, the table slots, and timings; exit 0, 2 bad input, 3 internal.
int Preprocess(const PreprocessArgs& args, std::ostream& out, std::ostream& err);

/// Arguments of `wrap render`.
struct RenderArgs {
  std::string project;           ///< Project file.
  std::string output;            ///< -o DIR: folder for the PNGs (created if missing).
  std::string plan;              ///< --plan PLAN.json; empty: none (plans are not supported yet).
  int frames = -1;               ///< --frames N along the plan; negative: not given.
  std::string at;                ///< --at T1,T2,... [s] along the plan; empty: not given.
  std::string size = "960x720";  ///< --size WIDTHxHEIGHT [px].
  std::string camera;            ///< --camera AZ,EL[,DIST] [deg, deg, m]; empty: automatic.
  std::string backend = "egl";   ///< --backend egl|osmesa.
  bool goal = false;             ///< --goal: only the goal (no initial scene).
  double explode = 0.0;          ///< --explode F: also the goal exploded by F (0: not).
  std::string video;             ///< --video FILE.mp4 through ffmpeg; empty: none.
  bool no_shadows = false;       ///< --no-shadows.
};

/// `wrap render PROJECT -o DIR`: PNGs of the initial scene and the assembled goal (and the
/// exploded goal), a captioned contact sheet and optionally a video; exit 0, 2 bad input (bad
/// option, unwritable folder, GL backend or ffmpeg unavailable, invalid project), 3 internal.
int Render(const RenderArgs& args, std::ostream& out, std::ostream& err);

}  // namespace wrap::cli
