// What a scene has besides geometry and materials, one row per feature: the renderer compiles the
// trace kernel without the code for what a scene lacks (scene.glsl hasFeature). layouts.h makes
// each row a constant kFeature<name> = 1 << bit for C++ and GLSL and kFeatureAll of them all;
// Renderer::kernelFeatures names the compiled ones by their labels. RenderSceneData::features
// (render_scene.cpp) says which a scene has. Included by layouts.h with RETILE_KERNEL_FEATURE
// defined: no include guard.
//
// RETILE_KERNEL_FEATURE(name, bit, label)

RETILE_KERNEL_FEATURE(Textures, 0, "textures")  // some material reads an albedo or blend-ratio texture
RETILE_KERNEL_FEATURE(EnvConstant, 1, "constant environment")
RETILE_KERNEL_FEATURE(EnvMap, 2, "environment map")
RETILE_KERNEL_FEATURE(Emitters, 3, "emissive triangles")
RETILE_KERNEL_FEATURE(DeltaLights, 4, "delta lights")  // point, spot and directional lights
RETILE_KERNEL_FEATURE(UncheckedShading, 5, "unchecked shading normals")  // ShadingConvention::Unchecked (scene.h)
RETILE_KERNEL_FEATURE(Bump, 6, "bump maps")  // some material has a bump map
RETILE_KERNEL_FEATURE(EmissionTextures, 7, "emission textures")  // some emitter's emission is textured
RETILE_KERNEL_FEATURE(Blend, 8, "blends")  // some material blends with another (Material::blendWith)
// How a sample's offset in its pixel is drawn (exactly one): the filter's tabulated inverse CDF, a
// tent's exact inverse, the stepped table searched step by step (a Gaussian), or the stepped tent,
// whose steps are found in closed form (FilterSampling::SteppedTable, render_scene.h).
RETILE_KERNEL_FEATURE(FilterTable, 9, "filter table")
RETILE_KERNEL_FEATURE(FilterTent, 10, "exact tent filter")
RETILE_KERNEL_FEATURE(FilterStepped, 11, "stepped filter table")
RETILE_KERNEL_FEATURE(Sun, 12, "suns with a disc")  // some directional light has a disc (Light::angularRadius)
RETILE_KERNEL_FEATURE(InstanceTransforms, 13, "instance transforms")  // some instance is not in world space as it is
RETILE_KERNEL_FEATURE(FilterSteppedTent, 14, "stepped tent")
RETILE_KERNEL_FEATURE(LowThroughputRoulette, 15, "low-throughput roulette")  // Roulette::LowThroughput (scene.h)
// The instance BVH's leaves are the instances' own top nodes and triangles, copied into its part
// of the buffer, not instance records: a ray goes from the instance BVH into an instance without
// a step of its own, and a triangle names its instance in e2.w (kTriInstanceMask, with its
// kTriSheet, kTriCullBack, kTriBoundary and kTriAlphaTested flags). Only for scenes without instance
// transforms whose triangles each belong to one instance (render_geometry.cpp packInstances);
// ignored with kFeatureInstanceTransforms.
RETILE_KERNEL_FEATURE(DirectReferences, 16, "direct references")
// How bitmaps' texels are stored (kTexEightBit): some in 8 bits, some in halves (an environment
// map is), some 8-bit ones sRGB-encoded. Each way of reading them costs speed wherever a texture
// lookup is inlined (the traversal loop's cut-out test too), read or not: 45 % on the living room
// with all three compiled in, where it has only the first. layouts.h also has them as macros
// (RT_FEATURE_BYTE_TEXELS and on), for the preprocessor (scene.glsl bitmapTexel).
RETILE_KERNEL_FEATURE(ByteTexels, 17, "8-bit texels")
RETILE_KERNEL_FEATURE(HalfTexels, 18, "half-float texels")
RETILE_KERNEL_FEATURE(SrgbTexels, 19, "sRGB texels")
// RayOffset::FixedEpsilon (scene.h): a ray leaving a surface skips what lies within
// kFixedRayEpsilon of it (scene units), the same for every primitive; so does one passing a
// cut-out (scene.glsl Trace::hitForward).
RETILE_KERNEL_FEATURE(FixedEpsilon, 20, "fixed ray epsilon")
// Some visible object is hit from the front only (Object::cullBackFaces, kInstanceCullBack).
RETILE_KERNEL_FEATURE(CullBack, 21, "back faces culled")
// Some emitter emits into a cone narrower than its hemisphere (Material::emissionCone; the cosine
// in its material's eighth texel, z).
RETILE_KERNEL_FEATURE(EmissionCone, 22, "emission cones")
// Light that arrives in fewer than FrameUniforms::bounces.x bounces is left out (RenderSettings::minBounces).
RETILE_KERNEL_FEATURE(MinBounces, 23, "min bounces")
// Light samples choose among the emissive instances (light groups) by what each would give the
// shading point (lights.glsl lightGroupWeight), then a triangle of the chosen one by power;
// without it, a triangle of all of them by power. For 2 to kMaxLightGroups groups
// (FrameUniforms::bounces.y).
RETILE_KERNEL_FEATURE(LightGroups, 24, "light groups")
// Some material reads a roughness texture (a thin sheet: its thickness). Apart from the albedo's:
// each texture lookup the kernel has costs every shading point (the kitchen, whose textures are
// all albedos, 1.04x the samples/s without it).
RETILE_KERNEL_FEATURE(RoughnessTextures, 25, "roughness textures")
// Some thin sheet reads a texture (albedo, thickness or bump map): shadow rays that pass a sheet
// (trace.comp sheetPasses) then look them up as its shading does. Without it they take its
// untextured values, which are all it has (the kitchen 1.05x the samples/s).
RETILE_KERNEL_FEATURE(SheetTextures, 26, "textured thin sheets")
// The tracer counts what it sees of the selection per tile (Renderer::setSelection), for the
// planner's indirection-aware policy: compiled in only for the frames that count
// (FrameOptions::selectionTileSize), since lavapipe runs the counting's atomics, each a loop over
// the lanes, at every shading point whether or not a lane counts (the Cornell box 1.08x the
// samples/s without).
RETILE_KERNEL_FEATURE(SelectionCounts, 27, "selection counts")
