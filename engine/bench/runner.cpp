// Runs a suite: every run a child `wrap plan` (and `wrap sim`) process under a wall-clock and an
// address-space limit, up to `jobs` at once; timeouts, out-of-memory and crashes become results.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "bench/bench.h"
#include "core/file_io.h"

namespace wrap::bench {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_interrupted = 0;
void OnInterrupt(int) { g_interrupted = 1; }

const std::vector<std::string> kStats = {
    "cost",   "first_cost", "t_init_s", "t_grasp_s",  "t_bwd_s", "t_lp_s",    "t_fwd_s",
    "t_ik_s", "t_kf_s",     "t_mp_s",   "t_retime_s", "t_opt_s", "makespan_s"};

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// The last non-empty line of a log file (at most 300 characters).
std::string LastLine(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  if (last.size() > 300) last = last.substr(0, 300) + "...";
  return last;
}

bool LogMentions(const fs::path& log, const std::string& what) {
  std::ifstream in(log);
  std::stringstream s;
  s << in.rdbuf();
  return s.str().find(what) != std::string::npos;
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

// One child process: the command, its limits and where it writes.
struct Child {
  pid_t pid = -1;
  Clock::time_point start;
  Clock::time_point deadline;
  bool term_sent = false;
  bool kill_sent = false;
};

// Starts `argv` in its own process group with stdout and stderr appended to `log`, its address
// space limited to `as_mib`. Returns the pid, or -1 (errno) when fork failed.
pid_t Spawn(const std::vector<std::string>& argv, const fs::path& log, long long as_mib) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  // Child: only async-signal-safe calls until exec.
  setpgid(0, 0);
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

// A job: one run, in the plan phase and then, if asked, the sim phase.
struct Job {
  RunSpec spec;
  std::string key;
  fs::path project_file;
  RunResult result;
  Child child;
  bool sim_phase = false;
};

fs::path ProjectFile(const RunSpec& spec, const BenchOptions& options, const fs::path& out) {
  if (spec.project.robots == 0 && spec.project.steps == 0) {
    return options.projects_dir / (spec.project.base + ".json");
  }
  return out / "projects" / (spec.project.name + ".json");
}

std::vector<std::string> PlanArgv(const Job& job, const fs::path& exe, const fs::path& out,
                                  const BenchOptions& options) {
  const RunSpec& s = job.spec;
  std::vector<std::string> a = {exe.string(),
                                "plan",
                                job.project_file.string(),
                                "--planner",
                                s.planner,
                                "--seed",
                                std::to_string(s.seed),
                                "--time-limit",
                                Num(s.time_limit_s),
                                "--wrench",
                                s.wrench,
                                "--force-scale",
                                Num(s.force_scale),
                                "--memory-limit",
                                std::to_string(options.memory_limit_mib),
                                "-o",
                                (out / "plans" / (job.key + ".json")).string()};
  if (s.optimize) a.push_back("--optimize");
  if (!s.motion) a.push_back("--task-only");
  return a;
}

// Fills the result from the plan file the child wrote (if any).
void ReadPlanStats(RunResult& r, const fs::path& plan_file, std::string& failure,
                   bool& out_of_memory) {
  auto text = ReadFile(plan_file);
  if (!text) return;
  const Json j = Json::parse(*text, nullptr, false);
  if (j.is_discarded() || !j.contains("stats") || !j["stats"].is_object()) return;
  const Json& st = j["stats"];
  const bool solved = st.value("solved", false);
  for (const std::string& k : kStats) {
    if (!st.contains(k) || !st[k].is_number()) continue;
    // Cost and its history mean nothing without a plan; the times do.
    if (!solved && (k == "cost" || k == "first_cost" || k == "makespan_s")) continue;
    // Motion times where motion was tried (also when it failed), none for a task-only plan.
    const bool motion_stat = k == "t_kf_s" || k == "t_mp_s" || k == "t_retime_s";
    if (motion_stat && !st.value("motion", false) && st[k].get<double>() == 0.0) continue;
    if (k == "makespan_s" && !st.value("motion", false)) continue;
    r.stats[k] = st[k].get<double>();
  }
  if (solved && st.contains("cost_history") && st["cost_history"].is_array()) {
    for (const Json& h : st["cost_history"]) {
      if (h.is_array() && h.size() == 2) {
        r.cost_history.emplace_back(h[0].get<double>(), h[1].get<double>());
      }
    }
  }
  failure = st.value("failure", "");
  out_of_memory = st.value("out_of_memory", false);
}

void ReadSimReport(RunResult& r, const fs::path& file) {
  auto text = ReadFile(file);
  const Json j = text ? Json::parse(*text, nullptr, false) : Json();
  if (!text || j.is_discarded() || !j.is_object() || !j.contains("success")) {
    r.sim_success = false;
    r.sim_failure = "no sim report";
    return;
  }
  r.sim_success = j.value("success", false);
  r.sim_tasks_completed = j.value("tasks_completed", 0);
  r.sim_tasks_total = j.value("tasks_total", 0);
  if (j.contains("failure") && j["failure"].is_object()) {
    r.sim_failure = j["failure"].value("reason", "failed");
  }
  if (j.contains("peak_utilisation_percent")) {
    const Json& u = j["peak_utilisation_percent"];
    const auto get = [&](const char* phase, const char* kind, const char* name) {
      if (u.contains(phase) && u[phase].contains(kind) && u[phase][kind].is_number()) {
        r.sim_util[name] = u[phase][kind].get<double>();
      }
    };
    get("transport", "two_finger", "transport_2f");
    get("transport", "vacuum", "transport_vac");
    get("insertion", "two_finger", "insertion_2f");
    get("insertion", "vacuum", "insertion_vac");
  }
}

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
  return s;
}

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

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  in >> a >> b >> c;
  return Num(a) + " " + Num(b) + " " + Num(c);
}

