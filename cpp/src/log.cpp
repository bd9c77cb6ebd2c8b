#include "ambfplus/log.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace ambfplus {
namespace {

LogLevel level_from_environment() {
  const char* value = std::getenv("AMBFPLUS_LOG_LEVEL");
  if (value == nullptr) return LogLevel::kWarning;
  if (std::strcmp(value, "debug") == 0) return LogLevel::kDebug;
  if (std::strcmp(value, "info") == 0) return LogLevel::kInfo;
  if (std::strcmp(value, "error") == 0) return LogLevel::kError;
  return LogLevel::kWarning;
}

const char* level_name(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "debug";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kWarning:
      return "warning";
    case LogLevel::kError:
      return "error";
  }
  return "?";
}

struct LogState {
  std::mutex mutex;
  LogSink sink;
  LogLevel level = level_from_environment();
};

LogState& state() {
  static LogState s;
  return s;
}

}  // namespace

void set_log_sink(LogSink sink) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().sink = std::move(sink);
}

void set_log_level(LogLevel level) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().level = level;
}

void log(LogLevel level, const std::string& message) {
  LogSink sink;
  {
    std::lock_guard<std::mutex> lock(state().mutex);
    if (level < state().level) return;
    sink = state().sink;
  }
  // The sink runs outside the lock: a Python sink takes the GIL, which must never wait on us.
  if (sink) {
    sink(level, message);
  } else {
    std::fprintf(stderr, "ambfplus %s: %s\n", level_name(level), message.c_str());
  }
}

}  // namespace ambfplus
