// SPDX-License-Identifier: Apache-2.0
#pragma once
// The daemon's optional layers (cellmap/layer/...): the occupied voxels of the map, the change regions of the
// latest sweep, where its frames were taken from and where the robot was, written after a sweep only while a
// viewer reads them.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/change/change_detector.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/robot/robot.hpp"
#include "cellmap/self_filter/self_filter.hpp"
#include "cellmap/transport/layers.hpp"

namespace cellmap::daemon {

/// Not thread-safe: the processing thread owns it. `participant` must outlive it.
class LayerPublisher final {
 public:
  /// @throws Error if the writers cannot be created.
  LayerPublisher(const dds::Participant& participant, std::string cell);

  /// The robot whose shapes the robot layer shows (the self filter's model) and the filter's padding
  /// (`filter.enabled` false: published as scale 1 and 0 m). Without a call the robot layer stays empty.
  void show_robot(Robot robot, const SelfFilterConfig& filter);

  /// Call after sweep `number` with the sweep, the map and the changes that sweep confirmed. Writes the
  /// occupied voxels when a voxel reader is matched and they differ from the last written or a reader
  /// joined since, the change regions when a region reader is matched and the sweep confirmed some or a
  /// reader joined, the sensor views of the sweep's frames whenever a sensor reader is matched, and the
  /// robot's shapes at the sweep's last frame that has the robot's pose whenever a robot reader is matched.
  /// With no reader it costs four matched-status queries. Never throws: a failed write is logged and retried
  /// on the next sweep. Logs when a layer gains its first reader or loses its last, with the bytes per
  /// update.
  void after_sweep(std::uint64_t number, const FrameSweep& sweep, const OccupancyMap& map,
                   const ChangeSet& changes);

 private:
  void publish_voxels(std::uint64_t sweep, const OccupancyMap& map);
  void publish_regions(std::uint64_t sweep, const ChangeSet& changes);
  void publish_sensors(std::uint64_t number, const FrameSweep& sweep);
  void publish_robot(std::uint64_t number, const FrameSweep& sweep);
  /// True when `layer` has a reader; logs its first reader and the loss of its last.
  bool read(transport::Layer layer, bool& was_read);

  transport::LayerWriter writer_;
  std::vector<transport::VoxelRun> voxels_written_;
  std::uint32_t voxel_readers_served_ = 0;   // readers_joined() at the last voxel write
  std::uint32_t region_readers_served_ = 0;  // readers_joined() at the last region write
  std::uint32_t sensor_readers_served_ = 0;  // readers_joined() at the last sensor write
  std::uint32_t robot_readers_served_ = 0;   // readers_joined() at the last robot write
  std::optional<Robot> robot_;
  double padding_scale_ = 1.0;
  double padding_ = 0.0;
  bool voxels_read_ = false;
  bool regions_read_ = false;
  bool sensors_read_ = false;
  bool robot_read_ = false;
};

}  // namespace cellmap::daemon
