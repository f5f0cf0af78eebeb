// The path tracer. A Renderer owns its own headless Vulkan device, the scene's GPU copy and the
// accumulation buffers.
//
// Threads: a Renderer is used by one thread at a time (the render thread in the editor, the
// main thread on the command line); it blocks that thread while the device works. The Scene
// passed in is read during the call only.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "retile/image.h"
#include "retile/scene.h"

namespace retile {

struct RendererOptions {
  std::string device;       // a substring of the device name or an index; RETILE_DEVICE overrides
  bool validation = false;  // Vulkan validation layers (debug builds turn them on)
  // Pack the instance BVH direct where the scene allows (no instance records to step through);
  // off for comparisons. The hits are the same either way.
  bool directReferences = true;
};

// A rectangle of pixels that receives `quality` samples each in one frame. Pixel samples use
// sample indices sampleBase .. sampleBase + quality - 1. `restart` replaces the pixels' sums
// instead of adding to them.
struct TileWork {
  int x = 0, y = 0, width = 0, height = 0;
  int quality = 1;
  std::uint32_t sampleBase = 0;
  bool restart = false;
  int capStale = 0;  // > 0 (and not restart): first scale the sums down to at most this many samples
  // > 1: coarse, a preview: each sample stands for a block x block square of pixels, which all
  // take it (a tile costs 1 / block^2 of its pixels' samples); quality is per block.
  int block = 1;
};

// What a tile of the displayed image shows (DenoiseWork::tileCodes): the raw accumulation, either
// not yet re-rendered by the current pass (stale) or re-rendered (fresh), or the denoised layer
// (kShowLayer + the index of the region whose result it holds, or kShowPreviousLayer: the result
// from before the pass). Or-ed in: kShowWriteLayer makes the tile take this frame's denoised
// result into the layer; kShowFiltered lets its pixels take part in this frame's filter.
enum TileShows : std::uint32_t {
  kShowStale = 0,
  kShowFresh = 1,
  kShowLayer = 2,
  kShowPreviousLayer = 0xffff,
  kShowFiltered = 0x40000000u,
  kShowWriteLayer = 0x80000000u,
};

// The denoiser and the compositor in one frame (schedule/denoise_regions.h decides what).
struct DenoiseWork {
  bool compose = false;                     // compose the displayed image (RenderImage::display) from the codes below
  bool filter = false;                      // denoise the domain first (into the layer, for tiles with kShowWriteLayer)
  int x = 0, y = 0, width = 0, height = 0;  // the domain, pixels
  int tileSize = 16;
  std::vector<std::uint32_t> tileCodes;  // per tile of tileSize: TileShows
  int featherPixels = 0;                 // soft borders: seams between tiles showing different things blend over this
  bool timePasses = false;               // measure each pass on the device (FrameStats::denoisePasses); benchmarks
};

// The whole image denoised (global + denoise, continuous refinement, `retile render --denoise`).
DenoiseWork wholeFrameDenoise(int width, int height, int tileSize = 16);

// Samples per pixel in each frame of an offline render (Renderer::render) of a W x H image: as
// many as make about 2^18 samples, at most 64. Frames of four samples per pixel traced the
// 320x180 spaceship 1.14 times as fast as frames of one on lavapipe, where both cores idled 6.4
// to 6.8 % of a 1-spp frame (its dispatches, the last invocations' tail); how much of the gain
// that idle time makes was not settled.
int offlineSamplesPerFrame(int width, int height);

struct FrameOptions {
  bool accumulate = true;  // false: trace only (a probe); readbackFrameLuminance() gives the result
  // > 0: count what the tracer sees of the selection per tile of this size, with a kernel that has
  // the counting (compiled at the first such frame of each scene variant, about 0.3 s on
  // lavapipe, and kept; the other frames run without that code)
  int selectionTileSize = 0;
  // Paths each trace invocation runs one after another; 0 chooses from the last frame's cost.
  // Fixed by tests and benchmarks: which invocation traces a sample never changes its value.
  int pathsPerInvocation = 0;
  DenoiseWork denoise;  // after accumulating (a probe composes nothing)
  // Verified reuse (schedule/reuse.h): operations on the history of these rectangles, applied
  // before the frame's samples are accumulated; a rectangle may appear once per frame.
  struct Reuse {
    int x = 0, y = 0, width = 0, height = 0;
    enum Op { Start = 1, Reject = 2 } op = Start;
  };
  std::vector<Reuse> reuse;
};

// Per tile of the counting tile size, summed over frames until read: primary hits on the counted
// objects, later path vertices on them weighted (maxBounces + 1) / depth, and shadow rays they
// blocked; for the selected object and, beside it, for its group (every object of its material,
// which a material edit changes).
struct SelectionCounts {
  struct Set {
    std::vector<std::uint32_t> direct, reflection, shadow;
  };
  int tileSize = 0;
  Set object, group;
};

// The trace pass stops its paths once its loop-iteration count passes this (trace.comp; the
// shaders' kLoopBudget, which renderer.cpp checks against it).
inline constexpr std::uint32_t kTraceLoopBudget = 30000;

struct FrameStats {
  std::uint64_t samples = 0;  // path samples traced this frame
  std::uint64_t primaryRays = 0;
  std::uint64_t bounceRays = 0;
  std::uint64_t shadowRays = 0;
  double seconds = 0;  // wall time from submitting the frame until it was seen complete
                       // (trace + accumulate on the device, when waited for at once)
  // lavapipe stops the loops of eight lock-stepped invocations after about 32767 of the loop
  // iterations the trace pass counts (trace.comp); paths end before that, at kTraceLoopBudget.
  std::uint32_t maxLoopIterations = 0;  // the most any one invocation counted (exact for its eight)
  std::uint64_t cutPaths = 0;           // paths ended early, and slots never started, to stay under it
  std::uint64_t loopIterations = 0;     // over all invocations, to the nearest 16 per invocation
  // The most one path segment (a ray, its shading and shadow ray, for the eight) counted: paths
  // stop when the count passes kTraceLoopBudget, so this must stay below the ~2700 left to the limit.
  std::uint32_t maxSegmentIterations = 0;
  double pathsPerInvocation = 0;  // each invocation traces this many paths one after another
  // How paths ended: the rest of `samples` were absorbed (no direction to go on in, no weight
  // left), cut short, or never started (cutPaths).
  enum PathEnd { LeftTheScene, AtEmitter, AtBounceLimit, ByRoulette, kPathEnds };  // AtEmitter: one that does not reflect
  std::array<std::uint64_t, kPathEnds> pathEnds{};
  // With DenoiseWork::timePasses: the device's time for each denoiser pass, in record order.
  struct PassTime {
    const char* name;
    double ms;
  };
  std::vector<PassTime> denoisePasses;

