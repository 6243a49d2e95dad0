// The command-line face of Wrap: one function per subcommand, dispatched by RunCli.
#pragma once

#include <iosfwd>
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

}  // namespace wrap::cli
