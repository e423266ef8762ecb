// SPDX-License-Identifier: Apache-2.0
#include "cellmap/transport/layers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/transport/input_limits.hpp"
#include "wire.hpp"

namespace cellmap::transport {
namespace {

const char* topic_name(Layer layer) {
  switch (layer) {
    case Layer::kVoxels:
      return kVoxelLayerTopic;
    case Layer::kChangeRegions:
      return kChangeRegionLayerTopic;
    case Layer::kSensors:
      return kSensorLayerTopic;
    case Layer::kRobot:
      return kRobotLayerTopic;
  }
  throw Error("layers: unknown layer");
}

const dds_topic_descriptor_t* descriptor(Layer layer) {
  switch (layer) {
    case Layer::kVoxels:
      return &cellmap_msg_VoxelLayer_desc;
    case Layer::kChangeRegions:
      return &cellmap_msg_ChangeRegionLayer_desc;
    case Layer::kSensors:
      return &cellmap_msg_SensorLayer_desc;
    case Layer::kRobot:
      return &cellmap_msg_RobotLayer_desc;
  }
  throw Error("layers: unknown layer");
}

// The generated structs take non-const pointers; Cyclone only reads them when writing.
template <class Sequence, class T>
Sequence sequence_of(const std::vector<T>& items) {
  Sequence seq{};
  seq._maximum = seq._length = static_cast<uint32_t>(items.size());
  seq._buffer = const_cast<T*>(items.data());
  seq._release = false;
  return seq;
}

void put_pose(const Eigen::Isometry3d& X, double position[3], double orientation[4]) {
  const Eigen::Quaterniond q(X.linear());
  for (int k = 0; k < 3; ++k) position[k] = X.translation()[k];
  orientation[0] = q.w();
  orientation[1] = q.x();
  orientation[2] = q.y();
  orientation[3] = q.z();
}

/// @throws Error starting with `where` if a number is not finite or the rotation is not a unit quaternion.
Eigen::Isometry3d pose_of(const double position[3], const double orientation[4], const std::string& where) {
  const Eigen::Vector3d p(position[0], position[1], position[2]);
  const Eigen::Quaterniond q(orientation[0], orientation[1], orientation[2], orientation[3]);
  if (!p.allFinite() || !q.coeffs().allFinite()) throw Error(where + ": not a finite number");
  if (std::abs(q.norm() - 1.0) > 1e-6) throw Error(where + ": orientation: must be a unit quaternion");
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q.normalized().toRotationMatrix();
  X.translation() = p;
  return X;
}

// Owns what a cellmap_msg_VoxelLayer points into, so it must outlive the write.
class VoxelSample {
 public:
  explicit VoxelSample(const VoxelLayer& layer) : cell_(layer.cell) {
    runs_.reserve(layer.runs.size());
    for (const VoxelRun& run : layer.runs) runs_.push_back({run.x, run.y, run.z, run.length});
    msg_.cell = cell_.data();
    msg_.sweep = layer.sweep;
    msg_.stamp_ns = layer.stamp_ns;
    msg_.resolution = layer.resolution;
    msg_.runs = sequence_of<dds_sequence_cellmap_msg_VoxelRun>(runs_);
  }
  [[nodiscard]] const cellmap_msg_VoxelLayer* get() const { return &msg_; }

 private:
  std::string cell_;
  std::vector<cellmap_msg_VoxelRun> runs_;
  cellmap_msg_VoxelLayer msg_{};
};

class RegionSample {
 public:
  explicit RegionSample(const ChangeRegionLayer& layer) : cell_(layer.cell) {
    regions_.reserve(layer.regions.size());
    for (const ChangeRegionBounds& region : layer.regions) {
      cellmap_msg_ChangeRegionBounds msg{};
      for (int i = 0; i < 3; ++i) {
        msg.min[i] = region.bounds.min[i];
        msg.max[i] = region.bounds.max[i];
      }
      msg.appeared = region.appeared;
      msg.vanished = region.vanished;
      regions_.push_back(msg);
    }
    msg_.cell = cell_.data();
    msg_.sweep = layer.sweep;
    msg_.stamp_ns = layer.stamp_ns;
    msg_.regions = sequence_of<dds_sequence_cellmap_msg_ChangeRegionBounds>(regions_);
  }
  [[nodiscard]] const cellmap_msg_ChangeRegionLayer* get() const { return &msg_; }

