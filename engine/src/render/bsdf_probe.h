// The renderer's BSDFs evaluated and sampled on the device, outside any path: the shaders'
// own code (common/bsdf.glsl through shaders/bsdf_probe.comp) for given materials, directions
// and random numbers, so that tests can hold it to the definitions (energy, reciprocity, pdfs,
// directional albedo). Directions are in the shading frame: z is the normal.
//
// Threads: on the thread that owns the Context, like every Vulkan use.
#pragma once

#include <memory>
#include <vector>

#include "retile/scene.h"
#include "vk/context.h"
#include "vk/pipeline.h"

namespace retile {

struct BsdfQuery {
  Material material;
  Vec3 wo{0, 0, 1}, wi{0, 0, 1};  // wi for eval; wo for eval and sample
  Vec3 u{0.5f};                   // the sample's random numbers in [0, 1)
  float hairH = 0;                // hair: where across the fibre, which runs along x (Material::Hair)
};

struct BsdfAnswer {
  Vec3 f;          // eval(wo, wi): f * |cos wi|
  float pdf = 0;   // what sampling would give wi (0 for delta lobes)
  Vec3 sampledWi;  // sample(wo, u)
  float sampledPdf = 0;
  Vec3 weight;  // f * |cos| / pdf of the sample; 0 when it failed
  bool delta = false, transmitted = false;
  Vec3 fAtSample;  // eval(wo, sampledWi)
  float pdfAtSample = 0;
};

class BsdfProbe {
 public:
  explicit BsdfProbe(vk::Context& ctx);
  ~BsdfProbe();
  BsdfProbe(const BsdfProbe&) = delete;
  BsdfProbe& operator=(const BsdfProbe&) = delete;
  // Answers in the order of the queries; waits for the device.
  std::vector<BsdfAnswer> run(const std::vector<BsdfQuery>& queries);

 private:
  vk::Context& ctx_;
  std::unique_ptr<vk::ComputePipeline> pipeline_;
};

}  // namespace retile
