// Bench folders as shards: identity, sessions, meta.json and the folder lock.
#include "bench/shard.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <thread>

#include "bench/build_revision.h"
#include "core/file_io.h"

namespace wrap::bench {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

constexpr const char* kFormat = "wrap-bench-folder";
constexpr int kVersion = 2;

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// FNV-1a, 64 bits, as 16 hex digits: a fingerprint, not a security measure.
class Fingerprint {
 public:
  void Add(const std::string& s) {
    for (unsigned char c : s) {
      h_ ^= c;
      h_ *= 1099511628211ull;
    }
    h_ ^= 0xff;  // separates "ab" + "c" from "a" + "bc"
    h_ *= 1099511628211ull;
  }
  std::string Hex() const {
    char buf[20];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h_));
    return buf;
  }

 private:
  std::uint64_t h_ = 14695981039346656037ull;
};

std::string CommandOutput(const std::string& command) {
  std::string out;
  if (FILE* f = popen(command.c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof buf, f)) out += buf;
    pclose(f);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

std::string Machine() {
  std::ifstream cpu("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  while (std::getline(cpu, line)) {
    if (line.starts_with("model name")) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  std::ifstream mem("/proc/meminfo");
  std::string key;
  long long kib = 0;
  mem >> key >> kib;
  std::string machine = model + ", " + std::to_string(std::thread::hardware_concurrency()) +
                        " cores, " + Num(std::round(kib / 1048576.0)) + " GiB";
  const std::string os = CommandOutput("uname -sr 2>/dev/null");
  if (!os.empty()) machine += ", " + os;
  return machine;
}

std::string Env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

Json IdToJson(const ShardId& id) {
  Json j;
  j["revision"] = id.revision;
  j["suite"] = id.suite;
  j["runs"] = id.runs;
  j["time_limit_s"] = id.time_limit_s ? Json(*id.time_limit_s) : Json(nullptr);
  j["hard_limit_s"] = id.hard_limit_s;
  j["memory_limit_mib"] = id.memory_limit_mib;
  j["shard"] = {id.shard_index, id.shard_count};
  j["suite_runs"] = id.suite_runs;
  j["shard_runs"] = id.shard_runs;
  j["suite_fingerprint"] = id.suite_fingerprint;
  j["projects_fingerprint"] = id.projects_fingerprint;
  return j;
}

ShardId IdFromJson(const Json& j) {
  ShardId id;
  id.revision = j.at("revision").get<std::string>();
  id.suite = j.at("suite").get<std::string>();
  id.runs = j.at("runs").get<int>();
  if (!j.at("time_limit_s").is_null()) id.time_limit_s = j.at("time_limit_s").get<double>();
  id.hard_limit_s = j.at("hard_limit_s").get<double>();
  id.memory_limit_mib = j.at("memory_limit_mib").get<long long>();
  id.shard_index = j.at("shard").at(0).get<int>();
  id.shard_count = j.at("shard").at(1).get<int>();
  id.suite_runs = j.at("suite_runs").get<int>();
  id.shard_runs = j.at("shard_runs").get<int>();
  id.suite_fingerprint = j.at("suite_fingerprint").get<std::string>();
  id.projects_fingerprint = j.at("projects_fingerprint").get<std::string>();
  return id;
}

Json SessionToJson(const Session& s) {
  return Json{{"host", s.host},
              {"machine", s.machine},
              {"cores", s.cores},
              {"jobs", s.jobs},
              {"start", s.start},
              {"end", s.end},
              {"load_start", s.load_start},
              {"load_end", s.load_end},
              {"slurm_job", s.slurm_job},
              {"unlocked", s.unlocked},
              {"runs_done", s.runs_done}};
}

Session SessionFromJson(const Json& j) {
  Session s;
  s.host = j.value("host", "");
  s.machine = j.value("machine", "");
  s.cores = j.value("cores", 0);
  s.jobs = j.value("jobs", 0);
  s.start = j.value("start", "");
  s.end = j.value("end", "");
  s.load_start = j.value("load_start", "");
  s.load_end = j.value("load_end", "");
  s.slurm_job = j.value("slurm_job", "");
  s.unlocked = j.value("unlocked", false);
  s.runs_done = j.value("runs_done", 0);
  return s;
}

}  // namespace

std::string ShardId::Describe() const {
  return "shard " + std::to_string(shard_index) + "/" + std::to_string(shard_count) +
         " of suite '" + suite + "'";
}

std::vector<std::string> Differences(const ShardId& here, const ShardId& there, bool with_index) {
  std::vector<std::string> d;
  const auto differ = [&](const std::string& what, const std::string& a, const std::string& b) {
    if (a != b) d.push_back(what + ": " + a + " here, " + b + " there");
  };
  const auto limit = [](const std::optional<double>& v) {
    return v ? Num(*v) + " s" : std::string("the suite's default");
  };
  differ("revision", here.revision, there.revision);
  differ("suite", here.suite, there.suite);
  differ("--runs", std::to_string(here.runs), std::to_string(there.runs));
  differ("--time-limit", limit(here.time_limit_s), limit(there.time_limit_s));
  differ("--hard-limit", here.hard_limit_s > 0 ? Num(here.hard_limit_s) + " s" : "automatic",
         there.hard_limit_s > 0 ? Num(there.hard_limit_s) + " s" : "automatic");
  differ("--memory-limit", std::to_string(here.memory_limit_mib) + " MiB",
         std::to_string(there.memory_limit_mib) + " MiB");
  differ("shards (--shard I/N)", std::to_string(here.shard_count),
         std::to_string(there.shard_count));
  if (with_index) {
    differ("shard (--shard I/N)", std::to_string(here.shard_index),
           std::to_string(there.shard_index));
  }
  if (d.empty() &&
      (here.suite_runs != there.suite_runs || here.suite_fingerprint != there.suite_fingerprint)) {
    d.push_back("the suite's runs: " + std::to_string(here.suite_runs) + " here (" +
                here.suite_fingerprint + "), " + std::to_string(there.suite_runs) + " there (" +
                there.suite_fingerprint + ")");
  }
  if (here.projects_fingerprint != there.projects_fingerprint) {
    d.push_back("the example projects' files differ (fingerprint " + here.projects_fingerprint +
                " here, " + there.projects_fingerprint + " there)");
  }
  return d;
}

std::string UtcNow() {
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  return date;
}

std::string LoadAverages() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  in >> a >> b >> c;
  return Num(a) + " " + Num(b) + " " + Num(c);
}