 private:
  std::string cell_;
  std::vector<cellmap_msg_ChangeRegionBounds> regions_;
  cellmap_msg_ChangeRegionLayer msg_{};
};

// Owns the names and outlines a cellmap_msg_SensorLayer points into.
class SensorSample {
 public:
  explicit SensorSample(const SensorLayer& layer) : cell_(layer.cell) {
    for (const SensorView& view : layer.views) {
      names_.push_back(view.sensor);
      std::vector<double>& outline = outlines_.emplace_back();
      if (view.field_of_view) {
        for (const Eigen::Vector3d& ray : view.field_of_view->outline_S)
          outline.insert(outline.end(), {ray.x(), ray.y(), ray.z()});
      }
    }
    for (std::size_t i = 0; i < layer.views.size(); ++i) views_.push_back(to_msg(layer.views[i], i));
    msg_.cell = cell_.data();
    msg_.sweep = layer.sweep;
    msg_.stamp_ns = layer.stamp_ns;
    msg_.views = sequence_of<dds_sequence_cellmap_msg_SensorView>(views_);
  }
  SensorSample(const SensorSample&) = delete;
  SensorSample& operator=(const SensorSample&) = delete;
  [[nodiscard]] const cellmap_msg_SensorLayer* get() const { return &msg_; }

 private:
  cellmap_msg_SensorView to_msg(const SensorView& view, std::size_t i) {
    cellmap_msg_SensorView msg{};
    msg.sensor = names_[i].data();
    put_pose(view.X_CS, msg.position, msg.orientation);
    msg.max_range = view.field_of_view ? view.field_of_view->max_range : 0.0;
    msg.closed = view.field_of_view && view.field_of_view->closed;
    msg.outline = sequence_of<dds_sequence_double>(outlines_[i]);
    return msg;
  }

