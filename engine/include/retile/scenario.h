// Scripted edit scenarios (`retile edit`): a JSON file of timed steps played against a
// RenderSession one frame at a time, as an artist's edits would arrive.
//
//   { "converge": 1024,                      // spp accumulated before the first step
//     "steps": [
//       { "select": "Cup" },                 // selects an object (no frame); a list of names
//                                            // selects the first that exists, so one script
//                                            // can serve several scenes
//       { "move": [0, 0.005, 0], "frames": 100, "object": "Cup" },  // per frame; default: selection
//       { "wait": 100 },                     // frames with no edit
//       { "material": "Ceramic", "set": { "roughness": 0.4, "albedo": [0.8, 0.2, 0.2] } },
//       { "light": "Area Light", "move": [0.5, 0, 0], "color": [1, 0.8, 0.6], "intensity": 2 },
//       { "camera": { "position": [0, 1, 5], "target": [0, 0.5, 0] } },
//       { "focus": [ { "pixel": [100, 90], "follows": false },     // image pixels, or
//                    { "uv": [0.7, 0.4], "follows": true } ] } ] }  // fractions of the image
//
// Objects are named by name, or as "#ID" (the node id) when names repeat or are empty. A `light`
// names a Light node or an emissive object (the default scene's area light): colour
// and intensity set the emission, `move` translates it. Every step but `select` and `focus` takes
// `frames` (default 1); an edit step applies its edit on each of them for `move`, on the first
// for the others. Pure data and parsing: any thread.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "retile/edit.h"
#include "retile/error.h"
#include "retile/method.h"
#include "retile/scene.h"

namespace retile {

struct ScenarioStep {
  enum class Kind { Select, Move, Wait, Material, Light, Camera, Focus } kind = Kind::Wait;
  std::string target;                   // object, material or light name
  std::vector<std::string> candidates;  // select: names to try in order
  int frames = 1;
  Vec3 vector{0.0f};  // move: per frame
  std::optional<float> roughness, ior, intensity;
  std::optional<Vec3> albedo, emission, color, position;
  std::optional<Vec3> cameraPosition, cameraTarget;
  std::vector<FocusPoint> focus;
  std::vector<bool> focusIsUv;  // per focus point: given as fractions of the image size
};

struct Scenario {
  std::string name;
  int converge = 0;  // spp before the first step
  std::vector<ScenarioStep> steps;
  int totalFrames() const;
};

Result<Scenario> parseScenario(const std::string& text, const std::string& name);
Result<Scenario> loadScenario(const std::filesystem::path& file);

// What one frame of a step does: edits to apply, and for select and focus steps their values.
struct StepEdits {
  std::vector<Edit> edits;
  std::optional<NodeId> select;                  // a select step
  std::optional<std::vector<FocusPoint>> focus;  // a focus step
};
// The edits of frame `frameInStep` (from 0) of a step, against `scene` as it is now (focus points
// in pixels of the scene's image size). Fails naming the target when it does not exist.
Result<StepEdits> stepEdits(const ScenarioStep& step, int frameInStep, const Scene& scene, NodeId selection);

// Relative RMSE of two images' luminance after averaging b x b pixel blocks (b = 1: per pixel):
// sqrt(mean((a - r)^2)) / mean(r). Blocks tame the noise both renders still carry. With a mask (a
// byte per pixel), only masked pixels count: a block is the mean of its masked pixels, and blocks
// without one are left out.
double relativeRmse(const std::vector<float>& rgbA, const std::vector<float>& rgbRef, int width, int height, int block,
                    const std::uint8_t* mask = nullptr);

}  // namespace retile
