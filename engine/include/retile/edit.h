// Edits are plain values that describe a change to a Scene. The GUI thread applies them to its
// document and sends the same values to the render thread, which applies them to its copy
// between frames. Each edit names one target, so a queue can coalesce repeated edits of the
// same target (a slider drag) into the newest one.
#pragma once

#include <cstdint>
#include <string>
#include <variant>

#include "retile/error.h"
#include "retile/scene.h"

namespace retile {

// Whole-value edits: the new value replaces the node with the same id.
struct SetMaterial {
  Material material;
};
struct SetObject {
  Object object;
};  // transform, visibility, name, material assignment
struct SetLight {
  Light light;
};
struct SetTexture {
  Texture texture;
};
struct SetCamera {
  Camera camera;
};
struct SetEnvironment {
  Environment environment;
};
struct SetRenderSettings {
  RenderSettings settings;
};
// Adding nodes: the id must be unused (take it from Scene::newId on the document).
struct AddMesh {
  Mesh mesh;
};
struct AddMaterial {
  Material material;
};
struct AddObject {
  Object object;
};
struct AddLight {
  Light light;
};
struct AddTexture {
  Texture texture;
};
// Removes any node; references to it (an object's material, a material's texture) are cleared.
struct RemoveNode {
  NodeId id = kNoNode;
};

using Edit = std::variant<SetMaterial, SetObject, SetLight, SetTexture, SetCamera, SetEnvironment, SetRenderSettings, AddMesh, AddMaterial,
                          AddObject, AddLight, AddTexture, RemoveNode>;

// What an applied edit invalidates in a render scene. A renderer updates only what is flagged:
// a transform never touches mesh BVHs, a material never touches instances.
enum UpdateFlags : std::uint32_t {
  kUpdateNone = 0,
  kUpdateMaterials = 1u << 0,
  kUpdateTextures = 1u << 1,
  kUpdateInstances = 1u << 2,  // transforms, visibility, material assignment: top-level BVH
  kUpdateGeometry = 1u << 3,   // meshes added or removed: bottom-level BVHs
  kUpdateLights = 1u << 4,     // delta lights, or emitters moved/recoloured
  kUpdateCamera = 1u << 5,
  kUpdateEnvironment = 1u << 6,
  kUpdateSettings = 1u << 7,
  kUpdateAll = 0xffu,
};

// The id an edit targets (kNoNode for camera, environment and settings, which are singletons).
NodeId editTarget(const Edit& edit);
// A key that is equal for two edits that may be coalesced (same kind, same target).
std::uint64_t editCoalesceKey(const Edit& edit);
const char* editName(const Edit& edit);

// Whether applying `edit` to `before` can change a rendered pixel. False for what no render
// reads: a new name; a node nothing visible uses (a texture or material no shown object reaches,
// a mesh no shown object has); an object or light hidden before and after; a node just added
// that nothing references yet. True when in doubt (camera, environment, settings).
bool changesImage(const Scene& before, const Edit& edit);

// Applies an edit to a scene. Fails (leaving the scene untouched) when the target does not exist,
// an added id is taken, or a value is unusable (NaN transform, reference to a missing node).
Result<std::uint32_t> applyEdit(Scene& scene, const Edit& edit);

// A scene with a version that every applied edit advances. Owned by one thread at a time.
class Document {
 public:
  Document() = default;
  explicit Document(Scene scene) : scene_(std::move(scene)) {}

  const Scene& scene() const { return scene_; }
  std::uint64_t version() const { return version_; }
  Result<std::uint32_t> apply(const Edit& edit);

 private:
  Scene scene_;
  std::uint64_t version_ = 1;
};

}  // namespace retile
