// Scenario scripts (retile edit --script, the eval suite): any bytes either fail with a message
// or give steps whose every frame's edits apply to the built-in scene, or fail naming a target.
#include "fuzz_support.h"
#include "retile/edit.h"
#include "retile/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace retile;
  std::string text(reinterpret_cast<const char*>(data), size);
  auto scenario = parseScenario(text, "script.json");
  if (!scenario) {
    if (scenario.error().empty()) fuzz::invariant("a parse failure without a message");
    return 0;
  }
  Scene scene = makeDefaultScene();
  NodeId selection = kNoNode;
  int budget = 2000;  // frames tried: a script of a million waits says nothing more
  for (const ScenarioStep& step : scenario->steps) {
    for (int f = 0; f < step.frames && budget > 0; ++f, --budget) {
      auto edits = stepEdits(step, f, scene, selection);
      if (!edits) break;
      if (edits->select) selection = *edits->select;
      for (const Edit& e : edits->edits) (void)applyEdit(scene, e);
    }
  }
  return 0;
}
