#include "core/diagnostics.h"

#include <algorithm>

namespace wrap {

void Diagnostics::Error(std::string file, std::string path, std::string message) {
  items.push_back({Severity::kError, std::move(file), std::move(path), std::move(message)});
}

void Diagnostics::Warning(std::string file, std::string path, std::string message) {
  items.push_back({Severity::kWarning, std::move(file), std::move(path), std::move(message)});
}

bool Diagnostics::has_errors() const { return error_count() > 0; }

int Diagnostics::error_count() const {
  return static_cast<int>(std::count_if(items.begin(), items.end(), [](const Diagnostic& d) {
    return d.severity == Severity::kError;
  }));
}

int Diagnostics::warning_count() const { return static_cast<int>(items.size()) - error_count(); }

void Diagnostics::Append(const Diagnostics& other) {
  items.insert(items.end(), other.items.begin(), other.items.end());
}

std::string Format(const Diagnostic& d) {
  std::string out;
  if (!d.file.empty()) out += d.file + ": ";
  if (!d.path.empty()) out += d.path + ": ";
  out += d.severity == Severity::kError ? "error: " : "warning: ";
  out += d.message;
  return out;
}

}  // namespace wrap
