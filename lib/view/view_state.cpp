// SPDX-License-Identifier: Apache-2.0
#include "cellmap/view/view_state.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace cellmap::view {
namespace {

using nlohmann::json;

// The message's text. Network text is made valid UTF-8 where it arrives (single_line); replacing keeps a
// string that slipped by from making the writer throw.
std::string text_of(const json& message) {
  return message.dump(-1, ' ', false, json::error_handler_t::replace);
}

json vector_json(const Eigen::Vector3d& v) {
  return json::array({v.x(), v.y(), v.z()});
}

json box_json(const Box& box, std::optional<std::uint64_t> changed_in) {
  return {{"id", box.id},
          {"center", vector_json(box.center)},
          {"half_extents", vector_json(box.half_extents)},
          {"rotation", json::array({box.rotation.w(), box.rotation.x(), box.rotation.y(), box.rotation.z()})},
          {"points", box.points},
          {"space", space_name(box.space)},
          {"changed_in", changed_in ? json(*changed_in) : json(nullptr)}};
}

json boxes_json(const std::vector<Box>& boxes, std::uint64_t changed_in) {
  json out = json::array();
  for (const Box& box : boxes) out.push_back(box_json(box, changed_in));
  return out;
}

json status_object(const transport::CellStatus& status) {
  json sensors = json::array();
  for (const transport::SensorStatus& sensor : status.sensors)
    sensors.push_back({{"name", sensor.name}, {"state", sensor.state}});
  return {{"cell", status.cell},
          {"state", status.state},
          {"reason", status.reason},
          {"sensors", sensors},
          {"last_sweep_ns", status.last_sweep_ns},
          {"sweeps", status.sweeps},
          {"dropped_frames", status.dropped_frames},
          {"refused_inputs", status.refused_inputs},
          {"boxes", status.boxes},
          {"version", status.version}};
}

json status_json(const transport::CellStatus& status, bool daemon) {
  json object = status_object(status);
  object["daemon"] = daemon;
  return object;
}

json voxels_json(const transport::VoxelLayer& layer) {
  json runs = json::array();
  for (const transport::VoxelRun& run : layer.runs) {
    runs.push_back(run.x);
    runs.push_back(run.y);
    runs.push_back(run.z);
    runs.push_back(run.length);
  }
  return {{"type", "voxels"},
          {"cell", layer.cell},
          {"sweep", layer.sweep},
          {"stamp_ns", layer.stamp_ns},
          {"resolution", layer.resolution},
          {"runs", runs}};
}

json regions_json(const transport::ChangeRegionLayer& layer) {
  json regions = json::array();
  for (const transport::ChangeRegionBounds& region : layer.regions) {
    regions.push_back({{"min", vector_json(region.bounds.min)},
                       {"max", vector_json(region.bounds.max)},
                       {"appeared", region.appeared},
                       {"vanished", region.vanished}});
  }
  return {{"type", "regions"},
          {"cell", layer.cell},
          {"sweep", layer.sweep},
          {"stamp_ns", layer.stamp_ns},
          {"regions", regions}};
}

json sensors_json(const transport::SensorLayer& layer) {
  json views = json::array();
  for (const transport::SensorView& view : layer.views) {
    const Eigen::Quaterniond q_CS(view.X_CS.linear());
    json outline = json::array();
    if (view.field_of_view) {
      for (const Eigen::Vector3d& ray : view.field_of_view->outline_S) outline.push_back(vector_json(ray));
    }
    views.push_back({{"sensor", view.sensor},
                     {"position", vector_json(view.X_CS.translation())},
                     {"rotation", json::array({q_CS.w(), q_CS.x(), q_CS.y(), q_CS.z()})},
                     {"max_range", view.field_of_view ? view.field_of_view->max_range : 0.0},
                     {"closed", view.field_of_view && view.field_of_view->closed},
                     {"outline", outline}});
  }
  return {{"type", "sensors"},
          {"cell", layer.cell},
          {"sweep", layer.sweep},
          {"stamp_ns", layer.stamp_ns},
          {"views", views}};
}

// Mesh vertices to 0.1 mm: the page draws them, and short numbers keep the message small.
json rounded(float v) {
  return std::round(static_cast<double>(v) * 1e4) / 1e4;
}

struct ShapeJson {
  json& out;
  void operator()(const BoxShape& box) const {
    out["kind"] = "box";
    out["half_extents"] = vector_json(box.half_extents);
  }
  void operator()(const CylinderShape& cylinder) const {
    out["kind"] = "cylinder";
    out["radius"] = cylinder.radius;
    out["half_length"] = cylinder.half_length;
  }
  void operator()(const SphereShape& sphere) const {
    out["kind"] = "sphere";
    out["radius"] = sphere.radius;
  }
  void operator()(const MeshShape& shape) const {
    out["kind"] = "mesh";
    json vertices = json::array();
    for (const Eigen::Vector3d& v : shape.mesh->vertices)
      for (int k = 0; k < 3; ++k) vertices.push_back(rounded(static_cast<float>(v[k])));
    json triangles = json::array();
    for (const Eigen::Vector3i& t : shape.mesh->triangles)
      for (int k = 0; k < 3; ++k) triangles.push_back(t[k]);
    out["vertices"] = std::move(vertices);
    out["triangles"] = std::move(triangles);
  }
};

json robot_json(const transport::RobotLayer& layer) {
  json shapes = json::array();
  for (const transport::PosedShape& shape : layer.shapes) {
    const Eigen::Quaterniond q_CG(shape.X_CG.linear());
    json out{{"link", shape.link},
             {"carried", shape.carried},
             {"position", vector_json(shape.X_CG.translation())},
             {"rotation", json::array({q_CG.w(), q_CG.x(), q_CG.y(), q_CG.z()})}};
    std::visit(ShapeJson{out}, shape.geometry);
    shapes.push_back(std::move(out));
  }
  return {{"type", "robot"},
          {"cell", layer.cell},
          {"sweep", layer.sweep},
          {"stamp_ns", layer.stamp_ns},
          {"padding_scale", layer.padding_scale},
          {"padding", layer.padding},
          {"shapes", shapes}};
}

struct LayerJson {
  json operator()(const transport::VoxelLayer& layer) const { return voxels_json(layer); }
  json operator()(const transport::ChangeRegionLayer& layer) const { return regions_json(layer); }
  json operator()(const transport::SensorLayer& layer) const { return sensors_json(layer); }
  json operator()(const transport::RobotLayer& layer) const { return robot_json(layer); }
};

}  // namespace

