// Reading whole files and writing them atomically (temporary file + rename).
#pragma once

#include <filesystem>
#include <string>

#include "core/result.h"

namespace wrap {

/// Reads a whole file. Fails with kIo naming the path when it is missing or unreadable.
Result<std::string> ReadFile(const std::filesystem::path& path);

/// Writes `contents` to `path` atomically: a temporary file in the same folder is written,
/// flushed to disk and renamed over `path`, so readers see the old or the new file, never a part.
/// An existing character device (`/dev/null`, `/dev/full`) is written in place instead, never
/// replaced. Fails with kIo (the old file, if any, is left untouched), also for a directory or
/// another special file at `path`.
Result<void> WriteFileAtomic(const std::filesystem::path& path, const std::string& contents);

}  // namespace wrap
