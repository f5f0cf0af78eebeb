// The render scene: the document flattened into the arrays the shaders read (see
// shaders/shared/layouts.h). Pure CPU, no Vulkan: the GPU upload lives in the renderer.
//
// Updates follow the edit's UpdateFlags so that the cost of an edit matches what it changed:
// a transform repacks instances, the top-level BVH and emitters, never mesh data; mesh BVHs are
// cached by geometry and shared by every instance of a mesh. A mesh is packed in the space its
// first object puts it in (MeshEntry::placed), so that a scene whose objects have not moved since
// it was packed needs no instance transforms, and the kernel for it carries none; such a scene's
// instance BVH leads straight into the meshes' BVHs where each triangle has one instance
// (layouts.h kFeatureDirectReferences).
//
// Threads: owned and used by one thread (the render thread).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "io/image_io.h"
#include "render/bvh.h"
#include "retile/edit.h"
#include "retile/scene.h"
#include "shared/layouts.h"

namespace retile {

using gpu::vec4;

// A material as the shaders read it: kMaterialTexels texels, each field of material_fields.h
// that has a slot written there for its types (the kernel reads it by name), the rest where
// packMaterial's code puts them (unpackMaterial in shaders/common/bsdf.glsl and trace.comp read
// those by position). textureIndex gives a texture's index in the texture buffer (-1: none, and
// every texture when it is empty); blendWith the partner's material index (-1: no blend).
// Roughness and IOR are clamped to what the BSDF code can sample.
std::array<vec4, gpu::kMaterialTexels> packMaterial(const Material& m, const std::function<int(NodeId)>& textureIndex = {},
                                                    int blendWith = -1);

// The cosine of Material::emissionCone, 0 for the hemisphere (or a cone that is not a number):
// the front emits toward directions whose cosine with its normal is above it.
float emissionConeCos(const Material& m);

// How the trace kernel draws a sample's offset in its pixel for these settings: one of the
// gpu::kFeatureFilter... bits (FilterSampling::SteppedTable has two of its own).
int filterFeature(const RenderSettings& s);

// How much lower, about, a light sample's second moment is where it chooses one of the light
// groups of `shapes` (two texels each, FrameUniforms::lightGroups) by what it gives the point than
// where it picks among all emitters by power, over points through `bounds`; `power` is each
// group's. Light groups are compiled in from kLightGroupMinGain on.
double lightGroupGain(const std::vector<vec4>& shapes, const std::vector<double>& power, const Bounds3& bounds);
inline constexpr double kLightGroupMinGain = 1.5;
// Where they are on already, they stay on from this gain on (packEmitters).
inline constexpr double kLightGroupKeepGain = 1.3;

// Which arrays changed in the last update, so the uploader copies only those.
enum DirtyArrays : std::uint32_t {
  kDirtyGeometry = 1u << 0,   // meshTraversal, triangleShading
  kDirtyInstances = 1u << 1,  // instances, topTraversal
  kDirtyMaterials = 1u << 2,
  kDirtyTextures = 1u << 3,       // textureInfo, texels
  kDirtyEmitters = 1u << 4,       // emitters, emitterAlias, deltaLights
  kDirtyEnvironment = 1u << 5,    // environmentCdf
  kDirtyTriangleNames = 1u << 6,  // meshTraversal only: the instances its triangles name (direct)
  kDirtyAllArrays = 0xffu,
};

// A homogeneous medium as the kernel holds it (Material::interiorAbsorption and on).
struct MediumAt {
  Vec3 absorption{0.0f}, scattering{0.0f};
  float anisotropy = 0;
  bool glass = false;  // the interior of glass (which blocks shadow rays), not of a boundary
  // Nothing from infinitely far gets through it in any channel.
  bool dimsEveryChannel() const { return minComponent(absorption + scattering) > 0; }
  friend bool operator==(const MediumAt&, const MediumAt&) = default;
};

// The medium that fills the world (Environment::mediumAbsorption and on), as the kernel holds it.
MediumAt worldMediumOf(const Environment& e);

struct RenderSceneData {
  // The traversal buffer (layouts.h), in two parts so that moving an object re-uploads only the
  // second: every triangle then every mesh BVH; the instance BVH then the instance records. Its
  // items hold offsets into the whole buffer, the second part starting after the first.
  std::vector<vec4> meshTraversal;
  std::vector<vec4> topTraversal;
  std::int32_t tlasRoot = -1;         // item of the instance BVH's root
  std::vector<vec4> triangleShading;  // kTriShadeTexels per triangle
  std::vector<vec4> instances;        // kInstanceTexels per instance
  std::vector<vec4> materials;        // kMaterialTexels per material
  std::vector<vec4> textureInfo;      // kTextureTexels per texture
  std::vector<std::uint32_t> texels;  // every bitmap: 8-bit RGBA or RGBA16F words (layouts.h kTexEightBit)
  std::vector<vec4> emitters;         // kEmitterTexels per emissive triangle
  // One per emitter (keep probability, alias index, light group), then the light groups' records
  // (layouts.h kLightGroupTexels). An emitter's alias and its pick probability (emitters' radiance.w)
  // are within its group, or, with no light groups, among all emitters.
  std::vector<vec4> emitterAlias;
  // Emissive instances chosen per shading point (kFeatureLightGroups), or 0: 2 to
  // kMaxLightGroups of them where lightGroupGain is at least kLightGroupMinGain.
  int lightGroups = 0;
  std::vector<vec4> lightGroupShapes;  // two per light group, for FrameUniforms::lightGroups
  double lightGroupGain = 1;           // lightGroupGain of the emissive instances (1: fewer than 2, or more than kMaxLightGroups)
  std::vector<vec4> deltaLights;       // kDeltaLightTexels per light, suns first
  int suns = 0;                        // directional lights with a disc (kLightSun)
  std::vector<float> environmentCdf;   // marginal (h+1) then conditional rows (w+1 each)

