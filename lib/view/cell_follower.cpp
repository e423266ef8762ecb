// SPDX-License-Identifier: Apache-2.0
#include "cellmap/view/cell_follower.hpp"

#include "cellmap/common/wall_clock.hpp"

namespace cellmap::view {

CellFollower::CellFollower(const dds::Participant& participant, std::string cell, ViewState& state,
                           Publish publish)
    : participant_(participant),
      cell_(std::move(cell)),
      state_(state),
      publish_(std::move(publish)),
      status_(participant, cell_.empty() ? transport::default_cell(participant) : cell_) {
  if (!cell_.empty()) follow(cell_);
}

void CellFollower::follow(const std::string& cell) {
  if (subscribers_.count(cell) != 0) return;
  // The callback runs on the subscriber's thread as each version reaches the local copy.
  subscribers_[cell] = std::make_unique<transport::EnvironmentSubscriber>(
      participant_, cell, [this](const Environment& env, const EnvironmentDelta& delta) {
        std::string message = state_.on_version(env, delta, wall_clock_ns());
        if (!message.empty()) publish_(std::move(message));
      });
}

void CellFollower::poll(std::chrono::nanoseconds timeout) {
  for (const transport::CellStatus& report : status_.take(timeout)) {
    if (!cell_.empty() && report.cell != cell_) continue;
    follow(report.cell);
    publish_(state_.on_status(report));
  }
  for (const std::string& cell : status_.departed()) {
    if (!cell_.empty() && cell != cell_) continue;
    publish_(state_.on_daemon_gone(cell));
  }
  std::set<transport::Layer> wanted;
  {
    const std::lock_guard<std::mutex> lock(wanted_mutex_);
    wanted = wanted_;
  }
  for (const transport::Layer layer : transport::kLayers) open_or_close(layer, wanted.count(layer) != 0);
}

void CellFollower::open_or_close(transport::Layer layer, bool wanted) {
  std::unique_ptr<transport::LayerReader>& reader = layer_readers_[layer];
  if (wanted && !reader) reader = std::make_unique<transport::LayerReader>(
        participant_, layer, cell_.empty() ? transport::default_cell(participant_) : cell_);
  if (!wanted && reader) reader.reset();
  if (!reader) return;
  for (const transport::LayerMessage& message : reader->take()) {
    std::string text = state_.on_layer(message);
    if (!text.empty()) publish_(std::move(text));
  }
}

void CellFollower::want_layers(std::set<transport::Layer> layers) {
  const std::lock_guard<std::mutex> lock(wanted_mutex_);
  wanted_ = std::move(layers);
}

}  // namespace cellmap::view
