// The MuJoCo adapter: compiles a cell's MJCF into an mjModel and places scene states into mjData.
// MuJoCo 2.2's errors exit the process by default: every call here runs under handlers that
// turn them into Results (MujocoGuard), and its warnings are collected instead of written to
// MUJOCO_LOG.TXT.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.h"
#include "sim/mjcf.h"
#include "sim/scene.h"

namespace wrap {

/// Installs MuJoCo's error and warning handlers (once per process; idempotent, thread-safe):
/// errors throw inside MuJoCo and are caught by RunGuarded, warnings are kept per thread
/// (TakeMujocoWarnings). Call it before any other MuJoCo function; the functions of this header
/// and of ui/render do.
void InstallMujocoHandlers();

/// Runs `body` (which calls MuJoCo) with the handlers installed; a MuJoCo error inside becomes
/// kInternal "MuJoCo: <what>: <message>". Exceptions other than MuJoCo's pass through.
Result<void> RunGuarded(std::string_view what, const std::function<void()>& body);

/// MuJoCo warnings raised on this thread since the last call, oldest first.
std::vector<std::string> TakeMujocoWarnings();

/// A compiled cell: the mjModel (immutable, shareable between threads) and the addresses that
/// put a SceneState into an mjData (one per thread).
class CellModel {
 public:
  /// Compiles `doc` (its XML and assets through an in-memory VFS). Fails with kInvalidInput
  /// carrying MuJoCo's compiler message (which names the element), or kInternal when a joint or
  /// body the document names is missing from the model.
  static Result<CellModel> Compile(const MjcfDocument& doc);

  /// The compiled model.
  const mjModel* model() const { return model_.get(); }

  /// A fresh mjData of this model at the reference configuration; null only when MuJoCo fails to
  /// allocate (reported through its error handler as kInternal by RunGuarded callers).
  std::unique_ptr<mjData, void (*)(mjData*)> MakeData() const;

  /// Free-joint qpos address of part `p` in a physics model (MjcfOptions::physics), else -1.
  int part_qpos(int p) const { return part_qpos_[p]; }

  /// Writes `state` into `data` (robot joints, finger slides, part mocap poses, or the parts'
  /// free joints in a physics model) and computes
  /// the positions of bodies, geoms, cameras and lights (mj_kinematics, mj_comPos,
  /// mj_camlight). Fails with kInvalidInput when the state's sizes do not match the model.
  Result<void> Apply(const SceneState& state, mjData* data) const;

  int num_robots() const { return static_cast<int>(robot_qpos_.size()); }  ///< Robots.
  int num_parts() const { return static_cast<int>(part_mocap_.size()); }   ///< Parts.

 private:
  struct ModelDeleter {
    void operator()(mjModel* m) const { mj_deleteModel(m); }
  };
  std::unique_ptr<mjModel, ModelDeleter> model_;
  std::vector<std::vector<int>> robot_qpos_;     // qpos address per robot joint
  std::vector<std::array<int, 2>> finger_qpos_;  // qpos address per finger, -1 none
  std::vector<int> part_mocap_;                  // mocap index per part, -1 free (physics)
  std::vector<int> part_qpos_;                   // free-joint qpos address per part, -1 mocap
};

}  // namespace wrap
