// The engine's three kinds of failure (see docs/ARCHITECTURE.md):
//  - bugs: RETILE_ASSERT, which prints the values involved and throws (never aborts the editor);
//  - runtime failures (Vulkan error, device lost, out of memory): retile::Error exceptions that
//    carry what was being done;
//  - expected failures (a file that does not parse): Result<T>, a value or a message a user can
//    act on.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace retile {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

// The machine has no Vulkan driver or no device that can run the renderer: a Renderer cannot be
// made at all (as opposed to a device that fails while working). Tests skip on it outside CI.
class NoDeviceError : public Error {
 public:
  using Error::Error;
};

// Thrown by RETILE_ASSERT: a broken invariant inside the engine.
class AssertionError : public Error {
 public:
  using Error::Error;
};

// The location comes from the macro, not std::source_location: clang 14 (the fuzz build's
// compiler) cannot compile libstdc++ 12's source_location.
[[noreturn]] void assertionFailed(const char* expr, const std::string& values, const char* file, int line, const char* function);

#define RETILE_ASSERT(cond, values)                                                        \
  do {                                                                                     \
    if (!(cond)) ::retile::assertionFailed(#cond, (values), __FILE__, __LINE__, __func__); \
  } while (false)

// A value or a user-facing message. Move-only types are fine.
template <class T>
class Result {
 public:
  Result(T value) : state_(std::in_place_index<0>, std::move(value)) {}  // NOLINT: implicit by design
  static Result failure(std::string message) {
    Result r;
    r.state_.template emplace<1>(std::move(message));
    return r;
  }
  bool ok() const { return state_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & { return std::get<0>(state_); }
  const T& value() const& { return std::get<0>(state_); }
  T&& value() && { return std::get<0>(std::move(state_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  const std::string& error() const { return std::get<1>(state_); }

 private:
  Result() = default;
  std::variant<T, std::string> state_;
};

}  // namespace retile
