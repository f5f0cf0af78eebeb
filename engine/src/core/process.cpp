#include "core/process.h"

#include <fcntl.h>
#include <malloc.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include "retile/log.h"

// An AddressSanitizer build (the asan preset) reserves terabytes of address space for its shadow
// memory at start: under an address-space limit every worker would abort before reading a byte.
// The limit is left out there; the wall-clock limit stays.
#if defined(RETILE_ASAN)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif

namespace retile {

#if defined(__SSE__)
constexpr unsigned kFlushToZero = 0x8000, kDenormalsAreZero = 0x0040;
#endif

void flushDenormals() {
#if defined(__SSE__)
  _mm_setcsr(_mm_getcsr() | kFlushToZero | kDenormalsAreZero);
#endif
}

void preferWideCpuVectors() {
  if (std::getenv("LP_NATIVE_VECTOR_WIDTH")) return;
#if defined(__x86_64__)
  __builtin_cpu_init();  // the test suites call this from a static initializer, maybe before libgcc's
  // The subsets LLVM's 512-bit code generation uses beyond the foundation.
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512dq"))
    setenv("LP_NATIVE_VECTOR_WIDTH", "512", 0);
#endif
}

KeepDenormals::KeepDenormals() {
#if defined(__SSE__)
  saved_ = _mm_getcsr();
  _mm_setcsr(saved_ & ~(kFlushToZero | kDenormalsAreZero));
#endif
}

KeepDenormals::~KeepDenormals() {
#if defined(__SSE__)
  _mm_setcsr(saved_);
#endif
}

std::string signalDescription(int sig) {
  const char* name = "";
  switch (sig) {
    case SIGSEGV: name = "SIGSEGV"; break;
    case SIGABRT: name = "SIGABRT"; break;
    case SIGBUS: name = "SIGBUS"; break;
    case SIGFPE: name = "SIGFPE"; break;
    case SIGILL: name = "SIGILL"; break;
    case SIGKILL: name = "SIGKILL"; break;
    case SIGXCPU: name = "SIGXCPU"; break;
    default: break;
  }
  const char* what = strsignal(sig);
  return *name ? cat(name, " (", what ? what : "?", ")") : cat("signal ", sig, " (", what ? what : "?", ")");
}

std::filesystem::path executableDirectory() {
  std::error_code ec;
  auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

ChildResult runChild(const std::filesystem::path& program, const std::vector<std::string>& args, const ChildLimits& limits) {
  ChildResult result;
  int outPipe[2], errPipe[2];
  if (::pipe2(outPipe, O_CLOEXEC) != 0) {
    result.startError = cat("pipe: ", std::strerror(errno));
    return result;
  }
  if (::pipe2(errPipe, O_CLOEXEC) != 0) {
    result.startError = cat("pipe: ", std::strerror(errno));
    ::close(outPipe[0]);
    ::close(outPipe[1]);
    return result;
  }

  // Everything the child needs is prepared before fork: between fork and exec a multithreaded
  // parent may only make async-signal-safe calls.
  std::string prog = program.string();
  std::vector<char*> argv;
  argv.push_back(prog.data());
  std::vector<std::string> argsCopy = args;
  for (auto& a : argsCopy) argv.push_back(a.data());
  argv.push_back(nullptr);
  rlimit as{static_cast<rlim_t>(limits.addressSpaceBytes), static_cast<rlim_t>(limits.addressSpaceBytes)};
  rlimit noCore{0, 0};

  pid_t pid = ::fork();
  if (pid < 0) {
    result.startError = cat("fork: ", std::strerror(errno));
    for (int fd : {outPipe[0], outPipe[1], errPipe[0], errPipe[1]}) ::close(fd);
    return result;
  }
  if (pid == 0) {
    ::dup2(outPipe[1], 1);
    ::dup2(errPipe[1], 2);
    int devnull = ::open("/dev/null", O_RDONLY);
    if (devnull >= 0) ::dup2(devnull, 0);
    if (limits.addressSpaceBytes && !kAddressSanitizer) ::setrlimit(RLIMIT_AS, &as);
    ::setrlimit(RLIMIT_CORE, &noCore);  // a crashing importer should not litter core files
    ::execv(prog.c_str(), argv.data());
    const char msg[] = "error: cannot execute the import worker\n";
    ssize_t ignored = ::write(2, msg, sizeof msg - 1);
    (void)ignored;
    ::_exit(127);
  }
  ::close(outPipe[1]);
  ::close(errPipe[1]);
  result.started = true;

  auto deadline = std::chrono::steady_clock::now() + limits.timeout;
  pollfd fds[2] = {{outPipe[0], POLLIN, 0}, {errPipe[0], POLLIN, 0}};
  std::string* sinks[2] = {&result.out, &result.err};
  int open = 2;
  char buf[65536];
  while (open > 0) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      result.timedOut = true;
      break;
    }
    int n = ::poll(fds, 2, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      ssize_t r = ::read(fds[i].fd, buf, sizeof buf);
      if (r > 0) {
        sinks[i]->append(buf, static_cast<std::size_t>(r));
        if (sinks[i]->size() > limits.maxOutputBytes) {
          result.outputTooLarge = true;
          open = 0;
          break;
        }
      } else if (r == 0 || (r < 0 && errno != EINTR && errno != EAGAIN)) {
        ::close(fds[i].fd);
        fds[i].fd = -1;
        --open;
      }
    }
  }
  if (result.timedOut || result.outputTooLarge) ::kill(pid, SIGKILL);
  for (auto& f : fds)
    if (f.fd >= 0) ::close(f.fd);

  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status)) result.exitCode = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) result.signal = WTERMSIG(status);
  return result;
}

void releaseFreedMemory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

}  // namespace retile
