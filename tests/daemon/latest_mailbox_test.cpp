#include "latest_mailbox.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace cellmap::daemon {
namespace {

using std::chrono::milliseconds;

TEST(LatestMailboxTest, NewestWinsAndDropsAreCounted) {
  LatestMailbox<int> box;
  box.put(1);
  box.put(2);
  box.put(3);
  EXPECT_EQ(box.dropped(), 2u);
  EXPECT_EQ(box.take(milliseconds(0)), 3);
  EXPECT_EQ(box.take(milliseconds(0)), std::nullopt);
}

TEST(LatestMailboxTest, TakeWaitsForAProducer) {
  LatestMailbox<int> box;
  std::thread producer([&] {
    std::this_thread::sleep_for(milliseconds(20));
    box.put(42);
  });
  EXPECT_EQ(box.take(milliseconds(10000)), 42);
  producer.join();
  EXPECT_EQ(box.dropped(), 0u);
}

TEST(LatestMailboxTest, AProducerThatWaitsUntilTakenLosesNothing) {
  LatestMailbox<int> box;
  EXPECT_TRUE(box.wait_taken(milliseconds(0)));  // empty from the start
  std::vector<int> got;
  std::thread consumer([&] {
    while (got.size() < 50) {
      if (const std::optional<int> item = box.take(milliseconds(10000))) got.push_back(*item);
    }
  });
  for (int i = 0; i < 50; ++i) {
    ASSERT_TRUE(box.wait_taken(milliseconds(10000)));
    box.put(i);
  }
  consumer.join();
  EXPECT_EQ(box.dropped(), 0u);
  ASSERT_EQ(got.size(), 50u);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(got[i], i);
  box.put(7);
  EXPECT_FALSE(box.wait_taken(milliseconds(1)));  // nobody takes it
}

TEST(LatestMailboxTest, CloseWakesWaitingConsumers) {
  LatestMailbox<int> box;
  std::thread closer([&] {
    std::this_thread::sleep_for(milliseconds(20));
    box.close();
  });
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(box.take(milliseconds(60000)), std::nullopt);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
  closer.join();
}

TEST(LatestMailboxTest, FastProducerSlowConsumerKeepsOneItem) {
  LatestMailbox<std::vector<int>> box;
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
}

}  // namespace
}  // namespace cellmap::daemon
