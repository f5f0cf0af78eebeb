// The trace kernel's descriptor set 0, one row per binding: layouts.h makes each row a constant
// kBind<name> for C++ and GLSL (common/scene.glsl and trace.comp declare their buffers at it), and
// the renderer builds the pipeline's layout from the rows' kinds (vk::Binding). Included by
// layouts.h and renderer.cpp with RETILE_TRACE_BINDING defined: no include guard.
//
// RETILE_TRACE_BINDING(name, binding, kind)

RETILE_TRACE_BINDING(Frame, 0, Storage)          // FrameUniforms
RETILE_TRACE_BINDING(Work, 1, Storage)           // WorkItem per item
RETILE_TRACE_BINDING(Traversal, 2, StorageTexel) // nodes, triangles, instance records (rgba32f)
RETILE_TRACE_BINDING(TriShade, 3, UniformTexel)  // kTriShadeTexels per triangle
RETILE_TRACE_BINDING(Instances, 4, UniformTexel) // kInstanceTexels per instance
RETILE_TRACE_BINDING(Materials, 5, UniformTexel) // kMaterialTexels per material
RETILE_TRACE_BINDING(TexInfo, 6, UniformTexel)   // kTextureTexels per texture
RETILE_TRACE_BINDING(Texels, 7, StorageTexel)    // bitmaps' texels, pairs of words (rg32ui)
RETILE_TRACE_BINDING(Emitters, 8, UniformTexel)  // kEmitterTexels per emissive triangle
RETILE_TRACE_BINDING(Alias, 9, UniformTexel)     // the emitters' alias table, then light groups
RETILE_TRACE_BINDING(Delta, 10, UniformTexel)    // kDeltaLightTexels per light
RETILE_TRACE_BINDING(EnvCdf, 11, UniformTexel)   // the environment map's CDF
RETILE_TRACE_BINDING(Samples, 12, Storage)       // a vec4 per sample slot
RETILE_TRACE_BINDING(Aux, 13, Storage)           // kAuxVec4s per sample slot
RETILE_TRACE_BINDING(Stats, 14, Storage)         // kStatsCount counters
RETILE_TRACE_BINDING(Selection, 15, Storage)     // the selection's sets and counters
RETILE_TRACE_BINDING(FilterWarp, 16, UniformTexel)  // the pixel filter's table
