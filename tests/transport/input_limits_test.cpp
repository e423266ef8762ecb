// SPDX-License-Identifier: Apache-2.0
// Every rule a DDS input of the daemon must pass, one by one, as the readers apply them: the wire format's
// (from_wire: finite numbers, unit quaternions, known kinds, names) and the cell's (check_limits: inside the
// cell, sizes that fit, stamps near now).
#include "cellmap/transport/input_limits.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "support/test_support.hpp"
// lib/client/transport's private wire conversion: the samples exactly as DDS delivers them.
#include "wire.hpp"

namespace cellmap::transport {
namespace {

using namespace std::chrono_literals;
constexpr std::int64_t kNow = 1'700'000'000'000'000'000;

InputLimits cell_limits() {
  InputLimits limits;  // the default simulated cell's bounds
  limits.cell = Eigen::AlignedBox3d(Eigen::Vector3d(-0.5, -0.5, -0.2), Eigen::Vector3d(3.5, 2.5, 2.6));
  limits.max_stamp_skew = 5s;
  return limits;
}

class SceneEditRulesTest : public ::testing::Test {
 protected:
  SceneEditRulesTest() {
    msg_.cell = cell_.data();
    msg_.name = name_.data();
    msg_.kind = cellmap_msg_SCENE_EDIT_ADD_BOX;
    msg_.center[0] = 2.12, msg_.center[1] = 0.45, msg_.center[2] = 0.9;
    msg_.half_extents[0] = msg_.half_extents[1] = 0.1, msg_.half_extents[2] = 0.15;
  }
  // The reason the edit is refused, "" if accepted.
  std::string refusal() {
    return test::error_of([&] { check_limits(wire::from_wire(msg_), cell_limits()); });
  }
  std::string cell_ = "cell-1";
  std::string name_ = "box-1";
  cellmap_msg_SceneEdit msg_{};
};

TEST_F(SceneEditRulesTest, AGoodEditPasses) {
  EXPECT_EQ(refusal(), "");
}

TEST_F(SceneEditRulesTest, NonFiniteNumbersAreRefused) {
  msg_.center[1] = std::nan("");
  EXPECT_EQ(refusal(), "cellmap/sim/scene_edits 'box-1': center: not a finite number");
  msg_.center[1] = 0.45;
  msg_.yaw = std::numeric_limits<double>::infinity();
  EXPECT_EQ(refusal(), "cellmap/sim/scene_edits 'box-1': yaw: not a finite number");
}

TEST_F(SceneEditRulesTest, CentresOutsideTheCellAreRefused) {
  msg_.center[0] = 1e300;
  EXPECT_EQ(refusal(),
            "cellmap/sim/scene_edits 'box-1': center: (1e+300, 0.45, 0.9) is outside the cell [-0.5, -0.5, "
            "-0.2] - [3.5, 2.5, 2.6]");
  msg_.kind = cellmap_msg_SCENE_EDIT_MOVE;
  EXPECT_NE(refusal().find("is outside the cell"), std::string::npos);
  msg_.kind = cellmap_msg_SCENE_EDIT_REMOVE;  // a removal uses only the name
  EXPECT_EQ(refusal(), "");
}

TEST_F(SceneEditRulesTest, SizesThatDoNotFitTheCellAreRefused) {
  msg_.half_extents[2] = 0.0;
  EXPECT_NE(refusal().find("half_extents: (0.1, 0.1, 0) must be positive and at most 2"), std::string::npos)
      << refusal();
  msg_.half_extents[2] = 2.01;  // the cell's largest side is 4 m
  EXPECT_NE(refusal().find("half_extents"), std::string::npos);
  msg_.half_extents[2] = -1.0;
  EXPECT_EQ(refusal(), "cellmap/sim/scene_edits 'box-1': half_extents: must not be negative");
}

TEST_F(SceneEditRulesTest, AYawBeyondAFullTurnIsRefused) {
  msg_.yaw = 1e300;
  EXPECT_NE(refusal().find("yaw: "), std::string::npos);
  msg_.yaw = -6.0;
  EXPECT_EQ(refusal(), "");
}

TEST_F(SceneEditRulesTest, UnknownKindsAndBadNamesAreRefused) {
  msg_.kind = static_cast<cellmap_msg_SceneEditKind>(7);
  EXPECT_EQ(refusal(), "cellmap/sim/scene_edits 'box-1': kind: unknown value 7");
  msg_.kind = cellmap_msg_SCENE_EDIT_ADD_BOX;
  name_.clear();
  msg_.name = name_.data();
  EXPECT_EQ(refusal(), "cellmap/sim/scene_edits '': name: must not be empty");
  name_.assign(200, 'x');
  msg_.name = name_.data();
  EXPECT_EQ(refusal(),
            "cellmap/sim/scene_edits '" + std::string(128, 'x') + "': name: longer than 128 bytes");
}

// A name with a line break would split the log line that quotes it (found by fuzz_dds_samples:
// fuzz/regressions/dds_samples/scene_edit_name_with_line_break).
TEST_F(SceneEditRulesTest, ANameWithAControlCharacterIsRefusedOnOneLine) {
  name_ = "c\n2026-12-02T06:00:00.000 info forged";
  msg_.name = name_.data();
  EXPECT_EQ(refusal(),
            "cellmap/sim/scene_edits 'c?2026-12-02T06:00:00.000 info forged': name: not UTF-8, or holding a "
            "control character");
  name_ = "tab\there";
  msg_.name = name_.data();
  EXPECT_EQ(refusal(), "cellmap/sim/scene_edits 'tab?here': name: not UTF-8, or holding a control character");
}

TEST_F(SceneEditRulesTest, ANameThatIsNotUtf8OrReordersTextIsRefused) {
  name_ = "c\xffx";
  msg_.name = name_.data();
  EXPECT_EQ(refusal(), "cellmap/sim/scene_edits 'c?x': name: not UTF-8, or holding a control character");
  name_ = "box\u202e1-xob";  // right-to-left override: shown as "boxbox-1"
  msg_.name = name_.data();
  EXPECT_EQ(refusal(),
            "cellmap/sim/scene_edits 'box?1-xob': name: not UTF-8, or holding a control character");
  name_ = "Kiste-\u00e4";
  msg_.name = name_.data();
  EXPECT_EQ(refusal(), "");
}

// Every text a sample carries reaches logs, JSON writers (cellmap echo, view) and the page: a cell id that is
// not clean refuses the sample; text only shown (states, sensor names, reasons) is made clean.
TEST(NetworkTextTest, AnUncleanCellRefusesTheSampleAndShownTextIsMadeClean) {
  std::string cell = "c\xffx";
  cellmap_msg_Environment environment{};
  environment.cell = cell.data();
  EXPECT_EQ(
      test::error_of([&] { (void)wire::from_wire(environment); }),
      "cellmap/environment 'c?x': cell: longer than 128 bytes, not UTF-8, or holding a control character");
  cell = std::string(129, 'c');
  environment.cell = cell.data();
  EXPECT_NE(test::error_of([&] { (void)wire::from_wire(environment); }).find("longer than 128 bytes"),
            std::string::npos);
  cell = "cell\n2026-12-02T06:00:00.000 info forged";
  cellmap_msg_Status status{};
  status.cell = cell.data();
  EXPECT_NE(test::error_of([&] { (void)wire::from_wire(status); }), "");

  cell = "cell-1";
  std::string state = "run\xffning<img src=x>", sensor = "post\u2028", reason = "gone\u202e";
  cellmap_msg_SensorState sensors[1]{};
  sensors[0].name = sensor.data();
  sensors[0].state = state.data();
  status.cell = cell.data();
  status.state = state.data();
  status.reason = reason.data();
  status.sensors._buffer = sensors;
  status.sensors._length = status.sensors._maximum = 1;
  const CellStatus read = wire::from_wire(status);
  EXPECT_EQ(read.cell, "cell-1");
  EXPECT_EQ(read.state, "run?ning<img src=x>");  // markup is the page's to escape
  EXPECT_EQ(read.sensors.at(0).name, "post?");
  EXPECT_EQ(read.sensors.at(0).state, "run?ning<img src=x>");
  EXPECT_EQ(read.reason, "gone?");
}

// No writer makes a reader hold or loop over more than a real cell could send.
TEST(CountLimitsTest, ASampleCarryingMoreThanItsLimitIsRefusedWithTheCount) {
  std::string cell = "cell-1";
  std::vector<cellmap_msg_Box> boxes(kMaxBoxes + 1);
  for (cellmap_msg_Box& box : boxes) box.rotation[0] = 1.0;
  cellmap_msg_Environment environment{};
  environment.cell = cell.data();
  environment.version = 3;
  environment.boxes._buffer = boxes.data();
  environment.boxes._length = environment.boxes._maximum = static_cast<std::uint32_t>(boxes.size());
  EXPECT_EQ(test::error_of([&] { (void)wire::from_wire(environment); }),
            "cellmap/environment version 3: boxes: 100001 boxes, more than the 100000 a sample may carry");
  environment.boxes._length = static_cast<std::uint32_t>(kMaxBoxes);
  EXPECT_EQ(test::error_of([&] { (void)wire::from_wire(environment); }).find("a sample may carry"),
            std::string::npos);

  std::vector<std::uint64_t> ids(kMaxBoxes + 1);
  cellmap_msg_EnvironmentDelta delta{};
  delta.cell = cell.data();
  delta.from_version = 3;
  delta.to_version = 4;
  delta.removed._buffer = ids.data();
  delta.removed._length = delta.removed._maximum = static_cast<std::uint32_t>(ids.size());
  EXPECT_EQ(test::error_of([&] { (void)wire::from_wire(delta); }),
            "cellmap/environment_delta 3 -> 4: removed: 100001 ids, more than the 100000 a sample may carry");

  std::string name = "camera", state = "streaming";
  std::vector<cellmap_msg_SensorState> sensors(kMaxSensors + 1,
                                               cellmap_msg_SensorState{name.data(), state.data()});
  cellmap_msg_Status status{};
  status.cell = cell.data();
  status.sensors._buffer = sensors.data();
  status.sensors._length = status.sensors._maximum = static_cast<std::uint32_t>(sensors.size());
  EXPECT_EQ(test::error_of([&] { (void)wire::from_wire(status); }),
            "cellmap/status 'cell-1': 65 sensors, more than the 64 a sample may carry");

  std::vector<char*> names(kMaxJoints + 1, name.data());
  std::vector<double> positions(kMaxJoints + 1, 0.0);
  cellmap_msg_RobotJoints joints{};
  joints.cell = cell.data();
  joints.names._buffer = names.data();
  joints.names._length = joints.names._maximum = static_cast<std::uint32_t>(names.size());
  joints.positions._buffer = positions.data();
  joints.positions._length = joints.positions._maximum = static_cast<std::uint32_t>(positions.size());
  EXPECT_EQ(test::error_of([&] { (void)wire::from_wire(joints); }),
            "cellmap/robot_joints 'cell-1': 65 names, more than the 64 a sample may carry");
  std::string long_name(kMaxNameLength + 1, 'j');
  names.assign(1, long_name.data());
  joints.names._length = joints.positions._length = 1;
  EXPECT_EQ(test::error_of([&] { (void)wire::from_wire(joints); }),
            "cellmap/robot_joints 'cell-1': names[0]: longer than 128 bytes");
}

class RobotStateRulesTest : public ::testing::Test {
 protected:
  RobotStateRulesTest() {
    msg_.cell = cell_.data();
    msg_.stamp_ns = kNow;
    msg_.position[0] = 1.0, msg_.position[1] = 0.5, msg_.position[2] = 1.5;
    msg_.orientation[0] = 1.0;
  }
  std::string refusal(const InputLimits& limits = cell_limits()) {
    return test::error_of([&] { check_limits(wire::from_wire(msg_), limits, kNow); });
  }
  std::string cell_ = "cell-1";
  cellmap_msg_RobotState msg_{};
};

TEST_F(RobotStateRulesTest, AGoodPosePasses) {
  EXPECT_EQ(refusal(), "");
}

TEST_F(RobotStateRulesTest, NonFiniteNumbersAndNonUnitQuaternionsAreRefused) {
  msg_.position[2] = std::nan("");
  EXPECT_NE(refusal().find("position: not a finite number"), std::string::npos) << refusal();
  msg_.position[2] = 1.5;
  msg_.orientation[0] = 2.0;
  EXPECT_NE(refusal().find("orientation: must be a unit quaternion"), std::string::npos) << refusal();
}

TEST_F(RobotStateRulesTest, PositionsOutsideTheCellAreRefused) {
  msg_.position[0] = 4.0;
  EXPECT_NE(refusal().find("position: (4, 0.5, 1.5) is outside the cell"), std::string::npos) << refusal();
  msg_.position[0] = 1e300;
  EXPECT_NE(refusal(InputLimits{}).find("is outside the cell [-100, -100, -100] - [100, 100, 100]"),
            std::string::npos)
      << "the limit for cells without bounds";
}

TEST_F(RobotStateRulesTest, StampsFarFromNowAreRefused) {
  msg_.stamp_ns = kNow + 4'000'000'000;
  EXPECT_EQ(refusal(), "");
  msg_.stamp_ns = kNow - 6'000'000'000;
  EXPECT_NE(refusal().find("stamp_ns: -6.000000 s from now (limit ±5.000000 s)"), std::string::npos)
      << refusal();
  msg_.stamp_ns = std::numeric_limits<std::int64_t>::min();  // no overflow in the difference
  EXPECT_NE(refusal().find("stamp_ns: "), std::string::npos);
  InputLimits no_clock = cell_limits();
  no_clock.max_stamp_skew = 0s;
  EXPECT_EQ(refusal(no_clock), "");
}

TEST_F(RobotStateRulesTest, AnEmptyCellIsRefused) {
  cell_.clear();
  msg_.cell = cell_.data();
  EXPECT_EQ(refusal(), "cellmap/robot_state: cell: must not be empty");
}

// A cell name with line breaks stays on one line in the refusal (the delta's twin: fuzz_dds_samples).
TEST_F(RobotStateRulesTest, ACellNameWithLineBreaksIsQuotedOnOneLine) {
  cell_ = "cell-1\n2026-12-02T06:00:00.000 info forged\r";
  msg_.cell = cell_.data();
  msg_.position[2] = std::nan("");
  // Such a cell is refused for what it is, before anything else, on one line.
  EXPECT_EQ(
      refusal(),
      "cellmap/robot_state 'cell-1?2026-12-02T06:00:00.000 info forged?': cell: longer than 128 bytes, not "
      "UTF-8, or holding a control character");
  msg_.position[2] = 1.5;
  msg_.stamp_ns = kNow - 6'000'000'000;
  EXPECT_EQ(refusal().find_first_of("\n\r"), std::string::npos) << refusal();
}

}  // namespace
}  // namespace cellmap::transport
