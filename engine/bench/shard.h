// A bench output folder as one shard of a suite: its identity (what must be equal for its runs
// to belong together), its sessions (each process that worked on it), meta.json, and the lock
// that keeps two processes out of one folder.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "core/result.h"

namespace wrap::bench {

/// What makes the runs of a folder comparable with another folder's: equal identities (but for
/// the shard index) are shards of one study.
struct ShardId {
  std::string revision;                ///< BuildRevision() of the `wrap bench` that ran it.
  std::string suite;                   ///< --suite.
  int runs = 0;                        ///< --runs (seeds per configuration).
  std::optional<double> time_limit_s;  ///< --time-limit; absent: the suite's defaults.
  double hard_limit_s = 0.0;           ///< --hard-limit; 0: automatic.
  long long memory_limit_mib = 0;      ///< --memory-limit.
  int shard_index = 1;                 ///< This shard, 1..shard_count.
  int shard_count = 1;                 ///< Shards of the suite.
  int suite_runs = 0;                  ///< Runs of the whole suite.
  int shard_runs = 0;                  ///< Runs of this shard.
  std::string suite_fingerprint;       ///< Hash of every run's key and group, in order.
  std::string projects_fingerprint;    ///< Hash of the example project files the suite reads.

  /// "shard 2/8 of suite 'all'".
  std::string Describe() const;
};

/// The differences between two identities that keep their runs apart, in words
/// ("--runs: 3 here, 10 there"); the shard index only when `with_index`.
std::vector<std::string> Differences(const ShardId& here, const ShardId& there, bool with_index);

/// One process's work on a folder.
struct Session {
  std::string host;        ///< Host name.
  std::string machine;     ///< CPU model, cores, memory, OS.
  int cores = 0;           ///< Online CPUs.
  int jobs = 0;            ///< Runs at once.
  std::string start, end;  ///< UTC date and time; end empty while running or when killed.
  std::string load_start;  ///< Load averages (1, 5, 15 min) at the start.
  std::string load_end;    ///< ... and at the end; empty when killed.
  std::string slurm_job;   ///< SLURM_JOB_ID (and array job and task), or empty.
  bool unlocked = false;   ///< The folder's file system refused the lock (FolderLock::held).
  int runs_done = 0;       ///< Runs with results when the session ended.
};

/// One shard's record in meta.json.
struct ShardRecord {
  ShardId id;
  std::vector<Session> sessions;
  /// Runs of the shard with a result: counted in its folder by `merge`; in a shard folder's
  /// meta.json, as of its last session's end.
  int runs_done = 0;
};

/// meta.json of a bench folder: "shard" (made by `wrap bench`, one record) or "merged" (by
/// `wrap bench merge`, the records of every shard merged into it).
struct FolderMeta {
  std::string kind = "shard";
  std::vector<ShardRecord> shards;
  RunInfo info;  ///< The report header's facts.
};

/// Reads DIR/meta.json; fails with kInvalidInput naming the file when it is missing, malformed
/// or from a `wrap bench` that did not record identities.
Result<FolderMeta> ReadFolderMeta(const std::filesystem::path& dir);
/// Writes DIR/meta.json atomically.
Result<void> WriteFolderMeta(const std::filesystem::path& dir, const FolderMeta& meta);

/// This machine's session facts (host, machine, cores, start, load, Slurm job) for `jobs`.
Session StartSession(int jobs);
/// Ends a session: date and load at the end, runs with results.
void EndSession(Session& session, int runs_done);
/// "2026-12-02 10:00 UTC".
std::string UtcNow();
/// "0.52 0.61 0.70".
std::string LoadAverages();

/// The identity of `options`' shard of `all_specs` (the projects read from options.projects_dir).
ShardId MakeShardId(const std::vector<RunSpec>& all_specs, const BenchOptions& options);

/// The report header's facts of these shards: machines, load of every session, the revision,
/// the dates, the suites' settings.
RunInfo ReportInfo(const std::vector<ShardRecord>& records);

/// An exclusive lock on a folder (flock on DIR/.lock, which names its holder), held while the
/// object lives; released when the process ends, also when it is killed.
class FolderLock {
 public:
  /// Fails with kInvalidInput naming the folder and the process holding it.
  static Result<FolderLock> Acquire(const std::filesystem::path& dir);
  FolderLock(FolderLock&& other) noexcept;
  FolderLock& operator=(FolderLock&&) = delete;
  FolderLock(const FolderLock&) = delete;
  ~FolderLock();
  /// False where the file system does not lock (no flock: Lustre without it, some NFS set-ups):
  /// then nothing keeps a second process out, which the session records.
  bool held() const { return held_; }

 private:
  FolderLock(int fd, bool held) : fd_(fd), held_(held) {}
  int fd_ = -1;
  bool held_ = true;
};

}  // namespace wrap::bench
