// Every kernel's descriptor set 0, one row per binding: layouts.h makes each row a constant
// kBind<pass><name> for C++ and GLSL (the kernels declare their buffers at it, the passes bind
// their buffers to it), and render/passes.cpp builds each pass's pipeline layout from its rows'
// kinds. Included by layouts.h and passes.cpp with RETILE_PASS and RETILE_BINDING defined: no
// include guard.
//
// RETILE_PASS(pass, shader)                  a kernel: its entry file
// RETILE_BINDING(pass, name, binding, kind)  numbered from 0 without gaps within the pass

RETILE_PASS(Trace, "trace.comp")
RETILE_BINDING(Trace, Frame, 0, Storage)          // FrameUniforms
RETILE_BINDING(Trace, Work, 1, Storage)           // WorkItem per item
RETILE_BINDING(Trace, Traversal, 2, StorageTexel) // nodes, triangles, instance records (rgba32f)
RETILE_BINDING(Trace, TriShade, 3, StorageTexel)  // kTriShadeTexels per triangle
RETILE_BINDING(Trace, Instances, 4, StorageTexel) // kInstanceTexels per instance
RETILE_BINDING(Trace, Materials, 5, StorageTexel) // kMaterialTexels per material
RETILE_BINDING(Trace, TexInfo, 6, StorageTexel)   // kTextureTexels per texture
RETILE_BINDING(Trace, Texels, 7, StorageTexel)    // bitmaps' texels, pairs of words (rg32ui)
RETILE_BINDING(Trace, Emitters, 8, StorageTexel)  // kEmitterTexels per emissive triangle
RETILE_BINDING(Trace, Alias, 9, StorageTexel)     // the emitters' alias table, then light groups
RETILE_BINDING(Trace, Delta, 10, StorageTexel)    // kDeltaLightTexels per light
RETILE_BINDING(Trace, EnvCdf, 11, StorageTexel)   // the environment map's CDF
RETILE_BINDING(Trace, Samples, 12, Storage)       // a vec4 per sample slot
RETILE_BINDING(Trace, Aux, 13, Storage)           // kAuxVec4s per sample slot
RETILE_BINDING(Trace, Stats, 14, Storage)         // kStatsCount counters
RETILE_BINDING(Trace, Selection, 15, Storage)     // the selection's sets and counters
RETILE_BINDING(Trace, FilterWarp, 16, StorageTexel)  // the pixel filter's table

RETILE_PASS(Accumulate, "accumulate.comp")
RETILE_BINDING(Accumulate, Frame, 0, Uniform)     // FrameUniforms
RETILE_BINDING(Accumulate, Work, 1, Storage)      // the trace's WorkItems
RETILE_BINDING(Accumulate, Samples, 2, Storage)   // the trace's samples
RETILE_BINDING(Accumulate, Aux, 3, Storage)       // and their auxiliary vec4s
RETILE_BINDING(Accumulate, Accum, 4, Storage)     // per pixel: sum, count; compensation, squares
RETILE_BINDING(Accumulate, AccumAux, 5, Storage)  // kAuxVec4s per pixel
RETILE_BINDING(Accumulate, History, 6, Storage)   // verified reuse's kept pixels (Accum without one)

RETILE_PASS(Reuse, "reuse.comp")
RETILE_BINDING(Reuse, Frame, 0, Uniform)
RETILE_BINDING(Reuse, Items, 1, Storage)          // ReuseItem per tile
RETILE_BINDING(Reuse, Accum, 2, Storage)
RETILE_BINDING(Reuse, History, 3, Storage)
RETILE_BINDING(Reuse, AccumAux, 4, Storage)

RETILE_PASS(DenoisePrepare, "denoise_prepare.comp")
RETILE_BINDING(DenoisePrepare, Accum, 0, UniformTexel)
RETILE_BINDING(DenoisePrepare, AccumAux, 1, UniformTexel)
RETILE_BINDING(DenoisePrepare, Colors, 2, Storage)   // demodulated colour (packColor)
RETILE_BINDING(DenoisePrepare, Surface, 3, Storage)  // normal, depth
RETILE_BINDING(DenoisePrepare, Moments, 4, Storage)  // luminance, mean square, samples
RETILE_BINDING(DenoisePrepare, Tiles, 5, Storage)    // a code per tile: denoised or not

RETILE_PASS(DenoiseVariance, "denoise_variance.comp")
RETILE_BINDING(DenoiseVariance, Colors, 0, UniformTexel)  // RGBA16F view of packColor
RETILE_BINDING(DenoiseVariance, Surface, 1, UniformTexel)
RETILE_BINDING(DenoiseVariance, Moments, 2, UniformTexel)
RETILE_BINDING(DenoiseVariance, Out, 3, Storage)
RETILE_BINDING(DenoiseVariance, Gradient, 4, Storage)     // |depth gradient| per pixel

RETILE_PASS(DenoiseAtrous, "denoise_atrous.comp")
RETILE_BINDING(DenoiseAtrous, In, 0, UniformTexel)        // RGBA16F: colour, std. dev. of the mean
RETILE_BINDING(DenoiseAtrous, Surface, 1, UniformTexel)
RETILE_BINDING(DenoiseAtrous, Gradient, 2, UniformTexel)
RETILE_BINDING(DenoiseAtrous, Out, 3, Storage)

RETILE_PASS(DenoiseFinish, "denoise_finish.comp")
RETILE_BINDING(DenoiseFinish, Colors, 0, UniformTexel)    // the filtered demodulated colour
RETILE_BINDING(DenoiseFinish, Accum, 1, UniformTexel)
RETILE_BINDING(DenoiseFinish, AccumAux, 2, UniformTexel)
RETILE_BINDING(DenoiseFinish, Tiles, 3, Storage)
RETILE_BINDING(DenoiseFinish, Layer, 4, Storage)          // the denoised layer

RETILE_PASS(Compose, "compose.comp")
RETILE_BINDING(Compose, Accum, 0, UniformTexel)
RETILE_BINDING(Compose, Layer, 1, UniformTexel)
RETILE_BINDING(Compose, Tiles, 2, Storage)
RETILE_BINDING(Compose, Display, 3, Storage)              // the displayed image

RETILE_PASS(BsdfProbe, "bsdf_probe.comp")
RETILE_BINDING(BsdfProbe, Queries, 0, Storage)
RETILE_BINDING(BsdfProbe, Answers, 1, Storage)

RETILE_PASS(IntegerProbe, "integer_probe.comp")
RETILE_BINDING(IntegerProbe, Queries, 0, Storage)
RETILE_BINDING(IntegerProbe, Answers, 1, Storage)
