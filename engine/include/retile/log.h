// Process-wide log. Any thread may log; the sink is called under a mutex, one message at a
// time, on the logging thread. The editor installs a sink that forwards to its log panel with a
// queued call; the command line prints to stderr.
#pragma once

#include <functional>
#include <sstream>
#include <string>
#include <string_view>

namespace retile {

enum class LogLevel { Debug, Info, Warning, Error };

using LogSink = std::function<void(LogLevel, std::string_view)>;

// Replaces the sink; returns the previous one. The default prints warnings and errors to stderr.
LogSink setLogSink(LogSink sink);
void setLogLevel(LogLevel minimum);
void logMessage(LogLevel level, std::string_view message);
const char* logLevelName(LogLevel level);

// Concatenates anything with an ostream operator (GCC 12 has no std::format).
template <class... Args>
std::string cat(const Args&... args) {
  std::ostringstream s;
  (s << ... << args);
  return s.str();
}

template <class... Args>
void logInfo(const Args&... args) {
  logMessage(LogLevel::Info, cat(args...));
}
template <class... Args>
void logWarning(const Args&... args) {
  logMessage(LogLevel::Warning, cat(args...));
}
template <class... Args>
void logDebug(const Args&... args) {
  logMessage(LogLevel::Debug, cat(args...));
}

}  // namespace retile
