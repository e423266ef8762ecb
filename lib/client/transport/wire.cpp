// SPDX-License-Identifier: Apache-2.0
#include "wire.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/transport/input_limits.hpp"
#include "cellmap/transport/topics.hpp"

namespace cellmap::transport::wire {
namespace {

// The generated structs take non-const char*; Cyclone only reads them when writing.
char* text(const std::string& s) {
  return const_cast<char*>(s.c_str());
}

template <class Sequence, class T>
Sequence sequence_of(std::vector<T>& items) {
  Sequence seq{};
  seq._maximum = seq._length = static_cast<uint32_t>(items.size());
  seq._buffer = items.data();
  seq._release = false;
  return seq;
}

cellmap_msg_Box to_msg(const Box& box) {
  cellmap_msg_Box msg{};
  msg.id = box.id;
  for (int i = 0; i < 3; ++i) {
    msg.center[i] = box.center[i];
    msg.half_extents[i] = box.half_extents[i];
  }
  msg.rotation[0] = box.rotation.w();
  msg.rotation[1] = box.rotation.x();
  msg.rotation[2] = box.rotation.y();
  msg.rotation[3] = box.rotation.z();
  msg.points = box.points;
  msg.space = static_cast<std::uint8_t>(box.space);
  return msg;
}

std::vector<cellmap_msg_Box> to_msgs(const std::vector<Box>& boxes) {
  std::vector<cellmap_msg_Box> out;
  out.reserve(boxes.size());
  for (const Box& box : boxes) out.push_back(to_msg(box));
  return out;
}

void require_finite(const double* values, int n, const std::string& where) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) throw Error(where + ": not a finite number");
  }
}

Box from_msg(const cellmap_msg_Box& msg, const std::string& where) {
  require_finite(msg.center, 3, where + ".center");
  require_finite(msg.half_extents, 3, where + ".half_extents");
  require_finite(msg.rotation, 4, where + ".rotation");
  Box box;
  box.id = msg.id;
  box.center = {msg.center[0], msg.center[1], msg.center[2]};
  box.half_extents = {msg.half_extents[0], msg.half_extents[1], msg.half_extents[2]};
  if (box.half_extents.minCoeff() < 0) throw Error(where + ".half_extents: must not be negative");
  // Kept bit for bit (no re-normalisation), so a box compares equal to the one the publisher sent.
  box.rotation = Eigen::Quaterniond(msg.rotation[0], msg.rotation[1], msg.rotation[2], msg.rotation[3]);
  if (std::abs(box.rotation.norm() - 1.0) > 1e-6) throw Error(where + ".rotation: must be a unit quaternion");
  box.points = msg.points;
  if (msg.space > static_cast<std::uint8_t>(BoxSpace::kUnknown))
    throw Error(where + ".space: " + std::to_string(msg.space) + " is not 0 (occupied) or 1 (unknown)");
  box.space = static_cast<BoxSpace>(msg.space);
  return box;
}

std::vector<Box> from_msgs(const dds_sequence_cellmap_msg_Box& seq, const std::string& where) {
  require_at_most(seq._length, kMaxBoxes, "boxes", where);
  std::vector<Box> boxes;
  boxes.reserve(seq._length);
  for (uint32_t i = 0; i < seq._length; ++i) {
    boxes.push_back(from_msg(seq._buffer[i], where + "[" + std::to_string(i) + "]"));
  }
  return boxes;
}

// A writer may send any 32-bit value; reading one outside the enumerators through the enum type is undefined
// behaviour, so the value is read as the integer it is on the wire.
std::int32_t kind_on_the_wire(const cellmap_msg_SceneEdit& msg) {
  static_assert(sizeof msg.kind == sizeof(std::int32_t), "IDL enums are 32 bits on the wire");
  std::int32_t kind;
  std::memcpy(&kind, &msg.kind, sizeof kind);
  return kind;
}

// Text a status carries only to be shown: made safe to show, whatever a writer put in it.
constexpr std::size_t kMaxReasonLength = 1024;
std::string shown(const char* text, std::size_t max_bytes = kMaxNameLength) {
  return text == nullptr ? std::string() : single_line(text, max_bytes);
}

}  // namespace

