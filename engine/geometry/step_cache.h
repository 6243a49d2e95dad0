// STEP imports cached by the file's contents: in this process, and on disk beside the project,
// so that reopening a project does not tessellate its STEP files again.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "core/result.h"
#include "geometry/step_import.h"

namespace wrap {

/// Options of LoadStep.
struct StepLoadOptions {
  StepTessellation tessellation;    ///< How finely to tessellate.
  std::filesystem::path cache_dir;  ///< Folder of cached tessellations; empty: no disk cache.
};

/// Where a LoadStep result came from.
enum class StepSource { kImported, kDiskCache, kMemory };

/// What LoadStep returns.
struct StepLoad {
  std::shared_ptr<const StepAssembly> assembly;  ///< The import (shared, never null).
  StepSource source = StepSource::kImported;     ///< Tessellated now, or read from a cache.
  std::filesystem::path cache_file;  ///< The disk cache entry (empty without a cache_dir).
  std::string cache_problem;         ///< Why the entry could not be written (empty when fine).
};

/// ImportStep through two caches keyed by the file's contents (a 128-bit hash of its bytes and
/// its size), the tessellation and the cache format: first this process's (the last few files),
/// then `cache_dir`, which holds one file per key. A cache file that is damaged, cut short or of
/// another format is ignored and replaced; one that cannot be written is skipped (the import
/// still succeeds and says why in `cache_problem`). Errors are ImportStep's.
Result<StepLoad> LoadStep(const std::filesystem::path& path, const StepLoadOptions& options = {});

/// The folder of cached tessellations for a project file: ".wrap-cache/step" beside it.
std::filesystem::path StepCacheDirFor(const std::filesystem::path& project_file);

/// Forgets this process's cached imports (the disk cache stays).
void ClearStepMemoryCache();

}  // namespace wrap
