// Every kernel's bindings are named once, in shaders/shared/bindings.h: the table numbers each
// pass's from 0 without gaps, and each kernel declares every buffer of its pass by the table's
// name (never by number), so the pipeline layout built from the table is the one the kernel was
// written for.
#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <regex>
#include <set>
#include <string>

#include "render/passes.h"
#include "vk/embedded_shaders.h"

namespace retile {
namespace {

std::map<std::string, std::string> shaderSources() {
  std::map<std::string, std::string> out;
  for (const vk::EmbeddedShader& s : vk::embeddedShaders()) out[s.name] = s.source;
  return out;
}

// The kernel's source with everything it includes, each file once.
std::string withIncludes(const std::map<std::string, std::string>& sources, const std::string& entry) {
  std::string all;
  std::set<std::string> seen;
  std::function<void(const std::string&)> add = [&](const std::string& name) {
    if (!seen.insert(name).second) return;
    auto it = sources.find(name);
    ASSERT_NE(it, sources.end()) << name << " is not among the embedded shaders";
    all += it->second;
    static const std::regex include(R"(#include\s+"([^"]+)\")");
    for (std::sregex_iterator m(it->second.begin(), it->second.end(), include), end; m != end; ++m) add((*m)[1].str());
  };
  add(entry);
  return all;
}

TEST(KernelBindings, EachKernelDeclaresItsPassesBindingsByTheirNames) {
  const auto sources = shaderSources();
  ASSERT_FALSE(allPasses().empty());
  for (Pass pass : allPasses()) {
    SCOPED_TRACE(shaderOf(pass));
    std::vector<PassBinding> table;
    ASSERT_NO_THROW(table = bindingTableOf(pass));
    ASSERT_FALSE(table.empty());
    const std::string source = withIncludes(sources, shaderOf(pass));
    for (const PassBinding& b : table)
      EXPECT_TRUE(std::regex_search(source, std::regex(std::string(R"(binding\s*=\s*)") + b.constant + R"(\b)")))
          << b.constant << " is not a binding the kernel declares";
  }
}

TEST(KernelBindings, NoKernelNumbersABindingItself) {
  static const std::regex literal(R"(binding\s*=\s*[0-9])");
  for (const vk::EmbeddedShader& s : vk::embeddedShaders())
    EXPECT_FALSE(std::regex_search(std::string(s.source), literal)) << s.name << " declares a binding by its number";
}

}  // namespace
}  // namespace retile
