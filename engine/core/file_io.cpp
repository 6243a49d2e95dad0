#include "core/file_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

namespace wrap {

namespace fs = std::filesystem;

Result<std::string> ReadFile(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    return Fail(ErrorCode::kIo, "'" + path.string() + "' is a directory, not a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return Fail(ErrorCode::kIo, "cannot open '" + path.string() + "': " + std::strerror(errno));
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return Fail(ErrorCode::kIo, "error reading '" + path.string() + "'");
  return ss.str();
}

namespace {

/// Writes all of `contents` to `fd`; false with errno set on failure.
bool WriteAll(int fd, const std::string& contents) {
  const char* p = contents.data();
  size_t left = contents.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  return true;
}

/// Writes to a character device (`-o /dev/null`, `/dev/full`, a terminal) in place: renaming a
/// temporary file over it would replace the device node with a regular file.
Result<void> WriteDevice(const fs::path& path, const std::string& contents) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    return Fail(ErrorCode::kIo, "cannot open '" + path.string() + "': " + std::strerror(errno));
  }
  const bool written = WriteAll(fd, contents);
  const int write_errno = errno;
  ::close(fd);
  if (!written) {
    return Fail(ErrorCode::kIo,
                "cannot write '" + path.string() + "': " + std::strerror(write_errno));
  }
  return {};
}

}  // namespace

Result<void> WriteFileAtomic(const fs::path& path, const std::string& contents) {
  struct stat target {};
  if (::stat(path.c_str(), &target) == 0 && !S_ISREG(target.st_mode)) {
    if (S_ISCHR(target.st_mode)) return WriteDevice(path, contents);
    return Fail(ErrorCode::kIo,
                "cannot write '" + path.string() + "': " +
                    (S_ISDIR(target.st_mode) ? "it is a directory" : "it is not a regular file"));
  }
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::random_device rd;
  const fs::path tmp = dir / ("." + path.filename().string() + ".tmp" + std::to_string(::getpid()) +
                              "_" + std::to_string(rd() & 0xffffff));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    return Fail(ErrorCode::kIo, "cannot create '" + tmp.string() + "': " + std::strerror(errno));
  }
  if (!WriteAll(fd, contents)) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    ::unlink(tmp.c_str());
    return Fail(ErrorCode::kIo, "cannot write '" + tmp.string() + "': " + why);
  }
  // Always close, even when fsync fails, so the descriptor never leaks.
  const bool synced = ::fsync(fd) == 0;
  const int sync_errno = errno;
  const bool closed = ::close(fd) == 0;
  if (!synced || !closed) {
    const std::string why = std::strerror(synced ? errno : sync_errno);
    ::unlink(tmp.c_str());
    return Fail(ErrorCode::kIo, "cannot flush '" + tmp.string() + "': " + why);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    ::unlink(tmp.c_str());
    return Fail(ErrorCode::kIo,
                "cannot rename '" + tmp.string() + "' to '" + path.string() + "': " + why);
  }
  return {};
}

}  // namespace wrap
