// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/environment_monitor.hpp"

#include <algorithm>

#include "cellmap/common/error.hpp"
#include "wire.hpp"

namespace cellmap::transport {

EnvironmentMonitor::EnvironmentMonitor(const dds::Participant& participant, const std::string& cell,
                                       std::uint32_t delta_depth)
    : snapshot_topic_(participant, &cellmap_msg_Environment_desc, kEnvironmentTopic),
      delta_topic_(participant, &cellmap_msg_EnvironmentDelta_desc, kEnvironmentDeltaTopic),
      snapshot_reader_(participant, snapshot_topic_, in_cell(environment_qos(), cell)),
      delta_reader_(participant, delta_topic_, in_cell(environment_delta_qos(delta_depth), cell)),
      waitset_(participant) {
  waitset_.attach(snapshot_reader_);
  waitset_.attach(delta_reader_);
}

EnvironmentMonitor::~EnvironmentMonitor() {
  try {
    waitset_.detach(snapshot_reader_);
    waitset_.detach(delta_reader_);
  } catch (const Error&) {
    // Deleting the readers below detaches them anyway.
  }
}

std::vector<EnvironmentMessage> EnvironmentMonitor::take(std::chrono::nanoseconds timeout) {
  waitset_.wait(timeout);
  std::vector<std::pair<dds_time_t, EnvironmentMessage>> stamped;
  auto keep = [&](dds_time_t written, auto&& convert) {
    try {
      stamped.emplace_back(written, convert());
    } catch (const Error& e) {
      ++rejected_;
      last_rejection_ = e.what();
    }
  };
  delta_reader_.take_all([&](const void* sample, const dds_sample_info_t& info) {
    keep(info.source_timestamp, [&] {
      return EnvironmentMessage(wire::from_wire(*static_cast<const cellmap_msg_EnvironmentDelta*>(sample)));
    });
  });
  snapshot_reader_.take_all([&](const void* sample, const dds_sample_info_t& info) {
    keep(info.source_timestamp, [&] {
      return EnvironmentMessage(wire::from_wire(*static_cast<const cellmap_msg_Environment*>(sample)));
    });
  });
  // Deltas were taken first, so for equal stamps a version's delta stays before its snapshot.
  std::stable_sort(stamped.begin(), stamped.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<EnvironmentMessage> messages;
  messages.reserve(stamped.size());
  for (auto& entry : stamped) messages.push_back(std::move(entry.second));
  return messages;
}

}  // namespace cellmap::transport
