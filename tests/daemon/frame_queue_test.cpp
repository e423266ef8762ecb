// SPDX-License-Identifier: Apache-2.0
#include "frame_queue.hpp"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace cellmap::daemon {
namespace {

using std::chrono::milliseconds;

SweepFrame frame_at(double stamp) {
  SweepFrame f;
  f.frame.stamp = stamp;
  return f;
}

// What the queue holds, in order: a frame's stamp, or -1 for the end of a sweep.
std::vector<double> drain(FrameQueue& queue) {
  std::vector<double> items;
  while (std::optional<FrameItem> item = queue.take(milliseconds(0)))
    items.push_back(item->frame ? item->frame->frame.stamp : -1.0);
  return items;
}

TEST(FrameQueueTest, AFullQueueDropsTheOldestFrameButNeverTheEndOfASweep) {
  FrameQueue queue(2);
  queue.put(frame_at(1));
  queue.end_sweep();
  queue.put(frame_at(2));
  queue.put(frame_at(3));  // full: frame 1 goes, its sweep's end stays
  queue.put(frame_at(4));  // frame 2 goes
  EXPECT_EQ(queue.dropped(), 2u);
  EXPECT_EQ(drain(queue), (std::vector<double>{-1, 3, 4}));
}

TEST(FrameQueueTest, EndsWithNoFrameBetweenAreOne) {
  FrameQueue queue(4);
  queue.end_sweep();
  queue.end_sweep();
  queue.put(frame_at(1));
  queue.end_sweep();
  queue.end_sweep();
  EXPECT_EQ(drain(queue), (std::vector<double>{-1, 1, -1}));
  EXPECT_EQ(queue.dropped(), 0u);
}

TEST(FrameQueueTest, AProducerThatWaitsForRoomLosesNoFrame) {
  FrameQueue queue(3);
  std::vector<double> got;
  std::thread consumer([&] {
    while (got.size() < 60) {
      if (std::optional<FrameItem> item = queue.take(milliseconds(10000)); item && item->frame)
        got.push_back(item->frame->frame.stamp);
    }
  });
  for (int i = 0; i < 60; ++i) {
    ASSERT_TRUE(queue.wait_for_room(milliseconds(10000)));
    queue.put(frame_at(i));
    if (i % 10 == 9) queue.end_sweep();
  }
  consumer.join();
  EXPECT_EQ(queue.dropped(), 0u);
  ASSERT_EQ(got.size(), 60u);
  for (int i = 0; i < 60; ++i) EXPECT_EQ(got[std::size_t(i)], i);
  for (int i = 0; i < 3; ++i) queue.put(frame_at(i));
  EXPECT_FALSE(queue.wait_for_room(milliseconds(1))) << "nobody takes them";
  queue.end_sweep();
  EXPECT_FALSE(queue.wait_for_room(milliseconds(1))) << "an end of sweep takes no room, a frame does";
}

TEST(FrameQueueTest, CloseWakesAWaitingConsumer) {
  FrameQueue queue(1);
  std::thread closer([&] { queue.close(); });
  EXPECT_FALSE(queue.take(milliseconds(60000)).has_value());
  closer.join();
}

}  // namespace
}  // namespace cellmap::daemon
