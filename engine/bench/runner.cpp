// Runs a suite: every run a child `wrap plan` (and `wrap sim`) process under a wall-clock and an
// address-space limit, up to `jobs` at once on cores of their own; timeouts, out-of-memory and
// crashes become results. The folder is one shard's: locked, its identity in meta.json.
#include <fcntl.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <thread>

#include "bench/bench.h"
#include "bench/child_output.h"
#include "bench/shard.h"
#include "core/file_io.h"

namespace wrap::bench {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_interrupted = 0;
void OnInterrupt(int) { g_interrupted = 1; }

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Messages name files by their place in the output folder, not by this machine's paths.
std::string WithinOutput(std::string message, const fs::path& out) {
  for (const std::string& prefix : {fs::absolute(out).string() + "/", out.string() + "/"}) {
    for (size_t at = message.find(prefix); at != std::string::npos; at = message.find(prefix, at)) {
      message.erase(at, prefix.size());
    }
  }
  return message;
}

double CpuSeconds(const rusage& ru) {
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// Threads ready to run on the machine now, the reader itself not counted (/proc/loadavg's
// "running/total" field); negative when unknown.
double RunnableThreads() {
  std::ifstream in("/proc/loadavg");
  double a, b, c;
  int running = 0;
  char slash = 0;
  if (!(in >> a >> b >> c >> running >> slash) || slash != '/') return -1.0;
  return std::max(0, running - 1);
}

// Starts `argv` in its own process group with stdout and stderr appended to `log`, its address
// space limited to `as_mib`, on `cpus` (all when empty); it dies with this process. Returns the
// pid, or -1 (errno) when fork failed.
pid_t Spawn(const std::vector<std::string>& argv, const fs::path& log, long long as_mib,
            const std::vector<int>& cpus) {
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid != 0) return pid;
  // Child: only async-signal-safe calls until exec.
  setpgid(0, 0);
  // A harness killed outright (SIGKILL, a node lost) takes its children along, so a resumed
  // shard never meets an orphan still writing the same files.
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(127);
  if (!cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (int c : cpus) CPU_SET(c, &set);
    sched_setaffinity(0, sizeof set, &set);
  }
  const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd >= 0) {
    dup2(fd, 1);
    dup2(fd, 2);
    close(fd);
  }
  const int null_fd = open("/dev/null", O_RDONLY);
  if (null_fd >= 0) {
    dup2(null_fd, 0);
    close(null_fd);
  }
#if defined(__SANITIZE_ADDRESS__)
  // An AddressSanitizer build maps terabytes of shadow memory at start: under an address-space
  // limit its children could not start. Such a build runs without the limit.
  as_mib = 0;
#endif
  if (as_mib > 0) {
    rlimit lim{};
    lim.rlim_cur = lim.rlim_max = static_cast<rlim_t>(as_mib) * 1024 * 1024;
    setrlimit(RLIMIT_AS, &lim);
  }
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  execv(args[0], args.data());
  const char msg[] = "wrap bench: could not start the child process\n";
  [[maybe_unused]] const ssize_t n = write(2, msg, sizeof msg - 1);
  _exit(127);
}

// One child process.
struct Child {
  pid_t pid = -1;
  Clock::time_point start;
  Clock::time_point deadline;
  bool term_sent = false;
  bool kill_sent = false;
};

// A job: one run, in the plan phase and then, if asked, the sim phase.
struct Job {
  RunSpec spec;
  std::string key;
  fs::path project_file;
  RunResult result;
  Child child;
  bool sim_phase = false;
  int slot = -1;          // which of the `jobs` core sets it runs on
  double load_sum = 0.0;  // runnable threads summed over the plan phase's samples
  int load_samples = 0;
};

std::string Describe(const RunResult& r) {
  std::string s = r.spec.project.name + " " + r.spec.planner + " " + r.spec.Options() + " seed " +
                  std::to_string(r.spec.seed) + ": " + ToString(r.status);
  if (r.solved()) {
    if (auto it = r.stats.find("cost"); it != r.stats.end()) s += ", cost " + Num(it->second);
    if (auto it = r.stats.find("t_init_s"); it != r.stats.end()) {
      s += ", t_init " + Num(it->second) + " s";
    }
  }
  if (r.sim_success) s += std::string(", sim ") + (*r.sim_success ? "holds" : r.sim_failure);
  if (r.loaded()) s += " (machine loaded: " + Num(std::round(r.load * 10) / 10) + " threads ready)";
  return s;
}

