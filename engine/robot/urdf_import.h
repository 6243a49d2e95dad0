// URDF import through urdfdom: a user's own serial arm as a Chain (the one urdfdom adapter).
#pragma once

#include <filesystem>
#include <map>
#include <numbers>
#include <string>

#include "core/result.h"
#include "robot/chain.h"

namespace wrap {

/// Options of ImportUrdf.
struct UrdfImportOptions {
  /// Base link of the chain (chain link 0); empty: the URDF's root link.
  std::string root;
  /// Tip link: its frame becomes the flange (Chain::X_LF). Empty: the one tip candidate (see
  /// ImportUrdf).
  std::string tip;
  /// Continuous joints get the position limits [-range, +range] [rad]. Default 2 pi: a full turn
  /// either way, like the UR arms' +-2 pi joints (wrap-around moves stay possible).
  double continuous_range_rad = 2.0 * std::numbers::pi;
  /// Velocity limit used when the URDF gives none or 0 [rad/s or m/s].
  double default_max_velocity = 1.0;
  /// Acceleration limit of every joint (URDF has none) [rad/s^2 or m/s^2]. Default 5, the value
  /// UR's ROS 2 driver calls conservative.
  double default_max_acceleration = 5.0;
  /// Read the visual elements into Link::visual too (their meshes are loaded).
  bool import_visual = true;
  /// Folders of ROS packages for `package://NAME/...` URIs, by package name. Packages not listed
  /// are looked for above the URDF's folder (a folder named NAME, or NAME inside an ancestor).
  std::map<std::string, std::filesystem::path> package_paths;
};

/// Reads a URDF file into a serial chain from `options.root` to the tip link.
///
/// - The tip: `options.tip`, or else the only leaf link that ends the chain. Leaves that hang off
///   the chain through fixed joints only (e.g. ROS's `base` frame under `base_link`) do not
///   count; several remaining candidates fail, naming them.
/// - Revolute, continuous and prismatic joints become Chain joints with their limits (position,
///   velocity, effort; continuous: see `continuous_range_rad`). Fixed joints are folded: their
///   transform goes into the next movable joint's X_PJ (or the flange), and the geometry of their
///   child links goes to the chain link before them. Fixed side branches are folded the same way;
///   side branches with movable joints (fingers, a second arm) are left out.
/// - Collision (and visual) boxes, cylinders, spheres and meshes become Shapes in the chain link
///   frames. Meshes load through ImportMesh with the URDF's scale (non-uniform allowed);
///   `package://` URIs are resolved as described at `package_paths`, plain paths relative to the
///   URDF's folder.
///
/// Fails with kIo when the file (or a mesh) cannot be read, and with kInvalidInput naming the
/// element for: malformed XML or anything urdfdom rejects (its message included, also when it
/// only drops an element), a closed loop (a link with two parent joints), floating or planar or
/// mimic joints on the chain, a missing or ambiguous tip, a tip not below the root, no movable
/// joint, bad limits or axes, bad geometry sizes, an unresolvable `package://` URI.
Result<Chain> ImportUrdf(const std::filesystem::path& file, const UrdfImportOptions& options = {});

}  // namespace wrap