std::string status_json(const transport::CellStatus& status) {
  return text_of(status_object(status));
}

const char* layer_name(transport::Layer layer) {
  switch (layer) {
    case transport::Layer::kVoxels:
      return "voxels";
    case transport::Layer::kChangeRegions:
      return "regions";
    case transport::Layer::kSensors:
      return "sensors";
    case transport::Layer::kRobot:
      return "robot";
  }
  return "?";
}

ViewState::ViewState(std::uint32_t domain, std::string cell_filter, std::size_t timeline_length)
    : domain_(domain), cell_filter_(std::move(cell_filter)), timeline_length_(timeline_length) {}

bool ViewState::followed(const std::string& cell) const {
  return cell_filter_.empty() || cell == cell_filter_;
}

std::string ViewState::on_version(const Environment& env, const EnvironmentDelta& delta,
                                  std::int64_t received_ns) {
  if (!followed(env.cell())) return "";
  const std::lock_guard<std::mutex> lock(mutex_);
  Cell& cell = cells_[env.cell()];
  // A first copy beyond version 1 carries boxes whose last change the viewer never saw.
  const bool joined_late = !cell.environment && delta.to_version > 1;
  for (const Box& box : delta.added) cell.changed_in[box.id] = delta.to_version;
  for (const Box& box : delta.modified) cell.changed_in[box.id] = delta.to_version;
  for (std::uint64_t id : delta.removed) cell.changed_in.erase(id);
  if (joined_late) {
    for (const Box& box : delta.added) cell.changed_in.erase(box.id);
  }
  cell.environment = env;
  cell.timeline.push_back({delta.from_version, delta.to_version, delta.stamp_ns, received_ns,
                           delta.added.size(), delta.modified.size(), delta.removed.size()});
  while (cell.timeline.size() > timeline_length_) cell.timeline.pop_front();

  const auto changed_in = [&](std::uint64_t id) -> std::optional<std::uint64_t> {
    const auto found = cell.changed_in.find(id);
    if (found == cell.changed_in.end()) return std::nullopt;
    return found->second;
  };
  json added = json::array();
  for (const Box& box : delta.added) added.push_back(box_json(box, changed_in(box.id)));
  return text_of(json{{"type", "version"},
                      {"cell", env.cell()},
                      {"from_version", delta.from_version},
                      {"to_version", delta.to_version},
                      {"stamp_ns", delta.stamp_ns},
                      {"received_ns", received_ns},
                      {"added", added},
                      {"modified", boxes_json(delta.modified, delta.to_version)},
                      {"removed", delta.removed}});
}