  std::string cell_;
  std::vector<std::string> names_;  // filled before views_ points into them
  std::vector<std::vector<double>> outlines_;
  std::vector<cellmap_msg_SensorView> views_;
  cellmap_msg_SensorLayer msg_{};
};

// Owns the link names, mesh vertices and indices a cellmap_msg_RobotLayer points into.
class RobotSample {
 public:
  explicit RobotSample(const RobotLayer& layer) : cell_(layer.cell) {
    for (const PosedShape& shape : layer.shapes) {
      links_.push_back(shape.link);
      std::vector<float>& vertices = vertices_.emplace_back();
      std::vector<std::uint32_t>& triangles = triangles_.emplace_back();
      if (const auto* mesh = std::get_if<MeshShape>(&shape.geometry)) {
        for (const Eigen::Vector3d& v : mesh->mesh->vertices)
          vertices.insert(vertices.end(),
                          {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())});
        for (const Eigen::Vector3i& t : mesh->mesh->triangles)
          triangles.insert(triangles.end(),
                           {static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]),
                            static_cast<std::uint32_t>(t[2])});
      }
    }
    for (std::size_t i = 0; i < layer.shapes.size(); ++i) shapes_.push_back(to_msg(layer.shapes[i], i));
    msg_.cell = cell_.data();
    msg_.sweep = layer.sweep;
    msg_.stamp_ns = layer.stamp_ns;
    msg_.padding_scale = layer.padding_scale;
    msg_.padding = layer.padding;
    msg_.shapes = sequence_of<dds_sequence_cellmap_msg_RobotShape>(shapes_);
  }
  RobotSample(const RobotSample&) = delete;
  RobotSample& operator=(const RobotSample&) = delete;
  [[nodiscard]] const cellmap_msg_RobotLayer* get() const { return &msg_; }

 private:
  struct KindAndSize {
    cellmap_msg_RobotShapeKind kind;
    std::array<double, 3> size;
    KindAndSize operator()(const BoxShape& box) const {
      return {cellmap_msg_ROBOT_SHAPE_BOX,
              {box.half_extents.x(), box.half_extents.y(), box.half_extents.z()}};
    }
    KindAndSize operator()(const CylinderShape& c) const {
      return {cellmap_msg_ROBOT_SHAPE_CYLINDER, {c.radius, c.half_length, 0.0}};
    }
    KindAndSize operator()(const SphereShape& s) const {
      return {cellmap_msg_ROBOT_SHAPE_SPHERE, {s.radius, 0, 0}};
    }
    KindAndSize operator()(const MeshShape&) const { return {cellmap_msg_ROBOT_SHAPE_MESH, {0, 0, 0}}; }
  };

  cellmap_msg_RobotShape to_msg(const PosedShape& shape, std::size_t i) {
    cellmap_msg_RobotShape msg{};
    msg.link = links_[i].data();
    msg.carried = shape.carried;
    put_pose(shape.X_CG, msg.position, msg.orientation);
    const KindAndSize kind = std::visit(KindAndSize{}, shape.geometry);
    msg.kind = kind.kind;
    for (int k = 0; k < 3; ++k) msg.size[k] = kind.size[k];
    msg.vertices = sequence_of<dds_sequence_float>(vertices_[i]);
    msg.triangles = sequence_of<dds_sequence_uint32>(triangles_[i]);
    return msg;
  }

  std::string cell_;
  std::vector<std::string> links_;  // filled before shapes_ points into them
  std::vector<std::vector<float>> vertices_;
  std::vector<std::vector<std::uint32_t>> triangles_;
  std::vector<cellmap_msg_RobotShape> shapes_;
  cellmap_msg_RobotLayer msg_{};
};

VoxelLayer from_wire(const cellmap_msg_VoxelLayer& msg) {
  VoxelLayer layer;
  layer.cell = wire::cell_of(msg.cell, kVoxelLayerTopic);
  if (!(msg.resolution > 0) || !std::isfinite(msg.resolution))
    throw Error(std::string(kVoxelLayerTopic) + ": resolution: must be a positive number");
  layer.sweep = msg.sweep;
  layer.stamp_ns = msg.stamp_ns;
  layer.resolution = msg.resolution;
  require_at_most(msg.runs._length, kMaxVoxelRuns, "runs", kVoxelLayerTopic);
  layer.runs.reserve(msg.runs._length);
  for (uint32_t i = 0; i < msg.runs._length; ++i) {
    const cellmap_msg_VoxelRun& run = msg.runs._buffer[i];
    layer.runs.push_back({run.x, run.y, run.z, run.length});
  }
  return layer;
}

ChangeRegionLayer from_wire(const cellmap_msg_ChangeRegionLayer& msg) {
  ChangeRegionLayer layer;
  layer.cell = wire::cell_of(msg.cell, kChangeRegionLayerTopic);
  layer.sweep = msg.sweep;
  layer.stamp_ns = msg.stamp_ns;
  require_at_most(msg.regions._length, kMaxRegions, "regions", kChangeRegionLayerTopic);
  for (uint32_t i = 0; i < msg.regions._length; ++i) {
    const cellmap_msg_ChangeRegionBounds& in = msg.regions._buffer[i];
    ChangeRegionBounds region;
    region.bounds.min = {in.min[0], in.min[1], in.min[2]};
    region.bounds.max = {in.max[0], in.max[1], in.max[2]};
    if (!region.bounds.min.allFinite() || !region.bounds.max.allFinite())
      throw Error(std::string(kChangeRegionLayerTopic) + ": regions[" + std::to_string(i) +
                  "]: not a finite number");
    region.appeared = in.appeared;
    region.vanished = in.vanished;
    layer.regions.push_back(region);
  }
  return layer;
}