std::string cell_of(const char* cell, const char* topic) {
  if (cell == nullptr || *cell == '\0') throw Error(std::string(topic) + ": cell: must not be empty");
  if (single_line(cell, kMaxNameLength) != cell) {
    throw Error(std::string(topic) + " " + quote_input(cell) + ": cell: longer than " +
                std::to_string(kMaxNameLength) + " bytes, not UTF-8, or holding a control character");
  }
  return cell;
}

std::string quote_input(const std::string& text) {
  return "'" + single_line(text, kMaxNameLength) + "'";
}

std::string sample_name(const char* topic, const std::string& cell, std::int64_t stamp_ns) {
  return std::string(topic) + " " + quote_input(cell) + " at " + std::to_string(stamp_ns);
}

std::string edit_name(const std::string& name) {
  return std::string(kSceneEditTopic) + " " + quote_input(name);
}

EnvironmentSample::EnvironmentSample(const Environment& env)
    : cell_(env.cell()), boxes_(to_msgs(env.boxes())) {
  msg_.cell = text(cell_);
  msg_.version = env.version();
  msg_.stamp_ns = env.stamp_ns();
  msg_.boxes = sequence_of<dds_sequence_cellmap_msg_Box>(boxes_);
}

DeltaSample::DeltaSample(const EnvironmentDelta& delta)
    : cell_(delta.cell),
      added_(to_msgs(delta.added)),
      modified_(to_msgs(delta.modified)),
      removed_(delta.removed) {
  msg_.cell = text(cell_);
  msg_.from_version = delta.from_version;
  msg_.to_version = delta.to_version;
  msg_.stamp_ns = delta.stamp_ns;
  msg_.added = sequence_of<dds_sequence_cellmap_msg_Box>(added_);
  msg_.modified = sequence_of<dds_sequence_cellmap_msg_Box>(modified_);
  msg_.removed = sequence_of<dds_sequence_uint64>(removed_);
}

StatusSample::StatusSample(const CellStatus& status) : status_(status) {
  for (const SensorStatus& sensor : status_.sensors)
    sensors_.push_back({text(sensor.name), text(sensor.state)});
  msg_.cell = text(status_.cell);
  msg_.state = text(status_.state);
  msg_.sensors = sequence_of<dds_sequence_cellmap_msg_SensorState>(sensors_);
  msg_.last_sweep_ns = status_.last_sweep_ns;
  msg_.sweeps = status_.sweeps;
  msg_.dropped_frames = status_.dropped_frames;
  msg_.boxes = status_.boxes;
  msg_.version = status_.version;
  msg_.reason = text(status_.reason);
  msg_.refused_inputs = status_.refused_inputs;
}

SceneEditSample::SceneEditSample(const SceneEdit& edit) : edit_(edit) {
  msg_.cell = text(edit_.cell);
  switch (edit_.kind) {
    case SceneEdit::Kind::kAddBox:
      msg_.kind = cellmap_msg_SCENE_EDIT_ADD_BOX;
      break;
    case SceneEdit::Kind::kRemove:
      msg_.kind = cellmap_msg_SCENE_EDIT_REMOVE;
      break;
    case SceneEdit::Kind::kMove:
      msg_.kind = cellmap_msg_SCENE_EDIT_MOVE;
      break;
  }
  msg_.name = text(edit_.name);
  for (int i = 0; i < 3; ++i) {
    msg_.center[i] = edit_.center[i];
    msg_.half_extents[i] = edit_.half_extents[i];
  }
  msg_.yaw = edit_.yaw;
}

RobotStateSample::RobotStateSample(const RobotState& state) : cell_(state.cell) {
  msg_.cell = text(cell_);
  msg_.stamp_ns = state.stamp_ns;
  const Eigen::Vector3d p_CE = state.X_CE.translation();
  const Eigen::Quaterniond q_CE(state.X_CE.linear());
  for (int i = 0; i < 3; ++i) msg_.position[i] = p_CE[i];
  msg_.orientation[0] = q_CE.w();
  msg_.orientation[1] = q_CE.x();
  msg_.orientation[2] = q_CE.y();
  msg_.orientation[3] = q_CE.z();
}

Environment from_wire(const cellmap_msg_Environment& msg) {
  const std::string where = std::string(kEnvironmentTopic) + " version " + std::to_string(msg.version);
  return Environment(cell_of(msg.cell, kEnvironmentTopic), msg.version, msg.stamp_ns,
                     from_msgs(msg.boxes, where + ": boxes"));
}