// The cores of each of `jobs` slots: this process's allowed CPUs split evenly, so that runs do
// not compete for cores; no pinning (empty sets) when there are fewer CPUs than jobs.
std::vector<std::vector<int>> CoreSlots(int jobs) {
  std::vector<std::vector<int>> slots(jobs);
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return slots;
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  }
  const int n = static_cast<int>(cpus.size());
  if (n < jobs) return slots;
  for (int s = 0; s < jobs; ++s) {
    for (int i = s * n / jobs; i < (s + 1) * n / jobs; ++i) slots[s].push_back(cpus[i]);
  }
  return slots;
}

fs::path ProjectFile(const RunSpec& spec, const BenchOptions& options, const fs::path& out) {
  if (spec.project.robots == 0 && spec.project.steps == 0) {
    return options.projects_dir / (spec.project.base + ".json");
  }
  return out / "projects" / (spec.project.name + ".json");
}

// The suite run of one shard in one folder.
class SuiteRunner {
 public:
  SuiteRunner(const BenchOptions& options, fs::path out, fs::path exe)
      : options_(options), out_(std::move(out)), exe_(std::move(exe)) {}

  Result<void> Prepare(const std::vector<RunSpec>& all_specs);
  Result<std::vector<RunResult>> Run();

 private:
  std::vector<std::string> PlanArgv(const Job& job) const;
  bool Start(Job& job);
  bool Finish(Job& job, int wstatus, const rusage& ru);
  void ClassifyPlan(Job& job, int wstatus, const rusage& ru, double wall);
  void Record(Job& job);
  void Report(const RunResult& r, bool fresh);
  Result<void> Close(bool finished);
  double HardLimit(const RunSpec& s) const;

  BenchOptions options_;
  fs::path out_;
  fs::path exe_;
  std::optional<FolderLock> lock_;
  FolderMeta meta_;
  std::vector<Job> jobs_;
  std::vector<size_t> queue_;
  std::vector<std::vector<int>> slots_;
  std::vector<bool> slot_used_;
  std::vector<RunResult> results_;
  Progress progress_;
  Clock::time_point t0_ = Clock::now();
  int fresh_done_ = 0;
  Result<void> write_error_;
};

// The plan child's wall-clock limit [s].
double PlanHardLimitS(const RunSpec& s, const BenchOptions& options) {
  if (options.hard_limit_s > 0.0) return options.hard_limit_s;
  return s.time_limit_s + std::max(10.0, 0.5 * s.time_limit_s);
}

double SuiteRunner::HardLimit(const RunSpec& s) const { return PlanHardLimitS(s, options_); }

