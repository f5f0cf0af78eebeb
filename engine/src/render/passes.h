// The engine's compute kernels, each made from its row of shaders/shared/bindings.h: its entry
// file and its descriptor set's layout. Owned by whoever makes them (the renderer, the denoiser,
// the BSDF probe); made and bound on the thread that owns the Context.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "vk/pipeline.h"

namespace retile {

enum class Pass {
#define RETILE_PASS(pass, shader) pass,
#define RETILE_BINDING(pass, name, binding, kind)
#include "shared/bindings.h"
#undef RETILE_BINDING
#undef RETILE_PASS
};

// Every pass, in the table's order.
std::vector<Pass> allPasses();
// The pass's entry file under shaders/.
const char* shaderOf(Pass pass);
struct PassBinding {
  const char* constant;  // the name both sides use: "kBind<pass><name>"
  vk::Binding kind;
};
// Its bindings by binding number; throws if the table numbers them other than 0..n-1.
std::vector<PassBinding> bindingTableOf(Pass pass);
// Their kinds, as the pipeline layout takes them.
std::vector<vk::Binding> bindingsOf(Pass pass);

std::unique_ptr<vk::ComputePipeline> makePass(vk::Context& ctx, Pass pass, std::uint32_t pushConstantBytes,
                                              const std::vector<vk::ShaderDefine>& defines = {});

}  // namespace retile
