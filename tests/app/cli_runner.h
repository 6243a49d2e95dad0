// Running the CLI in-process for tests: exit code and captured output.
#pragma once

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "cli.h"

namespace wrap::cli {

/// What one `wrap` invocation returned and printed.
struct CliRun {
  int code = -1;    ///< Exit code.
  std::string out;  ///< Standard output.
  std::string err;  ///< Standard error.
};

/// Runs `wrap ARGS...` through RunCli.
inline CliRun Wrap(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  CliRun r;
  r.code = RunCli(args, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

/// Path of an example project by name, e.g. "stool".
inline std::string Project(const std::string& name) {
  return (std::filesystem::path(WRAP_SOURCE_DIR) / "projects" / (name + ".json")).string();
}

}  // namespace wrap::cli