  std::vector<NodeId> instanceObject;  // instance index -> object id (hidden objects too, never reached)
  std::size_t instanceReferences = 0;  // leaves of the instance BVH: instances or their subtrees
  Bounds3 bounds;
  // emitters, environment, delta lights; all 0 without light sampling (RenderSettings::lightSampling),
  // which turns off next-event estimation and leaves every hit's emission its full weight.
  float lightPick[3] = {0, 0, 0};
  bool lightSampling = true;  // RenderSettings::lightSampling
  int minBounces = 0;         // RenderSettings::minBounces (kFeatureMinBounces when > 0)
  int environmentType = 0;    // kEnvNone / kEnvConstant / kEnvMap
  int environmentMap = -1;    // texture index of the map
  int environmentWidth = 0, environmentHeight = 0;
  Vec3 environmentTint{0.0f};
  Mat4 environmentToMap;            // world directions to the map's frame (a rotation)
  MediumAt worldMedium;             // Environment::medium..., none unless filled()
  std::uint64_t triangleCount = 0;  // packed triangles: each mesh's once, and the copies of small shared ones
  std::uint64_t instancedTriangles = 0;
  // Some visible instance pauses traversal on its candidate hits (RETILE_ALPHA_TEST): a cut-out
  // (cutOuts), every ray, or a thin sheet (sheetShadows), shadow rays.
  bool cutOuts = false, sheetShadows = false;
  bool alphaTested() const { return cutOuts || sheetShadows; }
  bool cullBack = false;            // some visible instance is hit from the front only
  std::uint32_t materialTypes = 0;  // bit kMat... of each material type present
  bool materialTextures = false;    // some material reads an albedo or blend-ratio texture
  bool roughnessTextures = false;   // some material reads a roughness texture
  bool sheetTextures = false;       // some thin sheet reads an albedo, roughness or bump texture
  bool materialBump = false;        // some material has a bump map
  bool emissionTextures = false;    // some emissive material has an emission texture
  bool emissionCones = false;       // some emissive material emits into a cone (Material::emissionCone)
  // How the packed bitmaps' texels are stored (layouts.h kFeatureByteTexels and on).
  bool byteTexels = false, halfTexels = false, srgbTexels = false;
  bool materialBlend = false;  // some material blends with another
  // Some light or emitter may lie inside glass whose medium scatters (their bounds meet). Where
  // none does, a scattering point in such glass samples no light (trace.comp scatterInMedium).
  bool lightInScatteringGlass = true;
  bool instanceTransforms = false;  // some instance's transform is not the identity
  bool directReferences = false;    // the instance BVH is packed direct (layouts.h kFeatureDirectReferences)

  bool uncheckedShading = false;                 // RenderSettings::shading is ShadingConvention::Unchecked
  bool lowThroughputRoulette = false;            // RenderSettings::roulette is Roulette::LowThroughput
  bool fixedEpsilon = false;                     // RenderSettings::rayOffset is RayOffset::FixedEpsilon
  int filterFeature = gpu::kFeatureFilterTable;  // filterFeature(RenderSettings)
  std::uint32_t features() const;                // kFeature... (layouts.h) of what the arrays hold

