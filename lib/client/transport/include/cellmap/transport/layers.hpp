// SPDX-License-Identifier: Apache-2.0
#pragma once
// The optional layers a viewer can ask the daemon for: the occupied voxels of the map, the change regions
// of the latest sweep, where its frames were taken from and where the robot was. A layer has its own topic
// (cellmap/layer/...), and the daemon computes and writes it only while a reader of that topic is matched:
// asking for a layer means opening its reader, and a layer nobody reads costs nothing, neither on the network
// nor in the daemon.

#include <Eigen/Geometry>

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "cellmap/common/field_of_view.hpp"
#include "cellmap/common/region.hpp"
#include "cellmap/robot/geometry.hpp"
#include "cellmap/transport/dds.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::transport {

/// `length` occupied voxels along the cell's x axis starting at voxel index (x, y, z). Voxel (i, j, k) is the
/// cube of edge `resolution` centred at ((i, j, k) + 0.5) · resolution in the cell frame.
struct VoxelRun final {
  std::int16_t x = 0;
  std::int16_t y = 0;
  std::int16_t z = 0;
  std::uint16_t length = 0;
  friend bool operator==(const VoxelRun& a, const VoxelRun& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z && a.length == b.length;
  }
};

/// cellmap/layer/voxels: the occupied voxels of one cell's map after a sweep, as runs along x (8 bytes per
/// run on the wire; surfaces along x make long runs, so a settled cell costs far less than 6 bytes a voxel).
struct VoxelLayer final {
  std::string cell;
  std::uint64_t sweep = 0;    ///< the daemon's sweep count
  std::int64_t stamp_ns = 0;  ///< when it was published, ns since the Unix epoch
  double resolution = 0.0;    ///< voxel edge, metres, > 0
  std::vector<VoxelRun> runs;
  [[nodiscard]] std::size_t voxel_count() const;
};

/// The runs of the voxels `indices` (voxel indices as in VoxelRun), which must be sorted by (z, y, x) without
/// repeats. @throws Error if they are not, or an index is outside the int16 range.
[[nodiscard]] std::vector<VoxelRun> voxel_runs(const std::vector<std::array<int, 3>>& indices);

/// One confirmed change region: bounds in the cell frame (metres, margin included), voxel counts.
struct ChangeRegionBounds final {
  Region bounds;               ///< cell frame
  std::uint32_t appeared = 0;  ///< voxels that became occupied
  std::uint32_t vanished = 0;  ///< voxels that became free
};

/// cellmap/layer/change_regions: the regions confirmed by one sweep (empty: none; sent when a reader joins).
struct ChangeRegionLayer final {
  std::string cell;
  std::uint64_t sweep = 0;
  std::int64_t stamp_ns = 0;
  std::vector<ChangeRegionBounds> regions;
};

/// Where one frame was taken from: its sensor's pose in the cell frame and what it could see.
struct SensorView final {
  std::string sensor;
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();
  std::optional<FieldOfView> field_of_view;  ///< none if the source does not know it
};

/// cellmap/layer/sensors: the views of one sweep's frames, in the order taken.
struct SensorLayer final {
  std::string cell;
  std::uint64_t sweep = 0;
  std::int64_t stamp_ns = 0;
  std::vector<SensorView> views;
};

/// One collision shape of the robot in the cell frame.
struct PosedShape final {
  std::string link;      ///< the link it is fixed to (the tool link for a carried payload)
  bool carried = false;  ///< a payload the tool holds
  Eigen::Isometry3d X_CG = Eigen::Isometry3d::Identity();  ///< the shape's frame G in the cell frame
  LinkGeometry geometry = BoxShape{};  ///< meshes travel as float vertices (about 0.1 µm lost at 1 m)
};

/// cellmap/layer/robot: the robot's collision shapes, as the self filter cuts them out before padding, where
/// the robot was at the latest frame of a sweep that had the robot's pose.
struct RobotLayer final {
  std::string cell;
  std::uint64_t sweep = 0;
  std::int64_t stamp_ns = 0;   ///< when it was published, ns since the Unix epoch
  double padding_scale = 1.0;  ///< the self filter's padding: every shape scaled about its centre, then
  double padding = 0.0;        ///< grown by this many metres on every side (1 and 0 with the filter off)
  std::vector<PosedShape> shapes;
};

