// `wrap sim --video` in a build without ui/ (WRAP_BUILD_UI=OFF): says so before any run.
#include "sim_video.h"

namespace wrap::cli {

namespace {

Error NoRenderer() {
  return {ErrorCode::kInvalidInput,
          "--video: this build has no renderer (configured with WRAP_BUILD_UI=OFF); reconfigure "
          "with -DWRAP_BUILD_UI=ON or leave out --video"};
}

}  // namespace

Result<void> CheckSimVideo() { return std::unexpected(NoRenderer()); }

Result<void> WriteSimVideo(const CellScene& /*scene*/, const std::vector<SimFrame>& /*frames*/,
                           const std::string& /*file*/) {
  return std::unexpected(NoRenderer());
}

}  // namespace wrap::cli
