// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/environment_subscriber.hpp"

#include "cellmap/common/error.hpp"
#include "wire.hpp"

namespace cellmap::transport {

EnvironmentSubscriber::EnvironmentSubscriber(const dds::Participant& participant, std::string cell,
                                             Callback on_change, std::uint32_t delta_depth)
    : participant_(participant),
      on_change_(std::move(on_change)),
      snapshot_topic_(participant, &cellmap_msg_Environment_desc, kEnvironmentTopic),
      delta_topic_(participant, &cellmap_msg_EnvironmentDelta_desc, kEnvironmentDeltaTopic),
      delta_reader_(participant, delta_topic_, in_cell(environment_delta_qos(delta_depth), cell)),
      waitset_(participant),
      tracker_(std::move(cell)) {
  waitset_.attach(delta_reader_);
  open_or_close_snapshot_reader();
  thread_ = std::thread([this] { run(); });
}

EnvironmentSubscriber::~EnvironmentSubscriber() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  try {
    waitset_.wake();
  } catch (const Error&) {
    // Cannot happen with a live guard condition; the thread also wakes on its periodic timeout.
  }
  thread_.join();
  if (snapshot_reader_) waitset_.detach(*snapshot_reader_);
}

void EnvironmentSubscriber::open_or_close_snapshot_reader() {
  bool needed = false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    needed = tracker_.needs_snapshot();
  }
  if (needed && !snapshot_reader_) {
    // Transient local: the writer hands the new reader its current snapshot right after matching.
    snapshot_reader_.emplace(participant_, snapshot_topic_, in_cell(environment_qos(), tracker_.cell()));
    waitset_.attach(*snapshot_reader_);
  } else if (!needed && snapshot_reader_) {
    waitset_.detach(*snapshot_reader_);
    snapshot_reader_.reset();
  }
}

void EnvironmentSubscriber::run() {
  for (;;) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (stop_) return;
    }
    try {
      // The timeout only bounds how long a lost wake-up could delay stopping.
      waitset_.wait(std::chrono::seconds(1));
      receive();
      open_or_close_snapshot_reader();
    } catch (const std::exception& e) {
      const std::lock_guard<std::mutex> lock(mutex_);
      last_error_ = e.what();
    }
  }
}

void EnvironmentSubscriber::receive() {
  std::vector<EnvironmentUpdate> updates;
  std::string problem;
  // Deltas first: when a version's delta and snapshot both wait, the delta path is the cheaper one.
  delta_reader_.take_all([&](const void* sample, const dds_sample_info_t&) {
    try {
      const EnvironmentDelta delta =
          wire::from_wire(*static_cast<const cellmap_msg_EnvironmentDelta*>(sample));
      const std::lock_guard<std::mutex> lock(mutex_);
      for (EnvironmentUpdate& u : tracker_.on_delta(delta)) updates.push_back(std::move(u));
    } catch (const Error& e) {
      problem = e.what();
    }
  });
  if (snapshot_reader_) {
    snapshot_reader_->take_all([&](const void* sample, const dds_sample_info_t&) {
      try {
        const Environment env = wire::from_wire(*static_cast<const cellmap_msg_Environment*>(sample));
        const std::lock_guard<std::mutex> lock(mutex_);
        for (EnvironmentUpdate& u : tracker_.on_snapshot(env)) updates.push_back(std::move(u));
      } catch (const Error& e) {
        problem = e.what();
      }
    });
  }
  if (!problem.empty()) {
    const std::lock_guard<std::mutex> lock(mutex_);
    last_error_ = problem;
  }
  if (updates.empty()) return;
  for (const EnvironmentUpdate& update : updates) {
    if (!on_change_) break;
    try {
      on_change_(update.environment, update.delta);
    } catch (const std::exception& e) {
      const std::lock_guard<std::mutex> lock(mutex_);
      last_error_ = std::string("on_change callback threw: ") + e.what();
    }
  }
  // After the callbacks: whoever waited for a version also sees its callback done.
  const std::lock_guard<std::mutex> lock(mutex_);
  delivered_version_ = updates.back().environment.version();
  changed_.notify_all();
}

std::optional<Environment> EnvironmentSubscriber::environment() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return tracker_.environment();
}

bool EnvironmentSubscriber::wait_for_version(std::uint64_t version, std::chrono::nanoseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return changed_.wait_for(lock, timeout, [&] { return delivered_version_ >= version; });
}

TrackerStats EnvironmentSubscriber::stats() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return tracker_.stats();
}

std::string EnvironmentSubscriber::last_error() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return last_error_;
}

}  // namespace cellmap::transport
