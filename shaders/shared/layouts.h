// Layouts shared by the C++ renderer and the GLSL shaders. Included by both: keep it to
// constants and std140-safe structs of 16-byte members. The C++ side static_asserts sizes.
#ifndef RETILE_SHARED_LAYOUTS_H
#define RETILE_SHARED_LAYOUTS_H

#ifdef __cplusplus
#include <cstdint>
namespace retile::gpu {
using uint = std::uint32_t;
struct alignas(16) vec4 { float x, y, z, w; };
struct alignas(16) uvec4 { std::uint32_t x, y, z, w; };
struct alignas(16) ivec4 { std::int32_t x, y, z, w; };
#define RT_CONST(type, name, value) constexpr type name = value;
#else
#define RT_CONST(type, name, value) const type name = value;
#endif

// Texels (RGBA32F) per record in the read-only scene buffers.
RT_CONST(int, kNodeTexels, 3)       // origin.xyz exponents | lo.xyz hi.x | hi.yz, inner and leaves (render/bvh.h QuantizedNode; below)
RT_CONST(int, kTriTexels, 3)        // v0.xyz triangle index | e1 = v1 - v0, last of its run | e2 = v2 - v0 (object space) instance (kFeatureDirectReferences)
RT_CONST(int, kInstanceRecordTexels, 6)  // root item, instance, flags, - | world-to-object rows 0..2 | -
RT_CONST(int, kTriShadeTexels, 4)   // n0.xyz uv0.x | n1.xyz uv0.y | n2.xyz uv1.x | uv1.y uv2.xy hasNormals
RT_CONST(int, kInstanceTexels, 5)   // shading: world-to-object rows 0..2 | - triOffset material emitterOffset | objectIndex+1 flags
RT_CONST(int, kMaterialTexels, 10)   // see render/render_scene.h packMaterial
#ifndef __cplusplus
// Where packMaterial writes each field material_fields.h places (C++ reads the same rows as
// kMaterialScalars and on): a scalar's or a texture's slot, texel * 4 + component; a colour's texel.
#define RETILE_MATERIAL_SCALAR(member, key, def, lo, hi, types, texel, component, label, unit, decimals, atLo, place, tip) \
  const int kMaterialSlot_##member = texel * 4 + component;
#define RETILE_MATERIAL_COLOR(member, key, r, g, b, hi, types, texel, label, widget, place, tip) \
  const int kMaterialTexel_##member = texel;
#define RETILE_MATERIAL_TEXTURE(member, key, types, texel, component, label, place) \
  const int kMaterialSlot_##member = texel * 4 + component;
#define RETILE_MATERIAL_CHOICE(member, key, off, on, types, flag, label, offLabel, onLabel, place, tip)
#include "shared/material_fields.h"
#undef RETILE_MATERIAL_SCALAR
#undef RETILE_MATERIAL_COLOR
#undef RETILE_MATERIAL_TEXTURE
#undef RETILE_MATERIAL_CHOICE
// A scalar field's value, and a texture field's index (-1: none), read from the texels of
// material `material` (an index).
#define RT_MATERIAL_SCALAR(material, member) \
  imageLoad(uMaterials, (material) * kMaterialTexels + kMaterialSlot_##member / 4)[kMaterialSlot_##member % 4]
#define RT_MATERIAL_TEXTURE(material, member) floatBitsToInt(RT_MATERIAL_SCALAR(material, member))
#endif
RT_CONST(int, kMaxBlendChain, 4)    // retile::kMaxBlendChain (scene.h)
RT_CONST(int, kTextureTexels, 3)    // a bitmap: offset w h kind | slopes (offset, -1: none) - - - | -; a checker: - - - kind | on.rgb resU | off.rgb resV
RT_CONST(int, kEmitterTexels, 5)    // v0.xyz area | e1.xyz instance | e2.xyz triangle | radiance.rgb pick pdf | normal.xyz emission texture
// position.xyz type | direction.xyz cosOuter | intensity.rgb cosInner | -; a sun (kLightSun):
// - type | direction.xyz 1 - cos(angular radius) | radiance.rgb solid angle | -
RT_CONST(int, kDeltaLightTexels, 4)
// With kFeatureLightGroups, the emitter alias table (one texel per emitter: keep probability,
// alias index, light group) is followed by kLightGroupTexels per group: its first emitter and
// emitter count. What the choice of group weighs is in FrameUniforms::lightGroups.
RT_CONST(int, kLightGroupTexels, 1)
RT_CONST(int, kMaxLightGroups, 16)

// The traversal buffer holds every triangle (packed triangle p at texel p * kTriTexels), then the
// mesh BVHs, the instance BVH and one record per reference to an instance (or, with
// kFeatureDirectReferences, copies of the nodes and triangle runs the references name). An item names one of
// its records: texel offset << kItemOffsetShift | n << 2 | kind. A BVH leaf's item names its
// first triangle (n 0), whose run of up to kMaxLeafTriangles ends at the one marked last; for a
// node, n is the rank of the child to take next (scene.glsl traceStep), 0 where a node names it.
RT_CONST(int, kItemNode, 0)
RT_CONST(int, kItemTriangles, 1)
RT_CONST(int, kItemInstance, 2)
RT_CONST(int, kItemOffsetShift, 4)
RT_CONST(int, kTriInstanceMask, 0x07ffffff)  // e2.w with kFeatureDirectReferences: the instance
RT_CONST(int, kTriSheet, 0x08000000)         // and its kInstanceSheet,
RT_CONST(int, kTriCullBack, 0x10000000)      // kInstanceCullBack,
RT_CONST(int, kTriBoundary, 0x20000000)      // kInstanceBoundary
RT_CONST(int, kTriAlphaTested, 0x40000000)   // and kInstanceAlphaTested flags
RT_CONST(int, kMaxLeafTriangles, 4)  // render/bvh.h maxLeafSize for mesh BVHs
// A node names its children without items, to fit 48 bytes, so that a traversal step fetches three
// texels instead of four. Its slots hold inner
// children first, then leaves, then nothing (render/bvh.h buildBvh orders them so). Bits 0..25 of
// its third texel's z and w are two bases, in units of kUnitTexels texels: `inner`, where its
// inner children are, one unit each in slot order, and `leaves`, where its leaves' records are,
// one run after another in slot order (a triangle is a unit, an instance record two). The 20 bits
// above its exponents and the two bases are the children's layout: first bits 24..31 of the
// first texel's w, then 26..31 of the third's z and w. In it: the inner children (kLayoutInner),
// the used slots (kLayoutUsed), whether the leaves are instance records (kLayoutInstances) and,
// from kLayoutStarts on, four bits for each of slots 1..3: where its leaf starts, in units from
// `leaves` (0 for an inner slot). A run of triangles ends at the triangle whose e1.w is 1.
RT_CONST(int, kUnitTexels, 3)
RT_CONST(int, kBaseBits, 26)
RT_CONST(int, kLayoutInner, 0)      // 3 bits
RT_CONST(int, kLayoutUsed, 3)       // 3 bits
RT_CONST(int, kLayoutInstances, 6)  // 1 bit
RT_CONST(int, kLayoutStarts, 7)     // 12 bits: kStartBits for each of slots 1..3
RT_CONST(int, kStartBits, 4)
RT_CONST(int, kMaxTraversalTexels, 134217728)  // 2^27: items stay positive; also lavapipe's texel-buffer limit

// Every kernel's bindings (bindings.h): kBind<pass><name>.
#define RETILE_PASS(pass, shader)
#define RETILE_BINDING(pass, name, binding, kind) RT_CONST(int, kBind##pass##name, binding)
#include "shared/bindings.h"
#undef RETILE_BINDING
#undef RETILE_PASS

// The kernel's features (kernel_features.h): kFeature<name>, and kFeatureAll of them all.
#define RETILE_KERNEL_FEATURE(name, bit, label) RT_CONST(int, kFeature##name, 1 << bit)
#include "shared/kernel_features.h"
#undef RETILE_KERNEL_FEATURE
#ifdef __cplusplus
constexpr int kFeatureAll = 0
#else
const int kFeatureAll = 0
#endif
#define RETILE_KERNEL_FEATURE(name, bit, label) | (1 << bit)
#include "shared/kernel_features.h"
#undef RETILE_KERNEL_FEATURE
    ;
// The texel formats' bits for the preprocessor (scene.glsl bitmapTexel).
#define RT_FEATURE_BYTE_TEXELS 131072
#define RT_FEATURE_HALF_TEXELS 262144
#define RT_FEATURE_SRGB_TEXELS 524288
#ifdef __cplusplus
static_assert(RT_FEATURE_BYTE_TEXELS == kFeatureByteTexels && RT_FEATURE_HALF_TEXELS == kFeatureHalfTexels &&
              RT_FEATURE_SRGB_TEXELS == kFeatureSrgbTexels);
#endif
// RayOffset::FixedEpsilon (kFeatureFixedEpsilon): what a ray leaving a surface skips, in scene units.
RT_CONST(float, kFixedRayEpsilon, 5e-4)

RT_CONST(int, kInstanceAlphaTested, 1)
RT_CONST(int, kInstanceBoundary, 2)  // its material is a boundary (kMatBoundary), which shadow rays cross
RT_CONST(int, kInstanceEmissive, 4)
RT_CONST(int, kInstanceCullBack, 8)  // no ray hits its back faces (Object::cullBackFaces)
// Its material (or one it blends with) is a thin sheet, which shadow rays pass dimmed: it pauses
// them as a cut-out pauses every ray (trace.comp sheetPasses).
RT_CONST(int, kInstanceSheet, 16)

RT_CONST(int, kMatLambert, 0)
RT_CONST(int, kMatOrenNayar, 1)
RT_CONST(int, kMatPlastic, 2)
RT_CONST(int, kMatRoughPlastic, 3)
RT_CONST(int, kMatConductor, 4)
RT_CONST(int, kMatRoughConductor, 5)
RT_CONST(int, kMatMirror, 6)
RT_CONST(int, kMatDielectric, 7)
RT_CONST(int, kMatRoughDielectric, 8)
RT_CONST(int, kMatThinSheet, 9)
RT_CONST(int, kMatNull, 10)
RT_CONST(int, kMatPhong, 11)
RT_CONST(int, kMatDiffuseTransmission, 12)
RT_CONST(int, kMatBoundary, 13)
RT_CONST(int, kMatHair, 14)
// Packed with a rough type (type | kMatBeckmann): Beckmann's distribution instead of GGX; and the
// bit of the kernel's material mask that says some material has it.
RT_CONST(int, kMatBeckmann, 256)
RT_CONST(int, kMaskBeckmann, 15)
// The bit of the kernel's material mask that says some material has a clear coat (Material::coatIor).
RT_CONST(int, kMaskCoat, 16)
// And the bit that says some glass or boundary is filled with a medium (Material::filled), and
// the one that says some such medium scatters (Material::interiorScattering).
RT_CONST(int, kMaskMedium, 17)
RT_CONST(int, kMaskScattering, 18)
// Packed with a rough type: Smith's G as the product G1(wo) G1(wi) (Material::separableShadowing).
// A multiply more per evaluation, so no kernel variant.
RT_CONST(int, kMatSeparable, 512)
// Packed with a glass type or a thin sheet: Material::tintsReflection. A multiply more, no variant.
RT_CONST(int, kMatTintsReflection, 1024)
RT_CONST(int, kMatTypeBits, 255)

RT_CONST(int, kTexBitmap, 0)
RT_CONST(int, kTexChecker, 1)
// A bitmap's flags, beside its kind (the low four bits): its file had alpha (else an alpha
// texture reads its channels' mean); its texels are 8-bit RGBA, a word each, instead of RGBA16F, two words
// each; their colour is sRGB-encoded (else linear). The texel buffer is read in pairs of words
// (R32G32_UINT), and a bitmap's offset counts pairs, so an 8-bit bitmap takes whole pairs. A bump
// map's slopes follow its colour, a word a texel of two halves (scene.glsl textureSlope).
RT_CONST(int, kTexAlpha, 16)
RT_CONST(int, kTexEightBit, 32)
RT_CONST(int, kTexSrgb, 64)
// Read at the nearest texel instead of bilinearly (Texture::interpolate), and with the edge
// texels held beyond [0, 1] instead of repeating (Texture::clampToEdge).
RT_CONST(int, kTexNearest, 128)
RT_CONST(int, kTexClamp, 32768)
// A checker's cells counted as uv times cells truncated toward zero, not floored
// (Texture::truncatedCells).
RT_CONST(int, kTexTruncate, 65536)
// And a half-float bitmap's colour is stored divided by 2^k, k in these bits, so that values
// beyond a half's range (a sun in a sky map) keep their light.
RT_CONST(int, kTexScaleShift, 8)
RT_CONST(int, kTexScaleMax, 127)
// Pairs of words the texel buffer may hold: lavapipe's texel-buffer limit (1 GiB).
RT_CONST(int, kMaxTexelPairs, 134217728)

RT_CONST(int, kLightPoint, 0)
RT_CONST(int, kLightSpot, 1)
RT_CONST(int, kLightDirectional, 2)
// A directional light with a disc: sampled over its cone, not a delta light, and seen by rays
// that leave the scene towards it. Suns come first among the lights (frame.lightPick.w counts them).
RT_CONST(int, kLightSun, 3)

RT_CONST(int, kEnvNone, 0)
RT_CONST(int, kEnvConstant, 1)
RT_CONST(int, kEnvMap, 2)

RT_CONST(int, kTraceWorkgroup, 64)
// The traversal loop ends when this many lanes of every sixteen have their rays done (trace.comp,
// rounded down): the ones done are shaded while the rest wait, their rays half traced. Six of
// eight lanes, 13 of sixteen: side by side against 12 of sixteen, 13 traced the kitchen 1.03x
// (+- 0.02), the living room 1.02x, the spaceship 1.00x, our glass and ice 1.06x as fast; 11 and
// 14 were no better.
RT_CONST(int, kTraceReadyLanes, 13)
RT_CONST(int, kStatsCount, 11)  // counters the trace pass writes (see trace.comp)
// Where the counters of the paths that ended each way start, in FrameStats::PathEnd's order.
RT_CONST(int, kStatsPathEnds, 7)
// The trace pass stops its paths once its loop-iteration count passes this (see trace.comp).
RT_CONST(uint, kLoopBudget, 30000u)
// Below lavapipe's limit (it stopped an invocation when the count read 32659): paths also stop
// when twice the longest segment so far would not fit under this.
RT_CONST(uint, kLoopLimit, 32000u)
RT_CONST(uint, kLoopIterationUnit, 16u)  // the loop-iteration sum counts in these units, so 32 bits suffice
RT_CONST(int, kAccumulateWorkgroup, 64)
// Auxiliary (guide) outputs, per sample slot and per accumulated pixel: [0] albedo.rgb, depth;
// [1] normal.xyz, object instance; [2] emission.rgb seen at the guide hit, -. The guides come from
// the first hit that is not a mirror or glass (see trace.comp).
RT_CONST(uint, kAuxVec4s, 3u)
RT_CONST(int, kMaxWorkItems, 65536)

RT_CONST(int, kFilterWarpSegments, 32)  // the pixel filter's inverse CDF: 33 points, linear between

// One frame's constants (a storage buffer for the trace kernel, a std140 uniform block for the
// accumulator: the layout is the same).
struct FrameUniforms {
  vec4 cameraPosition;  // xyz, tan(verticalFov / 2)
  vec4 cameraRight;     // xyz (unit), aspect = width / height
  vec4 cameraUp;        // xyz (unit), the thin lens's aperture radius (0: a pinhole)
  vec4 cameraForward;   // xyz (unit), the distance of the plane in focus along it
  uvec4 image;          // width, height, seed, maxBounces
  ivec4 scene;          // tlasRoot, instanceCount, emitterCount, deltaLightCount
  vec4 lightPick;       // probability of picking: emitters, environment, lights (of the delta lights' array); suns
  ivec4 environment;    // type, map texture, map width, map height
  vec4 environmentTint; // rgb multiplier (constant: the radiance), -
  vec4 environmentToMap[3]; // rows of the rotation from world directions to the map's frame (xyz)
  vec4 sceneSphere;     // bounding sphere: centre xyz, radius
  uvec4 work;           // work item count, total sample slots, where the selection buffer's
                        // counters start + 1 (0: not counting), tile size of the counters
  // A sample's offset from the pixel centre along each axis, in pixels, for u = i / 32: the
  // inverse CDF of the scene's pixel filter (filter importance sampling), 33 values, packed; the
  // last slot (filterWarp[8].w): a tent's radius, inverted exactly instead (0: use the table);
  // negative: minus the radius of a filter drawn from the stepped table, whose CDF at steps 1..30
  // then fills the first 30 slots (retile/scene.h, FilterSampling::SteppedTable); filterWarp[8].z
  // is then 1 for a tent, whose CDF the shader computes instead, and 0 for a Gaussian.
  vec4 filterWarp[9];
  // The medium the camera is in (render_scene.h mediaAround: inside glass or a boundary that holds
  // one, else the world's): its absorption xyz, 1 when it is glass's (else 0); its scattering xyz
  // and phase function's g. Then the same of the medium around that one.
  vec4 cameraAbsorption;
  vec4 cameraScattering;
  vec4 cameraOuterAbsorption;
  vec4 cameraOuterScattering;
  // The world's medium (Environment::mediumAbsorption and on; zero where it has none), which a
  // path goes back to when it leaves the outermost glass or boundary: as the camera's above, but
  // worldAbsorption.w is 1 when no light is inside glass whose medium scatters
  // (RenderSceneData::lightInScatteringGlass), else 0.
  vec4 worldAbsorption;
  vec4 worldScattering;
  ivec4 bounces;        // the fewest a path's light counts at (RenderSettings::minBounces), light groups (0 without kFeatureLightGroups), -, -
  // Two per light group (kFeatureLightGroups; lights.glsl lightGroupWeight), here because every
  // lane reads every group's at every light sample, where a texel fetch is a call per read on
  // lavapipe: a centre.xyz (on its plane, if it is one) and its weight scale (its power over pi
  // for a plane, over 4 pi otherwise); the plane's normal.xyz, 0 when the group is not one plane
  // facing one way, and the most weight it is given (the scale over its bounding radius squared).
  vec4 lightGroups[2 * kMaxLightGroups];
};

// A rectangle of pixels that receives q samples each this frame. Slot s of the frame belongs to
// the item with the largest slotStart <= s; the item's pixel p (row by row) has the q slots from
// slotStart + p q on, so that the eight lanes of the trace pass start on ceil(8 / q) pixels. Its
// sample r uses sampleBase + r as its sample index, so sampling depends only on (pixel, sample
// index, seed).
struct WorkItem {
  ivec4 rect;   // x0, y0, width, height
  uvec4 info;   // q, slotStart, sampleBase, flags (kWorkRestart: replace the pixel's sums)
  uvec4 pixels; // pixelStart (prefix of width * height over items), stale cap (kWorkCapStale),
                // block (> 1: a coarse item, each of its samples standing for a block x block
                // square of pixels, its slots per block instead of per pixel), -
};
RT_CONST(uint, kWorkRestart, 1u)
RT_CONST(uint, kWorkCapStale, 2u)   // scale the pixel's sums down to at most pixels.y samples first
// Per tile: direct hits, weighted reflections and blocked shadow rays of the selected object,
// then the same of its group (every object of its material), kCountedSets sets of three.
RT_CONST(int, kCountedSets, 2)
RT_CONST(int, kSelectionCounters, 6)
// The selection buffer starts with a word per 16 instances: two bits each, the sets the instance
// belongs to (bit 0: the selected object, bit 1: its group); the counters follow.
RT_CONST(int, kInstancesPerSetWord, 16)

struct TracePush {
  uint slotOffset;   // first slot of this dispatch (dispatches are split by size)
  uint slotCount;    // slots in this dispatch
  uint invocations;  // invocations launched; invocation i is given slots i, i + invocations, ... (trace.comp shares them among a subgroup's lanes)
  uint pad0;
};

struct AccumulatePush {
  uint pixelOffset;  // first (item, pixel) of this dispatch, in the items' pixel order
  uint pixelCount;
  uint itemCount;
  uint hasHistory;   // the history buffer is bound (verified reuse): the stale cap scales it too
};

// Verified reuse (reuse.comp, schedule/reuse.h): per pixel, the history is a copy of the
// accumulation's two vec4 as they were when an edit restarted the pixel's tile; the accumulation
// then holds history + fresh, so fresh = accumulation - history. Each item applies one operation
// to a rectangle before the frame's samples are accumulated.
struct ReuseItem {
  ivec4 rect;   // x0, y0, width, height
  uvec4 info;   // operation, pixelStart (prefix of width * height over items), -, -
};
RT_CONST(uint, kReuseStart, 1u)   // no history: keep the accumulation as the history; else go back to it
RT_CONST(uint, kReuseReject, 2u)  // drop the history from the accumulation, keep the fresh samples

struct ReusePush {
  uint pixelCount;
  uint itemCount;
  uint pad0, pad1;
};

// The denoiser (denoise_*.comp) and the compositor (compose.comp). Per tile, a code says what the
// displayed image shows there: the raw accumulation (stale: the pass has not re-rendered it yet;
// fresh: it has), or the denoised layer (a region's frozen result). kTileWrite marks the tiles
// that take this frame's denoised result into the layer.
RT_CONST(int, kDenoiseTile, 8)        // workgroups of 8x8 pixels
RT_CONST(int, kDenoiseIterations, 4)   // a-trous steps 1, 2, 4, 8 of the 3x3 kernel: a 31-pixel footprint
RT_CONST(uint, kTileStale, 0u)
RT_CONST(uint, kTileFresh, 1u)
RT_CONST(uint, kTileLayer, 2u)
RT_CONST(uint, kTileKindMask, 0xffffu)  // kind, or kTileLayer + region index: the seam test compares codes
RT_CONST(uint, kTilePreviousLayer, 0xffffu)  // the layer's result from before the pass
RT_CONST(uint, kTileFiltered, 0x40000000u)   // its pixels take part in the filter
RT_CONST(uint, kTileWrite, 0x80000000u)

struct DenoisePush {
  ivec4 domain;  // x0, y0, width, height: the pixels filtered (the whole image for compose)
  uvec4 image;   // width, height, a-trous step, feather width in pixels (compose; 0: none)
  uvec4 tiles;   // tile size, tile columns, -, -
};

#ifdef __cplusplus
static_assert(sizeof(DenoisePush) == 48);
static_assert(sizeof(FrameUniforms) == (30 + 2 * kMaxLightGroups) * 16);
static_assert(sizeof(WorkItem) == 48);
static_assert(sizeof(TracePush) == 16);
}  // namespace retile::gpu
#endif
#undef RT_CONST

#endif
