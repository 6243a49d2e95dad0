// What the motion tests share: an example project loaded, preprocessed and turned into its task
// world (once per test binary and name), with the first error in words.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "../task/planning_fixture.h"

namespace wrap {

struct PreparedProject {
  fs::path file;
  LoadedProject lp;
  std::optional<Preprocessed> pre;
  std::optional<TaskWorld> world;
  std::string error;  ///< Empty when loaded, preprocessed and built.
};

/// Loads the project `name` of projects/ into `p`, preprocesses it (seed 0) and builds its world,
/// in place: the world points into the loaded project and its preprocessing.
inline void PrepareProject(const std::string& name, PreparedProject& p) {
  p.file = ProjectFile(name);
  p.lp = LoadProject(p.file);
  if (!p.lp.ok()) {
    p.error = name + ": does not load";
    return;
  }
  auto pre = PreprocessProject(p.lp, p.file);
  if (!pre) {
    p.error = name + ": " + pre.error().message;
    return;
  }
  p.pre = std::move(*pre);
  auto world = BuildTaskWorld(*p.lp.project, p.lp.check, *p.pre, p.file);
  if (!world) {
    p.error = name + ": " + world.error().message;
    return;
  }
  p.world = std::move(*world);
}

/// One prepared project per name and test binary, solved by T::Solve (called once, when the
/// preparation succeeded): T derives from PreparedProject and has Solve(name).
template <typename T>
const T& PrepareOnce(const std::string& name) {
  static std::map<std::string, std::unique_ptr<T>> cache;
  auto& slot = cache[name];
  if (slot) return *slot;
  slot = std::make_unique<T>();
  PrepareProject(name, *slot);
  if (slot->error.empty()) slot->Solve(name);
  return *slot;
}

}  // namespace wrap
