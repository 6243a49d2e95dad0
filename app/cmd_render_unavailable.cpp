// `wrap render` in a build without ui/ (WRAP_BUILD_UI=OFF): says so.
#include <ostream>

#include "cli.h"

namespace wrap::cli {

int Render(const RenderArgs& /*args*/, std::ostream& /*out*/, std::ostream& err) {
  err << "wrap render: this build has no renderer (configured with WRAP_BUILD_UI=OFF); "
         "reconfigure with -DWRAP_BUILD_UI=ON\n";
  return 2;
}

}  // namespace wrap::cli
