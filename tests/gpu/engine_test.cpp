// The render thread end to end on lavapipe: frames arrive without the caller waiting on them,
// edits reach the session with their document version, bad commands become errors.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <thread>

#include <unistd.h>

#include "gpu_support.h"
#include "retile/engine.h"
#include "retile/io.h"
#include "retile/session.h"
#include "scene/synthetic.h"
#include "test_support.h"

namespace retile {
namespace {

using namespace std::chrono_literals;

// Polls (the test thread may wait; the GUI never does) until `pred` holds for the newest frame.
template <class Pred>
std::shared_ptr<const FrameRecord> waitFor(Engine& e, Pred pred, std::chrono::seconds limit = 60s) {
  auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    auto f = e.latestFrame();
    if (f && pred(*f)) return f;
    std::this_thread::sleep_for(5ms);
  }
  return nullptr;
}

Scene smallDefault() {
  Scene s = makeDefaultScene();
  s.settings.width = 64;
  s.settings.height = 36;
  s.settings.maxBounces = 3;
  return s;
}

// The process's resident memory, from /proc (Linux, like every machine Retile runs on).
long residentBytes() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return -1;
  long pages = 0, resident = 0;
  const int n = std::fscanf(f, "%ld %ld", &pages, &resident);
  std::fclose(f);
  return n == 2 ? resident * sysconf(_SC_PAGESIZE) : -1;
}

// Frame after frame the process does not grow. With the frame constants in a uniform buffer,
// lavapipe (Mesa 22.3) recompiled the trace kernel with their values inlined at every bind and
// kept every copy: 1.9 MB a frame whatever the image size, so the editor ran out of memory within
// minutes. The denoiser's passes run every frame too.
TEST(Session, MemoryStaysFlatFrameAfterFrame) {
  RETILE_RENDERER_OR_SKIP(probe);
  probe.reset();
#if defined(RETILE_ASAN)
  GTEST_SKIP() << "AddressSanitizer keeps freed memory in quarantine: the resident size says nothing here";
#endif
  for (bool denoise : {false, true}) {
    SCOPED_TRACE(denoise ? "denoised" : "raw");
    MethodSettings m;
    m.kind = MethodKind::Spiral;
    m.tileSize = 8;
    m.denoise = denoise;
    Scene scene = smallDefault();
    scene.settings.maxBounces = 1;
    RenderSession s(scene, m);
    NodeId cup = kNoNode;
    for (const Object& o : scene.objects)
      if (o.name == "Cup") cup = o.id;
    auto frames = [&](int n) {
      for (int f = 0; f < n; ++f) {
        if (f % 10 == 0) {  // edits now and then: passes restart, the denoised region grows
          Object o = *s.scene().object(cup);
          o.transform = Mat4::translate({0.001f, 0, 0}) * o.transform;
          ASSERT_TRUE(s.applyEdit(SetObject{o}).ok());
        }
        s.renderFrame(true);
      }
    };
    frames(20);  // pipelines, caches and allocator pools settle
    const long before = residentBytes();
    ASSERT_GT(before, 0);
    frames(150);
    const long grown = residentBytes() - before;
    EXPECT_LT(grown, 40l << 20) << "grew " << grown / 1024 << " KB in 150 frames";
  }
}

// The live chart leaves a frame that waited for a compile (about a second) out of its frame-time
// axis.
TEST(Session, AFrameSaysWhetherItCompiledTheTraceKernel) {
  RETILE_RENDERER_OR_SKIP(probe);
  probe.reset();
  RenderSession s(smallDefault(), MethodSettings{});
  EXPECT_FALSE(s.renderFrame(false).compiledKernel) << "the scene's kernel is compiled with its upload";
  s.submitFrame(false);
  s.prepareMoves();  // as the engine does with its first frame in flight
  EXPECT_TRUE(s.finishFrame().compiledKernel);
  EXPECT_FALSE(s.renderFrame(false).compiledKernel);
}