SensorView from_wire(const cellmap_msg_SensorView& msg, const std::string& where) {
  SensorView view;
  view.sensor = msg.sensor != nullptr ? single_line(msg.sensor, kMaxNameLength) : "";
  view.X_CS = pose_of(msg.position, msg.orientation, where);
  if (!std::isfinite(msg.max_range)) throw Error(where + ": not a finite number");
  require_at_most(msg.outline._length, kMaxOutlineValues, "outline coordinates", where);
  if (msg.outline._length % 3 != 0) throw Error(where + ": outline: not x, y, z triples");
  if (msg.max_range < 0) throw Error(where + ": max_range: must not be negative");
  if (msg.max_range == 0) return view;  // the source did not know its field of view
  FieldOfView fov{{}, msg.closed, msg.max_range};
  for (std::uint32_t i = 0; i < msg.outline._length; i += 3) {
    const double* ray = msg.outline._buffer + i;
    fov.outline_S.emplace_back(ray[0], ray[1], ray[2]);
    if (!fov.outline_S.back().allFinite()) throw Error(where + ": outline: not a finite number");
  }
  view.field_of_view = std::move(fov);
  return view;
}

SensorLayer from_wire(const cellmap_msg_SensorLayer& msg) {
  SensorLayer layer;
  layer.cell = wire::cell_of(msg.cell, kSensorLayerTopic);
  layer.sweep = msg.sweep;
  layer.stamp_ns = msg.stamp_ns;
  require_at_most(msg.views._length, kMaxSensors, "views", kSensorLayerTopic);
  for (std::uint32_t i = 0; i < msg.views._length; ++i) {
    layer.views.push_back(from_wire(msg.views._buffer[i],
                                    std::string(kSensorLayerTopic) + ": views[" + std::to_string(i) + "]"));
  }
  return layer;
}

std::shared_ptr<const TriangleMesh> mesh_of(const cellmap_msg_RobotShape& msg, const std::string& where) {
  require_at_most(msg.vertices._length, kMaxMeshValues, "vertex coordinates", where);
  require_at_most(msg.triangles._length, kMaxMeshValues, "triangle indices", where);
  if (msg.vertices._length % 3 != 0) throw Error(where + ": vertices: not x, y, z triples");
  if (msg.triangles._length % 3 != 0) throw Error(where + ": triangles: not three indices each");
  auto mesh = std::make_shared<TriangleMesh>();
  for (std::uint32_t i = 0; i < msg.vertices._length; i += 3) {
    const float* v = msg.vertices._buffer + i;
    mesh->vertices.emplace_back(v[0], v[1], v[2]);
  }
  for (std::uint32_t i = 0; i < msg.triangles._length; i += 3) {
    const std::uint32_t* t = msg.triangles._buffer + i;
    if (std::max({t[0], t[1], t[2]}) >= mesh->vertices.size())
      throw Error(where + ": triangles: index beyond the vertices");
    mesh->triangles.emplace_back(static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2]));
  }
  return mesh;
}

PosedShape from_wire(const cellmap_msg_RobotShape& msg, const std::string& where) {
  PosedShape shape;
  shape.link = msg.link != nullptr ? single_line(msg.link, kMaxNameLength) : "";
  shape.carried = msg.carried;
  shape.X_CG = pose_of(msg.position, msg.orientation, where);
  const double* size = msg.size;
  switch (msg.kind) {
    case cellmap_msg_ROBOT_SHAPE_BOX:
      shape.geometry = BoxShape{{size[0], size[1], size[2]}};
      break;
    case cellmap_msg_ROBOT_SHAPE_CYLINDER:
      shape.geometry = CylinderShape{size[0], size[1]};
      break;
    case cellmap_msg_ROBOT_SHAPE_SPHERE:
      shape.geometry = SphereShape{size[0]};
      break;
    case cellmap_msg_ROBOT_SHAPE_MESH:
      shape.geometry = MeshShape{mesh_of(msg, where)};
      break;
    default:
      throw Error(where + ": kind: unknown");
  }
  validate_shape({shape.link, Eigen::Isometry3d::Identity(), shape.geometry}, where);
  return shape;
}

