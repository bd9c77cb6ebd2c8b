#pragma once

#include <functional>
#include <string>

#include "ambfplus/export.h"

namespace ambfplus {

/// Severity of a log message, in increasing order.
enum class LogLevel { kDebug = 10, kInfo = 20, kWarning = 30, kError = 40 };

/// Receives every log message at or above the current level.
using LogSink = std::function<void(LogLevel, const std::string&)>;

/// Replaces the sink (the default writes to stderr); an empty function restores the default.
AMBFPLUS_API void set_log_sink(LogSink sink);

/// Messages below this level are dropped (default: kWarning, or AMBFPLUS_LOG_LEVEL).
AMBFPLUS_API void set_log_level(LogLevel level);

/// Sends one message to the sink.
AMBFPLUS_API void log(LogLevel level, const std::string& message);

}  // namespace ambfplus
