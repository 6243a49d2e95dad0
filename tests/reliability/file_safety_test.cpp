// Saving a project or writing results where the write cannot succeed (an unwritable folder, a
// "folder" that is a regular file, a full disk, a file-size limit): the call fails with a message
// naming the path, the previous file stays byte-for-byte intact and no temporary file is left.
//
// CI runs as root, where permission bits do not stop writes: there the unwritable-folder case
// saves from a child process that has dropped to the user 'nobody'. The parent-is-a-file,
// disk-full (a character device like /dev/full) and file-size-limit (RLIMIT_FSIZE, EFBIG) cases
// cover the other ways a write fails.
#include <fcntl.h>
#include <grp.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "model/project_io.h"
#include "reliability_fixture.h"

namespace wrap::reliability {
namespace {

using cli::CliRun;
using cli::Wrap;

/// The blocks project, parsed.
Project Blocks() {
  ProjectParse parsed = ParseProject(BlocksProject().dump(), "blocks.json");
  EXPECT_TRUE(parsed.project.has_value());
  return parsed.project.value_or(Project{});
}

/// A saved project file and its bytes, to compare with after a failed save.
struct Previous {
  fs::path file;
  std::string bytes;
};

Previous SaveOriginal(const fs::path& dir) {
  Project p = Blocks();
  p.name = "original";
  const fs::path file = dir / "project.json";
  EXPECT_TRUE(SaveProject(p, file).has_value());
  return {file, ReadBytes(file)};
}

/// The project to save over the original: bigger than it, so that a size limit between the two
/// stops the write half way.
Project Edited() {
  Project p = Blocks();
  p.name = "edited";
  p.description = std::string(20000, 'x');
  return p;
}

void ExpectIntact(const Previous& prev, const fs::path& dir) {
  EXPECT_EQ(ReadBytes(prev.file), prev.bytes) << prev.file << " changed";
  EXPECT_EQ(ListFiles(dir), std::vector<std::string>{"project.json"})
      << "a temporary file was left in " << dir;
}

/// Holds RLIMIT_FSIZE at `bytes` (SIGXFSZ ignored, so writes fail with EFBIG) until destroyed.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = old_;
    limit.rlim_cur = bytes;
    ok_ = setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }
  bool ok() const { return ok_; }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = SIG_DFL;
  bool ok_ = false;
};

/// The system's character device `name` (/dev/full: writes fail with ENOSPC; /dev/null: writes
/// vanish; major 1, `minor`) at dir/name: a node of our own where we may make one (root with
/// CAP_MKNOD, on a file system that allows devices), else a symbolic link to the system's device.
/// A write follows either to the device. A save that replaced the file (renaming its temporary
/// file over it) would replace our node or link, never the system's device, and leave a regular
/// file at dir/name.
fs::path CharDevice(const fs::path& dir, const std::string& name, unsigned minor) {
  const fs::path own = dir / name;
  if (::mknod(own.c_str(), S_IFCHR | 0666, makedev(1, minor)) == 0) {
    const int fd = ::open(own.c_str(), O_WRONLY);
    if (fd >= 0) {
      ::close(fd);
      return own;
    }
    fs::remove(own);  // a file system mounted nodev: the node cannot be opened
  }
  std::error_code ec;
  fs::create_symlink(fs::path("/dev") / name, own, ec);
  EXPECT_FALSE(ec) << "cannot link " << own << " to /dev/" << name << ": " << ec.message();
  return own;
}

TEST(FileSafety, SaveIntoAFolderThatIsARegularFile) {
  TempDir dir("parent_is_file");
  const Previous prev = SaveOriginal(dir.path);
  auto saved = SaveProject(Edited(), prev.file / "inner.json");
  ASSERT_FALSE(saved.has_value());
  EXPECT_EQ(saved.error().code, ErrorCode::kIo);
  EXPECT_NE(saved.error().message.find("project.json"), std::string::npos) << saved.error().message;
  ExpectIntact(prev, dir.path);
}

