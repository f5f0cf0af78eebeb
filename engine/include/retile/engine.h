// The engine facade: a render thread that owns a RenderSession (and so the Vulkan device), fed
// with commands as values and publishing frame records through a mailbox.
//
// Threads: every public member of Engine, EditQueue and Mailbox may be called from any thread.
// Nothing here waits on rendering: submit() queues, latestFrame() swaps a pointer. The render
// thread drains the queue only between frames; exceptions on it become errors (takeErrors()). A
// frame that fails (device lost, out of device memory) is reported and rendering starts again on
// a new session and device, from the old session's scene with every command applied.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "retile/edit.h"
#include "retile/method.h"
#include "retile/render.h"
#include "retile/session.h"

namespace retile {

struct SelectCommand {
  NodeId object = kNoNode;
};
struct FocusCommand {
  std::vector<FocusPoint> focus;
};
struct MethodCommand {
  MethodSettings method;
};
struct ResizeCommand {
  int width = 0, height = 0;
};
struct PauseCommand {
  bool paused = false;
};  // paused: no frames; resuming keeps the samples
struct RegionCommand {
  RegionRect region;
};  // a render region; empty: the whole image
// Pauses (if running) and renders `frames` more frames, then stays paused: a pass followed frame
// by frame. Each is counted (never coalesced with another step).
struct StepCommand {
  int frames = 1;
};
using Command = std::variant<Edit, SelectCommand, FocusCommand, MethodCommand, ResizeCommand, PauseCommand, RegionCommand, StepCommand>;

// Commands in arrival order. A command of the same kind and target as one still queued replaces
// it (a slider drag becomes its newest value), unless an add or remove was queued after it.
class EditQueue {
 public:
  struct Entry {
    Command command;
    std::uint64_t version = 0;  // document version the command brings the scene to
  };
  void push(Command command, std::uint64_t version = 0);
  std::vector<Entry> drain();
  // Waits until something is queued, `wake()` is called or `timeout` passes.
  void waitForWork(std::chrono::milliseconds timeout);
  void wake();
  std::size_t size() const;
  std::uint64_t coalesced() const;  // commands replaced by newer ones so far

 private:
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Entry> queue_;
  std::uint64_t coalesced_ = 0;
  bool woken_ = false;
};

// Triple-buffered mailbox: the writer publishes, the reader takes the newest; neither waits for
// the other (one atomic exchange each). One writer thread and one reader thread at a time.
template <class T>
class Mailbox {
 public:
  void publish(std::shared_ptr<const T> value) {
    slots_[writer_] = std::move(value);
    unsigned old = middle_.exchange(writer_ | kFresh, std::memory_order_acq_rel);
    writer_ = old & kIndex;
  }
  // The newest published value (the same one again when nothing newer came).
  std::shared_ptr<const T> latest() {
    std::lock_guard lock(readerMutex_);  // readers among themselves only; never the writer
    if (middle_.load(std::memory_order_acquire) & kFresh) {
      unsigned old = middle_.exchange(reader_, std::memory_order_acq_rel);
      reader_ = old & kIndex;
    }
    return slots_[reader_];
  }

 private:
  static constexpr unsigned kIndex = 3, kFresh = 4;
  std::shared_ptr<const T> slots_[3];
  unsigned writer_ = 0, reader_ = 1;
  std::atomic<unsigned> middle_{2};
  std::mutex readerMutex_;
};

struct EngineOptions {
  RendererOptions renderer;
  // Continuous refinement stops (the thread sleeps until a command) once every tile has this many
  // samples per pixel; 0 refines for ever.
  int maxSamplesPerPixel = 4096;
  // The document version the initial scene corresponds to: frames carry it until the first edit.
  std::uint64_t documentVersion = 0;
  // RenderSession::setPreview: coarse frames while edits come (the editor); 1: none.
  int previewBlock = 1;
  // Fault injection for tests: the Nth frame (from 1) fails as a frame on a lost device does, so
  // that the recovery can be tested on a device that never fails. 0: never.
  int failFrame = 0;
};

class Engine {
 public:
  Engine(Scene scene, MethodSettings method, EngineOptions options = {});
  ~Engine();  // stops the thread
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  void start();
  void stop();
  bool running() const { return running_.load(); }

  void submit(Command command, std::uint64_t documentVersion = 0);
  std::shared_ptr<const FrameRecord> latestFrame() { return mailbox_.latest(); }
  // Called on the render thread after each published frame (the GUI posts a queued call).
  void setFrameCallback(std::function<void()> callback);
  // Errors raised on the render thread since the last call (failed edits, device errors).
  std::vector<std::string> takeErrors();
  std::string deviceName() const;
  std::uint64_t framesRendered() const { return frames_.load(); }
  const EditQueue& queue() const { return queue_; }

 private:
  void run();

  Scene initialScene_;
  MethodSettings initialMethod_;
  EngineOptions options_;
  EditQueue queue_;
  Mailbox<FrameRecord> mailbox_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> frames_{0};
  mutable std::mutex mutex_;  // guards errors_, device_, callback_
  std::vector<std::string> errors_;
  std::string device_;
  std::function<void()> callback_;
};

}  // namespace retile
