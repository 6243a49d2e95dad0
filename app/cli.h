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


}  // namespace wrap::cli