EnvironmentDelta from_wire(const cellmap_msg_EnvironmentDelta& msg) {
  const std::string where = std::string(kEnvironmentDeltaTopic) + " " + std::to_string(msg.from_version) +
                            " -> " + std::to_string(msg.to_version);
  EnvironmentDelta delta;
  delta.cell = cell_of(msg.cell, kEnvironmentDeltaTopic);
  delta.from_version = msg.from_version;
  delta.to_version = msg.to_version;
  delta.stamp_ns = msg.stamp_ns;
  delta.added = from_msgs(msg.added, where + ": added");
  delta.modified = from_msgs(msg.modified, where + ": modified");
  require_at_most(msg.removed._length, kMaxBoxes, "ids", where + ": removed");
  delta.removed.assign(msg.removed._buffer, msg.removed._buffer + msg.removed._length);
  return delta;
}

CellStatus from_wire(const cellmap_msg_Status& msg) {
  CellStatus status;
  status.cell = cell_of(msg.cell, kStatusTopic);
  status.state = shown(msg.state);
  require_at_most(msg.sensors._length, kMaxSensors, "sensors",
                  std::string(kStatusTopic) + " " + quote_input(status.cell));
  for (uint32_t i = 0; i < msg.sensors._length; ++i) {
    const cellmap_msg_SensorState& s = msg.sensors._buffer[i];
    status.sensors.push_back({shown(s.name), shown(s.state)});
  }
  status.last_sweep_ns = msg.last_sweep_ns;
  status.sweeps = msg.sweeps;
  status.dropped_frames = msg.dropped_frames;
  status.boxes = msg.boxes;
  status.version = msg.version;
  status.reason = shown(msg.reason, kMaxReasonLength);
  status.refused_inputs = msg.refused_inputs;
  return status;
}

SceneEdit from_wire(const cellmap_msg_SceneEdit& msg) {
  const std::string where = edit_name(msg.name ? msg.name : "");
  SceneEdit edit;
  edit.cell = msg.cell == nullptr || *msg.cell == '\0' ? "" : cell_of(msg.cell, kSceneEditTopic);
  switch (kind_on_the_wire(msg)) {
    case cellmap_msg_SCENE_EDIT_ADD_BOX:
      edit.kind = SceneEdit::Kind::kAddBox;
      break;
    case cellmap_msg_SCENE_EDIT_REMOVE:
      edit.kind = SceneEdit::Kind::kRemove;
      break;
    case cellmap_msg_SCENE_EDIT_MOVE:
      edit.kind = SceneEdit::Kind::kMove;
      break;
    default:
      throw Error(where + ": kind: unknown value " + std::to_string(kind_on_the_wire(msg)));
  }
  edit.name = msg.name ? msg.name : "";
  if (edit.name.empty()) throw Error(where + ": name: must not be empty");
  // Names go to logs and scene files one per line.
  if (single_line(edit.name) != edit.name) {
    throw Error(where + ": name: not UTF-8, or holding a control character");
  }
  require_finite(msg.center, 3, where + ": center");
  require_finite(msg.half_extents, 3, where + ": half_extents");
  require_finite(&msg.yaw, 1, where + ": yaw");
  edit.center = {msg.center[0], msg.center[1], msg.center[2]};
  edit.half_extents = {msg.half_extents[0], msg.half_extents[1], msg.half_extents[2]};
  if (edit.half_extents.minCoeff() < 0) throw Error(where + ": half_extents: must not be negative");
  edit.yaw = msg.yaw;
  return edit;
}

RobotState from_wire(const cellmap_msg_RobotState& msg) {
  RobotState state;
  state.cell = cell_of(msg.cell, kRobotStateTopic);
  const std::string where = sample_name(kRobotStateTopic, state.cell, msg.stamp_ns);
  require_finite(msg.position, 3, where + ": position");
  require_finite(msg.orientation, 4, where + ": orientation");
  const Eigen::Quaterniond q(msg.orientation[0], msg.orientation[1], msg.orientation[2], msg.orientation[3]);
  // Controllers send single-precision or rounded quaternions; accept them, refuse swapped or zero ones.
  if (std::abs(q.norm() - 1.0) > 1e-3)
    throw Error(where + ": orientation: must be a unit quaternion [w, x, y, z]");
  state.stamp_ns = msg.stamp_ns;
  state.X_CE.linear() = q.normalized().toRotationMatrix();
  state.X_CE.translation() = Eigen::Vector3d(msg.position[0], msg.position[1], msg.position[2]);
  return state;
}

