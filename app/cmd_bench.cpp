// `wrap bench`: runs a benchmark suite in child processes and writes the report (engine/bench).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <thread>

#include "bench/bench.h"
#include "cli.h"

namespace wrap::cli {

namespace {

int Report(const Error& e, std::ostream& err) {
  err << "wrap bench: " << e.message << "\n";
  return ExitCodeFor(e.code);
}

std::string Duration(double s) {
  if (s < 0) return "?";
  char buf[32];
  const long long t = static_cast<long long>(s + 0.5);
  if (t >= 3600) {
    std::snprintf(buf, sizeof buf, "%lldh%02lldm", t / 3600, t / 60 % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lldm%02llds", t / 60, t % 60);
  }
  return buf;
}

// A progress bar redrawn in place on a terminal; one line per finished run otherwise (logs).
void PrintProgress(const bench::Progress& p, std::ostream& err, bool tty) {
  const int width = 30;
  const int filled = p.total > 0 ? width * p.done / p.total : width;
  std::string counts;
  for (const auto& [k, n] : p.counts) counts += " " + k + " " + std::to_string(n);
  const std::string status = "[" + std::string(filled, '#') + std::string(width - filled, '.') +
                             "] " + std::to_string(p.done) + "/" + std::to_string(p.total) + " " +
                             counts + ", elapsed " + Duration(p.elapsed_s) + ", left ~" +
                             Duration(p.eta_s);
  if (tty) {
    err << "\r\033[K" << p.last << "\n" << status << std::flush;
    if (p.done == p.total) err << "\n";
  } else {
    err << "[" << p.done << "/" << p.total << "] " << p.last << " (left ~" << Duration(p.eta_s)
        << ")\n";
  }
}

void Summarise(const std::vector<bench::RunResult>& results, const std::string& dir,
               std::ostream& out) {
  int solved = 0;
  for (const bench::RunResult& r : results) solved += r.solved() ? 1 : 0;
  out << results.size() << " runs, " << solved << " solved; wrote " << dir << "/results.csv, "
      << dir << "/report.md and " << dir << "/report.html\n";
}

// --dry-run: this shard's runs, and the longest they can take (every run at its hard limit).
int DryRun(const std::vector<bench::RunSpec>& specs, const bench::BenchOptions& options,
           std::ostream& out) {
  const auto slice = bench::ShardSlice(specs, options.shard_index, options.shard_count);
  double longest = 0.0;
  for (const bench::RunSpec& s : slice) {
    const double t = bench::LongestRunS(s, options);
    longest += t;
    out << s.Key() << "  (at most " << Duration(t) << ")\n";
  }
  const int jobs = options.jobs > 0
                       ? options.jobs
                       : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  out << "Suite '" << options.suite << "': " << specs.size() << " runs; shard "
      << options.shard_index << "/" << options.shard_count << ": " << slice.size()
      << " runs, at most " << Duration(longest) << " of run time (every run at its hard limit; "
      << "a simulation at 4 times its plan's), so at most " << Duration(longest / jobs) << " ("
      << static_cast<long long>(std::ceil(longest / jobs)) << " s) at --jobs " << jobs << "\n";
  return 0;
}

}  // namespace

int Bench(const BenchArgs& args, std::ostream& out, std::ostream& err) {
  if (!args.merge_dirs.empty()) {
    if (args.output.empty())
      return Report({ErrorCode::kInvalidInput, "merge: -o OUT is required"}, err);
    std::vector<std::filesystem::path> dirs(args.merge_dirs.begin(), args.merge_dirs.end());
    auto merged = bench::MergeShards(dirs, args.output, args.partial);
    if (!merged) return Report(merged.error(), err);
    Summarise(*merged, args.output, out);
    return 0;
  }
  if (args.output.empty() && !args.dry_run) {
    return Report({ErrorCode::kInvalidInput, "-o DIR: the output folder is required"}, err);
  }
  bench::BenchOptions options;
  options.suite = args.suite;
  options.runs = args.runs;
  options.time_limit_s = args.time_limit_s;
  options.jobs = args.jobs;
  options.projects_dir = args.projects;
  options.hard_limit_s = args.hard_limit_s;
  options.memory_limit_mib = args.memory_limit_mib;
  options.keep_plans = args.keep_plans;
  options.rerun_loaded = args.rerun_loaded;
  if (!args.shard.empty()) {
    int i = 0, n = 0;
    char extra = 0;
    if (std::sscanf(args.shard.c_str(), "%d/%d%c", &i, &n, &extra) != 2 || n < 1 || i < 1 ||
        i > n) {
      return Report({ErrorCode::kInvalidInput,
                     "--shard: '" + args.shard + "' is not I/N with 1 <= I <= N (e.g. 2/8)"},
                    err);
    }
    options.shard_index = i;
    options.shard_count = n;
  }
  const bool tty = isatty(2) != 0;
  options.on_progress = [&](const bench::Progress& p) { PrintProgress(p, err, tty); };
  auto specs = bench::MakeSuite(options);
  if (!specs) return Report(specs.error(), err);
  if (args.dry_run) return DryRun(*specs, options, out);
  out << "Suite '" << options.suite << "': " << specs->size() << " runs";
  if (options.shard_count > 1)
    out << " (this shard: " << options.shard_index << "/" << options.shard_count << ")";
  out << "\n" << std::flush;
  auto results = bench::RunSuite(*specs, options, args.output);
  if (!results) return Report(results.error(), err);
  Summarise(*results, args.output, out);
  return 0;
}

}  // namespace wrap::cli