// Plays the same frames with edits through renderFrame (waiting for each) and pipelined (frame
// n+1 submitted before n is finished, the edits for n+1 applied in between), and compares.
TEST(Session, PipelinedFramesEqualFramesWaitedFor) {
  RETILE_RENDERER_OR_SKIP(probe);
  probe.reset();
  for (MethodKind kind : {MethodKind::Change, MethodKind::Indirection}) {
    SCOPED_TRACE(methodName(kind));
    MethodSettings m;
    m.kind = kind;
    m.tileSize = 8;
    m.quality = kind == MethodKind::Indirection ? 0 : 4;
    m.indirectionFrames = 2;
    Scene scene = smallDefault();
    NodeId cup = kNoNode;
    for (const Object& o : scene.objects)
      if (o.name == "Cup") cup = o.id;
    auto play = [&](bool pipelined) {
      RenderSession s(scene, m);
      s.select(cup);
      std::vector<FrameRecord> out;
      for (int f = 0; f < 30; ++f) {
        if (f >= 6 && f < 12) {  // a short drag, then rest: counters, probe and passes all happen
          Object o = *s.scene().object(cup);
          o.transform = Mat4::translate({0.02f, 0, 0}) * o.transform;
          EXPECT_TRUE(s.applyEdit(SetObject{o}).ok());
        }
        if (!pipelined) {
          out.push_back(s.renderFrame(true));
          continue;
        }
        s.submitFrame(true);
        if (s.framesInFlight() > 1) out.push_back(s.finishFrame());
      }
      while (s.framesInFlight() > 0) out.push_back(s.finishFrame());
      return out;
    };
    std::vector<FrameRecord> waited = play(false), pipelined = play(true);
    ASSERT_EQ(waited.size(), pipelined.size());
    int probes = 0;
    for (std::size_t i = 0; i < waited.size(); ++i) {
      SCOPED_TRACE(testing::Message() << "frame " << i + 1);
      EXPECT_EQ(pipelined[i].frame, waited[i].frame);
      EXPECT_EQ(pipelined[i].mode, waited[i].mode);
      EXPECT_EQ(pipelined[i].servedTiles, waited[i].servedTiles);
      EXPECT_EQ(pipelined[i].tileClass, waited[i].tileClass);
      EXPECT_EQ(pipelined[i].samples, waited[i].samples);
      ASSERT_TRUE(pipelined[i].image && waited[i].image);
      EXPECT_TRUE(pipelined[i].image->color == waited[i].image->color) << "the same pixels";
      EXPECT_TRUE(pipelined[i].image->objectId == waited[i].image->objectId);
      probes += waited[i].mode == "probe";
    }
    if (kind == MethodKind::Change) {
      EXPECT_EQ(probes, 1) << "one probe, after the drag";
    } else {
      EXPECT_FALSE(waited.back().tileClass.empty()) << "counters were gathered";
    }
  }
}

// The device memory split (bench room's columns) adds up, and each part is what it says: 48 bytes
// of positions per unique triangle, 64 of shading data.
TEST(Engine, SceneMemoryPartsAddUp) {
  RETILE_RENDERER_OR_SKIP(r);
  r->setScene(makeFurnishedRoom(20000));
  const Renderer::SceneMemory m = r->sceneMemory();
  EXPECT_EQ(m.triangles + m.bvh + m.shading + m.textures + m.other, r->sceneDeviceBytes());
  EXPECT_EQ(m.triangles, r->sceneTriangles() * 48);
  EXPECT_EQ(m.shading, r->sceneTriangles() * 64);
  EXPECT_GT(m.bvh, r->sceneTriangles() * 8) << "a node per few triangles";
}

