// One render session: a scene, a method and the path tracer, driven frame by frame. Edits are
// applied in place between frames; each frame plans its tiles on the exact W x H budget, traces
// them and returns a FrameRecord that carries everything overlays, charts and tests need.
//
// Threads: a RenderSession belongs to one thread at a time (the render thread in the editor, the
// main thread on the command line, see engine.h). Every call blocks while the device works.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "retile/edit.h"
#include "retile/image.h"
#include "retile/method.h"
#include "retile/render.h"
#include "retile/scene.h"

namespace retile {

// A rectangle of pixels (y down); width or height 0: none.
struct RegionRect {
  int x = 0, y = 0, width = 0, height = 0;
  bool empty() const { return width <= 0 || height <= 0; }
  // Whether the rectangle (x, y, w, h) shares a pixel with this region.
  bool overlaps(int ox, int oy, int ow, int oh) const { return ox < x + width && x < ox + ow && oy < y + height && y < oy + oh; }
};

// A denoised region of the displayed image (schedule/denoise_regions.h).
struct DenoisedRegion {
  RegionRect rect;
  std::uint64_t age = 0;  // frames since it was denoised (0: this frame)
};

// Everything about one published frame. Immutable once published; shared between threads.
struct FrameRecord {
  std::uint64_t frame = 0;            // frames rendered by the session, from 1
  std::uint64_t documentVersion = 0;  // of the last edit applied before this frame
  std::string method;                 // methodLabel(): "spiral", "spiral+smooth+denoise", ...
  std::string mode;                   // accumulator mode: global-update, incremental, refinement, probe
  bool smooth = false;
  int staleCap = 0;
  int width = 0, height = 0;
  int tileSize = 0, cols = 0, rows = 0;
  int quality = 0;                   // Q of the current pass (automatic Q resolved)
  Vec2 pointOfChange{0.0f};          // image position of the last edit's point of change
  std::vector<Vec2> pointsOfChange;  // of every edit of the last batch (planned together)
  std::vector<Vec2> focus;           // focus points in use (followed ones moved)
  NodeId selection = kNoNode;
  std::vector<float> tilePriority;       // per tile: 1 at the head of the queue to 0 at its end; -1 unqueued
  std::vector<std::uint8_t> tileClass;   // indirection: 0 high, 1 middle, 2 low, 3 rest; else empty
  std::vector<float> tileSamples;        // per tile: mean samples per pixel since its last restart
  std::vector<int> servedTiles;          // tiles traced this frame, in order
  RegionRect region;                     // the render region (empty: the whole image is rendered)
  std::vector<DenoisedRegion> denoised;  // stacked denoised regions, oldest (innermost) first; empty: none
  // Verified reuse, per tile (empty without reuse): 0 no history, 1 reusing its history, 2 history
  // rejected; and for rejected tiles the frame that rejected it (else 0).
  std::vector<std::uint8_t> tileReuse;
  std::vector<std::uint64_t> tileRejectedAt;
  int reusedTiles = 0, rejectedTiles = 0;
  std::size_t queueLength = 0;  // tiles in the current pass (or the last, once it is finished)
  std::size_t queueServed = 0;  // tiles of the pass finished
  std::uint64_t samples = 0;    // samples traced this frame: width x height, a preview's fewer
  int block = 1;                // > 1: a preview while edits come, a sample per block x block pixels
  bool compiledKernel = false;  // a trace kernel was compiled while the frame was in flight: it waited
  double scheduleMs = 0, traceMs = 0, readbackMs = 0, frameMs = 0;
  std::shared_ptr<const RenderImage> image;  // the accumulated image after this frame (may be null)

  // A pass is re-rendering its queue's tiles; otherwise (refinement, a global update) the whole
  // image takes the frame's samples.
  bool inPass() const { return queueLength > 0 && mode != "refinement"; }
};

// Image position (pixels, y down) of a world point seen by `camera` in a width x height image,
// or nullopt when it lies behind the camera.
std::optional<Vec2> projectToImage(const Camera& camera, int width, int height, Vec3 p);

class RenderSession {
 public:
  // Uploads the scene; throws Error when no Vulkan device exists.
  RenderSession(Scene scene, MethodSettings method, const RendererOptions& options = {});
  ~RenderSession();
  RenderSession(const RenderSession&) = delete;
  RenderSession& operator=(const RenderSession&) = delete;

  std::string deviceName() const;
  const Scene& scene() const { return scene_; }
  const MethodSettings& method() const;  // the focus points as the planner moved them
  NodeId selection() const { return selection_; }
  // What uploading the scene warned about (missing textures and their substitutes).
  const std::vector<std::string>& sceneWarnings() const { return sceneWarnings_; }

  // Applies an edit to the session's scene and the renderer (in place: a transform touches only
  // instance data and the top-level BVH) and measures what it changed on screen. The next frame
  // plans once for every edit applied since the last (schedule/planner.h): the queue restarts from
  // their points of change, or everything resets (camera, resolution, global method). Fails
  // leaving everything unchanged.
  Result<std::uint32_t> applyEdit(const Edit& edit, std::uint64_t documentVersion = 0);
  void select(NodeId object);
  // Focus points for the focus policies (at most 3 are used).
  void setFocus(std::vector<FocusPoint> focus);
  // A new method or new settings; returns what is wrong, or an empty string. The accumulated
  // samples stay (no setting of the method changes what a sample is).
  std::string setMethod(const MethodSettings& method);
  void resize(int width, int height);
  void setMaxBounces(int maxBounces);
  // A render region: only tiles it touches are traced, with the whole budget (see TileScheduler);
  // an empty rectangle renders the whole image again. A resize clears it.
  void setRegion(RegionRect region);
  // The document version of the scene the session was made from (frames report it until an edit).
  void setDocumentVersion(std::uint64_t version);
  // Previews (the editor): while edits come, and for kPreviewLingerMs after the last, frames
  // trace W x H / block^2 samples, each standing for a `block` x `block` square of pixels (so they
  // come block^2 times as often), over the edit's global update (a sample a block) or its pass's
  // prioritized tiles (every tile without the smooth transition; Q / block^2 a block), which they
  // restart; then the edit's plan runs again at full resolution, the prioritized tiles first and
  // the converged rest kept as the method keeps it. 1: off (the command line, the evaluation).
  // Not with verified reuse, whose test needs every sample at its pixel.
  void setPreview(int block);
  static constexpr double kPreviewLingerMs = 250;

  // Plans, traces and accumulates one frame, and waits for it. `readImage`: read the accumulated
  // image back into the record (the command line and the viewport need it; benchmarks may not).
  // Not while pipelined frames are unfinished.
  FrameRecord renderFrame(bool readImage = true);

  // The same, pipelined (the render thread, `retile edit`): submitFrame() plans the next frame and
  // returns while the device traces it; finishFrame() returns the record of the oldest frame not
  // yet finished, reading its image back (waiting for the device if it still traces). Submitting
  // frame n+1 before finishing frame n converts n's image while n+1 traces. At most two frames
  // are unfinished. Edits, selection and settings may come between any two calls: they first
  // wait for the frame in flight.
  void submitFrame(bool readImage = true);
  FrameRecord finishFrame();
  std::size_t framesInFlight() const;  // submitted and not finished
  // Renderer::prepareMoves: the render thread calls it once its first frame is out.
  void prepareMoves();

 private:
  // Waits for the frame in flight and takes what planning needs from it (counters, the probe).
  void completeGpu();
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Scene scene_;
  NodeId selection_ = kNoNode;
  std::vector<std::string> sceneWarnings_;
};

}  // namespace retile
