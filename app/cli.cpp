#include "cli.h"

#include <CLI/CLI.hpp>
#include <ostream>

namespace wrap::cli {

namespace {

constexpr const char* kAbout =
    "Wrap: fixtureless wrench-aware multi-robot assembly planning (WRAP).\n"
    "Exit codes: 0 success, 1 no plan found / verification failed, 2 bad input, 3 internal "
    "error.";

}  // namespace

int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  CLI::App app{kAbout, "wrap"};
  app.set_version_flag("--version", std::string("wrap ") + WRAP_VERSION);
  app.require_subcommand(0, 1);

  std::string project;
  bool quiet = false;
  CLI::App* validate = app.add_subcommand(
      "validate", "Check a project file: every problem with file, JSON path and reason");
  validate->add_option("PROJECT", project, "Project file (.json)")->required();
  validate->add_flag("-q,--quiet", quiet, "Print errors only, not warnings or the summary");

  CLI::App* info = app.add_subcommand(
      "info", "Describe a project: parts, the assembly DAG, robots and end effectors");
  info->add_option("PROJECT", project, "Project file (.json)")->required();

  // CLI11 takes arguments in reverse order.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    // --help and --version arrive here as "errors" with exit code 0.
    const int code = app.exit(e, out, err);
    return code == 0 ? 0 : 2;
  }
  if (validate->parsed()) return Validate(project, quiet, out, err);
  if (info->parsed()) return Info(project, out, err);
  // No subcommand: the GUI will open here once it exists; until then explain what there is.
  out << app.help();
  return 0;
}

}  // namespace wrap::cli
