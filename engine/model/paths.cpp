#include "model/paths.h"

#include <cstdlib>

namespace wrap {

namespace fs = std::filesystem;

Result<ResolvedPath> ResolveProjectPath(const Project& project, const fs::path& project_file,
                                        const std::string& raw) {
  const fs::path dir = project_file.has_parent_path() ? project_file.parent_path() : fs::path(".");
  ResolvedPath out;
  std::string expanded;
  size_t pos = 0;
  while (pos < raw.size()) {
    const size_t start = raw.find("${", pos);
    if (start == std::string::npos) {
      expanded += raw.substr(pos);
      break;
    }
    expanded += raw.substr(pos, start - pos);
    const size_t end = raw.find('}', start + 2);
    if (end == std::string::npos) {
      return Fail(ErrorCode::kInvalidInput, "unterminated '${' in path '" + raw + "'");
    }
    const std::string name = raw.substr(start + 2, end - start - 2);
    auto it = project.paths.find(name);
    if (it == project.paths.end()) {
      return Fail(ErrorCode::kInvalidInput,
                  "path '" + raw + "' uses ${" + name + "}, which is not defined in 'paths'");
    }
    const PathVariable& var = it->second;
    const char* env = var.env.empty() ? nullptr : std::getenv(var.env.c_str());
    std::string value;
    if (env && *env) {
      // An environment variable is relative to the working directory, not the project file.
      std::error_code ec;
      const fs::path abs = fs::absolute(fs::path(env), ec);
      value = ec ? std::string(env) : abs.string();
      out.explanation += "${" + name + "} = '" + value + "' (from $" + var.env + ")";
    } else {
      // A default is relative to the project file; keep it that way when expanded.
      value = var.default_value;
      out.explanation += "${" + name + "} = '" + value + "' (default" +
                         (var.env.empty() ? std::string(")") : "; $" + var.env + " not set)");
    }
    if (!var.hint.empty()) out.hint = var.hint;
    expanded += value;
    pos = end + 1;
  }
  fs::path p(expanded);
  out.path = p.is_absolute() ? p : (dir / p).lexically_normal();
  return out;
}

}  // namespace wrap
