// Canonical encoding of a wrench question for the answer cache. Internal to the wrench stage.
#pragma once

#include <cstdint>
#include <vector>

#include "wrench/wrench.h"

namespace wrap::detail {

/// The reference point of the LP: the mean centre of mass of the bodies (the origin when there
/// are none). Moments are taken about it and the cache key encodes positions relative to it.
Vec3 ReferencePoint(const StepConfiguration& config);

/// Encodes everything the answer depends on into `words` (cleared first): counts, names, masses,
/// rotations, positions relative to ReferencePoint, bounds, the mating and the query. Equal words
/// give bit-identical LPs, hence identical answers; -0.0 is encoded as 0.0.
void EncodeQuestion(const StepConfiguration& config, const WrenchQuery& query,
                    std::vector<std::uint64_t>& words);

/// A 64-bit hash of the words (not cryptographic; the cache compares the words on a hit).
std::uint64_t HashWords(const std::vector<std::uint64_t>& words);

}  // namespace wrap::detail
