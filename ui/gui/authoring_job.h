// Authoring from geometry in the GUI: "Import assembly..." (the code of `wrap new`), "Suggest
// assembly order" (the DAG and matings of assembly by disassembly) and "Lay out parts on the
// table" (stable, pickable initial poses), each run on a worker thread on a snapshot of the
// document, with its stage shown; the App applies the result as one undoable edit and lists what
// changed. No window, no GL.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "authoring/mesh_intake.h"
#include "core/result.h"
#include "gui/document.h"
#include "model/project.h"

namespace wrap::gui {

/// Which authoring edit.
enum class AuthoringKind { kImportAssembly, kSuggestOrder, kLayOut };

/// "Import assembly", "Suggest assembly order", "Lay out parts on the table".
const char* ToString(AuthoringKind kind);

/// What to run.
struct AuthoringRequest {
  AuthoringKind kind = AuthoringKind::kSuggestOrder;
  Project project;                           ///< The document as it was when started.
  unsigned long revision = 0;                ///< Its revision.
  std::filesystem::path project_file;        ///< Paths resolve against it (ResolvePath()).
  std::vector<std::filesystem::path> meshes; ///< Import: mesh files or folders.
  LengthUnit unit = LengthUnit::kAuto;       ///< Import: their unit.
};

/// What it gave.
struct AuthoringOutcome {
  AuthoringKind kind = AuthoringKind::kSuggestOrder;
  unsigned long revision = 0;          ///< Revision of the document it started from.
  std::optional<Project> project;      ///< The edited project (none: it failed).
  std::string error;                   ///< Why it failed.
  std::vector<std::string> decisions;  ///< One line per decision, with its reason.
  double seconds = 0.0;                ///< How long it took [s].
};

/// Progress sink: the stage under way.
using AuthoringProgress = std::function<void(const std::string& stage, double fraction)>;

/// Runs one request on the calling thread (the worker's body; tests call it directly).
AuthoringOutcome RunAuthoring(const AuthoringRequest& request,
                              const AuthoringProgress& progress = {});

/// One authoring run at a time on a std::jthread. Destroying it waits for the run (bounded by
/// the meshes; the engine's stages have no cancel point).
class AuthoringJob {
 public:
  AuthoringJob() = default;
  ~AuthoringJob();
  AuthoringJob(const AuthoringJob&) = delete;
  AuthoringJob& operator=(const AuthoringJob&) = delete;

  /// Starts `request`; false when a run is under way.
  bool Start(AuthoringRequest request);
  /// True while a run is under way (its outcome not yet taken).
  bool running() const;
  /// The kind of the run under way or last run.
  AuthoringKind kind() const;
  /// The stage under way and the fraction done before it.
  std::string stage() const;
  double fraction() const;
  /// The outcome of a finished run, once.
  std::optional<AuthoringOutcome> Take();

 private:
  mutable std::mutex mutex_;
  bool running_ = false;
  AuthoringKind kind_ = AuthoringKind::kSuggestOrder;
  std::string stage_;
  double fraction_ = 0.0;
  std::optional<AuthoringOutcome> outcome_;
  std::jthread worker_;
};

/// What differs between two projects, one line per change in words: parts added, removed,
/// moved on the table; steps added, removed, or whose inputs, roles or axis changed; robots
/// added or removed; the table.
std::vector<std::string> DescribeChanges(const Project& before, const Project& after);

/// The edit that makes `outcome`'s project the document's, as one undo entry.
Command ApplyAuthoring(const AuthoringOutcome& outcome);

}  // namespace wrap::gui
