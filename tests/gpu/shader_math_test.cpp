// The shaders' integer helpers (shaders/common/integer.glsl, run on the device through
// integer_probe.comp) against the CPU's integer arithmetic, at the edges of their range and at
// random.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "gpu_support.h"
#include "render/passes.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"

namespace retile {
namespace {

// quotient(a, b) on the device for each pair.
std::vector<std::uint32_t> deviceQuotients(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs) {
  vk::Context ctx;
  auto pass = makePass(ctx, Pass::IntegerProbe, sizeof(std::uint32_t));
  std::vector<std::uint32_t> in;
  for (auto [a, b] : pairs) in.insert(in.end(), {a, b});
  const auto count = static_cast<std::uint32_t>(pairs.size());
  vk::Buffer inBuf(ctx, in.size() * sizeof(std::uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "integer probe queries");
  vk::Buffer outBuf(ctx, count * sizeof(std::uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "integer probe answers");
  inBuf.upload(in.data(), in.size() * sizeof(std::uint32_t));
  pass->bind(gpu::kBindIntegerProbeQueries, inBuf);
  pass->bind(gpu::kBindIntegerProbeAnswers, outBuf);
  ctx.submitAndWait([&](VkCommandBuffer cb) { pass->dispatch(cb, (count + 63) / 64, 1, &count, sizeof(count)); });
  std::vector<std::uint32_t> out(count);
  outBuf.download(out.data(), out.size() * sizeof(std::uint32_t));
  return out;
}

TEST(ShaderMath, QuotientIsExactOverItsRange) {
  RETILE_RENDERER_OR_SKIP(renderer);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  // Divisors from 1 to 2^30 (the helper's range), each against the dividends where a float
  // rounds or a quotient turns: multiples of b and their neighbours, powers of two, the top.
  std::vector<std::uint32_t> divisors{1,
                                      2,
                                      3,
                                      5,
                                      7,
                                      10,
                                      16,
                                      17,
                                      255,
                                      641,
                                      1000,
                                      65535,
                                      65536,
                                      65537,
                                      6700417,
                                      (1u << 23) - 1,
                                      1u << 23,
                                      (1u << 24) + 1,
                                      123456789,
                                      (1u << 29) + 7,
                                      (1u << 30) - 1,
                                      1u << 30};
  for (std::uint32_t b : divisors) {
    std::vector<std::uint64_t> around{0, 1, b, 4294967295u / b, 4294967295u / b / 2, 1u << 12, 1u << 24, 3u << 23};
    for (std::uint64_t k : around)
      for (std::int64_t d : {-2, -1, 0, 1, 2}) {
        const std::int64_t a = static_cast<std::int64_t>(k * b) + d;
        if (a >= 0 && a <= 4294967295) pairs.emplace_back(static_cast<std::uint32_t>(a), b);
      }
    for (std::uint32_t a : {4294967295u, 4294967294u, 4294967040u, 4294967041u, 2147483648u, 2147483647u, 16777217u})
      pairs.emplace_back(a, b);
  }
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint32_t> anyA;
  std::uniform_int_distribution<int> bits(0, 30);
  for (int i = 0; i < 200000; ++i) {
    const int n = bits(rng);
    const std::uint32_t b = std::max<std::uint32_t>(1, std::uniform_int_distribution<std::uint32_t>(0, 1u << n)(rng));
    std::uint32_t a = anyA(rng);
    if (i % 2 == 0) a = static_cast<std::uint32_t>((static_cast<std::uint64_t>(a / b) * b + (i % 4 == 0 ? 0 : b - 1)) & 0xffffffffu);
    pairs.emplace_back(a, b);
  }
  const std::vector<std::uint32_t> q = deviceQuotients(pairs);
  int wrong = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const auto [a, b] = pairs[i];
    if (q[i] != a / b && ++wrong <= 10) ADD_FAILURE() << a << " / " << b << ": " << q[i] << ", not " << a / b;
  }
  EXPECT_EQ(wrong, 0) << "of " << pairs.size();
}

}  // namespace
}  // namespace retile
