// `wrap` without a subcommand when the build has no ui/ (WRAP_BUILD_UI=OFF).
#include <ostream>

#include "cli.h"

namespace wrap::cli {

int Gui(const GuiArgs&, std::ostream&, std::ostream& err) {
  err << "wrap: this build has no GUI (configured with -DWRAP_BUILD_UI=OFF); use a subcommand "
         "(wrap --help)\n";
  return 2;
}

}  // namespace wrap::cli
