// The run's log: every stage's diagnostic lines go through one sink on the RunContext, by topic
// ("motion", "task", ...) and level, instead of each stage reading environment variables and
// printing to stderr. The engine never decides by itself what is logged or where: the CLI (from
// `--log` or WRAP_LOG) and the GUI set the sink and the topics. Logging never changes a result.
#pragma once

#include <functional>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.h"

namespace wrap {

/// How much a line tells: kDebug is a stage's decisions (a path query and its outcome), kTrace
/// the details under them (every collision of a check, every step of a simulation).
enum class LogLevel { kDebug = 0, kTrace = 1 };

/// A topic of the log and what it covers.
struct LogTopic {
  std::string_view name;  ///< e.g. "motion".
  std::string_view what;  ///< One line for `--help` and docs/debugging.md.
};

/// Every topic a stage logs under.
const std::vector<LogTopic>& KnownLogTopics();

/// Which topics are logged, each up to a level.
class LogTopics {
 public:
  /// Parses a comma-separated list: "motion,task" (each at kDebug), "motion:trace", "all" (every
  /// topic, also "all:trace"); empty: nothing. Fails with kInvalidInput naming an unknown topic
  /// or level and listing the known ones.
  static Result<LogTopics> Parse(std::string_view spec);
  /// True when `topic` is logged at `level`.
  bool Enabled(std::string_view topic, LogLevel level) const;
  /// True when nothing is logged.
  bool empty() const { return topics_.empty() && !all_; }

 private:
  std::map<std::string, LogLevel, std::less<>> topics_;
  std::optional<LogLevel> all_;
};

/// Receives one line: its topic, its level and its text (no trailing newline).
using LogSink = std::function<void(std::string_view topic, LogLevel level, const std::string&)>;

/// A sink that writes "[topic] text" lines to `out` (the command line's stderr), one line at a
/// time when several threads log. `out` must outlive the sink.
LogSink StreamLogSink(std::ostream& out);

/// printf-style formatting into a string.
std::string StrFormat(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace wrap
