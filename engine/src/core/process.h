// Runs a helper program in a child process with limits, for work we do not trust to survive
// hostile input (Assimp). The calling thread blocks until the child ends or the time limit
// passes; the child never shares memory with the caller.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace retile {

struct ChildLimits {
  std::chrono::milliseconds timeout{60000};
  std::uint64_t addressSpaceBytes = 0;  // 0: no limit
  std::uint64_t maxOutputBytes = std::uint64_t(4) << 30;
};

struct ChildResult {
  bool started = false;
  bool timedOut = false;
  bool outputTooLarge = false;
  int exitCode = -1;      // valid when the child exited normally
  int signal = 0;         // non-zero when a signal killed it
  std::string out;        // everything the child wrote to stdout
  std::string err;        // and to stderr
  std::string startError; // why it could not be started
};

ChildResult runChild(const std::filesystem::path& program, const std::vector<std::string>& args,
                     const ChildLimits& limits);

// Human-readable name of a signal, e.g. "SIGSEGV (segmentation fault)".
std::string signalDescription(int sig);

// Hands heap pages the process has freed back to the system (glibc keeps them), so that a big
// load's temporaries do not add to the peak of what is allocated after it. Any thread; a no-op
// where the C library cannot do it.
void releaseFreedMemory();

// Directory of the running executable (from /proc/self/exe); empty if unknown.
std::filesystem::path executableDirectory();

}  // namespace retile
