#pragma once
// Internal: splitting a loop over a few threads (the simulator's frames are a few hundred thousand rays).

#include <algorithm>
#include <thread>
#include <vector>

namespace cellmap::sim {

/// Runs body(0..count-1) on up to `threads` threads, interleaved so that neighbouring (similarly costly)
/// items go to different threads. body must be safe to call concurrently for different items.
template <typename Body>
void parallel_for(int count, int threads, const Body& body) {
  threads = std::clamp(threads, 1, std::max(1, count));
  if (threads == 1) {
    for (int i = 0; i < count; ++i) body(i);
    return;
  }
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&, t] {
      for (int i = t; i < count; i += threads) body(i);
    });
  }
  for (std::thread& thread : pool) thread.join();
}

}  // namespace cellmap::sim
