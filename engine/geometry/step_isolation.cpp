// An import in a forked child process (see detail/step_isolation.h). The child sends one record
// through a pipe: 'A' and the serialized assembly, or 'E', the error code and its message.
#include "geometry/detail/step_isolation.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <exception>
#include <optional>
#include <string_view>
#include <utility>

#include "geometry/detail/step_serial.h"

namespace wrap::detail {

namespace {

constexpr std::string_view kChildKey = "wrap-step-child";

std::string Quote(const std::string& s) { return "'" + s + "'"; }

bool WriteAll(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(static_cast<size_t>(n));
  }
  return true;
}

std::string ReadAll(int fd) {
  std::string out;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return out;
    out.append(buffer, static_cast<size_t>(n));
  }
}

/// The child's record of `result`.
std::string Record(const Result<StepAssembly>& result) {
  if (result) return "A" + SerializeStepAssembly(*result, std::string(kChildKey));
  const auto code = static_cast<uint32_t>(result.error().code);
  std::string out = "E";
  out.append(reinterpret_cast<const char*>(&code), sizeof code);
  return out + result.error().message;
}

/// The child: no core file, no descriptor of the parent's but the pipe (so that another
/// import's child cannot hold this pipe open), the import, its record, and out without running
/// the parent's exit handlers or flushing its buffers.
[[noreturn]] void RunChild(int out_fd, const std::string& file,
                           const std::function<Result<StepAssembly>()>& import) {
  const rlimit no_core{0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);
  if (out_fd > 3) ::close_range(3, static_cast<unsigned>(out_fd) - 1, 0);
  ::close_range(static_cast<unsigned>(out_fd) + 1, ~0u, 0);
  std::string record;
  try {
    record = Record(import());
  } catch (const std::exception& e) {
    record = Record(Fail(ErrorCode::kInvalidInput, "cannot read STEP file " + Quote(file) +
                                                       ": the importer failed (" + e.what() + ")"));
  } catch (...) {
    record = Record(Fail(ErrorCode::kInvalidInput,
                         "cannot read STEP file " + Quote(file) + ": the importer failed"));
  }
  ::_exit(WriteAll(out_fd, record) ? 0 : 1);
}

/// What the child's record says, or nothing when it is incomplete.
std::optional<Result<StepAssembly>> Parse(std::string_view record) {
  if (record.empty()) return std::nullopt;
  const char tag = record.front();
  record.remove_prefix(1);
  if (tag == 'A') {
    auto a = DeserializeStepAssembly(record, std::string(kChildKey));
    if (!a) return std::nullopt;
    return Result<StepAssembly>(std::move(*a));
  }
  uint32_t code = 0;
  if (tag != 'E' || record.size() < sizeof code) return std::nullopt;
  std::memcpy(&code, record.data(), sizeof code);
  if (code > static_cast<uint32_t>(ErrorCode::kInternal)) return std::nullopt;
  record.remove_prefix(sizeof code);
  return Result<StepAssembly>(Fail(static_cast<ErrorCode>(code), std::string(record)));
}

/// Why a child that sent no complete record ended: "SIGSEGV, Segmentation fault" or "exit
/// status 1".
std::string HowItEnded(int status) {
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* abbrev = ::sigabbrev_np(sig);
    const char* what = ::strsignal(sig);
    return (abbrev ? "SIG" + std::string(abbrev) : "signal " + std::to_string(sig)) +
           (what ? ", " + std::string(what) : "");
  }
  if (WIFEXITED(status)) return "exit status " + std::to_string(WEXITSTATUS(status));
  return "status " + std::to_string(status);
}

}  // namespace

Result<StepAssembly> ImportInChild(const std::string& file,
                                   const std::function<Result<StepAssembly>()>& import,
                                   std::mutex& held) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    return Fail(ErrorCode::kIo, "cannot read STEP file " + Quote(file) +
                                    ": cannot open a pipe to the importer (" +
                                    std::strerror(errno) + ")");
  }
  pid_t pid = -1;
  int fork_errno = 0;
  {
    std::lock_guard lock(held);
    pid = ::fork();
    fork_errno = errno;  // before the unlock can touch it
    if (pid == 0) {
      ::close(fds[0]);
      RunChild(fds[1], file, import);
    }
  }
  ::close(fds[1]);
  if (pid < 0) {
    ::close(fds[0]);
    return Fail(ErrorCode::kIo, "cannot read STEP file " + Quote(file) +
                                    ": cannot start the importer's process (" +
                                    std::strerror(fork_errno) + ")");
  }
  const std::string record = ReadAll(fds[0]);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  auto parsed = Parse(record);
  if (parsed && WIFEXITED(status) && WEXITSTATUS(status) == 0) return std::move(*parsed);
  return Fail(ErrorCode::kInvalidInput,
              "cannot read STEP file " + Quote(file) + ": OpenCASCADE crashed on it (" +
                  HowItEnded(status) +
                  "); the file is probably damaged: export it again from the CAD program, or "
                  "each part as STL, OBJ or PLY");
}

}  // namespace wrap::detail