RobotLayer from_wire(const cellmap_msg_RobotLayer& msg) {
  RobotLayer layer;
  layer.cell = wire::cell_of(msg.cell, kRobotLayerTopic);
  layer.sweep = msg.sweep;
  layer.stamp_ns = msg.stamp_ns;
  layer.padding_scale = msg.padding_scale;
  layer.padding = msg.padding;
  if (!std::isfinite(layer.padding_scale) || !std::isfinite(layer.padding))
    throw Error(std::string(kRobotLayerTopic) + ": padding: not a finite number");
  require_at_most(msg.shapes._length, kMaxShapes, "shapes", kRobotLayerTopic);
  for (std::uint32_t i = 0; i < msg.shapes._length; ++i) {
    layer.shapes.push_back(from_wire(msg.shapes._buffer[i],
                                     std::string(kRobotLayerTopic) + ": shapes[" + std::to_string(i) + "]"));
  }
  return layer;
}

void require_cell(const std::string& cell, const std::string& expected, const char* topic) {
  if (cell != expected)
    throw Error(std::string(topic) + ": layer of cell '" + cell + "' given to the writer of '" + expected +
                "'");
}

}  // namespace

std::size_t VoxelLayer::voxel_count() const {
  std::size_t count = 0;
  for (const VoxelRun& run : runs) count += run.length;
  return count;
}

std::vector<VoxelRun> voxel_runs(const std::vector<std::array<int, 3>>& indices) {
  constexpr int kMin = std::numeric_limits<std::int16_t>::min();
  constexpr int kMax = std::numeric_limits<std::int16_t>::max();
  std::vector<VoxelRun> runs;
  const std::array<int, 3>* previous = nullptr;
  for (const std::array<int, 3>& index : indices) {
    for (int axis = 0; axis < 3; ++axis) {
      if (index[axis] < kMin || index[axis] > kMax)
        throw Error("voxel_runs: index " + std::to_string(index[axis]) + " outside the int16 range");
    }
    if (previous != nullptr) {
      const auto zyx = [](const std::array<int, 3>& v) { return std::array<int, 3>{v[2], v[1], v[0]}; };
      if (!(zyx(*previous) < zyx(index)))
        throw Error("voxel_runs: indices not sorted by (z, y, x) or repeated");
    }
    VoxelRun* last = runs.empty() ? nullptr : &runs.back();
    if (last != nullptr && last->y == index[1] && last->z == index[2] && last->x + last->length == index[0] &&
        last->length < std::numeric_limits<std::uint16_t>::max()) {
      ++last->length;
    } else {
      runs.push_back({static_cast<std::int16_t>(index[0]), static_cast<std::int16_t>(index[1]),
                      static_cast<std::int16_t>(index[2]), 1});
    }
    previous = &index;
  }
  return runs;
}

std::size_t wire_size(const VoxelLayer& layer) {
  const VoxelSample sample(layer);
  return wire::serialized_size(sample.get(), cellmap_msg_VoxelLayer_desc);
}

std::size_t wire_size(const ChangeRegionLayer& layer) {
  const RegionSample sample(layer);
  return wire::serialized_size(sample.get(), cellmap_msg_ChangeRegionLayer_desc);
}

std::size_t wire_size(const SensorLayer& layer) {
  const SensorSample sample(layer);
  return wire::serialized_size(sample.get(), cellmap_msg_SensorLayer_desc);
}

std::size_t wire_size(const RobotLayer& layer) {
  const RobotSample sample(layer);
  return wire::serialized_size(sample.get(), cellmap_msg_RobotLayer_desc);
}

