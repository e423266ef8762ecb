// SPDX-License-Identifier: Apache-2.0
#include "closed_sweep_first.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace cellmap::daemon {
namespace {

using std::chrono::milliseconds;

TEST(ClosedSweepFirstTest, FramesGoOnAtOnceWhileNoSweepIsProcessed) {
  ClosedSweepFirst gate;
  const std::atomic<bool> stop{false};
  gate.wait([] { return std::size_t{0}; }, 8, stop);  // returns: nothing to wait for
  { const ClosedSweepFirst::Turn turn(gate); }
  gate.wait([] { return std::size_t{0}; }, 8, stop);  // the turn ended
  SUCCEED();
}

TEST(ClosedSweepFirstTest, FramesWaitUntilTheClosedSweepWasProcessed) {
  ClosedSweepFirst gate;
  const std::atomic<bool> stop{false};
  std::atomic<bool> turn_taken{false}, processed{false};
  std::thread processing([&] {
    const ClosedSweepFirst::Turn turn(gate);
    turn_taken = true;
    std::this_thread::sleep_for(milliseconds(50));
    processed = true;  // before the turn ends
  });
  while (!turn_taken) std::this_thread::yield();
  gate.wait([] { return std::size_t{0}; }, 8, stop);
  EXPECT_TRUE(processed);
  processing.join();
}

TEST(ClosedSweepFirstTest, FramesGoOnWhenTheBacklogIsReachedOrOnStop) {
  ClosedSweepFirst gate;
  std::atomic<bool> stop{false};
  const ClosedSweepFirst::Turn turn(gate);  // held throughout: only the backlog or stop end a wait
  std::atomic<std::size_t> waiting{0};
  std::thread camera([&] {
    for (int i = 0; i < 8; ++i) {
      std::this_thread::sleep_for(milliseconds(2));
      ++waiting;
    }
  });
  gate.wait([&] { return waiting.load(); }, 8, stop);
  EXPECT_EQ(waiting, 8u);
  camera.join();
  stop = true;
  gate.wait([] { return std::size_t{0}; }, 8, stop);
}

}  // namespace
}  // namespace cellmap::daemon