std::string ViewState::on_status(const transport::CellStatus& status) {
  if (!followed(status.cell)) return "";
  const std::lock_guard<std::mutex> lock(mutex_);
  Cell& cell = cells_[status.cell];
  cell.status = status;
  cell.daemon = true;
  json message = status_json(status, true);
  message["type"] = "status";
  return text_of(message);
}

std::string ViewState::on_daemon_gone(const std::string& cell_name) {
  if (!followed(cell_name)) return "";
  const std::lock_guard<std::mutex> lock(mutex_);
  Cell& cell = cells_[cell_name];
  cell.daemon = false;
  transport::CellStatus last = cell.status.value_or(transport::CellStatus{});
  last.cell = cell_name;
  json message = status_json(last, false);
  message["type"] = "status";
  return text_of(message);
}

std::string ViewState::on_layer(const transport::LayerMessage& layer) {
  const std::string& cell_name =
      std::visit([](const auto& l) -> const std::string& { return l.cell; }, layer);
  if (!followed(cell_name)) return "";
  std::string message = text_of(std::visit(LayerJson{}, layer));
  const std::lock_guard<std::mutex> lock(mutex_);
  cells_[cell_name].layers[transport::layer_of(layer)] = message;
  return message;
}

std::string ViewState::state() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  json cells = json::array();
  for (const auto& [name, cell] : cells_) {
    json boxes = json::array();
    json timeline = json::array();
    if (cell.environment) {
      for (const Box& box : cell.environment->boxes()) {
        const auto found = cell.changed_in.find(box.id);
        boxes.push_back(
            box_json(box, found == cell.changed_in.end() ? std::nullopt : std::optional(found->second)));
      }
    }
    for (const TimelineEntry& entry : cell.timeline) {
      timeline.push_back({{"from_version", entry.from_version},
                          {"to_version", entry.to_version},
                          {"stamp_ns", entry.stamp_ns},
                          {"received_ns", entry.received_ns},
                          {"added", entry.added},
                          {"modified", entry.modified},
                          {"removed", entry.removed}});
    }
    cells.push_back({{"cell", name},
                     {"version", cell.environment ? cell.environment->version() : 0},
                     {"stamp_ns", cell.environment ? cell.environment->stamp_ns() : 0},
                     {"boxes", boxes},
                     {"timeline", timeline},
                     {"status", cell.status ? status_json(*cell.status, cell.daemon) : json(nullptr)}});
  }
  return text_of(
      json{{"type", "state"}, {"domain", domain_}, {"cell_filter", cell_filter_}, {"cells", cells}});
}

std::vector<std::string> ViewState::layers(transport::Layer layer) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> messages;
  for (const auto& [name, cell] : cells_) {
    const auto found = cell.layers.find(layer);
    if (found != cell.layers.end()) messages.push_back(found->second);
  }
  return messages;
}

bool ViewState::daemon(const std::string& cell) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto found = cells_.find(cell);
  return found != cells_.end() && found->second.daemon;
}

std::vector<std::string> ViewState::cells() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> names;
  for (const auto& [name, cell] : cells_) names.push_back(name);
  return names;
}

}  // namespace cellmap::view