// Machine, commit and date of this run, and the settings of the suite.
RunInfo CollectInfo(const BenchOptions& options, size_t runs) {
  RunInfo info;
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
  info.machine = model + ", " + std::to_string(std::thread::hardware_concurrency()) + " cores, " +
                 Num(std::round(kib / 1048576.0)) + " GiB";
  const std::string host_os = CommandOutput("uname -sr 2>/dev/null");
  if (!host_os.empty()) info.machine += ", " + host_os;
  info.load = "at the start " + LoadAverage();
  const fs::path src = fs::absolute(options.projects_dir).parent_path();
  const std::string q = "'" + src.string() + "'";
  info.commit = CommandOutput("git -C " + q + " rev-parse --short HEAD 2>/dev/null");
  if (info.commit.empty()) {
    info.commit = "unknown";
  } else if (!CommandOutput("git -C " + q +
                            " status --porcelain --untracked-files=no -- engine app 2>/dev/null")
                  .empty()) {
    info.commit += " (with local changes)";
  }
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  info.date = date;
  info.settings = "suite " + options.suite + ", " + std::to_string(options.runs) +
                  " seed(s) per configuration, " + std::to_string(runs) + " runs, time limit " +
                  (options.time_limit_s ? Num(*options.time_limit_s) + " s"
                                        : std::string("the suite's default")) +
                  ", " + std::to_string(options.jobs) + " job(s) at once, shard " +
                  std::to_string(options.shard_index) + "/" + std::to_string(options.shard_count) +
                  ", planner memory limit " + std::to_string(options.memory_limit_mib) + " MiB";
  return info;
}

Json InfoToJson(const RunInfo& i) {
  return {{"machine", i.machine},
          {"load", i.load},
          {"commit", i.commit},
          {"date", i.date},
          {"settings", i.settings}};
}