Result<void> SuiteRunner::Prepare(const std::vector<RunSpec>& all_specs) {
  std::error_code ec;
  fs::create_directories(out_, ec);
  if (ec) return Fail(ErrorCode::kIo, out_.string() + ": cannot create folder: " + ec.message());
  auto lock = FolderLock::Acquire(out_);
  if (!lock) return std::unexpected(lock.error());
  lock_.emplace(std::move(*lock));

  // The folder is this shard's: a new one, or one that an earlier call with the same identity
  // left (then it resumes).
  const ShardId id = MakeShardId(all_specs, options_);
  if (fs::exists(out_ / "meta.json")) {
    auto old = ReadFolderMeta(out_);
    if (!old) return std::unexpected(old.error());
    if (old->kind != "shard") {
      return Fail(ErrorCode::kInvalidInput, out_.string() +
                                                ": holds a merged report, not a "
                                                "shard: give `wrap bench` a new -o");
    }
    const auto d = Differences(id, old->shards.front().id, true);
    if (!d.empty()) {
      std::string why;
      for (const std::string& s : d) why += (why.empty() ? "" : "; ") + s;
      return Fail(ErrorCode::kInvalidInput,
                  out_.string() + ": holds " + old->shards.front().id.Describe() +
                      " run otherwise than this call (" + why +
                      ", 'here' being this call): resume it with its own settings, or give "
                      "another -o");
    }
    meta_ = *old;
  } else if (fs::exists(out_ / "runs") && !fs::is_empty(out_ / "runs", ec)) {
    return Fail(ErrorCode::kInvalidInput,
                out_.string() +
                    ": has runs but no meta.json (an older `wrap bench`'s folder?): "
                    "give another -o");
  } else {
    meta_.shards = {ShardRecord{id, {}, 0}};
  }
  meta_.kind = "shard";
  meta_.shards.front().sessions.push_back(StartSession(options_.jobs));
  meta_.shards.front().sessions.back().unlocked = !lock_->held();

  for (const char* sub : {"runs", "plans", "logs", "sims", "projects"}) {
    fs::create_directories(out_ / sub, ec);
    if (ec) {
      return Fail(ErrorCode::kIo,
                  (out_ / sub).string() + ": cannot create folder: " + ec.message());
    }
  }
  // Temporary files of a write that a killed process left behind (never a result).
  for (const auto& e : fs::directory_iterator(out_ / "runs", ec)) {
    if (e.path().filename().string().starts_with(".")) fs::remove(e.path(), ec);
  }
  for (const RunSpec& spec : ShardSlice(all_specs, options_.shard_index, options_.shard_count)) {
    Job job;
    job.spec = spec;
    job.key = spec.Key();
    job.project_file = ProjectFile(spec, options_, out_);
    job.result.spec = spec;
    jobs_.push_back(std::move(job));
  }
  // Projects first: the examples must exist, the derived ones are written here.
  std::set<std::string> written;
  for (const Job& job : jobs_) {
    const ProjectSpec& p = job.spec.project;
    if (p.robots == 0 && p.steps == 0) {
      if (!fs::exists(job.project_file)) {
        return Fail(ErrorCode::kInvalidInput,
                    job.project_file.string() +
                        ": project file not found (set --projects to the folder of the example "
                        "projects)");
      }
      continue;
    }
    if (!written.insert(p.name).second) continue;
    const fs::path base = options_.projects_dir / (p.base + ".json");
    if (auto w = WriteDerivedProject(p, base, job.project_file); !w) {
      return std::unexpected(w.error());
    }
  }
  if (auto w = WriteFolderMeta(out_, meta_); !w) return w;

  progress_.total = static_cast<int>(jobs_.size());
  slots_ = CoreSlots(options_.jobs);
  slot_used_.assign(slots_.size(), false);
  // Runs finished by an earlier, interrupted call are kept (those made on a loaded machine run
  // again when asked to).
  for (size_t i = 0; i < jobs_.size(); ++i) {
    const fs::path file = out_ / "runs" / (jobs_[i].key + ".json");
    if (fs::exists(file)) {
      auto text = ReadFile(file);
      auto r = text ? RunResultFromJson(*text, file.string()) : Result<RunResult>();
      if (text && r && !(options_.rerun_loaded && r->loaded())) {
        results_.push_back(*r);
        Report(*r, false);
        continue;
      }
    }
    queue_.push_back(i);
  }
  std::reverse(queue_.begin(), queue_.end());
  return {};
}

void SuiteRunner::Report(const RunResult& r, bool fresh) {
  ++progress_.done;
  if (fresh) ++fresh_done_;
  ++progress_.counts[ToString(r.status)];
  progress_.elapsed_s = std::chrono::duration<double>(Clock::now() - t0_).count();
  const int left = progress_.total - progress_.done;
  progress_.eta_s = fresh_done_ > 0 ? progress_.elapsed_s / fresh_done_ * left : -1.0;
  progress_.last = (fresh ? "" : "(reused) ") + Describe(r);
  if (options_.on_progress) options_.on_progress(progress_);
}

std::vector<std::string> SuiteRunner::PlanArgv(const Job& job) const {
  return PlanArguments(job.spec, options_, exe_, job.project_file,
                       out_ / "plans" / (job.key + ".json"));
}