// A sky map that cannot be read is said once, as what stands in for it (a constant sky), not as
// a texture shown as a checker; said with its file's name first, so that a warning the import
// gave already is recognised (importReported). The same file as a material's texture is the
// material's checker.
TEST(Engine, AMissingSkyMapIsReportedOnceAsTheConstantSkyItBecomes) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(8, 8);
  const NodeId sky = test::addFileTexture(s, "no-such-sky.exr", TextureColorSpace::Auto);
  s.environment.type = EnvironmentType::Map;
  s.environment.map = sky;
  s.environment.color = Vec3{1.0f};
  auto naming = [](const std::vector<std::string>& warnings) {
    std::vector<std::string> out;
    for (const auto& w : warnings)
      if (w.find("no-such-sky.exr") != std::string::npos) out.push_back(w);
    return out;
  };
  const auto once = naming(r->setScene(s));
  ASSERT_EQ(once.size(), 1u);
  EXPECT_NE(once[0].find("constant"), std::string::npos) << once[0];
  EXPECT_EQ(once[0].find("checker"), std::string::npos) << once[0];
  EXPECT_TRUE(importReported(once[0], {"scene.json: environment map 'no-such-sky.exr' is missing"}));
  EXPECT_FALSE(importReported(once[0], {"scene.json: texture 'leaf.png' not found"}));

  Material m;
  m.albedoTexture = sky;
  test::addMaterial(s, m);
  const auto twice = naming(r->setScene(s));
  ASSERT_EQ(twice.size(), 2u);
  EXPECT_NE(twice[0].find("checker"), std::string::npos) << twice[0];
  EXPECT_NE(twice[1].find("constant"), std::string::npos) << twice[1];
}

TEST(Engine, FramesFlowAndEditsArriveWithTheirVersion) {
  RETILE_RENDERER_OR_SKIP(probe);
  probe.reset();  // one device at a time on lavapipe keeps the test light
  Engine engine(smallDefault(), MethodSettings{});
  std::atomic<int> called{0};
  engine.setFrameCallback([&] { ++called; });
  engine.start();
  auto first = waitFor(engine, [](const FrameRecord& f) { return f.frame >= 3; });
  ASSERT_TRUE(first) << "frames arrive";
  EXPECT_EQ(first->samples, 64u * 36u);
  ASSERT_TRUE(first->image);
  EXPECT_FALSE(engine.deviceName().empty());

  Scene doc = smallDefault();
  Material m = doc.materials[1];
  m.roughness = 0.6f;
  engine.submit(Edit{SetMaterial{m}}, 42);
  auto edited = waitFor(engine, [](const FrameRecord& f) { return f.documentVersion == 42; });
  ASSERT_TRUE(edited) << "the edit reached the render thread";
  EXPECT_EQ(edited->mode, "incremental");
  EXPECT_GT(edited->queueLength, 0u);

  // A bad edit is an error, not a crash; rendering goes on.
  Material ghost;
  ghost.id = 999999;
  engine.submit(Edit{SetMaterial{ghost}}, 43);
  std::vector<std::string> errors;
  for (int i = 0; i < 400 && errors.empty(); ++i) {
    std::this_thread::sleep_for(10ms);
    errors = engine.takeErrors();
  }
  ASSERT_FALSE(errors.empty());
  EXPECT_NE(errors[0].find("999999"), std::string::npos) << errors[0];
  std::uint64_t before = engine.framesRendered();
  ASSERT_TRUE(waitFor(engine, [&](const FrameRecord& f) { return f.frame > before + 2; }));

  // Paused: no frames; resumed: frames again, continuing the accumulation.
  engine.submit(PauseCommand{true});
  std::this_thread::sleep_for(300ms);
  std::uint64_t paused = engine.framesRendered();
  std::this_thread::sleep_for(300ms);
  EXPECT_LE(engine.framesRendered(), paused + 1);
  engine.submit(PauseCommand{false});
  ASSERT_TRUE(waitFor(engine, [&](const FrameRecord& f) { return f.frame > paused + 2; }));
  engine.stop();
  EXPECT_FALSE(engine.running());
  EXPECT_GT(called.load(), 3);
}