using LayerMessage = std::variant<VoxelLayer, ChangeRegionLayer, SensorLayer, RobotLayer>;
enum class Layer { kVoxels, kChangeRegions, kSensors, kRobot };
inline constexpr std::array<Layer, 4> kLayers{Layer::kVoxels, Layer::kChangeRegions, Layer::kSensors,
                                              Layer::kRobot};
/// Which layer a message is of (LayerMessage's alternatives are in the order of kLayers).
[[nodiscard]] inline Layer layer_of(const LayerMessage& message) {
  static_assert(std::variant_size_v<LayerMessage> == kLayers.size());
  return kLayers[message.index()];
}

/// The bytes a layer sample costs in an RTPS DATA submessage (encapsulation header + XCDR1 body, as
/// wire_size() counts environments).
[[nodiscard]] std::size_t wire_size(const VoxelLayer& layer);
[[nodiscard]] std::size_t wire_size(const ChangeRegionLayer& layer);
[[nodiscard]] std::size_t wire_size(const SensorLayer& layer);
[[nodiscard]] std::size_t wire_size(const RobotLayer& layer);

/// The daemon's side: one writer per layer for one cell (RELIABLE, VOLATILE, KEEP_LAST 1). `participant` must
/// outlive it. Thread-safe as Cyclone's writes are.
class LayerWriter final {
 public:
  /// @throws Error if a writer cannot be created or `cell` is empty or kEveryCell.
  LayerWriter(const dds::Participant& participant, std::string cell);
  /// Readers of `layer` matched now: write the layer only when this is above 0.
  [[nodiscard]] std::uint32_t readers(Layer layer) const;
  /// Readers of `layer` ever matched; it grows when a reader joins, so a writer that publishes only on change
  /// can tell that a newcomer needs the current layer.
  [[nodiscard]] std::uint32_t readers_joined(Layer layer) const;
  /// @throws Error if the layer is of another cell, has a non-positive resolution, or the write fails.
  void write(const VoxelLayer& layer) const;
  /// @throws Error if the layer is of another cell or the write fails.
  void write(const ChangeRegionLayer& layer) const;
  /// @throws Error if the layer is of another cell or the write fails.
  void write(const SensorLayer& layer) const;
  /// @throws Error if the layer is of another cell, a shape is invalid (validate_shape) or the write fails.
  void write(const RobotLayer& layer) const;
  [[nodiscard]] const std::string& cell() const { return cell_; }

 private:
  [[nodiscard]] const dds::Writer& writer(Layer layer) const;

  std::string cell_;
  dds::Topic voxel_topic_;
  dds::Topic region_topic_;
  dds::Topic sensor_topic_;
  dds::Topic robot_topic_;
  dds::Writer voxel_writer_;
  dds::Writer region_writer_;
  dds::Writer sensor_writer_;
  dds::Writer robot_writer_;
};

/// A viewer's side: reads one layer of one cell or of every cell (kEveryCell). Opening it is what asks the daemons for the layer;
/// destroying it stops them. `participant` must outlive it. Not thread-safe.
class LayerReader final {
 public:
  /// @throws Error if the reader cannot be created.
  LayerReader(const dds::Participant& participant, Layer layer, const std::string& cell = kEveryCell);
  ~LayerReader();
  LayerReader(const LayerReader&) = delete;
  LayerReader& operator=(const LayerReader&) = delete;
  /// Waits up to `timeout` (zero: just looks) and returns the layers received, oldest first. Malformed
  /// samples (empty cell, non-finite numbers, a non-positive resolution, a rotation that is not a unit
  /// quaternion, an outline of a length not a multiple of 3, a shape that validate_shape refuses) are skipped
  /// and counted.
  std::vector<LayerMessage> take(std::chrono::nanoseconds timeout = std::chrono::nanoseconds(0));
  [[nodiscard]] Layer layer() const { return layer_; }
  [[nodiscard]] std::uint64_t rejected() const { return rejected_; }

 private:
  Layer layer_;
  dds::Topic topic_;
  dds::Reader reader_;
  dds::WaitSet waitset_;
  std::uint64_t rejected_ = 0;
};

}  // namespace cellmap::transport
