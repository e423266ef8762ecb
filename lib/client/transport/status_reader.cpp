// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/status_reader.hpp"

#include <algorithm>

#include "cellmap/common/error.hpp"
#include "cellmap/transport/topics.hpp"
#include "wire.hpp"

namespace cellmap::transport {

StatusReader::StatusReader(const dds::Participant& participant, const std::string& cell)
    : topic_(participant, &cellmap_msg_Status_desc, kStatusTopic),
      reader_(participant, topic_, in_cell(status_qos(), cell)),
      waitset_(participant) {
  waitset_.attach(reader_);
}

StatusReader::~StatusReader() {
  try {
    waitset_.detach(reader_);
  } catch (const Error&) {
    // Deleting the reader detaches it anyway.
  }
}

std::vector<CellStatus> StatusReader::take(std::chrono::nanoseconds timeout) {
  if (timeout.count() > 0) waitset_.wait(timeout);
  std::vector<CellStatus> reports;
  departed_.clear();
  const auto forget = [&](const std::string& cell) {
    departed_.erase(std::remove(departed_.begin(), departed_.end(), cell), departed_.end());
  };
  reader_.take_all(
      [&](const void* sample, const dds_sample_info_t&) {
        try {
          reports.push_back(wire::from_wire(*static_cast<const cellmap_msg_Status*>(sample)));
          forget(reports.back().cell);
        } catch (const Error&) {
          // A report without a cell cannot be attributed; skip it.
        }
      },
      [&](const void* key_sample) {
        std::string cell;
        try {
          cell = wire::cell_of(static_cast<const cellmap_msg_Status*>(key_sample)->cell, kStatusTopic);
        } catch (const Error&) {
          return;  // as for its reports
        }
        forget(cell);
        departed_.push_back(std::move(cell));
      });
  return reports;
}

}  // namespace cellmap::transport