Session StartSession(int jobs) {
  Session s;
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  s.host = host;
  s.machine = Machine();
  s.cores = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  s.jobs = jobs;
  s.start = UtcNow();
  s.load_start = LoadAverages();
  const std::string array_job = Env("SLURM_ARRAY_JOB_ID"), task = Env("SLURM_ARRAY_TASK_ID");
  s.slurm_job = !array_job.empty() ? array_job + "_" + task : Env("SLURM_JOB_ID");
  return s;
}

void EndSession(Session& session, int runs_done) {
  session.end = UtcNow();
  session.load_end = LoadAverages();
  session.runs_done = runs_done;
}

ShardId MakeShardId(const std::vector<RunSpec>& all_specs, const BenchOptions& options) {
  ShardId id;
  id.revision = std::string(BuildRevision());
  id.suite = options.suite;
  id.runs = options.runs;
  id.time_limit_s = options.time_limit_s;
  id.hard_limit_s = options.hard_limit_s;
  id.memory_limit_mib = options.memory_limit_mib;
  id.shard_index = options.shard_index;
  id.shard_count = options.shard_count;
  id.suite_runs = static_cast<int>(all_specs.size());
  id.shard_runs =
      static_cast<int>(ShardSlice(all_specs, options.shard_index, options.shard_count).size());
  Fingerprint suite, projects;
  std::set<std::string> bases;
  for (const RunSpec& s : all_specs) {
    suite.Add(s.Key() + " " + s.group);
    bases.insert(s.project.base);
  }
  for (const std::string& base : bases) {
    projects.Add(base);
    auto text = ReadFile(options.projects_dir / (base + ".json"));
    projects.Add(text ? *text : std::string("(missing)"));
  }
  id.suite_fingerprint = suite.Hex();
  id.projects_fingerprint = projects.Hex();
  return id;
}

