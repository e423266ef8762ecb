// SPDX-License-Identifier: Apache-2.0
#include "bounded_mailbox.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <thread>
#include <vector>

namespace cellmap::daemon {
namespace {

using std::chrono::milliseconds;

TEST(BoundedMailboxTest, NewestWinsAndDropsAreCounted) {
  BoundedMailbox<int> box;
  box.put(1);
  box.put(2);
  box.put(3);
  EXPECT_EQ(box.dropped(), 2u);
  EXPECT_EQ(box.take(milliseconds(0)), 3);
  EXPECT_EQ(box.take(milliseconds(0)), std::nullopt);
}

TEST(BoundedMailboxTest, TakeWaitsForAProducer) {
  BoundedMailbox<int> box;
  std::thread producer([&] {
    std::this_thread::sleep_for(milliseconds(20));
    box.put(42);
  });
  EXPECT_EQ(box.take(milliseconds(10000)), 42);
  producer.join();
  EXPECT_EQ(box.dropped(), 0u);
}

TEST(BoundedMailboxTest, AProducerThatWaitsUntilTakenLosesNothing) {
  BoundedMailbox<int> box;
  EXPECT_TRUE(box.wait_for_room(milliseconds(0)));  // empty from the start
  std::vector<int> got;
  std::thread consumer([&] {
    while (got.size() < 50) {
      if (const std::optional<int> item = box.take(milliseconds(10000))) got.push_back(*item);
    }
  });
  for (int i = 0; i < 50; ++i) {
    ASSERT_TRUE(box.wait_for_room(milliseconds(10000)));
    box.put(i);
  }
  consumer.join();
  EXPECT_EQ(box.dropped(), 0u);
  ASSERT_EQ(got.size(), 50u);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(got[i], i);
  box.put(7);
  EXPECT_FALSE(box.wait_for_room(milliseconds(1)));  // nobody takes it
}

TEST(BoundedMailboxTest, CloseWakesWaitingConsumers) {
  BoundedMailbox<int> box;
  std::thread closer([&] {
    std::this_thread::sleep_for(milliseconds(20));
    box.close();
  });
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(box.take(milliseconds(60000)), std::nullopt);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
  closer.join();
}

TEST(BoundedMailboxTest, BusyConsumerGetsOnlyTheNewestAndTheRestAreCountedDropped) {
  // The consumer takes item 0, then stays busy while items 1..2000 arrive: the mailbox holds only the newest,
  // so the consumer then gets item 2000 and the 1999 in between are counted as dropped. A queue would hand
  // over all 2001 items and drop none.
  BoundedMailbox<std::vector<int>> box;
  std::promise<void> took_first;
  std::promise<void> finish_work;
  std::vector<int> taken;
  std::thread consumer([&] {
    if (const auto first = box.take(milliseconds(10000))) taken.push_back(first->front());
    took_first.set_value();
    finish_work.get_future().wait();
    while (const auto item = box.take(milliseconds(0))) taken.push_back(item->front());
  });
  box.put(std::vector<int>(100, 0));
  took_first.get_future().wait();
  for (int i = 1; i <= 2000; ++i) box.put(std::vector<int>(100, i));
  finish_work.set_value();
  consumer.join();
  EXPECT_EQ(taken, (std::vector<int>{0, 2000}));
  EXPECT_EQ(box.dropped(), 1999u);
}

TEST(BoundedMailboxTest, FastProducerSlowConsumerKeepsOneItem) {
  BoundedMailbox<std::vector<int>> box;
  std::uint64_t taken = 0;
  std::atomic<bool> closed{false};
  std::thread consumer([&] {
    for (;;) {
      const bool was_closed = closed.load();
      if (box.take(milliseconds(200))) {
        ++taken;
        std::this_thread::sleep_for(milliseconds(1));
      } else if (was_closed) {
        break;
      }
    }
  });
  for (int i = 0; i < 2000; ++i) box.put(std::vector<int>(100, i));
  box.close();
  closed = true;
  consumer.join();
  // Every item was either taken or counted as dropped: none lost silently, none queued.
  EXPECT_EQ(taken + box.dropped(), 2000u);
  // The consumer rests 1 ms per item while the producer puts 2000 at once: items were replaced, not queued.
  EXPECT_GT(box.dropped(), 0u);
}

TEST(BoundedMailboxTest, AStalledConsumerCatchesUpOnItsBacklogInOrderThenTheOldestAreDropped) {
  BoundedMailbox<int> box(4);
  for (int i = 0; i < 4; ++i) box.put(i);
  EXPECT_FALSE(box.wait_for_room(milliseconds(0)));
  EXPECT_EQ(box.dropped(), 0u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(box.take(milliseconds(0)), i);
  EXPECT_TRUE(box.wait_for_room(milliseconds(0)));
  for (int i = 4; i < 10; ++i) box.put(i);
  EXPECT_EQ(box.dropped(), 2u);  // 4 and 5
  for (int i = 6; i < 10; ++i) EXPECT_EQ(box.take(milliseconds(0)), i);
  EXPECT_EQ(box.take(milliseconds(0)), std::nullopt);
}

}  // namespace
}  // namespace cellmap::daemon
