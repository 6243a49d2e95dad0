// Diagnostics: problems found in user input, each naming the file, the JSON path and the problem.
#pragma once

#include <string>
#include <vector>

namespace wrap {

/// How bad a diagnostic is. Errors make the input unusable; warnings are shown and kept going.
enum class Severity { kWarning, kError };

/// One problem in a user's file, e.g. `stool.json: parts[3].mesh: file 'leg4.stl' not found`.
struct Diagnostic {
  Severity severity = Severity::kError;  ///< Error or warning.
  std::string file;                      ///< File name as the user gave it (may be empty).
  std::string path;                      ///< JSON path, e.g. `parts[3].mesh`; empty for the file.
  std::string message;                   ///< What is wrong and, where useful, a hint.
};

/// Every problem found in one pass, in the order they were found.
struct Diagnostics {
  std::vector<Diagnostic> items;  ///< All problems, errors and warnings mixed.

  /// Records an error at `path`.
  void Error(std::string file, std::string path, std::string message);
  /// Records a warning at `path`.
  void Warning(std::string file, std::string path, std::string message);
  /// True when at least one item is an error.
  bool has_errors() const;
  /// Number of errors.
  int error_count() const;
  /// Number of warnings.
  int warning_count() const;
  /// Appends all items of `other`.
  void Append(const Diagnostics& other);
};

/// One line per item: `FILE: PATH: error: MESSAGE` (PATH omitted when empty).
std::string Format(const Diagnostic& d);

}  // namespace wrap
