#include "render/passes.h"

#include "retile/error.h"
#include "retile/log.h"

namespace retile {

namespace {

struct Row {
  Pass pass;
  int binding;
  PassBinding entry;
};

constexpr Row kRows[] = {
#define RETILE_PASS(pass, shader)
#define RETILE_BINDING(pass, name, binding, kind) {Pass::pass, binding, {"kBind" #pass #name, vk::Binding::kind}},
#include "shared/bindings.h"
#undef RETILE_BINDING
#undef RETILE_PASS
};

struct Kernel {
  Pass pass;
  const char* shader;
};

constexpr Kernel kKernels[] = {
#define RETILE_PASS(pass, shader) {Pass::pass, shader},
#define RETILE_BINDING(pass, name, binding, kind)
#include "shared/bindings.h"
#undef RETILE_BINDING
#undef RETILE_PASS
};

}  // namespace

std::vector<Pass> allPasses() {
  std::vector<Pass> out;
  for (const Kernel& k : kKernels) out.push_back(k.pass);
  return out;
}

const char* shaderOf(Pass pass) {
  for (const Kernel& k : kKernels)
    if (k.pass == pass) return k.shader;
  throw Error(cat("no kernel for pass ", static_cast<int>(pass)));
}

std::vector<PassBinding> bindingTableOf(Pass pass) {
  std::vector<PassBinding> out;
  std::vector<bool> seen;
  for (const Row& r : kRows) {
    if (r.pass != pass) continue;
    const auto b = static_cast<std::size_t>(r.binding);
    if (b >= seen.size()) {
      seen.resize(b + 1, false);
      out.resize(b + 1);
    }
    if (seen[b]) throw Error(cat(shaderOf(pass), ": binding ", r.binding, " is in bindings.h twice"));
    seen[b] = true;
    out[b] = r.entry;
  }
  for (std::size_t b = 0; b < seen.size(); ++b)
    if (!seen[b]) throw Error(cat(shaderOf(pass), ": bindings.h skips binding ", b));
  return out;
}

std::vector<vk::Binding> bindingsOf(Pass pass) {
  std::vector<vk::Binding> out;
  for (const PassBinding& b : bindingTableOf(pass)) out.push_back(b.kind);
  return out;
}

std::unique_ptr<vk::ComputePipeline> makePass(vk::Context& ctx, Pass pass, std::uint32_t pushConstantBytes,
                                              const std::vector<vk::ShaderDefine>& defines) {
  return std::make_unique<vk::ComputePipeline>(ctx, shaderOf(pass), bindingsOf(pass), pushConstantBytes, defines);
}

}  // namespace retile