  std::uint64_t deviceBytes() const;
};

// The medium a point (the camera) is in, and the one around that: those of the glass or
// boundaries around it, found by fourteen rays through the packed scene (tracePacked), each
// leaving by faces it did not enter by; a holder that most rays leave, of those that meet no
// opaque surface first (all of them again, through walls, when none does). Two levels, as a path
// keeps (trace.comp crossMedium); where no holder is, the world's medium (worldMedium). Up to
// 14 x 64 CPU traversals, so the renderer asks again only when the camera or the scene changes;
// none without glass or boundaries, or without any medium (materialTypes). It only reads `d`,
// which its owner (the render thread, see above) must not change meanwhile.
struct MediaAround {
  MediumAt in, around;
};
MediaAround mediaAround(const RenderSceneData& d, Vec3 point);

// The textures some material bumps by, as packMaterial keeps them (a strength, a type that
// reads it), sorted: these are packed with their slopes.
std::vector<NodeId> bumpTextures(const Scene& scene);

class RenderSceneBuilder {
 public:
  // Applies `flags` (from edit.h) by refreshing the affected arrays; returns DirtyArrays.
  // Warnings (missing textures and the substitutes used) are appended to `warnings`.
  std::uint32_t update(const Scene& scene, std::uint32_t flags, std::vector<std::string>* warnings);
  const RenderSceneData& data() const { return data_; }
  // Whether the instance BVH may be packed direct (layouts.h kFeatureDirectReferences) where the
  // scene allows; off, every reference is entered through its record, as for comparisons.
  void setDirectReferences(bool on) { directReferences_ = on; }

  // Seconds spent in the last update, by part, for the benchmarks.
  struct Timing {
    double blas = 0, tlas = 0, textures = 0, emitters = 0, environment = 0;
  };
  const Timing& lastTiming() const { return timing_; }
  // How many times the instance BVH's braid factor was chosen (packInstances), for the tests.
  std::uint64_t braidChoices() const { return braidChoices_; }

 private:
  struct MeshEntry {
    std::shared_ptr<const MeshGeometry> geometry;  // keeps the key alive
    Bvh bvh;
    // kTriTexels and kTriShadeTexels per triangle, packed order (w of the first unset, and of
    // the third until an instance is named in it), from the BVH build until packGeometry moves
    // them into RenderSceneData; empty after.
    std::vector<vec4> triangles;
    std::vector<vec4> shading;
    std::vector<float> steps;     // expectedSteps of each BVH node
    std::int32_t rootItem = -1;   // in data_.meshTraversal
    std::uint32_t triOffset = 0;  // global index of its first packed triangle (in data_ once placed)
    // The transform its vertices were packed with (its first object's, or the one it is a copy
    // for): an object's instance maps world space to it.
    Mat4 placed, placedInverse;
    bool used = false;
    // What its packed triangles' third texel's w holds (layouts.h kTriInstanceMask), so that
    // naming an instance again costs nothing when it is the same; kUnnamed when never written.
    static constexpr std::uint32_t kUnnamed = 0xffffffffu;
    mutable std::uint32_t named = kUnnamed;
    // Whether its triangles close a surface, every edge met once each way (closedSurface); -1 until asked.
    mutable int closed = -1;
  };
  // An object's transform from its mesh's packed space to world space.
  static Mat4 placement(const Mat4& objectTransform, const MeshEntry& mesh);
  // Decoding is the slow part of a texture update, so unchanged textures are not decoded again:
  // their texels are copied from where the last update packed them in data_.texels (a copy of
  // their own would double the memory that textures take).
  struct Decoded {
    std::string signature;
    bool ok = false;
    std::size_t offset = 0, words = 0;  // its colour in data_.texels as last packed
    std::size_t slopeWords = 0;         // its slopes' words after the colour's (0: none packed)
    int width = 0, height = 0, flags = 0;
    Vec3 mean{0.0f};
    std::string error;  // why it could not be read ("" when it was)
  };

