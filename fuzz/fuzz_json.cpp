// The JSON reader and writer: any bytes either fail with a message or parse to a value that is
// written and read back to the same text (the writer's output is always valid JSON, numbers
// round-trip exactly).
#include "core/json.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace retile;
  std::string_view text(reinterpret_cast<const char*>(data), size);
  auto parsed = json::parse(text);
  if (!parsed) {
    if (parsed.error().empty()) fuzz::invariant("a parse failure without a message");
    return 0;
  }
  for (bool pretty : {false, true}) {
    std::string once = json::write(parsed.value(), pretty);
    auto again = json::parse(once);
    if (!again) fuzz::invariant("the writer's output does not parse", again.error() + "\n" + once);
    std::string twice = json::write(again.value(), pretty);
    if (twice != once) fuzz::invariant("write(parse(write(v))) differs from write(v)", once + "\n---\n" + twice);
  }
  return 0;
}
