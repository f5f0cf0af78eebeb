#include "retile/engine.h"

#include <pthread.h>

#include <algorithm>
#include <exception>

#include "retile/log.h"
#include "vk/check.h"

namespace retile {

namespace {

// Two commands may be coalesced when they are of the same kind and target; session commands
// (select, focus, method, resize, pause) coalesce by kind.
std::uint64_t commandKey(const Command& c) {
  if (const Edit* e = std::get_if<Edit>(&c)) {
    if (std::holds_alternative<AddMesh>(*e) || std::holds_alternative<AddMaterial>(*e) || std::holds_alternative<AddObject>(*e) ||
        std::holds_alternative<AddLight>(*e) || std::holds_alternative<AddTexture>(*e) || std::holds_alternative<RemoveNode>(*e))
      return 0;  // structural: never coalesced
    return editCoalesceKey(*e);
  }
  if (std::holds_alternative<StepCommand>(c)) return 0;  // each step counts
  return 0xff00000000000000ull + c.index();
}

bool structural(const Command& c) { return commandKey(c) == 0; }

// Every tile that is rendered (all, or those the render region touches) has `spp` samples.
bool regionConverged(const FrameRecord& f, int spp) {
  for (std::size_t t = 0; t < f.tileSamples.size(); ++t) {
    if (!f.region.empty() && f.cols > 0) {
      int x = static_cast<int>(t) % f.cols * f.tileSize, y = static_cast<int>(t) / f.cols * f.tileSize;
      if (!f.region.overlaps(x, y, f.tileSize, f.tileSize)) continue;
    }
    if (f.tileSamples[t] < static_cast<float>(spp)) return false;
  }
  return true;
}

}  // namespace

void EditQueue::push(Command command, std::uint64_t version) {
  {
    std::lock_guard lock(mutex_);
    std::uint64_t key = commandKey(command);
    bool replaced = false;
    if (key != 0) {
      for (auto it = queue_.rbegin(); it != queue_.rend(); ++it) {
        if (structural(it->command)) break;  // the newer value must not jump an add or remove
        if (commandKey(it->command) == key) {
          it->command = std::move(command);
          it->version = std::max(it->version, version);
          ++coalesced_;
          replaced = true;
          break;
        }
      }
    }
    if (!replaced) queue_.push_back({std::move(command), version});
  }
  cv_.notify_one();
}

std::vector<EditQueue::Entry> EditQueue::drain() {
  std::lock_guard lock(mutex_);
  std::vector<Entry> out(std::make_move_iterator(queue_.begin()), std::make_move_iterator(queue_.end()));
  queue_.clear();
  woken_ = false;
  return out;
}

void EditQueue::waitForWork(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  cv_.wait_for(lock, timeout, [&] { return !queue_.empty() || woken_; });
}

void EditQueue::wake() {
  {
    std::lock_guard lock(mutex_);
    woken_ = true;
  }
  cv_.notify_all();
}

std::size_t EditQueue::size() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

std::uint64_t EditQueue::coalesced() const {
  std::lock_guard lock(mutex_);
  return coalesced_;
}

Engine::Engine(Scene scene, MethodSettings method, EngineOptions options)
    : initialScene_(std::move(scene)), initialMethod_(std::move(method)), options_(options) {}

Engine::~Engine() { stop(); }

void Engine::start() {
  if (running_.exchange(true)) return;
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void Engine::stop() {
  stop_ = true;
  queue_.wake();
  if (thread_.joinable()) thread_.join();
  running_ = false;
}

void Engine::submit(Command command, std::uint64_t documentVersion) { queue_.push(std::move(command), documentVersion); }

void Engine::setFrameCallback(std::function<void()> callback) {
  std::lock_guard lock(mutex_);
  callback_ = std::move(callback);
}

std::vector<std::string> Engine::takeErrors() {
  std::lock_guard lock(mutex_);
  return std::exchange(errors_, {});
}

std::string Engine::deviceName() const {
  std::lock_guard lock(mutex_);
  return device_;
}

void Engine::run() {
  pthread_setname_np(pthread_self(), "retile-render");
  auto report = [this](std::string e) {
    logWarning("render thread: ", e);
    std::lock_guard lock(mutex_);
    errors_.push_back(std::move(e));
  };
  std::unique_ptr<RenderSession> session;
  try {
    session = std::make_unique<RenderSession>(std::move(initialScene_), initialMethod_, options_.renderer);
    session->setDocumentVersion(options_.documentVersion);
    session->setPreview(options_.previewBlock);
    std::lock_guard lock(mutex_);
    device_ = session->deviceName();
    for (const auto& w : session->sceneWarnings()) errors_.push_back("warning: " + w);
  } catch (const std::exception& e) {
    report(cat("cannot start rendering: ", e.what()));
    running_ = false;
    return;
  }
  bool paused = false;
  int steps = 0;  // frames still to render while paused (StepCommand)
  std::shared_ptr<const FrameRecord> last;
  // What a new session needs beyond the old one's scene when a device fails.
  std::uint64_t version = options_.documentVersion;
  RegionRect region;
  int restarts = 0;  // devices started since the last frame that made it
  std::uint64_t submitted = 0;
  bool movesPrepared = false;  // the session's kernel for moved objects (RenderSession::prepareMoves)
  while (!stop_) {
    bool changed = false;
    for (auto& entry : queue_.drain()) {
      changed = true;
      version = std::max(version, entry.version);
      if (const auto* r = std::get_if<RegionCommand>(&entry.command)) region = r->region;
      try {
        std::visit(
            [&](auto& c) {
              using T = std::decay_t<decltype(c)>;
              if constexpr (std::is_same_v<T, Edit>) {
                auto r = session->applyEdit(c, entry.version);
                if (!r) report(cat(editName(c), ": ", r.error()));
              } else if constexpr (std::is_same_v<T, SelectCommand>) {
                session->select(c.object);
              } else if constexpr (std::is_same_v<T, FocusCommand>) {
                session->setFocus(c.focus);
              } else if constexpr (std::is_same_v<T, MethodCommand>) {
                if (auto bad = session->setMethod(c.method); !bad.empty()) report(cat("method: ", bad));
              } else if constexpr (std::is_same_v<T, ResizeCommand>) {
                session->resize(c.width, c.height);
              } else if constexpr (std::is_same_v<T, PauseCommand>) {
                paused = c.paused;
                steps = 0;
              } else if constexpr (std::is_same_v<T, StepCommand>) {
                paused = true;
                steps += std::max(c.frames, 0);
              } else if constexpr (std::is_same_v<T, RegionCommand>) {
                session->setRegion(c.region);
              }
            },
            entry.command);
      } catch (const std::exception& e) {
        report(cat("applying a command: ", e.what()));
      }
    }
    if (stop_) break;
    auto publish = [&](FrameRecord r) {
      auto rec = std::make_shared<const FrameRecord>(std::move(r));
      last = rec;
      mailbox_.publish(rec);
      ++frames_;
      restarts = 0;
      std::function<void()> cb;
      {
        std::lock_guard lock(mutex_);
        cb = callback_;
      }
      if (cb) cb();
    };
    bool converged = options_.maxSamplesPerPixel > 0 && last && !changed && last->mode == "refinement" && !last->tileSamples.empty() &&
                     regionConverged(*last, options_.maxSamplesPerPixel);
    try {
      if ((paused || converged) && steps == 0) {
        // Show the frame still unfinished before resting.
        while (session->framesInFlight() > 0) publish(session->finishFrame());
        queue_.waitForWork(std::chrono::milliseconds(100));
        continue;
      }
      // Pipelined: frame n+1 traces while frame n is read back and published.
      if (++submitted == static_cast<std::uint64_t>(options_.failFrame))
        throw Error("the device was lost (injected by EngineOptions::failFrame)");
      session->submitFrame(true);
      if (steps > 0) --steps;
      if (session->framesInFlight() > 1) publish(session->finishFrame());
      // Once the first picture is out, before the first drag can ask for it.
      if (!movesPrepared && last) {
        session->prepareMoves();
        movesPrepared = true;
      }
    } catch (const std::exception& e) {
      // A failed frame (device lost, out of memory) takes the session's GPU state with it, not its
      // scene, which holds every edit applied so far: rendering starts again with it in a new
      // session (the accumulation restarts), on a new device when the device was lost
      // (vk::Context gives a lost device to no one). The document, on the GUI thread, is never
      // touched.
      constexpr int kMaxRestarts = 3;
      if (++restarts > kMaxRestarts) {
        report(cat("rendering stopped: ", e.what(), " (", kMaxRestarts, " restarts failed in a row)"));
        break;
      }
      report(cat("the device failed: ", e.what(), "; rendering starts again",
                 dynamic_cast<const vk::DeviceLost*>(&e) ? " on a new device" : ""));
      try {
        Scene scene = session->scene();
        MethodSettings method = session->method();
        NodeId selection = session->selection();
        session.reset();  // destroys the old device first: lavapipe and small GPUs hold one well
        session = std::make_unique<RenderSession>(std::move(scene), std::move(method), options_.renderer);
        session->setDocumentVersion(version);
        session->setPreview(options_.previewBlock);
        session->select(selection);
        if (!region.empty()) session->setRegion(region);
        last.reset();
        movesPrepared = false;
        std::lock_guard lock(mutex_);
        device_ = session->deviceName();
      } catch (const std::exception& again) {
        report(cat("rendering stopped: no new device: ", again.what()));
        break;
      }
    }
  }
  running_ = false;
}

}  // namespace retile
