// `wrap bench merge`: shard folders into one report, after checking that they belong together
// (one revision, one setting per suite, every shard once and finished); the report header's facts.
#include <algorithm>
#include <cstdlib>
#include <map>
#include <set>

#include "bench/bench.h"
#include "bench/shard.h"
#include "core/file_io.h"

namespace wrap::bench {

namespace {

namespace fs = std::filesystem;

std::string Join(const std::vector<std::string>& items, const std::string& sep) {
  std::string r;
  for (const std::string& s : items) r += (r.empty() ? "" : sep) + s;
  return r;
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// One shard record found in one of the folders given.
struct Entry {
  std::string dir;  // as given
  ShardRecord record;
};

// The problems that forbid merging `entries`, and the caveats of a partial merge.
struct Verdict {
  std::vector<std::string> problems;
  std::vector<std::string> gaps;  // missing or unfinished shards
};

Verdict Check(const std::vector<Entry>& entries) {
  Verdict v;
  // One revision.
  std::map<std::string, std::vector<std::string>> by_revision;
  for (const Entry& e : entries) by_revision[e.record.id.revision].push_back(e.dir);
  if (by_revision.size() > 1) {
    std::vector<std::string> parts;
    for (const auto& [rev, dirs] : by_revision) parts.push_back(Join(dirs, ", ") + ": " + rev);
    v.problems.push_back(
        "the folders come from different revisions of Wrap (" + Join(parts, "; ") +
        "): build every shard from one revision, or run the odd ones again into new folders");
  }
  // Per suite: one setting, every shard once, each finished.
  std::map<std::string, std::vector<const Entry*>> by_suite;
  for (const Entry& e : entries) by_suite[e.record.id.suite].push_back(&e);
  for (const auto& [suite, list] : by_suite) {
    const Entry& first = *list.front();
    bool consistent = true;
    for (const Entry* e : list) {
      auto d = Differences(e->record.id, first.record.id, false);
      std::erase_if(d, [](const std::string& s) { return s.starts_with("revision"); });
      if (d.empty()) continue;
      consistent = false;
      v.problems.push_back(e->dir + " (" + e->record.id.Describe() +
                           ") was run with other "
                           "settings than " +
                           first.dir + " (" + first.record.id.Describe() + "): " + Join(d, "; ") +
                           " (here: " + e->dir + ", there: " + first.dir + ")");
    }
    if (!consistent) continue;
    const int n = first.record.id.shard_count;
    std::map<int, std::vector<const Entry*>> by_index;
    for (const Entry* e : list) by_index[e->record.id.shard_index].push_back(e);
    for (int i = 1; i <= n; ++i) {
      const std::string what =
          "shard " + std::to_string(i) + "/" + std::to_string(n) + " of suite '" + suite + "'";
      const auto it = by_index.find(i);
      if (it == by_index.end()) {
        v.gaps.push_back(what + " is missing (no folder given holds it)");
        continue;
      }
      if (it->second.size() > 1) {
        std::vector<std::string> dirs;
        for (const Entry* e : it->second) dirs.push_back(e->dir);
        v.problems.push_back(what + " is in more than one folder (" + Join(dirs, ", ") +
                             "): give each shard once");
        continue;
      }
      const Entry& e = *it->second.front();
      if (e.record.runs_done < e.record.id.shard_runs) {
        v.gaps.push_back(e.dir + " (" + what + ") has " + std::to_string(e.record.runs_done) +
                         " of its " + std::to_string(e.record.id.shard_runs) +
                         " runs: it was interrupted; run it again with the same command and "
                         "folder to resume it");
      }
    }
  }
  return v;
}

// Many sessions (a cluster study) in one line: the range of the 1-minute load averages at the
// sessions' starts and ends.
std::string LoadRange(const std::vector<ShardRecord>& records) {
  double lo = 1e9, hi = -1.0, end_lo = 1e9, end_hi = -1.0;
  int sessions = 0, stopped = 0;
  std::set<std::string> hosts;
  for (const ShardRecord& r : records) {
    for (const Session& s : r.sessions) {
      ++sessions;
      hosts.insert(s.host);
      const double a = std::atof(s.load_start.c_str());
      lo = std::min(lo, a);
      hi = std::max(hi, a);
      if (s.end.empty()) {
        ++stopped;
        continue;
      }
      const double b = std::atof(s.load_end.c_str());
      end_lo = std::min(end_lo, b);
      end_hi = std::max(end_hi, b);
    }
  }
  std::string text = std::to_string(sessions) + " sessions on " + std::to_string(hosts.size()) +
                     " host(s), 1-minute load " + Num(lo) + " to " + Num(hi) + " at their starts";
  if (end_hi >= 0.0) text += ", " + Num(end_lo) + " to " + Num(end_hi) + " at their ends";
  if (stopped > 0) text += ", " + std::to_string(stopped) + " stopped before their end";
  return text + " (each session's in meta.json)";
}

}  // namespace

RunInfo ReportInfo(const std::vector<ShardRecord>& records) {
  RunInfo info;
  std::set<std::string> machines, revisions, starts, ends;
  std::vector<std::string> loads;
  std::map<std::string, std::vector<const ShardRecord*>> by_suite;
  for (const ShardRecord& r : records) {
    revisions.insert(r.id.revision);
    by_suite[r.id.suite].push_back(&r);
    for (const Session& s : r.sessions) {
      machines.insert(s.machine);
      starts.insert(s.start);
      if (!s.end.empty()) ends.insert(s.end);
      std::string load =
          "at the start " + s.load_start + ", " +
          (s.end.empty() ? std::string("stopped before its end") : "at the end " + s.load_end);
      if (records.size() > 1) load = r.id.Describe() + " on " + s.host + ": " + load;
      loads.push_back(load);
    }
  }
  info.machine = machines.empty() ? "unknown" : Join({machines.begin(), machines.end()}, "; ");
  info.commit = Join({revisions.begin(), revisions.end()}, "; ");
  info.load = loads.empty() ? "unknown" : Join(loads, "; ");
  if (loads.size() > 4) info.load = LoadRange(records);
  if (!starts.empty()) {
    info.date = *starts.begin();
    const std::string last = ends.empty() ? "" : *ends.rbegin();
    if (!last.empty() && last != info.date) info.date += " to " + last;
  }
  std::vector<std::string> settings;
  for (const auto& [suite, list] : by_suite) {
    const ShardId& id = list.front()->id;
    std::set<int> jobs;
    int done = 0;
    for (const ShardRecord* r : list) {
      done += r->runs_done;
      for (const Session& s : r->sessions) jobs.insert(s.jobs);
    }
    std::vector<std::string> job_words;
    for (int j : jobs) job_words.push_back(std::to_string(j));
    settings.push_back(
        "suite " + suite + ": " + std::to_string(id.runs) + " seed(s) per configuration, " +
        std::to_string(id.suite_runs) + " runs in " + std::to_string(id.shard_count) +
        " shard(s) (" + std::to_string(list.size()) + " here, " + std::to_string(done) +
        " runs with results), time limit " +
        (id.time_limit_s ? Num(*id.time_limit_s) + " s" : std::string("the suite's default")) +
        ", planner memory limit " + std::to_string(id.memory_limit_mib) + " MiB, " +
        (id.hard_limit_s > 0 ? "hard limit " + Num(id.hard_limit_s) + " s, " : "") +
        Join(job_words, " or ") + " job(s) at once");
  }
  info.settings = Join(settings, "; ");
  return info;
}

Result<std::vector<RunResult>> MergeShards(const std::vector<fs::path>& dirs, const fs::path& out,
                                           bool partial) {
  if (dirs.empty()) return Fail(ErrorCode::kInvalidInput, "merge: no shard folders given");
  std::error_code ec;
  const fs::path out_canonical = fs::weakly_canonical(out, ec);
  std::vector<Entry> entries;
  std::vector<std::string> problems;
  std::vector<RunResult> all;
  std::set<std::string> keys;
  for (const fs::path& dir : dirs) {
    if (fs::weakly_canonical(dir, ec) == out_canonical) {
      return Fail(ErrorCode::kInvalidInput,
                  "merge: -o " + out.string() + " is one of the folders to merge; give another");
    }
    auto results = ReadRunResults({dir});
    if (!results) return std::unexpected(results.error());
    auto meta = ReadFolderMeta(dir);
    if (!meta) {
      problems.push_back(meta.error().message);
      continue;
    }
    for (ShardRecord& r : meta->shards) {
      // A shard folder's count is what is in it now (a killed session did not update it).
      if (meta->kind == "shard") r.runs_done = static_cast<int>(results->size());
      entries.push_back(Entry{dir.string(), r});
    }
    if (meta->kind == "merged" && !meta->info.caveats.empty()) {
      problems.push_back(dir.string() + " is a partial merge (" + meta->info.caveats +
                         "): merge its shards instead");
    }
    for (RunResult& r : *results) {
      if (keys.insert(r.spec.Key()).second) all.push_back(std::move(r));
    }
  }
  Verdict verdict;
  if (problems.empty()) {
    verdict = Check(entries);
    problems = verdict.problems;
    if (!partial) problems.insert(problems.end(), verdict.gaps.begin(), verdict.gaps.end());
  }
  if (!problems.empty()) {
    return Fail(ErrorCode::kInvalidInput,
                "merge refused:\n  " + Join(problems, "\n  ") +
                    (partial || verdict.gaps.empty()
                         ? ""
                         : "\n(`wrap bench merge --partial` merges what there is, and says so)"));
  }

  fs::create_directories(out / "runs", ec);
  if (ec) return Fail(ErrorCode::kIo, (out / "runs").string() + ": " + ec.message());
  auto lock = FolderLock::Acquire(out);
  if (!lock) return std::unexpected(lock.error());
  if (auto old = ReadFolderMeta(out); old && old->kind == "shard") {
    return Fail(ErrorCode::kInvalidInput, "merge: -o " + out.string() + " is a shard's folder (" +
                                              old->shards.front().id.Describe() +
                                              "); give a new or a merged folder");
  }
  // The output holds exactly the merged runs: those of an earlier merge there go.
  for (const auto& e : fs::directory_iterator(out / "runs", ec)) {
    if (e.path().extension() == ".json") fs::remove(e.path(), ec);
  }
  for (const RunResult& r : all) {
    if (auto w = WriteFileAtomic(out / "runs" / (r.spec.Key() + ".json"), RunResultToJson(r)); !w) {
      return std::unexpected(w.error());
    }
  }
  FolderMeta meta;
  meta.kind = "merged";
  for (const Entry& e : entries) meta.shards.push_back(e.record);
  meta.info = ReportInfo(meta.shards);
  meta.info.settings =
      "merged from " + std::to_string(dirs.size()) + " folder(s): " + meta.info.settings;
  if (!verdict.gaps.empty()) meta.info.caveats = "partial merge: " + Join(verdict.gaps, "; ");
  if (auto w = WriteFolderMeta(out, meta); !w) return std::unexpected(w.error());
  SortResults(all);
  if (auto w = WriteReport(all, meta.info, out); !w) return std::unexpected(w.error());
  return all;
}

}  // namespace wrap::bench
