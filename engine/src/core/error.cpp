#include "retile/error.h"

#include "retile/log.h"

namespace retile {

void assertionFailed(const char* expr, const std::string& values, std::source_location where) {
  std::string message = cat("internal error: ", expr, " failed at ", where.file_name(), ":",
                            where.line(), " in ", where.function_name(),
                            values.empty() ? "" : " with ", values);
  logMessage(LogLevel::Error, message);
  throw AssertionError(message);
}

}  // namespace retile
