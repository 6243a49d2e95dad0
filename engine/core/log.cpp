#include "core/log.h"

#include <cstdarg>
#include <cstdio>
#include <ostream>
#include <mutex>

namespace wrap {

const std::vector<LogTopic>& KnownLogTopics() {
  static const std::vector<LogTopic> kTopics = {
      {"task", "the task planner: milestone fills, edges that fail validation and why, the "
               "backward abstraction (trace: every collision of a keyframe check)"},
      {"motion", "the motion planner: every path query and its outcome, suspensions, timed "
                 "trajectories refused by the self-check, skills that cannot be tracked"},
      {"motion.diag", "for a path search that spent its budget: is its start or its goal cut off "
                      "from the robot's home, and what do they touch (plans extra paths: slower, "
                      "same result)"},
      {"sim", "the simulation: why a run failed, replayed keyframes that were skipped (trace: "
              "each robot's grip force and torque at every step)"},
  };
  return kTopics;
}

namespace {

bool KnownTopic(std::string_view name) {
  for (const LogTopic& t : KnownLogTopics()) {
    if (t.name == name) return true;
  }
  return false;
}

std::string KnownList() {
  std::string list = "all";
  for (const LogTopic& t : KnownLogTopics()) list += ", " + std::string(t.name);
  return list;
}

}  // namespace

Result<LogTopics> LogTopics::Parse(std::string_view spec) {
  LogTopics out;
  while (!spec.empty()) {
    const size_t comma = spec.find(',');
    std::string_view item = spec.substr(0, comma);
    spec = comma == std::string_view::npos ? std::string_view() : spec.substr(comma + 1);
    if (item.empty()) continue;
    LogLevel level = LogLevel::kDebug;
    if (const size_t colon = item.find(':'); colon != std::string_view::npos) {
      const std::string_view l = item.substr(colon + 1);
      if (l == "trace") {
        level = LogLevel::kTrace;
      } else if (l != "debug") {
        return Fail(ErrorCode::kInvalidInput, "log level '" + std::string(l) + "' of '" +
                                                  std::string(item) +
                                                  "' is not one of debug, trace");
      }
      item = item.substr(0, colon);
    }
    if (item == "all") {
      out.all_ = level;
    } else if (KnownTopic(item)) {
      out.topics_[std::string(item)] = level;
    } else {
      return Fail(ErrorCode::kInvalidInput,
                  "unknown log topic '" + std::string(item) + "' (known: " + KnownList() + ")");
    }
  }
  return out;
}

bool LogTopics::Enabled(std::string_view topic, LogLevel level) const {
  if (all_ && level <= *all_) return true;
  const auto it = topics_.find(topic);
  return it != topics_.end() && level <= it->second;
}

LogSink StreamLogSink(std::ostream& out) {
  return [&out](std::string_view topic, LogLevel, const std::string& text) {
    // Threads of one run (the parallel grasp sampling) may log at once: one line at a time.
    static std::mutex mutex;
    std::lock_guard lock(mutex);
    out << '[' << topic << "] " << text << '\n';
  };
}

std::string StrFormat(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string out;
  if (n > 0) {
    out.resize(static_cast<size_t>(n));
    std::vsnprintf(out.data(), out.size() + 1, format, args);
  }
  va_end(args);
  return out;
}

}  // namespace wrap