  // Adds a later frame's figures: counts and seconds sum, the maxima stay maxima, the paths per
  // invocation are the later frame's.
  void add(const FrameStats& later);
};

struct FrameTicket {
  std::uint64_t id = 0;
};

struct RenderRequest {
  int width = 0, height = 0;  // 0: the scene's settings
  int samplesPerPixel = 0;    // 0: the scene's settings
  int maxBounces = -1;        // -1: the scene's settings
  std::uint32_t seed = 0;
  bool denoise = false;        // the result's display is the whole frame denoised
  int pathsPerInvocation = 0;  // as FrameOptions' (0: chosen from the last frame's cost)
};

class Renderer {
 public:
  explicit Renderer(const RendererOptions& options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  std::string deviceName() const;
  bool cpuDevice() const;
  std::uint32_t subgroupSize() const;  // invocations the device runs in lock-step

  // Uploads the whole scene. Returns warnings (missing textures and their substitutes).
  std::vector<std::string> setScene(const Scene& scene);
  // Refreshes what `updateFlags` (edit.h) says changed in `scene`, which must be the scene last
  // given, edited. Cost follows the flags: a transform never touches mesh data.
  std::vector<std::string> updateScene(const Scene& scene, std::uint32_t updateFlags);

  // Sets the image size and clears the accumulation.
  void resize(int width, int height);
  void setMaxBounces(int maxBounces);
  void setSeed(std::uint32_t seed);

  // Traces one frame: every tile's pixels get `quality` samples, accumulated as the tile says.
  // Tiles must not overlap within a frame. Waits for the device.
  FrameStats renderFrame(const std::vector<TileWork>& tiles, const FrameOptions& options = {});
  // The same, pipelined: returns while the device traces. The frame completes when completeFrame
  // is called, or when anything else that touches the device is (the next submitFrame, an
  // update, a read-back): its statistics are kept. With `copyImage`, the accumulated image after
  // the frame is copied aside on the device, and frameImage converts it on the calling thread
  // even while the next frame traces; it stays readable until the frame after next is submitted.
  FrameTicket submitFrame(const std::vector<TileWork>& tiles, const FrameOptions& options, bool copyImage);
  FrameStats completeFrame(FrameTicket frame);  // waits for it if it is still in flight
  RenderImage frameImage(FrameTicket frame);
  // Per pixel (row-major), the mean luminance of the last frame's samples; NaN where it traced
  // nothing. For the change-aware policy's probe frame.
  std::vector<float> readbackFrameLuminance();
  // The object whose hits are counted (kNoNode: none), and the group counted beside it. Takes
  // effect with the next frame, and clears the counts when it changes what is counted.
  void setSelection(NodeId object, std::vector<NodeId> group = {});
  // Returns the counts gathered since the last call (or since the tile size changed) and clears them.
  SelectionCounts takeSelectionCounts();
  // Reads back the accumulated image (mean per pixel) and auxiliary outputs.
  RenderImage readback();

  // Convenience for the command line and tests: resize, then samplesPerPixel samples per pixel in
  // frames of offlineSamplesPerFrame(W, H) each, then read back. `progress` gets (samples per
  // pixel done, total) after each frame and may return false to stop early.
  // Uses the scene last given to setScene/updateScene.
  RenderImage render(const RenderRequest& request, const std::function<bool(int, int)>& progress = {}, FrameStats* total = nullptr);

  // Device memory held by the scene's buffers (BVH included), and triangles, for the benchmarks.
  std::uint64_t sceneDeviceBytes() const;
  // The same bytes by what they hold: triangle positions, BVH nodes (every mesh's and the top
  // level's), per-triangle shading data (normals, uvs), textures, and the rest (instances,
  // materials, lights, the environment's distribution).
  struct SceneMemory {
    std::uint64_t triangles = 0, bvh = 0, shading = 0, textures = 0, other = 0;
  };
  SceneMemory sceneMemory() const;
  // What the trace kernel was compiled with for this scene ("lambert", "rough plastic",
  // "alpha test", "textures", "emitters", ...): a scene pays only for what it uses.
  std::vector<std::string> kernelFeatures() const;
  // Compiles, ahead of need, the kernel a move switches to: a scene packed where its objects are
  // runs without instance transforms (render/render_scene.h), and its first move would otherwise
  // wait for that kernel (about 0.3 s on lavapipe); with direct references also the kernel for
  // an object duplicated in place. Nothing for a scene that has transforms.
  void prepareMoves();
  std::size_t kernelsCompiled() const;  // trace kernel variants compiled so far, for tests
  std::uint64_t sceneTriangles() const;
  // Instances: one per object with geometry, hidden ones too (they keep their numbers, and no
  // ray reaches them). References, the instance BVH's leaves: one per visible object, more where
  // objects overlap and their own BVHs are entered at subtrees (render/render_scene.cpp).
  std::uint64_t sceneInstances() const;
  std::uint64_t sceneInstanceReferences() const;
  // Seconds the last setScene/updateScene spent building BVHs (bottom level, top level).
  double lastBlasSeconds() const;
  double lastTlasSeconds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace retile
