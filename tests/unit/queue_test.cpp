// The render thread's two channels without a GPU: the coalescing command queue and the
// triple-buffered frame mailbox (run these under the tsan preset too).
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "retile/engine.h"

namespace retile {
namespace {

Edit moveObject(NodeId id, float x) {
  Object o;
  o.id = id;
  o.transform = Mat4::translate({x, 0, 0});
  return SetObject{o};
}

float xOf(const EditQueue::Entry& e) {
  return std::get<SetObject>(std::get<Edit>(e.command)).object.transform.transformPoint(Vec3{0.0f}).x;
}

TEST(EditQueue, RepeatedEditsOfOneTargetCoalesceIntoTheNewest) {
  EditQueue q;
  for (int i = 1; i <= 50; ++i) q.push(moveObject(7, static_cast<float>(i)), static_cast<std::uint64_t>(i));
  q.push(moveObject(8, -1.0f), 51);
  q.push(moveObject(7, 99.0f), 52);
  auto entries = q.drain();
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(xOf(entries[0]), 99.0f) << "a drag becomes its newest value";
  EXPECT_EQ(entries[0].version, 52u);
  EXPECT_EQ(xOf(entries[1]), -1.0f) << "another target keeps its own entry";
  EXPECT_EQ(q.coalesced(), 50u);
  EXPECT_TRUE(q.drain().empty());
}

TEST(EditQueue, NothingJumpsAnAddOrRemove) {
  EditQueue q;
  q.push(moveObject(7, 1.0f), 1);
  q.push(Edit{RemoveNode{7}}, 2);
  q.push(moveObject(7, 2.0f), 3);  // must stay after the removal (it will fail there, visibly)
  auto entries = q.drain();
  ASSERT_EQ(entries.size(), 3u);
  EXPECT_TRUE(std::holds_alternative<RemoveNode>(std::get<Edit>(entries[1].command)));
}

TEST(EditQueue, SessionCommandsCoalesceByKind) {
  EditQueue q;
  q.push(SelectCommand{1});
  q.push(ResizeCommand{100, 50});
  q.push(SelectCommand{2});
  q.push(ResizeCommand{200, 100});
  auto entries = q.drain();
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(std::get<SelectCommand>(entries[0].command).object, 2u);
  EXPECT_EQ(std::get<ResizeCommand>(entries[1].command).width, 200);
}

TEST(EditQueue, ConcurrentProducersLoseNothing) {
  EditQueue q;
  std::atomic<int> drained{0};
  std::atomic<bool> done{false};
  std::thread consumer([&] {
    while (!done || q.size() > 0) {
      q.waitForWork(std::chrono::milliseconds(5));
      drained += static_cast<int>(q.drain().size());
    }
  });
  std::vector<std::thread> producers;
  for (int p = 0; p < 4; ++p)
    producers.emplace_back([&, p] {
      for (int i = 0; i < 500; ++i) q.push(Edit{RemoveNode{static_cast<NodeId>(p * 1000 + i)}});  // never coalesced
    });
  for (auto& t : producers) t.join();
  done = true;
  q.wake();
  consumer.join();
  EXPECT_EQ(drained.load(), 2000);
}

TEST(Mailbox, NewestWinsAndNobodyWaits) {
  Mailbox<int> box;
  EXPECT_EQ(box.latest(), nullptr);
  box.publish(std::make_shared<const int>(1));
  box.publish(std::make_shared<const int>(2));
  box.publish(std::make_shared<const int>(3));
  ASSERT_NE(box.latest(), nullptr);
  EXPECT_EQ(*box.latest(), 3);
  EXPECT_EQ(*box.latest(), 3) << "reading again gives the same newest value";
  box.publish(std::make_shared<const int>(4));
  EXPECT_EQ(*box.latest(), 4);
}

TEST(Mailbox, ReaderSeesNonDecreasingValuesUnderConcurrency) {
  Mailbox<int> box;
  constexpr int kCount = 20000;
  std::thread writer([&] {
    for (int i = 1; i <= kCount; ++i) box.publish(std::make_shared<const int>(i));
  });
  int last = 0;
  bool ordered = true;
  while (last < kCount) {
    auto v = box.latest();
    if (!v) continue;
    if (*v < last) ordered = false;
    last = *v;
  }
  writer.join();
  EXPECT_TRUE(ordered);
  EXPECT_EQ(*box.latest(), kCount);
}

}  // namespace
}  // namespace retile