// Saves `project` to `file` as another user than root (a forked child that drops to 'nobody',
// uid and gid 65534), where permission bits apply; the child's exit code says how it went: 0
// saved, 10 failed with kIo naming "Permission denied", 11 failed otherwise, 12 could not drop.
int SaveAsNobody(const Project& project, const fs::path& file) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::setgroups(0, nullptr) != 0 || ::setgid(65534) != 0 || ::setuid(65534) != 0) _exit(12);
    auto saved = SaveProject(project, file);
    if (saved) _exit(0);
    const bool denied = saved.error().code == ErrorCode::kIo &&
                        saved.error().message.find("Permission denied") != std::string::npos;
    _exit(denied ? 10 : 11);
  }
  int status = 0;
  if (pid < 0 || ::waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

TEST(FileSafety, SaveIntoAnUnwritableFolder) {
  TempDir dir("unwritable");
  const Previous prev = SaveOriginal(dir.path);
  // Readable and searchable by everyone (the child as 'nobody' reaches the file), writable by
  // no one.
  const auto rx = fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                  fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec;
  fs::permissions(dir.path, rx);
  if (::geteuid() == 0) {
    // Root writes whatever the permission bits say: the save runs as 'nobody'.
    const int code = SaveAsNobody(Edited(), prev.file);
    fs::permissions(dir.path, fs::perms::owner_all);
    ASSERT_NE(code, 12) << "could not drop to the user nobody";
    EXPECT_EQ(code, 10) << "0: saved into a read-only folder; 11: failed without naming the "
                           "permission; -1: the child died";
  } else {
    auto saved = SaveProject(Edited(), prev.file);
    fs::permissions(dir.path, fs::perms::owner_all);
    ASSERT_FALSE(saved.has_value());
    EXPECT_EQ(saved.error().code, ErrorCode::kIo);
    EXPECT_NE(saved.error().message.find("Permission denied"), std::string::npos)
        << saved.error().message;
  }
  ExpectIntact(prev, dir.path);
}

TEST(FileSafety, SaveStoppedByAFileSizeLimit) {
  TempDir dir("fsize");
  const Previous prev = SaveOriginal(dir.path);
  Result<void> saved;
  {
    FileSizeLimit limit(4096);
    ASSERT_TRUE(limit.ok());
    saved = SaveProject(Edited(), prev.file);
  }
  ASSERT_FALSE(saved.has_value());
  EXPECT_EQ(saved.error().code, ErrorCode::kIo);
  EXPECT_NE(saved.error().message.find("cannot write"), std::string::npos) << saved.error().message;
  ExpectIntact(prev, dir.path);
  // Without the limit the same save goes through.
  ASSERT_TRUE(SaveProject(Edited(), prev.file).has_value());
  EXPECT_NE(ReadBytes(prev.file).find("\"edited\""), std::string::npos);
}

// A device is written in place, never replaced by the temporary file (`-o /dev/null` as root
// used to turn /dev/null into a regular file); a full disk is an error that names the path.
TEST(FileSafety, DiskFullDeviceIsWrittenInPlaceAndFails) {
  TempDir dir("disk_full");
  const fs::path full = CharDevice(dir.path, "full", 7);
  ASSERT_TRUE(fs::is_character_file(full));
  auto saved = SaveProject(Edited(), full);
  ASSERT_FALSE(saved.has_value());
  EXPECT_EQ(saved.error().code, ErrorCode::kIo);
  EXPECT_NE(saved.error().message.find(full.string()), std::string::npos) << saved.error().message;
  EXPECT_NE(saved.error().message.find("No space left"), std::string::npos)
      << saved.error().message;
  EXPECT_TRUE(fs::is_character_file(full)) << full << " was replaced";
  // And a null device takes the bytes and stays a device.
  const fs::path null = CharDevice(dir.path, "null", 3);
  ASSERT_TRUE(fs::is_character_file(null));
  EXPECT_TRUE(WriteFileAtomic(null, "bytes").has_value());
  EXPECT_TRUE(fs::is_character_file(null)) << null << " was replaced";
}

TEST(FileSafety, SaveOverADirectoryFails) {
  TempDir dir("over_dir");
  const Previous prev = SaveOriginal(dir.path);
  fs::create_directory(dir.path / "folder");
  auto saved = SaveProject(Edited(), dir.path / "folder");
  ASSERT_FALSE(saved.has_value());
  EXPECT_NE(saved.error().message.find("directory"), std::string::npos) << saved.error().message;
  EXPECT_TRUE(fs::is_directory(dir.path / "folder"));
  EXPECT_EQ(ReadBytes(prev.file), prev.bytes);
}

// The results of `wrap plan -o` and `wrap preprocess -o`: exit 2 naming the path; an earlier
// result at that path stays as it was.
TEST(FileSafety, CommandResultsKeepThePreviousFile) {
  TempDir dir("results");
  const Previous prev = SaveOriginal(dir.path);  // Stands for an earlier result.
  const std::string project = cli::Project("half_stool");

  // The parent of the output is a regular file.
  const std::string under_file = (prev.file / "plan.json").string();
  CliRun r = Wrap({"plan", project, "--task-only", "-o", under_file});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(under_file), std::string::npos) << r.err;
  r = Wrap({"preprocess", project, "--grasps", "4", "-o", under_file});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(under_file), std::string::npos) << r.err;
  ExpectIntact(prev, dir.path);

  // The disk fills up (a file-size limit below the plan's size) while the plan is written.
  {
    FileSizeLimit limit(prev.bytes.size() + 16);
    ASSERT_TRUE(limit.ok());
    r = Wrap({"plan", project, "--task-only", "-o", prev.file.string()});
  }
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("project.json"), std::string::npos) << r.err;
  ExpectIntact(prev, dir.path);

  const fs::path full = CharDevice(dir.path, "full", 7);
  r = Wrap({"plan", project, "--task-only", "-o", full.string()});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("No space left"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_character_file(full)) << full << " was replaced";
}

}  // namespace
}  // namespace wrap::reliability
