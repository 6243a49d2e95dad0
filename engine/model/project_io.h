// Reading and writing project files (JSON, format "wrap-project" version 1).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "core/diagnostics.h"
#include "core/result.h"
#include "model/project.h"

namespace wrap {

/// What parsing a project file gave: the project (absent when the text is not a usable project
/// at all, e.g. malformed JSON) and every problem found, each with its JSON path.
struct ProjectParse {
  std::optional<Project> project;  ///< The project; fields with errors keep their defaults.
  Diagnostics diagnostics;         ///< Syntax, type and structure problems; unknown keys warn.
};

/// Parses project JSON. `file_label` names the file in diagnostics. Never throws.
ProjectParse ParseProject(std::string_view json_text, const std::string& file_label);

/// Reads and parses a project file (kIo diagnostics when unreadable). Never throws.
ProjectParse ReadProjectFile(const std::filesystem::path& path);

/// The project as JSON text (2-space indent, trailing newline). Optional fields that are absent
/// stay absent; everything else is written explicitly. Parse(Serialize(p)) == p.
std::string SerializeProject(const Project& project);

/// Writes the project atomically (temporary file + rename): never a half-written file.
[[nodiscard]] Result<void> SaveProject(const Project& project, const std::filesystem::path& path);

}  // namespace wrap
