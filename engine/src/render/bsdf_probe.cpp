#include "render/bsdf_probe.h"

#include <array>
#include <cstring>

#include "render/passes.h"
#include "render/render_scene.h"
#include "vk/buffer.h"
#include "vk/pipeline.h"

namespace retile {

BsdfProbe::BsdfProbe(vk::Context& ctx)
    : ctx_(ctx), pipeline_(makePass(ctx, Pass::BsdfProbe, static_cast<std::uint32_t>(sizeof(std::uint32_t)))) {}

BsdfProbe::~BsdfProbe() = default;

std::vector<BsdfAnswer> BsdfProbe::run(const std::vector<BsdfQuery>& queries) {
  vk::Context& ctx = ctx_;
  if (queries.empty()) return {};
  constexpr std::size_t kQueryVec4s = gpu::kMaterialTexels + 3;
  std::vector<vec4> in;
  in.reserve(queries.size() * kQueryVec4s);
  // Queries come in runs of one material (tests ask hundreds of thousands of one): each run is
  // packed once.
  const Material* packedFrom = nullptr;
  std::array<vec4, gpu::kMaterialTexels> packed{};
  for (const BsdfQuery& q : queries) {
    if (!packedFrom || !(*packedFrom == q.material)) packed = packMaterial(q.material);
    packedFrom = &q.material;
    in.insert(in.end(), packed.begin(), packed.end());
    in.push_back({q.wo.x, q.wo.y, q.wo.z, q.hairH});
    for (Vec3 v : {q.wi, q.u}) in.push_back({v.x, v.y, v.z, 0.0f});
  }
  const auto count = static_cast<std::uint32_t>(queries.size());
  vk::Buffer inBuf(ctx, in.size() * sizeof(vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "bsdf probe queries");
  vk::Buffer outBuf(ctx, static_cast<VkDeviceSize>(count) * 4 * sizeof(vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true,
                    "bsdf probe answers");
  inBuf.upload(in.data(), in.size() * sizeof(vec4));
  pipeline_->bind(gpu::kBindBsdfProbeQueries, inBuf);
  pipeline_->bind(gpu::kBindBsdfProbeAnswers, outBuf);
  ctx.submitAndWait([&](VkCommandBuffer cb) { pipeline_->dispatch(cb, (count + 63) / 64, 1, &count, sizeof(count)); });
  std::vector<vec4> out(static_cast<std::size_t>(count) * 4);
  outBuf.download(out.data(), out.size() * sizeof(vec4));
  std::vector<BsdfAnswer> answers(queries.size());
  for (std::size_t i = 0; i < answers.size(); ++i) {
    const vec4* a = &out[i * 4];
    BsdfAnswer& r = answers[i];
    r.f = {a[0].x, a[0].y, a[0].z};
    r.pdf = a[0].w;
    r.sampledWi = {a[1].x, a[1].y, a[1].z};
    r.sampledPdf = a[1].w;
    r.weight = {a[2].x, a[2].y, a[2].z};
    int flags = static_cast<int>(a[2].w);
    r.delta = (flags & 1) != 0;
    r.transmitted = (flags & 2) != 0;
    r.fAtSample = {a[3].x, a[3].y, a[3].z};
    r.pdfAtSample = a[3].w;
  }
  return answers;
}

}  // namespace retile
