// Resolving the file paths written in a project (relative paths, ${NAME} variables).
#pragma once

#include <filesystem>
#include <string>

#include "core/result.h"
#include "model/project.h"

namespace wrap {

/// A path from a project file, resolved.
struct ResolvedPath {
  std::filesystem::path path;  ///< Absolute or relative-to-cwd path to open.
  std::string explanation;     ///< How variables were expanded, e.g. "${FABRICA} = '../x'
                               ///< (default; $WRAP_FABRICA_DIR not set)"; empty if none.
  std::string hint;            ///< The variables' hints, for missing-file messages.
};

/// Expands `${NAME}` through `project.paths` (environment variable first, then the default,
/// which is relative to the project file) and makes the result relative to the project file's
/// folder. Fails with kInvalidInput for an undefined variable or an unterminated `${`.
Result<ResolvedPath> ResolveProjectPath(const Project& project,
                                        const std::filesystem::path& project_file,
                                        const std::string& raw);

}  // namespace wrap
