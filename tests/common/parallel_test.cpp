// SPDX-License-Identifier: Apache-2.0
#include "cellmap/common/parallel.hpp"

#include <gtest/gtest.h>
#include <sched.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace cellmap {
namespace {

// Burns about `seconds` of the calling thread's CPU.
void spin(double seconds) {
  const double until = thread_cpu_seconds() + seconds;
  while (thread_cpu_seconds() < until) {
  }
}

TEST(ParallelTest, EveryItemRunsOnceWhateverTheThreadCountOfEarlierCalls) {
  for (const int threads : {3, 1, 2, 4, 2}) {
    for (const int count : {0, 1, 5, 100}) {
      std::vector<std::atomic<int>> runs(static_cast<std::size_t>(count));
      parallel_for(count, threads, [&](int i) { ++runs[static_cast<std::size_t>(i)]; });
      for (const auto& r : runs) EXPECT_EQ(r.load(), 1) << threads << " threads, " << count << " items";
    }
  }
}

TEST(ParallelTest, ItemTRunsOnThreadTAndHelpersAreKeptBetweenCalls) {
  std::vector<std::thread::id> first(3), second(3);
  parallel_for(3, 3, [&](int t) { first[static_cast<std::size_t>(t)] = std::this_thread::get_id(); });
  parallel_for(3, 3, [&](int t) { second[static_cast<std::size_t>(t)] = std::this_thread::get_id(); });
  EXPECT_EQ(first[0], std::this_thread::get_id());
  EXPECT_NE(first[1], first[0]);
  EXPECT_NE(first[2], first[1]);
  EXPECT_NE(first[2], first[0]);
  EXPECT_EQ(second, first);
}

// Names show in top -H and perf: cut to Linux's 15 characters, and each helper named after its caller.
TEST(ParallelTest, ThreadsAreNamedAndHelpersAfterTheirCaller) {
  std::vector<std::string> names(3);
  std::thread caller([&] {
    name_this_thread("a name longer than fifteen");
    parallel_for(3, 3, [&](int t) { names[static_cast<std::size_t>(t)] = this_thread_name(); });
  });
  caller.join();
  EXPECT_EQ(names, (std::vector<std::string>{"a name longer t", "a name longe+1", "a name longe+2"}));
}

TEST(ParallelTest, NestedCallsAndOtherCallingThreadsRunTheirOwnHelpers) {
  std::atomic<int> inner{0};
  parallel_for(2, 2, [&](int) { parallel_for(4, 2, [&](int) { ++inner; }); });
  EXPECT_EQ(inner.load(), 8);
  std::atomic<int> other{0};
  std::thread caller([&] { parallel_for(6, 3, [&](int) { ++other; }); });
  caller.join();
  EXPECT_EQ(other.load(), 6);
}

TEST(ParallelTest, AnExceptionOnTheCallingThreadWaitsForTheHelpers) {
  std::atomic<int> helped{0};
  EXPECT_THROW(parallel_for(3, 3,
                            [&](int t) {
                              if (t == 0) throw std::runtime_error("item 0");
                              spin(0.01);
                              ++helped;
                            }),
               std::runtime_error);
  EXPECT_EQ(helped.load(), 2);
  std::atomic<int> after{0};
  parallel_for(3, 3, [&](int) { ++after; });
  EXPECT_EQ(after.load(), 3);
}

TEST(ParallelTest, HelperCpuCountsForTheCallingThread) {
  const double before = cpu_seconds_with_helpers();
  const double own_before = thread_cpu_seconds();
  parallel_for(2, 2, [](int t) {
    if (t == 1) spin(0.05);
  });
  const double helpers = (cpu_seconds_with_helpers() - before) - (thread_cpu_seconds() - own_before);
  EXPECT_GT(helpers, 0.04);
  EXPECT_LT(helpers, 0.5);
}

// The helper may run on every CPU the process may use but the one its caller was on when the call began, so
// a scheduler that packs woken threads onto the waker's CPU cannot run it behind its caller.
TEST(ParallelTest, HelpersAreKeptOffTheCallersCpu) {
  cpu_set_t allowed;
  ASSERT_EQ(::sched_getaffinity(0, sizeof allowed, &allowed), 0);
  if (CPU_COUNT(&allowed) < 2) GTEST_SKIP() << "one CPU: nowhere else to run a helper";
  for (int call = 0; call < 20; ++call) {
    cpu_set_t helper{};
    parallel_for(2, 2, [&](int t) {
      if (t == 1) {
        ASSERT_EQ(::pthread_getaffinity_np(::pthread_self(), sizeof helper, &helper), 0);
      }
    });
    EXPECT_EQ(CPU_COUNT(&helper), CPU_COUNT(&allowed) - 1);
    cpu_set_t both;
    CPU_OR(&both, &helper, &allowed);
    EXPECT_TRUE(CPU_EQUAL(&both, &allowed)) << "a helper allowed a CPU the process may not use";
  }
}

}  // namespace
}  // namespace cellmap
