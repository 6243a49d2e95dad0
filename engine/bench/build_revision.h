// The source revision the running binary was built from (cmake/BuildRevision.cmake writes its
// definition at every build).
#pragma once

#include <string_view>

namespace wrap::bench {

/// The git commit of the build's sources (short hash), with "+changes.HASH" when the build's
/// sources (engine, app, assets, cmake) differed from it, HASH naming those changes; "unknown"
/// when the sources were not a git checkout.
std::string_view BuildRevision();

}  // namespace wrap::bench
