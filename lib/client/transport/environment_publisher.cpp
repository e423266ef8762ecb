// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/environment_publisher.hpp"

#include "cellmap/common/error.hpp"
#include "wire.hpp"

namespace cellmap::transport {
namespace {

dds::Qos writer_qos(dds::Qos qos) {
  qos.autodispose(false);
  return qos;
}

}  // namespace

EnvironmentPublisher::EnvironmentPublisher(const dds::Participant& participant, std::string cell,
                                           std::uint32_t delta_depth)
    : cell_(one_cell(std::move(cell), "environment publisher")),
      snapshot_topic_(participant, &cellmap_msg_Environment_desc, kEnvironmentTopic),
      delta_topic_(participant, &cellmap_msg_EnvironmentDelta_desc, kEnvironmentDeltaTopic),
      status_topic_(participant, &cellmap_msg_Status_desc, kStatusTopic),
      snapshot_writer_(participant, snapshot_topic_, writer_qos(in_cell(environment_qos(), cell_))),
      delta_writer_(participant, delta_topic_,
                    writer_qos(in_cell(environment_delta_qos(delta_depth), cell_))),
      status_writer_(participant, status_topic_, writer_qos(in_cell(status_qos(), cell_))) {}

void EnvironmentPublisher::check_version(const Environment& env) const {
  const std::string what = "publish '" + env.cell() + "' version " + std::to_string(env.version());
  if (env.cell() != cell_) throw Error(what + ": this publisher is for cell '" + cell_ + "'");
  if (env.version() == 0) throw Error(what + ": version 0 means nothing published");
  if (env.version() <= last_version_) {
    throw Error(what + ": not above the last published version " + std::to_string(last_version_));
  }
}

void EnvironmentPublisher::publish(const Environment& env) {
  publish(env, diff(Environment(cell_), env));
}

void EnvironmentPublisher::publish(const Environment& env, const EnvironmentDelta& delta) {
  check_version(env);
  if (delta.cell != cell_ || delta.to_version != env.version() || delta.from_version >= delta.to_version) {
    throw Error("publish '" + cell_ + "' version " + std::to_string(env.version()) + ": delta " + delta.cell +
                " " + std::to_string(delta.from_version) + " -> " + std::to_string(delta.to_version) +
                " does not lead to it");
  }
  const wire::DeltaSample delta_sample(delta);
  delta_writer_.write(delta_sample.get());
  const wire::EnvironmentSample sample(env);
  snapshot_writer_.write(sample.get());
  last_version_ = env.version();
}

void EnvironmentPublisher::publish_status(const CellStatus& status) {
  if (status.cell != cell_) throw Error("publish status: cell '" + status.cell + "' is not '" + cell_ + "'");
  const wire::StatusSample sample(status);
  status_writer_.write(sample.get());
}

bool EnvironmentPublisher::wait_for_subscribers(std::uint32_t count, std::chrono::nanoseconds timeout) const {
  return delta_writer_.wait_for_readers(count, timeout);
}

bool EnvironmentPublisher::wait_for_snapshot_readers(std::uint32_t count,
                                                     std::chrono::nanoseconds timeout) const {
  return snapshot_writer_.wait_for_readers(count, timeout);
}

std::uint32_t EnvironmentPublisher::subscribers_joined() const {
  return delta_writer_.matched_readers_ever();
}

}  // namespace cellmap::transport
