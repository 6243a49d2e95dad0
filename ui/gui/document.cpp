#include "gui/document.h"

#include <atomic>
#include <system_error>

#include "core/file_io.h"
#include "model/entity_path.h"
#include "model/project_io.h"

namespace wrap::gui {

namespace fs = std::filesystem;

namespace {

// Revisions are unique across documents: a new or opened document never repeats the revision
// of the one it replaces, so whatever was derived from that one (the viewport's cell) is redone.
std::atomic<unsigned long> g_revision{0};

}  // namespace

Document::Document() : Document(Project{}, {}) {}

Document::Document(Project project, fs::path path) : path_(std::move(path)) {
  history_.push_back(Entry{std::move(project), "", "", 0});
  saved_id_ = 0;
  recovered_id_ = 0;
  revision_ = ++g_revision;
}

Result<Document> Document::Open(const fs::path& path) {
  ProjectParse parse = ReadProjectFile(path);
  if (!parse.project || parse.diagnostics.has_errors()) {
    std::string message;
    for (const Diagnostic& d : parse.diagnostics.items) {
      if (d.severity != Severity::kError) continue;
      if (!message.empty()) message += "\n";
      message += FormatNamed(d, parse.project ? &*parse.project : nullptr);
    }
    if (message.empty()) message = path.string() + ": not a project file";
    std::error_code ec;
    const bool io = !fs::is_regular_file(path, ec);
    return Fail(io ? ErrorCode::kIo : ErrorCode::kInvalidInput, message);
  }
  return Document(std::move(*parse.project), path);
}

fs::path Document::ResolvePath() const {
  if (!path_.empty()) return path_;
  std::error_code ec;
  return fs::current_path(ec) / "untitled.json";
}

Result<void> Document::Execute(const Command& command) {
  Project next = project();
  if (auto done = command.apply(next); !done) return done;
  if (next == project()) return {};  // no change: no undo entry, not dirty
  history_.resize(current_ + 1);
  const bool merge = merge_open_ && current_ > 0 && !command.merge_key.empty() &&
                     history_[current_].merge_key == command.merge_key &&
                     history_[current_].id != saved_id_;
  if (merge) {
    history_[current_].project = std::move(next);
    history_[current_].id = next_id_++;
  } else {
    history_.push_back(Entry{std::move(next), command.label, command.merge_key, next_id_++});
    ++current_;
  }
  merge_open_ = !command.merge_key.empty();
  revision_ = ++g_revision;
  return {};
}

bool Document::Undo() {
  if (!CanUndo()) return false;
  --current_;
  merge_open_ = false;
  revision_ = ++g_revision;
  return true;
}

bool Document::Redo() {
  if (!CanRedo()) return false;
  ++current_;
  merge_open_ = false;
  revision_ = ++g_revision;
  return true;
}

std::string Document::UndoLabel() const { return CanUndo() ? history_[current_].label : ""; }

std::string Document::RedoLabel() const { return CanRedo() ? history_[current_ + 1].label : ""; }

Result<void> Document::Save() {
  if (path_.empty()) {
    return Fail(ErrorCode::kInvalidInput, "the project has no file yet: use Save As");
  }
  if (auto saved = SaveProject(project(), path_); !saved) return saved;
  saved_id_ = history_[current_].id;
  merge_open_ = false;
  RemoveRecovery();
  return {};
}

Result<void> Document::SaveAs(const fs::path& path) {
  if (path.empty()) return Fail(ErrorCode::kInvalidInput, "Save As: no file name given");
  const fs::path from_dir = ResolvePath().parent_path();
  const fs::path to_dir = fs::absolute(path).parent_path();
  Project moved = project();
  RebasePaths(moved, from_dir, to_dir);
  if (auto saved = SaveProject(moved, path); !saved) return saved;
  RemoveRecovery();
  // The rebased project is what the file holds: it becomes the clean state. Every state of the
  // history moves with the file (its relative paths rewritten the same way), so undo and redo
  // after Save As name the same files as before it.
  path_ = path;
  for (Entry& e : history_) RebasePaths(e.project, from_dir, to_dir);
  saved_id_ = history_[current_].id;
  merge_open_ = false;
  revision_ = ++g_revision;
  return {};
}

fs::path Document::RecoveryPath() const {
  if (path_.empty()) return ResolvePath().parent_path() / "untitled.wrap-recovery.json";
  return fs::path(path_.string() + ".recovery");
}

Result<bool> Document::WriteRecovery() {
  if (!dirty() || history_[current_].id == recovered_id_) return false;
  if (auto written = WriteFileAtomic(RecoveryPath(), SerializeProject(project())); !written) {
    return std::unexpected(written.error());
  }
  recovered_id_ = history_[current_].id;
  return true;
}

void Document::RemoveRecovery() const {
  std::error_code ec;
  fs::remove(RecoveryPath(), ec);
}

bool Document::HasRecovery(const fs::path& project_file) {
  std::error_code ec;
  const fs::path recovery(project_file.string() + ".recovery");
  if (!fs::exists(recovery, ec)) return false;
  if (!fs::exists(project_file, ec)) return true;
  return fs::last_write_time(recovery, ec) >= fs::last_write_time(project_file, ec);
}

Result<void> Document::Recover() {
  const fs::path file = RecoveryPath();
  ProjectParse parse = ReadProjectFile(file);
  if (!parse.project || parse.diagnostics.has_errors()) {
    return Fail(ErrorCode::kInvalidInput, file.string() + ": the recovery file cannot be read");
  }
  Project recovered = std::move(*parse.project);
  return Execute(Command{"recover unsaved edits", "", [recovered](Project& p) -> Result<void> {
                           p = recovered;
                           return {};
                         }});
}

void RebasePaths(Project& project, const fs::path& from_dir, const fs::path& to_dir) {
  auto rebase = [&](std::string& path) {
    if (path.empty() || path.starts_with("${") || fs::path(path).is_absolute()) return;
    const fs::path absolute = (from_dir / path).lexically_normal();
    fs::path relative = absolute.lexically_relative(to_dir);
    path = relative.empty() ? absolute.string() : relative.generic_string();
  };
  for (Part& part : project.parts) rebase(part.mesh);
  for (Robot& robot : project.robots) rebase(robot.urdf);
  for (auto& [name, variable] : project.paths) rebase(variable.default_value);
}

}  // namespace wrap::gui
