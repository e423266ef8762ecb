#pragma once
// Splitting a loop over a few threads: the one thread splitter of the library (the simulator's rays, the
// occupancy map's ray casting).

#include <algorithm>
#include <thread>
#include <vector>

namespace cellmap {

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
  for (int t = 1; t < threads; ++t) pool.emplace_back(share, t);
  share(0);
  for (std::thread& thread : pool) thread.join();
}

}  // namespace cellmap
