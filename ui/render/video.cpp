#include "render/video.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "core/file_io.h"

extern char** environ;

namespace wrap::render {

namespace fs = std::filesystem;

namespace {

// A path quoted for ffmpeg's concat list: 'it'\''s' style.
std::string ConcatQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string Tail(const std::string& text, size_t lines) {
  std::vector<std::string> all;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    if (end > start) all.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  std::string out;
  for (size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i) {
    out += (out.empty() ? "" : " | ") + all[i];
  }
  return out;
}

}  // namespace

std::optional<fs::path> FindProgram(std::string_view name) {
  const char* path = std::getenv("PATH");
  if (!path) return std::nullopt;
  const std::string all(path);
  size_t start = 0;
  while (start <= all.size()) {
    size_t end = all.find(':', start);
    if (end == std::string::npos) end = all.size();
    const std::string dir = all.substr(start, end - start);
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) {
      return candidate;
    }
    start = end + 1;
  }
  return std::nullopt;
}

Result<void> CheckVideoEncoder() {
  if (FindProgram("ffmpeg")) return {};
  return Fail(ErrorCode::kInvalidInput,
              "--video needs the ffmpeg program, which is not installed (not found on PATH); "
              "install it (Debian: apt-get install ffmpeg) or leave out --video");
}

Result<void> EncodeVideo(const std::vector<fs::path>& frames,
                         const std::vector<double>& durations_s, const fs::path& output) {
  const auto ffmpeg = FindProgram("ffmpeg");
  if (!ffmpeg) return std::unexpected(CheckVideoEncoder().error());
  if (frames.empty() || frames.size() != durations_s.size()) {
    return Fail(ErrorCode::kInternal, "video: frames and durations do not match");
  }
  // The concat demuxer: each file with its duration; the last file again (it ignores the last
  // duration otherwise).
  std::string list = "ffconcat version 1.0\n";
  for (size_t i = 0; i < frames.size(); ++i) {
    list += "file " + ConcatQuote(fs::absolute(frames[i]).string()) + "\n";
    char d[64];
    std::snprintf(d, sizeof d, "duration %.6f\n", durations_s[i]);
    list += d;
  }
  list += "file " + ConcatQuote(fs::absolute(frames.back()).string()) + "\n";
  const fs::path list_file = output.string() + ".ffconcat";
  const fs::path log_file = output.string() + ".log";
  if (auto ok = WriteFileAtomic(list_file, list); !ok) return ok;

  const std::vector<std::string> args = {ffmpeg->string(),
                                         "-nostdin",
                                         "-y",
                                         "-loglevel",
                                         "error",
                                         "-f",
                                         "concat",
                                         "-safe",
                                         "0",
                                         "-i",
                                         list_file.string(),
                                         "-vf",
                                         "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white,fps=30",
                                         "-c:v",
                                         "libx264",
                                         "-pix_fmt",
                                         "yuv420p",
                                         output.string()};
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, ffmpeg->c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    return Fail(ErrorCode::kIo,
                "video: cannot run " + ffmpeg->string() + ": " + std::strerror(spawned));
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  std::error_code ec;
  fs::remove(list_file, ec);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    fs::remove(log_file, ec);
    return {};
  }
  const auto log = ReadFile(log_file);
  return Fail(ErrorCode::kIo, "video: ffmpeg failed writing '" + output.string() + "'" +
                                  (log ? ": " + Tail(*log, 3) : std::string()) +
                                  " (log: " + log_file.string() + ")");
}

}  // namespace wrap::render
