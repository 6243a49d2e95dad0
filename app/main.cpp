// wrap: fixtureless wrench-aware multi-robot assembly planning.
#include <exception>
#include <iostream>

#include "cli.h"

int main(int argc, char** argv) {
  try {
    std::vector<std::string> args(argv + 1, argv + argc);
    return wrap::cli::RunCli(args, std::cout, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "wrap: internal error: " << e.what() << "\n";
    return 3;
  } catch (...) {
    std::cerr << "wrap: internal error: unknown exception\n";
    return 3;
  }
}