RobotJointsSample::RobotJointsSample(const RobotJoints& joints) : joints_(joints) {
  for (const std::string& name : joints_.names) names_.push_back(text(name));
  msg_.cell = text(joints_.cell);
  msg_.stamp_ns = joints_.stamp_ns;
  msg_.names = sequence_of<dds_sequence_string>(names_);
  msg_.positions = sequence_of<dds_sequence_double>(joints_.positions);
  if (joints_.payload) {
    const Payload& payload = *joints_.payload;
    const Eigen::Quaterniond q_EB(payload.X_EB.linear());
    for (int i = 0; i < 3; ++i) {
      payload_.center[i] = payload.X_EB.translation()[i];
      payload_.half_extents[i] = payload.half_extents[i];
    }
    payload_.rotation[0] = q_EB.w();
    payload_.rotation[1] = q_EB.x();
    payload_.rotation[2] = q_EB.y();
    payload_.rotation[3] = q_EB.z();
    msg_.payload._maximum = msg_.payload._length = 1;
    msg_.payload._buffer = &payload_;
    msg_.payload._release = false;
  }
}

void validate(const RobotJoints& joints) {
  if (joints.cell.empty()) throw Error(std::string(kRobotJointsTopic) + ": cell: must not be empty");
  const std::string where = std::string(kRobotJointsTopic) + " " + quote_input(joints.cell);
  if (!joints.names.empty() && joints.names.size() != joints.positions.size()) {
    throw Error(where + ": " + std::to_string(joints.names.size()) + " names for " +
                std::to_string(joints.positions.size()) + " positions");
  }
  require_finite(joints.positions.data(), static_cast<int>(joints.positions.size()), where + ": positions");
  if (joints.payload) {
    const Payload& payload = *joints.payload;
    if (!payload.X_EB.matrix().allFinite() || !payload.half_extents.allFinite()) {
      throw Error(where + ": payload: not a finite number");
    }
    if (payload.half_extents.minCoeff() < 0)
      throw Error(where + ": payload.half_extents: must not be negative");
    const Eigen::Matrix3d R = payload.X_EB.linear();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
        R.determinant() < 0) {
      throw Error(where + ": payload.rotation: must be a rotation");
    }
  }
}

RobotJoints from_wire(const cellmap_msg_RobotJoints& msg) {
  RobotJoints joints;
  joints.cell = cell_of(msg.cell, kRobotJointsTopic);
  joints.stamp_ns = msg.stamp_ns;
  const std::string where = std::string(kRobotJointsTopic) + " " + quote_input(joints.cell);
  require_at_most(msg.names._length, kMaxJoints, "names", where);
  require_at_most(msg.positions._length, kMaxJoints, "positions", where);
  for (uint32_t i = 0; i < msg.names._length; ++i) {
    joints.names.emplace_back(msg.names._buffer[i] ? msg.names._buffer[i] : "");
    if (joints.names.back().size() > kMaxNameLength)
      throw Error(where + ": names[" + std::to_string(i) + "]: longer than " +
                  std::to_string(kMaxNameLength) + " bytes");
  }
  joints.positions.assign(msg.positions._buffer, msg.positions._buffer + msg.positions._length);
  if (msg.payload._length == 1) {
    const cellmap_msg_ToolPayload& p = msg.payload._buffer[0];
    require_finite(p.rotation, 4, where + ": payload.rotation");
    const Eigen::Quaterniond q(p.rotation[0], p.rotation[1], p.rotation[2], p.rotation[3]);
    if (std::abs(q.norm() - 1.0) > 1e-3)
      throw Error(where + ": payload.rotation: must be a unit quaternion [w, x, y, z]");
    Payload payload;
    payload.X_EB.linear() = q.normalized().toRotationMatrix();
    payload.X_EB.translation() = Eigen::Vector3d(p.center[0], p.center[1], p.center[2]);
    payload.half_extents = Eigen::Vector3d(p.half_extents[0], p.half_extents[1], p.half_extents[2]);
    joints.payload = payload;
  }
  validate(joints);
  return joints;
}

}  // namespace cellmap::transport::wire