bool SuiteRunner::Start(Job& job) {
  std::error_code ec;
  const fs::path log = out_ / "logs" / (job.key + ".log");
  std::vector<std::string> argv;
  if (!job.sim_phase) {
    fs::remove(log, ec);
    argv = PlanArgv(job);
  } else {
    argv = {exe_.string(),
            "sim",
            job.project_file.string(),
            "--plan",
            (out_ / "plans" / (job.key + ".json")).string(),
            "-o",
            (out_ / "sims" / (job.key + ".json")).string()};
  }
  {
    std::ofstream l(log, std::ios::app);
    for (const std::string& a : argv) l << a << " ";
    l << "\n";
  }
  if (job.slot < 0) {
    for (size_t s = 0; s < slot_used_.size(); ++s) {
      if (!slot_used_[s]) {
        job.slot = static_cast<int>(s);
        slot_used_[s] = true;
        break;
      }
    }
  }
  job.child = Child{};
  job.child.start = Clock::now();
  // Simulating a plan takes longer than planning it on a slow machine (MuJoCo steps through
  // the whole makespan): the sim child gets four times the plan's limit.
  const double limit_s = HardLimit(job.spec) * (job.sim_phase ? 4.0 : 1.0);
  job.child.deadline =
      job.child.start + std::chrono::milliseconds(static_cast<long long>(1000 * limit_s));
  static const std::vector<int> kAnyCpu;
  job.child.pid =
      Spawn(argv, log, 4 * options_.memory_limit_mib, job.slot >= 0 ? slots_[job.slot] : kAnyCpu);
  return job.child.pid > 0;
}

void SuiteRunner::ClassifyPlan(Job& job, int wstatus, const rusage& ru, double wall) {
  RunResult& r = job.result;
  const fs::path log = out_ / "logs" / (job.key + ".log");
  r.wall_s = wall;
  r.peak_rss_mib = static_cast<double>(ru.ru_maxrss) / 1024.0;
  r.cpu_s = CpuSeconds(ru);
  const PlanOutcome plan = ReadPlanFile(r, out_ / "plans" / (job.key + ".json"));
  if (job.child.term_sent) {
    r.status = Status::kTimeout;
    r.signal = WIFSIGNALED(wstatus) ? WTERMSIG(wstatus) : 0;
    r.exit_code = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
    r.message = "killed by the harness after " + Num(std::round(wall * 10) / 10) +
                " s (hard limit " + Num(HardLimit(job.spec)) + " s)";
  } else if (WIFSIGNALED(wstatus)) {
    r.signal = WTERMSIG(wstatus);
    r.exit_code = -1;
    r.status = r.signal == SIGKILL ? Status::kOutOfMemory : Status::kCrash;
    r.message = std::string("signal ") + std::to_string(r.signal) + " (" + strsignal(r.signal) +
                ")" + (r.signal == SIGKILL ? ", likely the OOM killer" : "");
  } else {
    r.exit_code = WEXITSTATUS(wstatus);
    switch (r.exit_code) {
      case 0:
        r.status = Status::kSolved;
        break;
      case 1:
        r.status =
            plan.out_of_memory ? Status::kOutOfMemory
            : plan.failure.starts_with("time limit") || LogMentions(log, "time limit ran out")
                ? Status::kTimeout
                : Status::kUnsolved;
        r.message = plan.failure.empty() ? LastLine(log) : plan.failure;
        break;
      case 2:
        r.status = Status::kError;
        r.message = LastLine(log);
        break;
      default:
        r.status = LogMentions(log, "bad_alloc") || LogMentions(log, "out of memory")
                       ? Status::kOutOfMemory
                       : Status::kCrash;
        r.message = "exit " + std::to_string(r.exit_code) + ": " + LastLine(log);
    }
  }
  r.message = WithinOutput(r.message, out_);
  if (r.message.size() > 400) r.message = r.message.substr(0, 400) + "...";
  const Session& session = meta_.shards.front().sessions.back();
  r.cores = session.cores;
  r.host = session.host;
  const double now = RunnableThreads();
  r.load = job.load_samples > 0 ? job.load_sum / job.load_samples : now;
}

