// SPDX-License-Identifier: Apache-2.0
#pragma once
// The viewer's DDS side: follows one cell, or every cell on the domain, exactly as a planner does (an
// EnvironmentSubscriber per cell: snapshot at start, deltas, resync after a gap), reads the daemons' status
// reports and notices when a daemon goes away, and reads the optional layers while some page shows them.
// Every change goes into the ViewState, and the message it returns to `publish`.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>

#include "cellmap/transport/environment_subscriber.hpp"
#include "cellmap/transport/layers.hpp"
#include "cellmap/transport/status_reader.hpp"
#include "cellmap/view/view_state.hpp"

namespace cellmap::view {

/// `participant` and `state` must outlive it. poll() is for one thread; want_layers() for any.
class CellFollower final {
 public:
  using Publish = std::function<void(std::string message)>;

  /// @param cell the cell to follow, or "" for every cell whose daemon reports on the domain
  /// @throws Error if a reader cannot be created.
  CellFollower(const dds::Participant& participant, std::string cell, ViewState& state, Publish publish);

  /// Waits up to `timeout` for status reports or layers and handles what came: a cell seen for the first
  /// time gets its subscriber, a daemon that left is reported gone, and the layer readers are opened or
  /// closed as want_layers() last said.
  void poll(std::chrono::nanoseconds timeout);
  /// Which layers some page shows. A layer's reader exists only while it is wanted, and that reader is what
  /// makes the daemons publish the layer.
  void want_layers(std::set<transport::Layer> layers);
  /// The cells followed so far.
  [[nodiscard]] std::size_t cells() const { return subscribers_.size(); }

 private:
  void follow(const std::string& cell);
  void open_or_close(transport::Layer layer, bool wanted);

  const dds::Participant& participant_;
  std::string cell_;
  ViewState& state_;
  Publish publish_;
  transport::StatusReader status_;
  std::map<std::string, std::unique_ptr<transport::EnvironmentSubscriber>> subscribers_;
  std::map<transport::Layer, std::unique_ptr<transport::LayerReader>> layer_readers_;

  std::mutex wanted_mutex_;
  std::set<transport::Layer> wanted_;  // guarded by wanted_mutex_
};

}  // namespace cellmap::view