// A step renders that many frames and leaves the engine paused, from running or paused, steps
// sent together each counted: a teacher follows a pass frame by frame.
TEST(Engine, AStepRendersItsFramesAndStaysPaused) {
  RETILE_RENDERER_OR_SKIP(probe);
  probe.reset();
  Engine engine(smallDefault(), MethodSettings{});
  engine.start();
  ASSERT_TRUE(waitFor(engine, [](const FrameRecord& f) { return f.frame >= 2; }));
  auto settled = [&] {
    std::uint64_t n = engine.framesRendered();
    for (int i = 0; i < 20; ++i) {
      std::this_thread::sleep_for(100ms);
      if (engine.framesRendered() == n) return n;
      n = engine.framesRendered();
    }
    return n;
  };
  engine.submit(StepCommand{1});  // from running: pauses
  const std::uint64_t paused = settled();
  std::this_thread::sleep_for(300ms);
  EXPECT_EQ(engine.framesRendered(), paused) << "paused after the step";
  engine.submit(StepCommand{1});
  engine.submit(StepCommand{1});
  engine.submit(StepCommand{2});
  EXPECT_EQ(settled(), paused + 4) << "four frames stepped";
  EXPECT_EQ(engine.latestFrame()->frame, paused + 4);
  engine.submit(PauseCommand{false});
  ASSERT_TRUE(waitFor(engine, [&](const FrameRecord& f) { return f.frame > paused + 6; })) << "resumed";
  engine.stop();
}

TEST(Engine, StopsWhileRendering) {
  RETILE_RENDERER_OR_SKIP(probe);
  probe.reset();
  Engine engine(smallDefault(), MethodSettings{});
  engine.start();
  ASSERT_TRUE(waitFor(engine, [](const FrameRecord& f) { return f.frame >= 1; }));
  engine.submit(ResizeCommand{32, 18});  // queued work does not keep the thread from stopping
  engine.stop();
  EXPECT_FALSE(engine.running());
  engine.stop();  // twice is harmless
}

// Fault: the device fails mid-render (injected: lavapipe never loses its device). The failure is
// reported, rendering starts again in a new session, and that session renders the scene with
// every edit and resize that arrived before the failure: here the lights off and a new size, so a
// session that came back with the initial scene would show a lit picture of the wrong size.
TEST(Engine, AFailedDeviceIsReplacedAndTheEditsSurvive) {
  RETILE_RENDERER_OR_SKIP(probe);
  probe.reset();
  EngineOptions options;
  options.failFrame = 4;
  Scene doc = smallDefault();
  Engine engine(doc, MethodSettings{}, options);
  std::uint64_t v = 1;
  for (Material m : doc.materials) {
    m.emission = Vec3{0.0f};
    engine.submit(Edit{SetMaterial{m}}, v++);
  }
  for (Light l : doc.lights) {
    l.intensity = 0.0f;
    engine.submit(Edit{SetLight{l}}, v++);
  }
  Environment dark = doc.environment;
  dark.intensity = 0.0f;
  engine.submit(Edit{SetEnvironment{dark}}, v++);
  engine.submit(ResizeCommand{48, 24}, v);
  engine.start();

  std::vector<std::string> errors;
  for (int i = 0; i < 2000 && errors.empty(); ++i) {
    std::this_thread::sleep_for(10ms);
    errors = engine.takeErrors();
  }
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("rendering starts again"), std::string::npos) << errors[0];
  const std::uint64_t atFailure = engine.framesRendered();
  ASSERT_TRUE(waitFor(engine, [&](const FrameRecord&) { return engine.framesRendered() > atFailure + 3; })) << "frames flow again";
  EXPECT_TRUE(engine.running());
  auto f = engine.latestFrame();
  ASSERT_TRUE(f && f->image);
  EXPECT_EQ(f->documentVersion, v);
  EXPECT_EQ(f->image->width, 48);
  EXPECT_EQ(f->image->height, 24);
  double sum = 0;
  for (float c : f->image->color) sum += c;
  EXPECT_EQ(sum, 0.0) << "the lights stay off on the new device";
  EXPECT_TRUE(engine.takeErrors().empty()) << "one failure, one report";
}

}  // namespace
}  // namespace retile
