#include "retile/error.h"

#include "retile/log.h"

namespace retile {

void assertionFailed(const char* expr, const std::string& values, const char* file, int line, const char* function) {
  std::string message =
      cat("internal error: ", expr, " failed at ", file, ":", line, " in ", function, values.empty() ? "" : " with ", values);
  logMessage(LogLevel::Error, message);
  throw AssertionError(message);
}

}  // namespace retile
