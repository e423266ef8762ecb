#pragma once
// Splitting a loop over a few threads: the one thread splitter of the library (the simulator's rays, the
// occupancy map's ray casting), and the CPU time of a thread with the helpers it split its work onto.

#include <time.h>

#include <algorithm>
#include <thread>
#include <vector>

namespace cellmap {

/// CPU seconds the calling thread used so far (CLOCK_THREAD_CPUTIME_ID).
inline double thread_cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

namespace detail {
// CPU seconds of the helper threads this thread's parallel_for calls ran, added once they were joined.
inline thread_local double helper_cpu_seconds = 0.0;
}  // namespace detail

/// CPU seconds the calling thread used so far, with those of the helper threads its parallel_for calls ran:
/// what a step costs on a thread that splits its work, whatever else the process runs meanwhile.
inline double cpu_seconds_with_helpers() {
  return thread_cpu_seconds() + detail::helper_cpu_seconds;
}

/// Runs body(0..count-1) on up to `threads` threads (the calling thread is one of them) and returns when all
/// are done. Items are interleaved, so neighbouring (similarly costly) items go to different threads; with
/// count == threads, item t runs on thread t (the caller runs item 0). body must be safe to call
/// concurrently for different items; which thread runs an item must not change its result.
template <typename Body>
void parallel_for(int count, int threads, const Body& body) {
  threads = std::clamp(threads, 1, std::max(1, count));
  const auto share = [&](int t) {
    for (int i = t; i < count; i += threads) body(i);
  };
  std::vector<std::thread> pool;
  std::vector<double> helper_cpu(static_cast<std::size_t>(threads), 0.0);
  for (int t = 1; t < threads; ++t) {
    pool.emplace_back([&, t] {
      share(t);
      helper_cpu[static_cast<std::size_t>(t)] = thread_cpu_seconds();
    });
  }
  share(0);
  for (std::thread& thread : pool) thread.join();
  for (const double cpu : helper_cpu) detail::helper_cpu_seconds += cpu;
}

}  // namespace cellmap
