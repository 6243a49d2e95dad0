// A StepAssembly as bytes and back: the disk cache's entries (step_cache.cpp) and what the
// isolated importer's child process sends its parent (step_isolation.cpp). Host byte order, a
// trailing digest; not a file format for other programs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "geometry/step_import.h"

namespace wrap::detail {

/// Bump when the importer's output or the layout changes: older cache entries are then ignored.
inline constexpr uint32_t kStepFormatVersion = 1;

/// A 128-bit digest of bytes. Not cryptographic: it tells files apart, nothing more.
struct Digest {
  uint64_t a = 0, b = 0;
  bool operator==(const Digest&) const = default;
};

/// The digest of `bytes`: FNV-1a and a multiply-rotate hash over 8-byte words, each finished by a
/// 64-bit mixer.
Digest HashBytes(std::string_view bytes);

/// `v` as 16 lower-case hex digits.
std::string Hex16(uint64_t v);

/// `assembly` as bytes, tagged with `key` (what the reader must expect).
std::string SerializeStepAssembly(const StepAssembly& assembly, const std::string& key);

/// The assembly in `bytes`, or nothing when they are not a complete, intact record for `key` of
/// this format version.
std::optional<StepAssembly> DeserializeStepAssembly(std::string_view bytes, const std::string& key);

}  // namespace wrap::detail