Result<FolderMeta> ReadFolderMeta(const fs::path& dir) {
  const fs::path file = dir / "meta.json";
  auto text = ReadFile(file);
  if (!text) {
    return Fail(ErrorCode::kInvalidInput,
                file.string() + ": missing (not a folder written by `wrap bench`?)");
  }
  const Json j = Json::parse(*text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    return Fail(ErrorCode::kInvalidInput, file.string() + ": not a JSON object");
  }
  if (j.value("format", "") != kFormat || j.value("version", 0) != kVersion) {
    return Fail(ErrorCode::kInvalidInput,
                file.string() + ": format: not a " + kFormat + " version " +
                    std::to_string(kVersion) +
                    " file (written by an older `wrap bench`, which recorded no shard "
                    "identity: run that suite again into a new folder)");
  }
  FolderMeta meta;
  std::string field = "kind";
  try {
    meta.kind = j.at("kind").get<std::string>();
    if (meta.kind != "shard" && meta.kind != "merged") throw std::runtime_error("unknown kind");
    field = "shards";
    for (const Json& r : j.at("shards")) {
      ShardRecord record;
      record.id = IdFromJson(r.at("id"));
      record.runs_done = r.at("runs_done").get<int>();
      for (const Json& s : r.at("sessions")) record.sessions.push_back(SessionFromJson(s));
      meta.shards.push_back(std::move(record));
    }
    if (meta.shards.empty() || (meta.kind == "shard" && meta.shards.size() != 1)) {
      throw std::runtime_error("wrong count");
    }
    field = "report";
    const Json& info = j.at("report");
    meta.info.machine = info.value("machine", "");
    meta.info.load = info.value("load", "");
    meta.info.commit = info.value("commit", "");
    meta.info.date = info.value("date", "");
    meta.info.settings = info.value("settings", "");
    meta.info.caveats = info.value("caveats", "");
  } catch (const std::exception&) {
    return Fail(ErrorCode::kInvalidInput,
                file.string() + ": " + field + ": missing or of the wrong type");
  }
  return meta;
}

Result<void> WriteFolderMeta(const fs::path& dir, const FolderMeta& meta) {
  Json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["kind"] = meta.kind;
  Json shards = Json::array();
  for (const ShardRecord& r : meta.shards) {
    Json sessions = Json::array();
    for (const Session& s : r.sessions) sessions.push_back(SessionToJson(s));
    shards.push_back(
        Json{{"id", IdToJson(r.id)}, {"runs_done", r.runs_done}, {"sessions", sessions}});
  }
  j["shards"] = shards;
  j["report"] = Json{{"machine", meta.info.machine},   {"load", meta.info.load},
                     {"commit", meta.info.commit},     {"date", meta.info.date},
                     {"settings", meta.info.settings}, {"caveats", meta.info.caveats}};
  return WriteFileAtomic(dir / "meta.json", j.dump(2) + "\n");
}

Result<FolderLock> FolderLock::Acquire(const fs::path& dir) {
  const fs::path file = dir / ".lock";
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    return Fail(ErrorCode::kIo, file.string() + ": cannot open: " + std::strerror(errno));
  }
  bool held = true;
  const int locked = ::flock(fd, LOCK_EX | LOCK_NB);
  const int why = errno;
  if (locked != 0 && why != EWOULDBLOCK) {
    // A file system without flock (Lustre mounted without it, some NFS set-ups): the folder
    // cannot be guarded; the shard goes on unguarded, as its session records.
    held = false;
  } else if (locked != 0) {
    std::string holder;
    char buf[512] = {};
    if (::pread(fd, buf, sizeof buf - 1, 0) > 0) holder = buf;
    while (!holder.empty() && holder.back() == '\n') holder.pop_back();
    ::close(fd);
    return Fail(ErrorCode::kInvalidInput,
                dir.string() + ": in use by another `wrap bench` (" +
                    (holder.empty() ? std::string("holder unknown") : holder) +
                    "); two processes never share a folder: wait for it, or give each shard "
                    "its own -o");
  }
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  std::string holder = "pid " + std::to_string(::getpid()) + " on " + host + " since " + UtcNow();
  const std::string job = Env("SLURM_JOB_ID");
  if (!job.empty()) holder += ", Slurm job " + job;
  holder += "\n";
  if (::ftruncate(fd, 0) == 0) {
    [[maybe_unused]] const ssize_t n = ::pwrite(fd, holder.data(), holder.size(), 0);
  }
  return FolderLock(fd, held);
}

FolderLock::FolderLock(FolderLock&& other) noexcept : fd_(other.fd_), held_(other.held_) {
  other.fd_ = -1;
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the descriptor releases the flock
}

}  // namespace wrap::bench
