// Live validation: after each edit of the document, once edits pause, the project is checked on
// a worker thread with every check `wrap validate` makes (CheckProject: the model's validation,
// the robots'; geometry checks added there appear here too). The GUI lists the diagnostics in the
// Problems panel by entity name. No window, no GL.
#pragma once

#include <filesystem>
#include <memory>
#include <mutex>
#include <stop_token>
#include <thread>

#include "core/diagnostics.h"
#include "mating/check.h"
#include "model/project.h"

namespace wrap::gui {

/// What the last finished validation found.
struct ValidationResult {
  Diagnostics diagnostics;                 ///< Errors and warnings, in the order they were found.
  unsigned long revision = 0;              ///< Document revision that was checked (0: none yet).
  std::shared_ptr<const Project> project;  ///< The project as it was checked.
  double seconds = 0.0;                    ///< How long the check took [s].
  /// What the geometry's checks found (contacts, each step's insertion path and free
  /// directions), as CheckProject computed it; null before the first check.
  std::shared_ptr<const GeometryReport> geometry;
};

/// One validation at a time on a std::jthread, started by Update when the document has been
/// quiet for `quiet_s`. Destroying it waits for a check under way (they are bounded by the
/// meshes' size; a check has no cancel point).
class LiveValidation {
 public:
  explicit LiveValidation(double quiet_s = 0.3) : quiet_s_(quiet_s) {}
  ~LiveValidation();
  LiveValidation(const LiveValidation&) = delete;
  LiveValidation& operator=(const LiveValidation&) = delete;

  /// Called every frame with the document's project, revision and file, and the clock [s]: a
  /// revision not yet checked is checked once it has not changed for quiet_s (or at once with
  /// `now_please`, e.g. a script waiting for it).
  void Update(const Project& project, unsigned long revision,
              const std::filesystem::path& project_file, double now, bool now_please = false);
  /// The last finished check (a copy, taken under the lock).
  ValidationResult result() const;
  /// True while a check runs or one is waiting for the edits to pause.
  bool pending() const;
  /// Revision of the last finished check.
  unsigned long checked_revision() const;

 private:
  void Start(const Project& project, unsigned long revision,
             const std::filesystem::path& project_file);

  const double quiet_s_;
  mutable std::mutex mutex_;
  ValidationResult result_;
  bool running_ = false;
  unsigned long seen_revision_ = 0;     // revision last seen by Update
  unsigned long started_revision_ = 0;  // revision of the check under way or last started
  double seen_at_ = 0.0;                // when seen_revision_ was first seen [s]
  std::jthread worker_;
};

}  // namespace wrap::gui
