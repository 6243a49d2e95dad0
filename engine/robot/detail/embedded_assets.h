// The catalog's JSON files, compiled into the library (no assets folder needed at run time).
#pragma once

#include <span>
#include <string_view>

namespace wrap::detail {

/// One embedded JSON file.
struct EmbeddedAsset {
  std::string_view name;  ///< Catalog key, e.g. "ur5e".
  std::string_view file;  ///< Source path in the repository, for messages.
  std::string_view text;  ///< The file's contents.
};

/// Every file of assets/robots listed in engine/robot/CMakeLists.txt, in that order.
std::span<const EmbeddedAsset> EmbeddedRobotAssets();

}  // namespace wrap::detail
