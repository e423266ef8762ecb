#include "cellmap/view/cell_follower.hpp"

namespace cellmap::view {
namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

CellFollower::CellFollower(const dds::Participant& participant, std::string cell, ViewState& state,
                           Publish publish)
    : participant_(participant),
      cell_(std::move(cell)),
      state_(state),
      publish_(std::move(publish)),
      status_(participant) {
  if (!cell_.empty()) follow(cell_);
}

void CellFollower::follow(const std::string& cell) {
  if (subscribers_.count(cell) != 0) return;
  // The callback runs on the subscriber's thread as each version reaches the local copy.
  subscribers_[cell] = std::make_unique<transport::EnvironmentSubscriber>(
      participant_, cell, [this](const Environment& env, const EnvironmentDelta& delta) {
        std::string message = state_.on_version(env, delta, now_ns());
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
  bool voxels = false;
  bool regions = false;
  {
    const std::lock_guard<std::mutex> lock(wanted_mutex_);
    voxels = want_voxels_;
    regions = want_regions_;
  }
  open_or_close(voxels_, transport::Layer::kVoxels, voxels);
  open_or_close(regions_, transport::Layer::kChangeRegions, regions);
}

void CellFollower::open_or_close(std::optional<transport::LayerReader>& reader, transport::Layer layer,
                                 bool wanted) {
  if (wanted && !reader) reader.emplace(participant_, layer);
  if (!wanted && reader) reader.reset();
  if (!reader) return;
  for (const transport::LayerMessage& message : reader->take()) {
    std::string text = state_.on_layer(message);
    if (!text.empty()) publish_(std::move(text));
  }
}

void CellFollower::want_layers(bool voxels, bool regions) {
  const std::lock_guard<std::mutex> lock(wanted_mutex_);
  want_voxels_ = voxels;
  want_regions_ = regions;
}

}  // namespace cellmap::view