LayerWriter::LayerWriter(const dds::Participant& participant, std::string cell)
    : cell_(one_cell(std::move(cell), "layer writer")),
      voxel_topic_(participant, descriptor(Layer::kVoxels), kVoxelLayerTopic),
      region_topic_(participant, descriptor(Layer::kChangeRegions), kChangeRegionLayerTopic),
      sensor_topic_(participant, descriptor(Layer::kSensors), kSensorLayerTopic),
      robot_topic_(participant, descriptor(Layer::kRobot), kRobotLayerTopic),
      voxel_writer_(participant, voxel_topic_, in_cell(layer_qos(), cell_)),
      region_writer_(participant, region_topic_, in_cell(layer_qos(), cell_)),
      sensor_writer_(participant, sensor_topic_, in_cell(layer_qos(), cell_)),
      robot_writer_(participant, robot_topic_, in_cell(layer_qos(), cell_)) {}

const dds::Writer& LayerWriter::writer(Layer layer) const {
  switch (layer) {
    case Layer::kVoxels:
      return voxel_writer_;
    case Layer::kChangeRegions:
      return region_writer_;
    case Layer::kSensors:
      return sensor_writer_;
    case Layer::kRobot:
      return robot_writer_;
  }
  throw Error("layer writer: unknown layer");
}

std::uint32_t LayerWriter::readers(Layer layer) const {
  return writer(layer).matched_readers();
}

std::uint32_t LayerWriter::readers_joined(Layer layer) const {
  return writer(layer).matched_readers_ever();
}

void LayerWriter::write(const VoxelLayer& layer) const {
  require_cell(layer.cell, cell_, kVoxelLayerTopic);
  if (!(layer.resolution > 0))
    throw Error(std::string(kVoxelLayerTopic) + ": resolution: must be a positive number");
  const VoxelSample sample(layer);
  voxel_writer_.write(sample.get());
}

void LayerWriter::write(const ChangeRegionLayer& layer) const {
  require_cell(layer.cell, cell_, kChangeRegionLayerTopic);
  const RegionSample sample(layer);
  region_writer_.write(sample.get());
}

void LayerWriter::write(const SensorLayer& layer) const {
  require_cell(layer.cell, cell_, kSensorLayerTopic);
  const SensorSample sample(layer);
  sensor_writer_.write(sample.get());
}

void LayerWriter::write(const RobotLayer& layer) const {
  require_cell(layer.cell, cell_, kRobotLayerTopic);
  for (std::size_t i = 0; i < layer.shapes.size(); ++i) {
    const PosedShape& shape = layer.shapes[i];
    validate_shape({shape.link, shape.X_CG, shape.geometry},
                   std::string(kRobotLayerTopic) + ": shapes[" + std::to_string(i) + "]");
  }
  const RobotSample sample(layer);
  robot_writer_.write(sample.get());
}

LayerReader::LayerReader(const dds::Participant& participant, Layer layer, const std::string& cell)
    : layer_(layer),
      topic_(participant, descriptor(layer), topic_name(layer)),
      reader_(participant, topic_, in_cell(layer_qos(), cell)),
      waitset_(participant) {
  waitset_.attach(reader_);
}

LayerReader::~LayerReader() {
  try {
    waitset_.detach(reader_);
  } catch (const Error&) {
    // Deleting the reader detaches it anyway.
  }
}

std::vector<LayerMessage> LayerReader::take(std::chrono::nanoseconds timeout) {
  if (timeout.count() > 0) waitset_.wait(timeout);
  std::vector<LayerMessage> layers;
  reader_.take_all([&](const void* sample, const dds_sample_info_t&) {
    try {
      switch (layer_) {
        case Layer::kVoxels:
          layers.emplace_back(from_wire(*static_cast<const cellmap_msg_VoxelLayer*>(sample)));
          break;
        case Layer::kChangeRegions:
          layers.emplace_back(from_wire(*static_cast<const cellmap_msg_ChangeRegionLayer*>(sample)));
          break;
        case Layer::kSensors:
          layers.emplace_back(from_wire(*static_cast<const cellmap_msg_SensorLayer*>(sample)));
          break;
        case Layer::kRobot:
          layers.emplace_back(from_wire(*static_cast<const cellmap_msg_RobotLayer*>(sample)));
          break;
      }
    } catch (const Error&) {
      ++rejected_;
    }
  });
  return layers;
}

}  // namespace cellmap::transport
