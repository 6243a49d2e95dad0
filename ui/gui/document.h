// The document: the project being edited, its file, and the undo/redo history of commands.
// Plain C++ (no window, no GL): every edit the GUI makes goes through Document::Execute, so it
// can be undone, redone, saved and recovered, and the unit tests drive it without a display.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/result.h"
#include "model/project.h"

namespace wrap::gui {

/// One edit of a project: a label for the Edit menu and a function that changes the project.
/// `apply` either changes the project and succeeds, or leaves it untouched and fails with
/// kInvalidInput and a message that says why (e.g. the cycle a new input would make).
struct Command {
  std::string label;  ///< In words, e.g. "rename step 'a' to 'b'".
  /// Commands with the same non-empty key that follow each other directly are merged into one
  /// undo entry (dragging a slider is one edit, not one per frame). Empty: never merged.
  std::string merge_key;
  std::function<Result<void>(Project&)> apply;  ///< The edit.
};

/// The project being edited with its history. Undo restores the project exactly as it was
/// before the command (the history keeps the project before and after each command: a project
/// is a few kilobytes, the meshes are not in it).
class Document {
 public:
  /// An untitled empty project (default table, limits and planner settings, no parts).
  Document();
  /// A document on `project`, as read from `path` (empty: untitled); clean, empty history.
  Document(Project project, std::filesystem::path path);

  /// Reads and parses `path` (structure only: meshes are checked when planning or validating).
  /// Fails with kIo or kInvalidInput carrying the parse errors, one per line.
  static Result<Document> Open(const std::filesystem::path& path);

  /// The project as it stands.
  const Project& project() const { return history_[current_].project; }
  /// The file it was read from or last saved to; empty when untitled.
  const std::filesystem::path& path() const { return path_; }
  /// The file relative paths in the project are resolved against: path(), or for an untitled
  /// project "untitled.json" in the current folder.
  std::filesystem::path ResolvePath() const;

  /// Runs `command`. On success the project changes, redo history is dropped and the document
  /// is dirty; on failure nothing changes and the error says why.
  Result<void> Execute(const Command& command);
  /// Ends merging: the next command starts a new undo entry even with the same merge key (call
  /// when a drag or text edit ends).
  void CloseMerge() { merge_open_ = false; }

  bool CanUndo() const { return current_ > 0; }                    ///< Something to undo.
  bool CanRedo() const { return current_ + 1 < history_.size(); }  ///< Something to redo.
  /// Undoes the last command (false when there is none).
  bool Undo();
  /// Redoes the last undone command (false when there is none).
  bool Redo();
  /// Label of the command Undo would undo ("" when none).
  std::string UndoLabel() const;
  /// Label of the command Redo would redo ("" when none).
  std::string RedoLabel() const;

  /// True when the project differs from the file (an edit since the last save or open, and not
  /// undone back to it).
  bool dirty() const { return history_[current_].id != saved_id_; }
  /// Changes with every change of the project (edit, undo, redo), and is unique across
  /// documents (a new or opened document has a revision no other had): panels that cache what
  /// they derive from the project compare it.
  unsigned long revision() const { return revision_; }

  /// Saves to path() atomically and marks the document clean; removes the recovery file.
  /// Fails with kInvalidInput when untitled, kIo when the file cannot be written.
  Result<void> Save();
  /// Saves to `path` (then the document's file): relative mesh and URDF paths are rewritten
  /// relative to the new folder so they still name the same files, in every state of the undo
  /// history too (undo after Save As works, and names the same files).
  Result<void> SaveAs(const std::filesystem::path& path);

  /// The recovery file of this document: beside the project, "<file>.recovery"; for an untitled
  /// project "untitled.wrap-recovery.json" in the current folder.
  std::filesystem::path RecoveryPath() const;
  /// Writes the project to RecoveryPath() (atomically) when it is dirty and changed since the
  /// last recovery write; returns true when it wrote. Fails with kIo.
  Result<bool> WriteRecovery();
  /// Removes the recovery file, if any.
  void RemoveRecovery() const;
  /// True when a recovery file for `project_file` exists and is newer than the file: the app
  /// crashed or was killed with unsaved edits.
  static bool HasRecovery(const std::filesystem::path& project_file);
  /// Replaces the project by the recovery file's content as one undoable command (the document
  /// becomes dirty). Fails with kIo or kInvalidInput.
  Result<void> Recover();

 private:
  struct Entry {
    Project project;        // the project after the command
    std::string label;      // the command that made it (empty for the first entry)
    std::string merge_key;  // its merge key
    unsigned long id = 0;   // identity of this state, for the dirty flag
  };
  std::vector<Entry> history_;
  size_t current_ = 0;
  std::filesystem::path path_;
  unsigned long saved_id_ = 0;
  unsigned long next_id_ = 1;
  unsigned long revision_ = 0;
  unsigned long recovered_id_ = 0;  // state last written to the recovery file
  bool merge_open_ = false;
};

/// Rewrites the relative mesh and URDF paths of `project` (those without a leading ${VAR}) from
/// `from_dir` to `to_dir`, so that they name the same files when the project moves.
void RebasePaths(Project& project, const std::filesystem::path& from_dir,
                 const std::filesystem::path& to_dir);

}  // namespace wrap::gui