// Classifies a finished child; returns true when the job is complete.
bool SuiteRunner::Finish(Job& job, int wstatus, const rusage& ru) {
  RunResult& r = job.result;
  const double wall = std::chrono::duration<double>(Clock::now() - job.child.start).count();
  if (job.sim_phase) {
    const fs::path log = out_ / "logs" / (job.key + ".log");
    r.sim_wall_s = wall;
    r.cpu_s += CpuSeconds(ru);
    if (job.child.term_sent) {
      r.sim_success = false;
      r.sim_failure = "sim killed at the hard limit";
    } else if (WIFSIGNALED(wstatus) || (WIFEXITED(wstatus) && WEXITSTATUS(wstatus) >= 2)) {
      r.sim_success = false;
      r.sim_failure = "sim error: " + WithinOutput(LastLine(log), out_);
    } else {
      ReadSimReport(r, out_ / "sims" / (job.key + ".json"));
    }
    return true;
  }
  ClassifyPlan(job, wstatus, ru, wall);
  if (r.solved() && job.spec.sim && job.spec.motion) {
    job.sim_phase = true;
    return false;
  }
  if (job.spec.sim && !r.solved()) {
    r.sim_success = false;
    r.sim_failure = "no plan";
  }
  return true;
}

// A complete job: its result file (atomic), then the progress.
void SuiteRunner::Record(Job& job) {
  std::error_code ec;
  if (job.slot >= 0) slot_used_[job.slot] = false;
  job.slot = -1;
  if (!options_.keep_plans) fs::remove(out_ / "plans" / (job.key + ".json"), ec);
  const fs::path file = out_ / "runs" / (job.key + ".json");
  if (auto w = WriteFileAtomic(file, RunResultToJson(job.result)); !w) write_error_ = w;
  results_.erase(std::remove_if(results_.begin(), results_.end(),
                                [&](const RunResult& r) { return r.spec.Key() == job.key; }),
                 results_.end());
  results_.push_back(job.result);
  Report(job.result, true);
}

Result<void> SuiteRunner::Close(bool finished) {
  ShardRecord& record = meta_.shards.front();
  record.runs_done = static_cast<int>(results_.size());
  EndSession(record.sessions.back(), record.runs_done);
  meta_.info = ReportInfo(meta_.shards);
  if (auto w = WriteFolderMeta(out_, meta_); !w) return w;
  if (!finished) return {};
  SortResults(results_);
  return WriteReport(results_, meta_.info, out_);
}

Result<std::vector<RunResult>> SuiteRunner::Run() {
  const auto old_int = std::signal(SIGINT, OnInterrupt);
  const auto old_term = std::signal(SIGTERM, OnInterrupt);
  g_interrupted = 0;
  std::vector<size_t> running;
  Clock::time_point next_sample = Clock::now();
  while (!queue_.empty() || !running.empty()) {
    if (g_interrupted) {
      for (size_t i : running) {
        if (jobs_[i].child.pid <= 0) continue;  // already reaped
        kill(-jobs_[i].child.pid, SIGKILL);
        waitpid(jobs_[i].child.pid, nullptr, 0);
      }
      std::signal(SIGINT, old_int);
      std::signal(SIGTERM, old_term);
      if (auto c = Close(false); !c) return std::unexpected(c.error());
      return Fail(ErrorCode::kCancelled, "interrupted: " + std::to_string(progress_.done) + " of " +
                                             std::to_string(progress_.total) + " runs are in " +
                                             (out_ / "runs").string() + "; run again to resume");
    }
    while (static_cast<int>(running.size()) < options_.jobs && !queue_.empty()) {
      const size_t i = queue_.back();
      queue_.pop_back();
      if (!Start(jobs_[i])) {
        jobs_[i].result.status = Status::kCrash;
        jobs_[i].result.message = "fork failed: " + std::string(std::strerror(errno));
        Record(jobs_[i]);
        continue;
      }
      running.push_back(i);
    }
    progress_.running = static_cast<int>(running.size());
    // How busy the machine is while plans run (every 0.1 s).
    if (Clock::now() >= next_sample) {
      next_sample = Clock::now() + std::chrono::milliseconds(100);
      if (const double n = RunnableThreads(); n >= 0.0) {
        for (size_t i : running) {
          if (jobs_[i].sim_phase) continue;
          jobs_[i].load_sum += n;
          ++jobs_[i].load_samples;
        }
      }
    }
    std::vector<size_t> still;
    for (size_t i : running) {
      Job& job = jobs_[i];
      int wstatus = 0;
      rusage ru{};
      if (wait4(job.child.pid, &wstatus, WNOHANG, &ru) == job.child.pid) {
        // The process group may hold grandchildren (none today); end them with it.
        kill(-job.child.pid, SIGKILL);
        // A child stopped by SIGTERM or SIGINT that the harness did not send was stopped with
        // it (scancel signals every process of the job; Ctrl-C the whole process group): the
        // run did not end, so it is not recorded, and the suite stops to be resumed.
        const bool stopped_from_outside =
            WIFSIGNALED(wstatus) && !job.child.term_sent &&
            (WTERMSIG(wstatus) == SIGTERM || WTERMSIG(wstatus) == SIGINT);
        if (g_interrupted || stopped_from_outside) {
          g_interrupted = 1;
          job.child.pid = -1;
          continue;
        }
        if (!Finish(job, wstatus, ru)) {
          if (Start(job)) {
            still.push_back(i);
            continue;
          }
          job.result.sim_success = false;
          job.result.sim_failure = "sim could not start";
        }
        Record(job);
        continue;
      }
      const Clock::time_point now = Clock::now();
      if (!job.child.term_sent && now > job.child.deadline) {
        kill(-job.child.pid, SIGTERM);
        job.child.term_sent = true;
      } else if (job.child.term_sent && !job.child.kill_sent &&
                 now > job.child.deadline + std::chrono::seconds(2)) {
        kill(-job.child.pid, SIGKILL);
        job.child.kill_sent = true;
      }
      still.push_back(i);
    }
    running = std::move(still);
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  std::signal(SIGINT, old_int);
  std::signal(SIGTERM, old_term);
  if (!write_error_) return std::unexpected(write_error_.error());
  if (auto c = Close(true); !c) return std::unexpected(c.error());
  return results_;
}

}  // namespace

