// Internal to the scripted mode (script.cpp, script_edit.cpp, script_expect.cpp,
// script_authoring.cpp): the line helpers every verb uses and the verb handlers the table in
// script.cpp dispatches to.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>

#include "core/result.h"
#include "gui/commands.h"
#include "gui/script.h"

namespace wrap::gui::script_detail {

/// A refusal of `line`: kInvalidInput, "script line N: MESSAGE".
std::unexpected<Error> LineError(const ScriptLine& line, const std::string& message);
/// `word` as a finite number, or a refusal naming it.
Result<double> Number(const ScriptLine& line, const std::string& word);
/// Exactly three numbers from word `first` on (the line's last three words).
Result<Vec3> Vector(const ScriptLine& line, size_t first);
/// Words from `first` on, joined by single spaces.
std::string Rest(const ScriptLine& line, size_t first);
/// A path of the script: absolute as written, else relative to the script's folder `base`.
std::filesystem::path Resolve(const std::filesystem::path& base, const std::string& file);
/// Runs `command` on the document; a refusal fails the line with its reason.
Result<ScriptEffect> RunEdit(AppState& app, const ScriptLine& line, const Command& command);
/// A check of the state a frame left (ScriptEffect::check); fails with the line's message.
using Check = std::function<Result<void>(const AppState&)>;

/// What one verb does: its edit of `app` (or nothing) and what it asks of the frame loop.
using VerbHandler = Result<ScriptEffect> (*)(AppState& app, const ScriptLine& line,
                                             const std::filesystem::path& base);

// The document's edits (script_edit.cpp).
Result<ScriptEffect> SelectVerb(AppState& app, const ScriptLine& line,
                                const std::filesystem::path& base);
Result<ScriptEffect> ImportVerb(AppState& app, const ScriptLine& line,
                                const std::filesystem::path& base);
Result<ScriptEffect> AddUrdfVerb(AppState& app, const ScriptLine& line,
                                 const std::filesystem::path& base);
Result<ScriptEffect> AddStepVerb(AppState& app, const ScriptLine& line,
                                 const std::filesystem::path& base);
Result<ScriptEffect> DeleteStepVerb(AppState& app, const ScriptLine& line,
                                    const std::filesystem::path& base);
Result<ScriptEffect> RenameVerb(AppState& app, const ScriptLine& line,
                                const std::filesystem::path& base);
Result<ScriptEffect> AddEdgeVerb(AppState& app, const ScriptLine& line,
                                 const std::filesystem::path& base);
Result<ScriptEffect> RemoveEdgeVerb(AppState& app, const ScriptLine& line,
                                    const std::filesystem::path& base);
Result<ScriptEffect> AddRobotVerb(AppState& app, const ScriptLine& line,
                                  const std::filesystem::path& base);
Result<ScriptEffect> RemoveRobotVerb(AppState& app, const ScriptLine& line,
                                     const std::filesystem::path& base);
Result<ScriptEffect> SetVerb(AppState& app, const ScriptLine& line,
                             const std::filesystem::path& base);
Result<ScriptEffect> UndoVerb(AppState& app, const ScriptLine& line,
                              const std::filesystem::path& base);
Result<ScriptEffect> RedoVerb(AppState& app, const ScriptLine& line,
                              const std::filesystem::path& base);

// The checks (script_expect.cpp).
/// Every `expect-*` verb that checks what the next frame drew or the state it left (all but
/// expect-plan and expect-refused): sets the effect's check.
Result<ScriptEffect> ExpectVerb(AppState& app, const ScriptLine& line,
                                const std::filesystem::path& base);
/// `expect-plan`: fails unless the last run gave a solved plan.
Result<ScriptEffect> ExpectPlanVerb(AppState& app, const ScriptLine& line,
                                    const std::filesystem::path& base);
/// `expect-refused COMMAND...`: runs COMMAND and fails unless it is refused without an edit.
Result<ScriptEffect> ExpectRefusedVerb(AppState& app, const ScriptLine& line,
                                       const std::filesystem::path& base);

/// The arguments `verb` takes (least, most), or nullopt for an unknown verb (script.cpp).
std::optional<std::pair<int, int>> VerbArity(const std::string& verb);

}  // namespace wrap::gui::script_detail
