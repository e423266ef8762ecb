// SPDX-License-Identifier: Apache-2.0
#pragma once
// Splitting a loop over a few threads: the one thread splitter of the library (the simulator's rays, the
// occupancy map's ray casting), and the CPU time of a thread with the helpers it split its work onto.

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace cellmap {

/// CPU seconds the calling thread used so far (CLOCK_THREAD_CPUTIME_ID).
inline double thread_cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

/// Names the calling thread for top -H, ps, gdb and perf (Linux keeps 15 characters of it; longer names are
/// cut there). A failure only leaves the name as it was.
inline void name_this_thread(const std::string& name) {
  (void)::pthread_setname_np(::pthread_self(), name.substr(0, 15).c_str());
}

/// The calling thread's name ("" if it cannot be read).
inline std::string this_thread_name() {
  char name[16] = {};
  return ::pthread_getname_np(::pthread_self(), name, sizeof name) == 0 ? name : "";
}

namespace detail {
// CPU seconds of the helper threads this thread's parallel_for calls ran, added once they were joined.
inline thread_local double helper_cpu_seconds = 0.0;
}  // namespace detail

/// CPU seconds the calling thread used so far, with those of the helper threads its parallel_for calls ran
/// (and those credited by add_helper_cpu_seconds): what a step costs on a thread that splits its work,
/// whatever else the process runs meanwhile.
inline double cpu_seconds_with_helpers() {
  return thread_cpu_seconds() + detail::helper_cpu_seconds;
}

/// Credits the calling thread with `seconds` of CPU a thread of another kind spent on its behalf (a
/// replay's file reader for the camera thread that takes its frames).
inline void add_helper_cpu_seconds(double seconds) {
  detail::helper_cpu_seconds += seconds;
}

namespace detail {
// Helper threads kept for one calling thread's parallel_for calls: starting a thread costs tens of µs (and
// page faults for its stack), and the occupancy map splits its work twice per scan. Helpers wait on a
// condition variable between calls (no spinning: they use no CPU while idle) and end with the calling
// thread. Helpers are kept off the caller's CPU: a scheduler that packs woken threads onto the waker's CPU
// (seen on 2-vCPU VMs: a 5 ms share then started 1-7 ms late, after the caller's) would otherwise run a
// helper behind its caller instead of beside it.
class HelperPool {
 public:
  HelperPool() = default;
  HelperPool(const HelperPool&) = delete;
  HelperPool& operator=(const HelperPool&) = delete;
  ~HelperPool() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& thread : threads_) thread.join();
  }

  // Whether a run is under way (a body that calls parallel_for again must not reuse the pool).
  [[nodiscard]] bool busy() const { return busy_; }

  // Runs share(1..helpers) on helper threads and share(0) on the caller; returns when all are done, with
  // the CPU seconds the helpers spent on it.
  double run(int helpers, const std::function<void(int)>& share) {
    busy_ = true;
    while (static_cast<int>(threads_.size()) < helpers) {
      const int index = static_cast<int>(threads_.size()) + 1;
      // A helper is named after the thread it helps: "gathering+1" is the gathering thread's first.
      threads_.emplace_back([this, index, name = this_thread_name()] {
        name_this_thread(name.substr(0, 12) + "+" + std::to_string(index));
        serve(index);
      });
    }
    keep_helpers_off(::sched_getcpu());
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      share_ = &share;
      helpers_ = helpers;
      pending_ = helpers;
      cpu_ = 0.0;
      ++generation_;
    }
    wake_.notify_all();
    std::exception_ptr error;  // the helpers still use `share`: wait for them before passing it on
    try {
      share(0);
    } catch (...) {
      error = std::current_exception();
    }
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_ == 0; });
    busy_ = false;
    if (error) std::rethrow_exception(error);
    return cpu_;
  }

 private:
  // Allows the helpers every CPU the process may use but `caller_cpu`; a failure, or a machine with one CPU,
  // leaves them where the scheduler puts them.
  void keep_helpers_off(int caller_cpu) {
    if (caller_cpu < 0 || caller_cpu >= CPU_SETSIZE) return;
    if (caller_cpu == helpers_kept_off_ && threads_.size() == helpers_placed_) return;
    cpu_set_t others;
    if (::sched_getaffinity(0, sizeof others, &others) != 0) return;
    CPU_CLR(caller_cpu, &others);
    if (CPU_COUNT(&others) == 0) return;
    for (std::thread& thread : threads_)
      (void)::pthread_setaffinity_np(thread.native_handle(), sizeof others, &others);
    helpers_kept_off_ = caller_cpu;
    helpers_placed_ = threads_.size();
  }

  void serve(int index) {
    std::uint64_t seen = 0;
    for (;;) {
      const std::function<void(int)>* share = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        if (index > helpers_) continue;  // this run needs fewer helpers
        share = share_;
      }
      const double start = thread_cpu_seconds();
      (*share)(index);
      const double cpu = thread_cpu_seconds() - start;
      const std::lock_guard<std::mutex> lock(mutex_);
      cpu_ += cpu;
      if (--pending_ == 0) done_.notify_one();
    }
  }

  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(int)>* share_ = nullptr;
  std::uint64_t generation_ = 0;
  int helpers_ = 0, pending_ = 0;
  double cpu_ = 0.0;
  bool stop_ = false, busy_ = false;
  int helpers_kept_off_ = -1;       // the CPU the helpers were last kept off
  std::size_t helpers_placed_ = 0;  // helpers that were
};

inline HelperPool& helper_pool() {
  thread_local HelperPool pool;
  return pool;
}
}  // namespace detail

/// Runs body(0..count-1) on up to `threads` threads (the calling thread is one of them) and returns when all
/// are done. Items are interleaved, so neighbouring (similarly costly) items go to different threads; with
/// count == threads, item t runs on thread t (the caller runs item 0). body must be safe to call
/// concurrently for different items; which thread runs an item must not change its result. The helper
/// threads are kept for the calling thread's next call and end with it (a nested call from body starts
/// threads of its own).
template <typename Body>
void parallel_for(int count, int threads, const Body& body) {
  threads = std::clamp(threads, 1, std::max(1, count));
  const std::function<void(int)> share = [&](int t) {
    for (int i = t; i < count; i += threads) body(i);
  };
  if (threads == 1) {
    share(0);
    return;
  }
  detail::HelperPool& pool = detail::helper_pool();
  if (!pool.busy()) {
    detail::helper_cpu_seconds += pool.run(threads - 1, share);
    return;
  }
  detail::HelperPool nested;
  detail::helper_cpu_seconds += nested.run(threads - 1, share);
}

}  // namespace cellmap
