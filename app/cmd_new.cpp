#include <filesystem>
#include <ostream>

#include "authoring/new_project.h"
#include "authoring/suggest.h"
#include "cli.h"
#include "load.h"
#include "model/entity_path.h"
#include "model/project_io.h"

namespace wrap::cli {

namespace fs = std::filesystem;

int NewCommand(const NewArgs& args, std::ostream& out, std::ostream& err) {
  auto unit = ParseLengthUnit(args.unit);
  if (!unit) {
    err << unit.error().message << "\n";
    return 2;
  }
  NewProjectOptions options;
  options.unit = *unit;
  options.robots = args.robots;
  options.robot_model = args.robot_model;
  options.end_effector = args.end_effector;
  options.force_N = args.force_N;
  options.name = args.name;
  std::vector<fs::path> meshes(args.meshes.begin(), args.meshes.end());
  auto made = NewProject(meshes, args.output, options);
  if (!made) {
    err << "wrap new: " << made.error().message << "\n";
    return ExitCodeFor(made.error().code);
  }
  for (const std::string& d : made->decisions) out << "  " << d << "\n";
  if (auto saved = SaveProject(made->project, args.output); !saved) {
    err << "wrap new: " << saved.error().message << "\n";
    return ExitCodeFor(saved.error().code);
  }
  out << "Wrote " << args.output << ": " << made->project.parts.size() << " parts, "
      << made->project.steps.size() << " steps, " << made->project.robots.size()
      << " robots (wrap validate, wrap plan)\n";
  return 0;
}

int SuggestCommand(const SuggestArgs& args, std::ostream& out, std::ostream& err) {
  if (args.apply && args.output.empty()) {
    err << "wrap suggest: --apply needs -o OUT.json (name the input to overwrite it)\n";
    return 2;
  }
  const LoadedProject loaded = LoadProject(args.project);
  if (!loaded.project || !loaded.check.tree) {
    for (const Diagnostic& d : loaded.check.diagnostics.items)
      err << FormatNamed(d, loaded.project ? &*loaded.project : nullptr) << "\n";
    err << args.project << ": cannot be read well enough to suggest fixes\n";
    return 2;
  }
  auto result = SuggestFixes(*loaded.project, loaded.check, args.project);
  if (!result) {
    err << "wrap suggest: " << result.error().message << "\n";
    return ExitCodeFor(result.error().code);
  }
  if (result->suggestions.empty()) {
    out << args.project << ": the geometry finds nothing to fix\n";
    return 0;
  }
  for (const Suggestion& s : result->suggestions) {
    out << "  " << (s.path.empty() ? "" : s.path + ": ") << s.what << "\n";
  }
  if (!args.apply) {
    out << result->suggestions.size() << " suggestion(s); wrap suggest " << args.project
        << " --apply -o OUT.json writes them\n";
    return 1;
  }
  if (auto saved = SaveProject(result->edited, args.output); !saved) {
    err << "wrap suggest: " << saved.error().message << "\n";
    return ExitCodeFor(saved.error().code);
  }
  out << "Wrote " << args.output << " with " << result->suggestions.size() << " edit(s)\n";
  return 0;
}

}  // namespace wrap::cli
