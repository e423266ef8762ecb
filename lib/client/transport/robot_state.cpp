// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/robot_state.hpp"

#include <utility>

#include "cellmap/common/error.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "cellmap/transport/topics.hpp"
#include "wire.hpp"

namespace cellmap::transport {

RobotStateWriter::RobotStateWriter(const dds::Participant& participant, std::string cell)
    : cell_(one_cell(std::move(cell), std::string(kRobotStateTopic) + " writer")),
      topic_(participant, &cellmap_msg_RobotState_desc, kRobotStateTopic),
      writer_(participant, topic_, in_cell(robot_state_qos(), cell_)) {}

bool RobotStateWriter::wait_for_reader(std::chrono::nanoseconds timeout) const {
  return writer_.wait_for_readers(1, timeout);
}

void RobotStateWriter::write(const RobotState& state) const {
  if (state.cell.empty()) throw Error(std::string(kRobotStateTopic) + ": cell: must not be empty");
  if (state.cell != cell_)
    throw Error(std::string(kRobotStateTopic) + " '" + state.cell + "': this writer is for cell '" + cell_ + "'");
  if (!state.X_CE.matrix().allFinite())
    throw Error(std::string(kRobotStateTopic) + " '" + state.cell + "': pose is not finite");
  const wire::RobotStateSample sample(state);
  writer_.write(sample.get());
}

bool RobotStateWriter::wait_for_acks(std::chrono::nanoseconds timeout) const {
  return writer_.wait_for_acks(timeout);
}

RobotStateReader::RobotStateReader(const dds::Participant& participant, std::string cell, InputLimits limits,
                                   OnRefused on_refused)
    : cell_(one_cell(std::move(cell), std::string(kRobotStateTopic) + " reader")),
      limits_(std::move(limits)),
      on_refused_(std::move(on_refused)),
      topic_(participant, &cellmap_msg_RobotState_desc, kRobotStateTopic),
      reader_(participant, topic_, in_cell(robot_state_qos(), cell_)),
      waitset_(participant) {
  waitset_.attach(reader_);
}

RobotStateReader::~RobotStateReader() {
  try {
    waitset_.detach(reader_);
  } catch (const Error&) {
    // Deleting the reader detaches it anyway.
  }
}

std::vector<RobotState> RobotStateReader::take(std::chrono::nanoseconds timeout) {
  if (timeout.count() > 0) waitset_.wait(timeout);
  std::vector<RobotState> states;
  const std::int64_t now_ns = wall_clock_ns();
  reader_.take_all([&](const void* sample, const dds_sample_info_t&) {
    const auto& msg = *static_cast<const cellmap_msg_RobotState*>(sample);
    if (msg.cell != nullptr && cell_ != msg.cell) return;
    try {
      RobotState state = wire::from_wire(msg);
      check_limits(state, limits_, now_ns);
      states.push_back(std::move(state));
    } catch (const Error& e) {
      ++rejected_;
      if (on_refused_) on_refused_(e.what());
    }
  });
  return states;
}

}  // namespace cellmap::transport