std::vector<RunSpec> ShardSlice(const std::vector<RunSpec>& specs, int shard_index,
                                int shard_count) {
  std::vector<RunSpec> slice;
  for (size_t i = 0; i < specs.size(); ++i) {
    if (static_cast<int>(i % shard_count) == shard_index - 1) slice.push_back(specs[i]);
  }
  return slice;
}

std::vector<std::string> PlanArguments(const RunSpec& spec, const BenchOptions& options,
                                       const fs::path& exe, const fs::path& project_file,
                                       const fs::path& plan_file) {
  std::vector<std::string> a = {exe.string(),
                                "plan",
                                project_file.string(),
                                "--planner",
                                spec.planner,
                                "--seed",
                                std::to_string(spec.seed),
                                "--time-limit",
                                Num(spec.time_limit_s),
                                "--wrench",
                                spec.wrench,
                                "--force-scale",
                                Num(spec.force_scale),
                                "--memory-limit",
                                std::to_string(options.memory_limit_mib),
                                "-o",
                                plan_file.string()};
  if (spec.optimize) a.push_back("--optimize");
  // The planner's own default when not given: the command lines of earlier suites stay as they
  // were.
  if (spec.objective != "actions") {
    a.push_back("--objective");
    a.push_back(spec.objective);
  }
  if (!spec.motion) a.push_back("--task-only");
  return a;
}

double LongestRunS(const RunSpec& spec, const BenchOptions& options) {
  const double plan = PlanHardLimitS(spec, options);
  return spec.sim ? 5.0 * plan : plan;
}

Result<std::vector<RunResult>> RunSuite(const std::vector<RunSpec>& all_specs,
                                        const BenchOptions& given, const fs::path& out) {
  BenchOptions options = given;
  if (options.jobs <= 0) options.jobs = std::max(1u, std::thread::hardware_concurrency());
  if (options.shard_count < 1 || options.shard_index < 1 ||
      options.shard_index > options.shard_count) {
    return Fail(ErrorCode::kInvalidInput, "--shard: expected I/N with 1 <= I <= N");
  }
  fs::path exe = options.wrap_exe;
  if (exe.empty()) {
    std::error_code ec;
    exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return Fail(ErrorCode::kInternal, "bench: cannot find this executable");
  }
  SuiteRunner runner(options, out, fs::absolute(exe));
  if (auto p = runner.Prepare(all_specs); !p) return std::unexpected(p.error());
  return runner.Run();
}

}  // namespace wrap::bench
