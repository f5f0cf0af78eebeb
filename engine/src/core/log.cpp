#include "retile/log.h"

#include <atomic>
#include <cstdio>
#include <mutex>

namespace retile {
namespace {

std::mutex gMutex;
std::atomic<int> gMinimum{static_cast<int>(LogLevel::Warning)};

void stderrSink(LogLevel level, std::string_view message) {
  std::fprintf(stderr, "retile: %s: %.*s\n", logLevelName(level), static_cast<int>(message.size()), message.data());
}

LogSink& sink() {
  static LogSink s = stderrSink;
  return s;
}

}  // namespace

const char* logLevelName(LogLevel level) {
  switch (level) {
    case LogLevel::Debug: return "debug";
    case LogLevel::Info: return "info";
    case LogLevel::Warning: return "warning";
    case LogLevel::Error: return "error";
  }
  return "?";
}

LogSink setLogSink(LogSink s) {
  std::lock_guard lock(gMutex);
  LogSink old = std::move(sink());
  sink() = s ? std::move(s) : LogSink(stderrSink);
  return old;
}

void setLogLevel(LogLevel minimum) { gMinimum = static_cast<int>(minimum); }

void logMessage(LogLevel level, std::string_view message) {
  if (static_cast<int>(level) < gMinimum.load(std::memory_order_relaxed)) return;
  std::lock_guard lock(gMutex);
  sink()(level, message);
}

}  // namespace retile
