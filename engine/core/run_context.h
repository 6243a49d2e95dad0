// RunContext: what every pipeline stage receives besides its input and options.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <random>
#include <stop_token>
#include <string>
#include <string_view>

#include "core/log.h"

namespace wrap {

/// CPU time the calling thread has used [s]. Budgets of inner searches (a path query, a carry
/// search) count it rather than wall-clock time, so that a loaded machine slows them down but
/// does not change what they find; the run's own deadline stays wall-clock.
double ThreadCpuSeconds();

/// Per-stage wall-clock totals [s], keyed by stage name (e.g. "grasp", "fwd_search").
using StageTimes = std::map<std::string, double>;

/// Cancellation, deadline, progress, randomness, timing and the log for one planner run. A run
/// owns one context; stages check `ShouldStop()` in every loop that can take longer than ~50 ms.
class RunContext {
 public:
  using Clock = std::chrono::steady_clock;
  /// Progress sink: stage name, fraction done in [0, 1] (negative when unknown), short message.
  using ProgressFn = std::function<void(const std::string&, double, const std::string&)>;

  /// A context with no deadline, no stop token and a generator seeded with `seed`.
  explicit RunContext(std::uint64_t seed = 0) : rng_(seed) {}

  /// Cancels the run when `token` is signalled.
  void set_stop_token(std::stop_token token) { stop_ = std::move(token); }
  /// Gives up at `deadline`.
  void set_deadline(Clock::time_point deadline) { deadline_ = deadline; }
  /// Gives up `seconds` from now.
  void set_time_limit_s(double seconds);
  /// Receives progress reports.
  void set_progress(ProgressFn fn) { progress_ = std::move(fn); }
  /// Sends the lines of `topics` to `sink` (none by default).
  void set_log(LogSink sink, LogTopics topics) {
    log_ = std::move(sink);
    log_topics_ = std::move(topics);
  }
  /// The same log as `other`'s (a sub-run of it).
  void set_log_from(const RunContext& other) { set_log(other.log_, other.log_topics_); }

  /// The stop token (for a sub-run that must stop with this one).
  const std::stop_token& stop_token() const { return stop_; }
  /// The deadline (time_point::max() when there is none).
  Clock::time_point deadline() const { return deadline_; }
  /// True when cancelled.
  bool cancelled() const { return stop_.stop_requested(); }
  /// True when the deadline has passed.
  bool timed_out() const { return Clock::now() >= deadline_; }
  /// True when the run must stop now (cancelled or past its deadline).
  bool ShouldStop() const { return cancelled() || timed_out(); }
  /// True when lines of `topic` at `level` are logged (check it before building an expensive
  /// line).
  bool Logs(std::string_view topic, LogLevel level = LogLevel::kDebug) const {
    return log_ && log_topics_.Enabled(topic, level);
  }
  /// Logs `text` under `topic` at `level`, if that is logged.
  void Log(std::string_view topic, const std::string& text,
           LogLevel level = LogLevel::kDebug) const {
    if (Logs(topic, level)) log_(topic, level, text);
  }
  /// The progress sink (empty when none), for a sub-run that reports through this one.
  const ProgressFn& progress_fn() const { return progress_; }
  /// Reports progress to the sink, if any.
  void Progress(const std::string& stage, double fraction, const std::string& message) const {
    if (progress_) progress_(stage, fraction, message);
  }
  /// The run's random generator. Stages also seed generators of their own from fixed values
  /// or hashes of what they sample (a grasp, a keyframe, an effort level), so that one check
  /// gives the same answer whenever it is asked; no randomness comes from outside the run.
  std::mt19937_64& rng() { return rng_; }
  /// Accumulated seconds per stage.
  const StageTimes& stage_times() const { return times_; }
  /// Adds `seconds` to the total of `stage`.
  void AddTime(const std::string& stage, double seconds) { times_[stage] += seconds; }

 private:
  std::stop_token stop_;
  Clock::time_point deadline_ = Clock::time_point::max();
  ProgressFn progress_;
  LogSink log_;
  LogTopics log_topics_;
  std::mt19937_64 rng_;
  StageTimes times_;
};

/// Adds the wall time of its scope to one stage of a RunContext.
class ScopedStageTimer {
 public:
  ScopedStageTimer(RunContext& ctx, std::string stage)
      : ctx_(ctx), stage_(std::move(stage)), start_(RunContext::Clock::now()) {}
  ~ScopedStageTimer() {
    ctx_.AddTime(stage_, std::chrono::duration<double>(RunContext::Clock::now() - start_).count());
  }
  ScopedStageTimer(const ScopedStageTimer&) = delete;
  ScopedStageTimer& operator=(const ScopedStageTimer&) = delete;

 private:
  RunContext& ctx_;
  std::string stage_;
  RunContext::Clock::time_point start_;
};

/// The process's resident memory [bytes] (Linux: /proc/self/statm), 0 when unknown. For memory
/// limits of long searches.
std::size_t ResidentMemoryBytes();

}  // namespace wrap