  void packGeometry(const Scene& scene);
  // chooseBraid: choose how far instances are opened (packInstances), as when meshes change.
  // Returns whether triangles were renamed (kDirtyTriangleNames).
  bool packInstances(const Scene& scene, bool chooseBraid);
  // packInstances' steps and what they hand on (render_geometry.cpp).
  struct InstanceCandidate;
  struct InstanceRecords;
  struct BraidRef;
  struct TopPacking;
  class TopLevel;
  std::vector<InstanceCandidate> instanceCandidates(const Scene& scene) const;
  int instanceFlags(const Scene& scene, const InstanceCandidate& c) const;
  InstanceRecords packInstanceRecords(const Scene& scene, const std::vector<InstanceCandidate>& cands, bool direct, bool transforms);
  bool nameTriangles(const std::vector<InstanceCandidate>& cands, const std::vector<int>& flagsOf);
  void resetBraidIfStale(const std::vector<InstanceCandidate>& cands, std::size_t visible, bool chooseBraid);
  TopPacking chooseBraidFactors(const Scene& scene, const TopLevel& top, const std::vector<InstanceCandidate>& cands,
                                const InstanceRecords& records, bool direct);
  void packMaterials(const Scene& scene);
  void packTextures(const Scene& scene, std::vector<std::string>* warnings);
  void packEmitters(const Scene& scene);
  bool lightInScatteringGlass(const Scene& scene) const;  // RenderSceneData::lightInScatteringGlass
  // Returns the DirtyArrays it changed: kDirtyTextures when a baked sky came or went,
  // kDirtyEnvironment when the light-sampling distribution changed. An intensity or colour edit
  // changes neither, so dragging it copies no texels (packTextures runs only when textures change).
  std::uint32_t packEnvironment(const Scene& scene, std::vector<std::string>* warnings);
  // Fills data_.environmentCdf for the w x h map packed from texel word firstWord with `flags`
  // (layouts.h kTex...); returns its mean of luminance * sin(theta).
  double environmentDistribution(std::size_t firstWord, int w, int h, int flags);
  void choosePickProbabilities(const Scene& scene);
  int textureIndex(NodeId id) const;
  int materialIndex(NodeId id) const;

  RenderSceneData data_;
  // By geometry, with the object a copy is for (kNoNode: the entry every other object shares).
  std::map<std::pair<const MeshGeometry*, NodeId>, MeshEntry> meshes_;
  std::unordered_map<NodeId, Decoded> decoded_;
  // The textures packed with their slopes (bumpTextures at the last packTextures), sorted.
  std::vector<NodeId> slopeTextures_;
  std::unordered_map<NodeId, int> textureIndex_;
  // Each texture's mean RGB as packed: a textured emitter's share of the light samples.
  std::unordered_map<NodeId, Vec3> textureMean_;
  std::unordered_map<NodeId, int> materialIndex_;
  std::unordered_map<NodeId, const MeshEntry*> meshOf_;  // mesh node id -> its shared entry
  std::unordered_map<NodeId, const MeshEntry*> copyOf_;  // object id -> its own copy, if it has one
  const MeshEntry* entryOf(const Object& o) const;
  void packMesh(MeshEntry& e, const Mat4* place);
  int defaultMaterial_ = 0;
  float emitterPower_ = 0;
  float environmentPower_ = 0;
  // A baked sky is packed after the scene's textures, which end at these sizes of data_.texels
  // and data_.textureInfo (halfTexels as they leave it), so that an environment edit replaces the
  // sky alone. packedSky_ names the sky packed there (environmentSource), empty when none is.
  std::size_t sceneTexelWords_ = 0, sceneTextureInfos_ = 0;
  bool sceneHalfTexels_ = false;
  std::string packedSky_;
  // What data_.environmentCdf was made from (environmentSource; empty: no map or sky), and its
  // mean of luminance * sin(theta), the environment's power before the tint.
  std::string environmentSource_;
  double environmentMean_ = 0;
  float deltaPower_ = 0;
  bool first_ = true;
  bool directReferences_ = true;
  // Re-braiding (packInstances): references per instance tried up to kMaxBraidFactor, and at most
  // kMaxBraidReferences in all; the factors chosen for records and for a direct instance BVH
  // (indexed by direct; 0 until chosen); the visible objects when the choices were last made
  // anew, sorted.
  static constexpr std::size_t kMaxBraidFactor = 64, kMaxBraidReferences = 16384;
  std::array<std::size_t, 2> braidFactor_{0, 0};
  std::vector<NodeId> braidVisible_;
  std::uint64_t braidChoices_ = 0;
  Timing timing_;
};

// IEEE half from float (round to nearest even), for RGBA16F texels.
std::uint16_t floatToHalf(float f);
float halfToFloat(std::uint16_t h);

}  // namespace retile
