// SPDX-License-Identifier: Apache-2.0
#include "layer_publisher.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>

#include "cellmap/common/error.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "versions.hpp"

namespace cellmap::daemon {
namespace {

using transport::Layer;

// OctoMap's leaf keys at depth 16: key 2^15 is the voxel whose lower corner lies at 0 on that axis.
constexpr int kKeyOfZero = 1 << 15;

std::vector<transport::VoxelRun> occupied_runs(const OccupancyMap& map) {
  std::vector<std::array<int, 3>> indices;
  const std::vector<octomap::OcTreeKey> keys = map.occupied_keys();  // sorted (z, y, x)
  indices.reserve(keys.size());
  for (const octomap::OcTreeKey& key : keys)
    indices.push_back({key[0] - kKeyOfZero, key[1] - kKeyOfZero, key[2] - kKeyOfZero});
  return transport::voxel_runs(indices);
}

const char* name(Layer layer) {
  switch (layer) {
    case Layer::kVoxels:
      return "voxels";
    case Layer::kChangeRegions:
      return "change regions";
    case Layer::kSensors:
      return "sensors";
    case Layer::kRobot:
      return "robot";
  }
  return "?";
}

// The robot's shapes at `at`, and the payload its tool holds (a box; none if it has no volume).
std::vector<transport::PosedShape> posed_shapes(const Robot& robot, const RobotAt& at) {
  std::vector<transport::PosedShape> shapes;
  const std::vector<LinkShape>& on_links = robot.shapes();
  for (std::size_t i = 0; i < on_links.size(); ++i) {
    const Eigen::Isometry3d& X_CL = at.X_CL.at(static_cast<std::size_t>(robot.shape_links()[i]));
    shapes.push_back({on_links[i].link, false, X_CL * on_links[i].X_LG, on_links[i].geometry});
  }
  if (at.payload && (at.payload->half_extents.array() > 0).all()) {
    shapes.push_back({robot.link_names().back(), true, at.X_CL.back() * at.payload->X_EB,
                      BoxShape{at.payload->half_extents}});
  }
  return shapes;
}

}  // namespace

LayerPublisher::LayerPublisher(const dds::Participant& participant, std::string cell)
    : writer_(participant, std::move(cell)) {}

void LayerPublisher::after_sweep(std::uint64_t number, const FrameSweep& sweep, const OccupancyMap& map,
                                 const ChangeSet& changes) {
  try {
    if (read(Layer::kVoxels, voxels_read_)) publish_voxels(number, map);
    if (read(Layer::kChangeRegions, regions_read_)) publish_regions(number, changes);
    if (read(Layer::kSensors, sensors_read_)) publish_sensors(number, sweep);
    if (read(Layer::kRobot, robot_read_)) publish_robot(number, sweep);
  } catch (const Error& e) {
    spdlog::warn("layers: {}; retrying after the next sweep", e.what());
  }
}

bool LayerPublisher::read(Layer layer, bool& was_read) {
  const bool is_read = writer_.readers(layer) > 0;
  if (is_read != was_read) {
    if (is_read) {
      spdlog::info("layer {}: {} reader(s), publishing after each sweep", name(layer),
                   writer_.readers(layer));
    } else {
      spdlog::info("layer {}: no reader, not published", name(layer));
    }
    was_read = is_read;
  }
  return is_read;
}

void LayerPublisher::publish_voxels(std::uint64_t sweep, const OccupancyMap& map) {
  const std::uint32_t joined = writer_.readers_joined(Layer::kVoxels);
  std::vector<transport::VoxelRun> runs = occupied_runs(map);
  if (runs == voxels_written_ && joined == voxel_readers_served_) return;
  transport::VoxelLayer layer{writer_.cell(), sweep, wall_clock_ns(), map.config().resolution,
                              std::move(runs)};
  writer_.write(layer);
  if (joined != voxel_readers_served_) {
    spdlog::info("layer voxels: {} voxels in {} runs, {} bytes", layer.voxel_count(), layer.runs.size(),
                 transport::wire_size(layer));
  }
  voxels_written_ = std::move(layer.runs);
  voxel_readers_served_ = joined;
}

void LayerPublisher::publish_regions(std::uint64_t sweep, const ChangeSet& changes) {
  const std::uint32_t joined = writer_.readers_joined(Layer::kChangeRegions);
  if (changes.empty() && joined == region_readers_served_) return;
  transport::ChangeRegionLayer layer{writer_.cell(), sweep, wall_clock_ns(), {}};
  for (const ChangeRegion& region : changes.regions) {
    layer.regions.push_back({region.bounds, static_cast<std::uint32_t>(region.appeared.size()),
                             static_cast<std::uint32_t>(region.vanished.size())});
  }
  writer_.write(layer);
  if (!changes.empty()) {
    spdlog::info("layer change regions: {} regions, {} bytes", layer.regions.size(),
                 transport::wire_size(layer));
  }
  region_readers_served_ = joined;
}

void LayerPublisher::publish_sensors(std::uint64_t number, const FrameSweep& sweep) {
  const std::uint32_t joined = writer_.readers_joined(Layer::kSensors);
  transport::SensorLayer layer{writer_.cell(), number, wall_clock_ns(), {}};
  for (const SweepFrame& taken : sweep.frames) {
    const Frame& frame = taken.frame;
    layer.views.push_back({frame.sensor, frame.X_CS, field_of_view(frame)});
  }
  writer_.write(layer);
  if (joined != sensor_readers_served_) {
    spdlog::info("layer sensors: {} views, {} bytes", layer.views.size(), transport::wire_size(layer));
  }
  sensor_readers_served_ = joined;
}

void LayerPublisher::show_robot(Robot robot, const SelfFilterConfig& filter) {
  robot_ = std::move(robot);
  padding_scale_ = filter.enabled ? filter.padding_scale : 1.0;
  padding_ = filter.enabled ? filter.padding : 0.0;
}

void LayerPublisher::publish_robot(std::uint64_t number, const FrameSweep& sweep) {
  const auto last = std::find_if(sweep.frames.rbegin(), sweep.frames.rend(),
                                 [](const SweepFrame& taken) { return taken.robot.has_value(); });
  if (!robot_ || last == sweep.frames.rend()) return;  // no robot model, or no frame posed it
  if (last->robot->X_CL.size() != robot_->link_names().size())
    throw Error("robot layer: the frame's robot has " + std::to_string(last->robot->X_CL.size()) +
                " link poses, the model " + std::to_string(robot_->link_names().size()) + " links");
  const std::uint32_t joined = writer_.readers_joined(Layer::kRobot);
  const transport::RobotLayer layer{writer_.cell(), number,   wall_clock_ns(),
                                    padding_scale_, padding_, posed_shapes(*robot_, *last->robot)};
  writer_.write(layer);
  if (joined != robot_readers_served_) {
    spdlog::info("layer robot: {} shapes ({} triangles), {} bytes", layer.shapes.size(),
                 robot_->triangle_count(), transport::wire_size(layer));
  }
  robot_readers_served_ = joined;
}

}  // namespace cellmap::daemon
