// STEP import in a build without OpenCASCADE (-DWRAP_WITH_OCCT=OFF): every call fails saying so.
#include "geometry/detail/step_common.h"
#include "geometry/step_import.h"

namespace wrap {

namespace {

std::string Unavailable(const std::string& what) {
  return what +
         ": STEP is unavailable in this build of Wrap (configured with -DWRAP_WITH_OCCT=OFF); "
         "install OpenCASCADE (scripts/install_deps.sh) and configure with -DWRAP_WITH_OCCT=ON, "
         "or export the parts as STL, OBJ or PLY";
}

}  // namespace

bool StepImportAvailable() { return false; }

Result<StepAssembly> ImportStep(const std::filesystem::path& path, const StepTessellation&) {
  // Missing and unreadable files are reported as such; a readable one as unavailable.
  if (auto ok = detail::CheckStepFile(path); !ok) return std::unexpected(ok.error());
  return Fail(ErrorCode::kInvalidInput,
              Unavailable("cannot read STEP file '" + path.string() + "'"));
}

Result<StepAssembly> ImportStepInProcess(const std::filesystem::path& path,
                                         const StepTessellation& tessellation) {
  return ImportStep(path, tessellation);
}

Result<void> WriteStep(const StepDocumentSpec&, const std::filesystem::path& path) {
  return Fail(ErrorCode::kInvalidInput,
              Unavailable("cannot write STEP file '" + path.string() + "'"));
}

}  // namespace wrap