RunInfo InfoFromJson(const Json& j) {
  RunInfo i;
  i.machine = j.value("machine", "");
  i.load = j.value("load", "");
  i.commit = j.value("commit", "");
  i.date = j.value("date", "");
  i.settings = j.value("settings", "");
  return i;
}

}  // namespace

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
  exe = fs::absolute(exe);
  std::error_code ec;
  for (const char* sub : {"runs", "plans", "logs", "sims", "projects"}) {
    fs::create_directories(out / sub, ec);
    if (ec) {
      return Fail(ErrorCode::kIo, (out / sub).string() + ": cannot create folder: " + ec.message());
    }
  }

  // This shard's slice: every shard_count-th configuration, so shards get a mix of sizes.
  std::vector<Job> jobs;
  for (size_t i = 0; i < all_specs.size(); ++i) {
    if (static_cast<int>(i % options.shard_count) != options.shard_index - 1) continue;
    Job job;
    job.spec = all_specs[i];
    job.key = job.spec.Key();
    job.project_file = ProjectFile(job.spec, options, out);
    job.result.spec = job.spec;
    jobs.push_back(std::move(job));
  }
  // Projects first: the examples must exist, the derived ones are written here.
  std::set<std::string> written;
  for (const Job& job : jobs) {
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
    const fs::path base = options.projects_dir / (p.base + ".json");
    if (auto w = WriteDerivedProject(p, base, job.project_file); !w) {
      return std::unexpected(w.error());
    }
  }

  RunInfo info = CollectInfo(options, jobs.size());
  if (auto w = WriteFileAtomic(out / "meta.json", InfoToJson(info).dump(2) + "\n"); !w) {
    return std::unexpected(w.error());
  }

  const auto old_int = std::signal(SIGINT, OnInterrupt);
  const auto old_term = std::signal(SIGTERM, OnInterrupt);
  g_interrupted = 0;

  Progress progress;
  progress.total = static_cast<int>(jobs.size());
  const Clock::time_point t0 = Clock::now();
  int fresh_done = 0;
  std::vector<RunResult> results;
  const auto report = [&](const RunResult& r, bool fresh) {
    ++progress.done;
    if (fresh) ++fresh_done;
    ++progress.counts[ToString(r.status)];
    progress.elapsed_s = std::chrono::duration<double>(Clock::now() - t0).count();
    const int left = progress.total - progress.done;
    progress.eta_s = fresh_done > 0 ? progress.elapsed_s / fresh_done * left : -1.0;
    progress.last = (fresh ? "" : "(reused) ") + Describe(r);
    if (options.on_progress) options.on_progress(progress);
  };

  // Runs finished by an earlier, interrupted call are kept.
  std::vector<size_t> queue;
  for (size_t i = 0; i < jobs.size(); ++i) {
    const fs::path file = out / "runs" / (jobs[i].key + ".json");
    if (fs::exists(file)) {
      auto text = ReadFile(file);
      auto r = text ? RunResultFromJson(*text, file.string()) : Result<RunResult>();
      if (text && r) {
        results.push_back(*r);
        report(*r, false);
        continue;
      }
    }
    queue.push_back(i);
  }
  std::reverse(queue.begin(), queue.end());

  const double hard_limit_fallback = options.hard_limit_s;
  const auto limit_for = [&](const RunSpec& s) {
    if (hard_limit_fallback > 0.0) return hard_limit_fallback;
    return s.time_limit_s + std::max(10.0, 0.5 * s.time_limit_s);
  };
  const long long as_mib = 4 * options.memory_limit_mib;

  const auto start = [&](Job& job) -> bool {
    const fs::path log = out / "logs" / (job.key + ".log");
    std::vector<std::string> argv;
    if (!job.sim_phase) {
      fs::remove(log, ec);
      argv = PlanArgv(job, exe, out, options);
    } else {
      argv = {exe.string(),
              "sim",
              job.project_file.string(),
              "--plan",
              (out / "plans" / (job.key + ".json")).string(),
              "-o",
              (out / "sims" / (job.key + ".json")).string()};
    }
    {
      std::ofstream l(log, std::ios::app);
      for (const std::string& a : argv) l << a << " ";
      l << "\n";
    }
    job.child = Child{};
    job.child.start = Clock::now();
    // Simulating a plan takes longer than planning it on a slow machine (MuJoCo steps through
    // the whole makespan): the sim child gets four times the plan's limit.
    const double limit_s = limit_for(job.spec) * (job.sim_phase ? 4.0 : 1.0);
    job.child.deadline =
        job.child.start + std::chrono::milliseconds(static_cast<long long>(1000 * limit_s));
    job.child.pid = Spawn(argv, log, as_mib);
    return job.child.pid > 0;
  };

  // Classifies a finished child; returns true when the job is complete.
  const auto finish = [&](Job& job, int wstatus, const rusage& ru) -> bool {
    RunResult& r = job.result;
    const fs::path log = out / "logs" / (job.key + ".log");
    const fs::path plan_file = out / "plans" / (job.key + ".json");
    const double wall = std::chrono::duration<double>(Clock::now() - job.child.start).count();
    const bool killed = job.child.term_sent;
    if (job.sim_phase) {
      if (killed) {
        r.sim_success = false;
        r.sim_failure = "sim killed at the hard limit";
      } else if (WIFSIGNALED(wstatus) || (WIFEXITED(wstatus) && WEXITSTATUS(wstatus) >= 2)) {
        r.sim_success = false;
        r.sim_failure = "sim error: " + WithinOutput(LastLine(log), out);
      } else {
        ReadSimReport(r, out / "sims" / (job.key + ".json"));
      }
      return true;
    }
    r.wall_s = wall;
    r.peak_rss_mib = static_cast<double>(ru.ru_maxrss) / 1024.0;
    std::string failure;
    bool oom = false;
    ReadPlanStats(r, plan_file, failure, oom);
    if (killed) {
      r.status = Status::kTimeout;
      r.signal = WIFSIGNALED(wstatus) ? WTERMSIG(wstatus) : 0;
      r.exit_code = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
      r.message = "killed by the harness after " + Num(std::round(wall * 10) / 10) +
                  " s (hard limit " + Num(limit_for(job.spec)) + " s)";
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
          r.status = oom ? Status::kOutOfMemory
                     : failure.starts_with("time limit") || LogMentions(log, "time limit ran out")
                         ? Status::kTimeout
                         : Status::kUnsolved;
          r.message = failure.empty() ? LastLine(log) : failure;
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
    r.message = WithinOutput(r.message, out);
    if (r.message.size() > 400) r.message = r.message.substr(0, 400) + "...";
    if (r.solved() && job.spec.sim && job.spec.motion) {
      job.sim_phase = true;
      return false;
    }
    if (job.spec.sim && !r.solved()) {
      r.sim_success = false;
      r.sim_failure = "no plan";
    }
    return true;
  };

  std::vector<size_t> running;
  Result<void> write_error;
  while ((!queue.empty() || !running.empty())) {
    if (g_interrupted) {
      for (size_t i : running) kill(-jobs[i].child.pid, SIGKILL);
      for (size_t i : running) waitpid(jobs[i].child.pid, nullptr, 0);
      std::signal(SIGINT, old_int);
      std::signal(SIGTERM, old_term);
      return Fail(ErrorCode::kCancelled, "interrupted: " + std::to_string(progress.done) + " of " +
                                             std::to_string(progress.total) + " runs are in " +
                                             (out / "runs").string() + "; run again to resume");
    }
    while (static_cast<int>(running.size()) < options.jobs && !queue.empty()) {
      const size_t i = queue.back();
      queue.pop_back();
      if (!start(jobs[i])) {
        jobs[i].result.status = Status::kCrash;
        jobs[i].result.message = "fork failed: " + std::string(std::strerror(errno));
        results.push_back(jobs[i].result);
        report(jobs[i].result, true);
        continue;
      }
      running.push_back(i);
    }
    progress.running = static_cast<int>(running.size());
    std::vector<size_t> still;
    for (size_t i : running) {
      Job& job = jobs[i];
      int wstatus = 0;
      rusage ru{};
      const pid_t w = wait4(job.child.pid, &wstatus, WNOHANG, &ru);
      if (w == job.child.pid) {
        // The process group may hold grandchildren (none today); end them with it.
        kill(-job.child.pid, SIGKILL);
        if (!finish(job, wstatus, ru)) {
          if (start(job)) {
            still.push_back(i);
            continue;
          }
          job.result.sim_success = false;
          job.result.sim_failure = "sim could not start";
        }
        if (!options.keep_plans) fs::remove(out / "plans" / (job.key + ".json"), ec);
        const fs::path file = out / "runs" / (job.key + ".json");
        if (auto wr = WriteFileAtomic(file, RunResultToJson(job.result)); !wr) write_error = wr;
        results.push_back(job.result);
        report(job.result, true);
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
  if (!write_error) return std::unexpected(write_error.error());

  info.load += ", at the end " + LoadAverage();
  if (auto w = WriteFileAtomic(out / "meta.json", InfoToJson(info).dump(2) + "\n"); !w) {
    return std::unexpected(w.error());
  }
  SortResults(results);
  if (auto w = WriteReport(results, info, out); !w) return std::unexpected(w.error());
  return results;
}

Result<std::vector<RunResult>> MergeShards(const std::vector<fs::path>& dirs, const fs::path& out) {
  if (dirs.empty()) return Fail(ErrorCode::kInvalidInput, "merge: no shard folders given");
  auto results = ReadRunResults(dirs);
  if (!results) return results;
  std::error_code ec;
  fs::create_directories(out / "runs", ec);
  if (ec) return Fail(ErrorCode::kIo, (out / "runs").string() + ": " + ec.message());
  for (const RunResult& r : *results) {
    if (auto w = WriteFileAtomic(out / "runs" / (r.spec.Key() + ".json"), RunResultToJson(r)); !w) {
      return std::unexpected(w.error());
    }
  }
  // The report names every folder's machine, commit, date, load and settings.
  RunInfo info;
  std::set<std::string> machines, commits, dates;
  std::string loads, settings;
  for (const fs::path& d : dirs) {
    auto text = ReadFile(d / "meta.json");
    if (!text) continue;
    const Json j = Json::parse(*text, nullptr, false);
    if (j.is_discarded() || !j.is_object()) continue;
    const RunInfo i = InfoFromJson(j);
    const std::string name = fs::absolute(d).lexically_normal().filename().string();
    machines.insert(i.machine);
    commits.insert(i.commit);
    dates.insert(i.date);
    loads += (loads.empty() ? "" : "; ") + name + ": " + i.load;
    settings += (settings.empty() ? "" : "; ") + name + ": " + i.settings;
  }
  const auto join = [](const std::set<std::string>& s) {
    std::string r;
    for (const std::string& x : s) r += (r.empty() ? "" : "; ") + x;
    return r.empty() ? std::string("unknown") : r;
  };
  info.machine = join(machines);
  info.commit = join(commits);
  info.date = dates.empty() ? "unknown"
              : dates.size() == 1
                  ? *dates.begin()
                  : *dates.begin() + " to " + *dates.rbegin() + " (the folders' starts)";
  info.load = loads.empty() ? "unknown" : loads;
  info.settings = "merged from " + std::to_string(dirs.size()) + " folder(s): " + settings;
  if (auto w = WriteFileAtomic(out / "meta.json", InfoToJson(info).dump(2) + "\n"); !w) {
    return std::unexpected(w.error());
  }
  if (auto w = WriteReport(*results, info, out); !w) return std::unexpected(w.error());
  return results;
}

}  // namespace wrap::bench
