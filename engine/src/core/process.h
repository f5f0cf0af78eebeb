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
  int exitCode = -1;       // valid when the child exited normally
  int signal = 0;          // non-zero when a signal killed it
  std::string out;         // everything the child wrote to stdout
  std::string err;         // and to stderr
  std::string startError;  // why it could not be started
};

ChildResult runChild(const std::filesystem::path& program, const std::vector<std::string>& args, const ChildLimits& limits);

// Human-readable name of a signal, e.g. "SIGSEGV (segmentation fault)".
std::string signalDescription(int sig);

// Hands heap pages the process has freed back to the system (glibc keeps them), so that a big
// load's temporaries do not add to the peak of what is allocated after it. Any thread; a no-op
// where the C library cannot do it.
void releaseFreedMemory();

// Makes the calling thread, and every thread it creates afterwards (they inherit the setting),
// treat denormal floats as zero (x86 MXCSR DAZ and FTZ; a no-op elsewhere). lavapipe runs every
// branch of a shader for every invocation, so the traversal loop does float arithmetic on
// records of other kinds (node items and packed bytes read as floats, many of them denormal),
// and each denormal operand costs a microcode assist: on the spaceship, the four-wide BVH
// traced 15 % more samples per second with them flushed. Vulkan 1.2's
// float controls would say it per shader, but lavapipe offers no flush-to-zero. Call before the
// Vulkan device is created (its worker threads inherit). Little Retile computes needs denormals;
// what does runs under KeepDenormals.
void flushDenormals();

// Has lavapipe (Mesa's CPU Vulkan driver) compile shaders for sixteen lanes of 512 bits where
// the CPU has AVX-512, instead of the eight of 256 it keeps to by default on any x86 CPU. Side by
// side on this project's AVX-512 machine, sixteen traced the kitchen 1.16x, the living room 1.14x,
// the spaceship 1.11x, our glass and ice 1.15x and the Cornell box 1.03x as many samples a second,
// with the images identical to the bit (which lane traces a path changes nothing in it). lavapipe
// reads LP_NATIVE_VECTOR_WIDTH once, when a process makes its first lavapipe device, so call this
// early in main, before any thread starts (setenv is not thread-safe) and before any Vulkan
// instance is made. A width the user set is kept. Other drivers do not read it.
// Not in the editor: with 512 bits, lavapipe crashed compiling the graphics pipeline that shows
// the viewport in a Qt Vulkan window whenever Mesa's shader cache was cold (gui_vulkan_tests,
// three runs of three with ~/.cache/mesa_shader_cache removed; none at 256 bits). The compute
// kernels, the command line's whole use of the device, compile and run correctly at 512.
void preferWideCpuVectors();

// Undoes flushDenormals for the calling thread while it lives, and puts the flags back as they
// were when it ends. Code that needs denormals runs under one: OpenImageIO's half-to-float
// conversion, for one, reads a half below 6.1e-5 as 0 when denormals are treated as zero (a
// reference EXR's dark backdrop block read as 7.7e-7 instead of 2.6e-5).
class KeepDenormals {
 public:
  KeepDenormals();
  ~KeepDenormals();
  KeepDenormals(const KeepDenormals&) = delete;
  KeepDenormals& operator=(const KeepDenormals&) = delete;

 private:
  unsigned saved_ = 0;
};

// Directory of the running executable (from /proc/self/exe); empty if unknown.
std::filesystem::path executableDirectory();

}  // namespace retile
