// SPDX-License-Identifier: Apache-2.0
#pragma once
// Conversions between cellmap's value types and the idlc-generated wire types (private to this stage).
// Outgoing: a *Sample object builds the C struct pointing into its own storage (nothing is dds_alloc'ed), so
// it must outlive the write. Incoming: from_wire() copies out of Cyclone's loaned sample and validates it.

#include <cstdint>
#include <vector>

#include "cellmap.h"
#include "cellmap/environment/environment.hpp"
#include "cellmap/transport/messages.hpp"

namespace cellmap::transport::wire {

class EnvironmentSample {
 public:
  explicit EnvironmentSample(const Environment& env);
  [[nodiscard]] const cellmap_msg_Environment* get() const { return &msg_; }

 private:
  std::string cell_;
  std::vector<cellmap_msg_Box> boxes_;
  cellmap_msg_Environment msg_{};
};

class DeltaSample {
 public:
  explicit DeltaSample(const EnvironmentDelta& delta);
  [[nodiscard]] const cellmap_msg_EnvironmentDelta* get() const { return &msg_; }

 private:
  std::string cell_;
  std::vector<cellmap_msg_Box> added_;
  std::vector<cellmap_msg_Box> modified_;
  std::vector<std::uint64_t> removed_;
  cellmap_msg_EnvironmentDelta msg_{};
};

class StatusSample {
 public:
  explicit StatusSample(const CellStatus& status);
  [[nodiscard]] const cellmap_msg_Status* get() const { return &msg_; }

 private:
  CellStatus status_;
  std::vector<cellmap_msg_SensorState> sensors_;
  cellmap_msg_Status msg_{};
};

class SceneEditSample {
 public:
  explicit SceneEditSample(const SceneEdit& edit);
  [[nodiscard]] const cellmap_msg_SceneEdit* get() const { return &msg_; }

 private:
  SceneEdit edit_;
  cellmap_msg_SceneEdit msg_{};
};

class RobotStateSample {
 public:
  explicit RobotStateSample(const RobotState& state);
  [[nodiscard]] const cellmap_msg_RobotState* get() const { return &msg_; }

 private:
  std::string cell_;
  cellmap_msg_RobotState msg_{};
};

class RobotJointsSample {
 public:
  explicit RobotJointsSample(const RobotJoints& joints);
  [[nodiscard]] const cellmap_msg_RobotJoints* get() const { return &msg_; }

 private:
  RobotJoints joints_;
  std::vector<char*> names_;
  cellmap_msg_ToolPayload payload_{};
  cellmap_msg_RobotJoints msg_{};
};

/// @throws Error naming the topic and field if the cell is empty, names are given but not one per position, a
/// number is not finite, a payload half extent is negative or its rotation is not orthonormal.
void validate(const RobotJoints& joints);

/// The cell of an incoming sample. @throws Error naming the topic if it is empty, longer than kMaxNameLength
/// bytes, not UTF-8 or holding a control character (single_line would change it).
[[nodiscard]] std::string cell_of(const char* cell, const char* topic);
/// Text from the network as a refusal quotes it: in single quotes, on one line (single_line), cut at
/// kMaxNameLength bytes.
[[nodiscard]] std::string quote_input(const std::string& text);
/// How refusals name a sample: "<topic> '<cell>' at <stamp_ns>", the cell as quote_input() gives it.
[[nodiscard]] std::string sample_name(const char* topic, const std::string& cell, std::int64_t stamp_ns);
/// How refusals name a scene edit: "<topic> '<name>'", the name as quote_input() gives it.
[[nodiscard]] std::string edit_name(const std::string& name);
/// The bytes of `sample` (of the generated `type`) in an RTPS DATA submessage: the 4-byte encapsulation
/// header plus the XCDR1 body, measured with Cyclone's own serializer.
[[nodiscard]] std::size_t serialized_size(const void* sample, const dds_topic_descriptor_t& type);

/// @throws Error naming the topic and field if a number is not finite, a half extent is negative, a rotation
/// is not a unit quaternion, the cell is empty or box ids repeat.
[[nodiscard]] Environment from_wire(const cellmap_msg_Environment& msg);
[[nodiscard]] EnvironmentDelta from_wire(const cellmap_msg_EnvironmentDelta& msg);
[[nodiscard]] CellStatus from_wire(const cellmap_msg_Status& msg);
[[nodiscard]] SceneEdit from_wire(const cellmap_msg_SceneEdit& msg);
/// @throws Error also for an empty cell, a non-finite number or a quaternion whose norm is not 1 ± 1e-3.
[[nodiscard]] RobotState from_wire(const cellmap_msg_RobotState& msg);
/// @throws Error as validate(), or for a payload quaternion whose norm is not 1 ± 1e-3.
[[nodiscard]] RobotJoints from_wire(const cellmap_msg_RobotJoints& msg);

}  // namespace cellmap::transport::wire
