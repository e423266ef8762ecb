// SPDX-License-Identifier: Apache-2.0
// cellmap/robot_joints on real Cyclone DDS participants (loopback): the controller's side writes joint
// positions (and what the tool holds), the daemon's side reads them for its cell and robot, refusing what
// does not fit the robot.
#include "cellmap/transport/robot_joints.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "cellmap/common/error.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "loopback.hpp"
#include "support/dds_domains.hpp"
#include "support/test_support.hpp"

namespace cellmap::transport {
namespace {

using namespace std::chrono_literals;
using test::kPatience;
const std::vector<std::string> kJoints{"j1", "j2", "j3"};

RobotJoints joints_at(const std::string& cell, std::int64_t stamp_ns, std::vector<std::string> names,
                      std::vector<double> positions) {
  RobotJoints joints;
  joints.cell = cell;
  joints.stamp_ns = stamp_ns;
  joints.names = std::move(names);
  joints.positions = std::move(positions);
  return joints;
}

std::vector<RobotJoints> take_until(RobotJointsReader& reader, std::size_t count,
                                    std::uint64_t rejected = 0) {
  std::vector<RobotJoints> all;
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while ((all.size() < count || reader.rejected() < rejected) &&
         std::chrono::steady_clock::now() < deadline) {
    for (RobotJoints& j : reader.take(100ms)) all.push_back(std::move(j));
  }
  return all;
}

TEST(RobotJointsTest, ReaderGetsItsCellsSamplesInTheRobotsJointOrder) {
  test::use_loopback();
  dds::Participant controller(test::domain::kJointsInOrder);
  dds::Participant daemon(test::domain::kJointsInOrder);
  RobotJointsReader reader(daemon, "cell-a", kJoints);
  RobotJointsWriter writer(controller, "cell-a");
  RobotJointsWriter other_cell(controller, "cell-b");
  ASSERT_TRUE(writer.wait_for_reader(kPatience));
  EXPECT_FALSE(other_cell.wait_for_reader(0s)) << "cell-a's reader matched cell-b's partition";
  const std::int64_t t0 = wall_clock_ns();
  RobotJoints named = joints_at("cell-a", t0, {"j3", "j1", "j2"}, {0.3, 0.1, 0.2});  // any order
  Payload carton;
  carton.X_EB.translation() = Eigen::Vector3d(0, 0, 0.2);
  carton.X_EB.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  carton.half_extents = Eigen::Vector3d(0.2, 0.15, 0.15);
  named.payload = carton;
  writer.write(named);
  writer.write(joints_at("cell-a", t0 + 4'000'000, {}, {1.0, 2.0, 3.0}));  // the robot's order
  other_cell.write(joints_at("cell-b", t0, {}, {9, 9, 9}));                // another cell: never arrives
  ASSERT_TRUE(writer.wait_for_acks(kPatience));
  const std::vector<RobotJoints> got = take_until(reader, 2);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].names, kJoints);
  EXPECT_EQ(got[0].positions, (std::vector<double>{0.1, 0.2, 0.3}));
  ASSERT_TRUE(got[0].payload.has_value());
  EXPECT_TRUE(got[0].payload->X_EB.isApprox(carton.X_EB, 1e-12));
  EXPECT_EQ(got[0].payload->half_extents, carton.half_extents);
  EXPECT_EQ(got[1].positions, (std::vector<double>{1.0, 2.0, 3.0}));
  EXPECT_FALSE(got[1].payload.has_value());
  const JointState state = got[1].state();
  EXPECT_NEAR(state.stamp, (t0 + 4'000'000) * 1e-9, 1e-6);
  EXPECT_EQ(state.q, Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(reader.take().empty());
  EXPECT_EQ(reader.rejected(), 0u);
}

TEST(RobotJointsTest, SamplesThatDoNotFitTheRobotAreRefusedAndCounted) {
  test::use_loopback();
  dds::Participant controller(test::domain::kJointsRefused);
  dds::Participant daemon(test::domain::kJointsRefused);
  InputLimits limits;
  limits.max_stamp_skew = std::chrono::minutes(10);  // no pause of a loaded machine refuses the fine sample
  std::string last_refusal;
  RobotJointsReader reader(daemon, "cell-a", kJoints, limits,
                           [&](const std::string& why) { last_refusal = why; });
  RobotJointsWriter writer(controller, "cell-a");
  ASSERT_TRUE(writer.wait_for_reader(kPatience));
  const std::int64_t t = wall_clock_ns();
  writer.write(joints_at("cell-a", t, {"j1", "j2", "wrist"}, {0, 0, 0}));  // unknown joint
  writer.write(joints_at("cell-a", t, {"j1", "j1", "j2"}, {0, 0, 0}));     // repeated joint
  writer.write(joints_at("cell-a", t, {}, {0, 0}));                        // wrong count
  writer.write(joints_at("cell-a", 1'000'000'000, {}, {0, 0, 0}));         // 1970: a clock not set
  writer.write(joints_at("cell-a", t, {}, {0.5, 0.5, 0.5}));               // fine
  ASSERT_TRUE(writer.wait_for_acks(kPatience));
  const std::vector<RobotJoints> got = take_until(reader, 1, 4);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].positions, (std::vector<double>{0.5, 0.5, 0.5}));
  EXPECT_EQ(reader.rejected(), 4u);
  EXPECT_NE(last_refusal.find("stamp_ns: "), std::string::npos) << last_refusal;

  // The writer refuses what no reader could use.
  EXPECT_NE(test::error_of([&] { writer.write(joints_at("", t, {}, {0})); }).find("cell"), std::string::npos);
  EXPECT_NE(test::error_of([&] {
              writer.write(joints_at("cell-a", t, {}, {0, NAN, 0}));
            }).find("positions: not a finite number"),
            std::string::npos);
  EXPECT_NE(test::error_of([&] {
              writer.write(joints_at("cell-a", t, {"j1"}, {0, 0}));
            }).find("1 names"),
            std::string::npos);
  RobotJoints scaled = joints_at("cell-a", t, {}, {0, 0, 0});
  scaled.payload = Payload{};
  scaled.payload->X_EB.linear() *= 2.0;
  EXPECT_NE(test::error_of([&] { writer.write(scaled); }).find("payload.rotation"), std::string::npos);
  EXPECT_THROW(RobotJointsReader(daemon, "cell-a", {"j1", "j1"}), Error);
}

// A joint name from the network stays on one line in the refusal (found by fuzz_dds_samples:
// fuzz/regressions/dds_samples/joint_name_with_line_break).
TEST(RobotJointsTest, AJointNameWithALineBreakIsQuotedOnOneLine) {
  const RobotJoints unknown = joints_at("cell-a", 7, {"j1", "sh\nou\rlder", "j3"}, {0, 0, 0});
  EXPECT_EQ(test::error_of([&] { (void)in_robot_order(unknown, kJoints); }),
            "cellmap/robot_joints 'cell-a' at 7: unknown joint 'sh?ou?lder'");
  const RobotJoints twice = joints_at("cell-a", 7, {"j1", "j1", "j3"}, {0, 0, 0});
  EXPECT_EQ(test::error_of([&] { (void)in_robot_order(twice, kJoints); }),
            "cellmap/robot_joints 'cell-a' at 7: joint 'j1' given twice");
}

TEST(RobotJointsTest, RobotPoseCommandPublishesNamedJointsWithAPayload) {
  test::use_loopback();
  dds::Participant daemon(test::domain::kJointsCommand);
  RobotJointsReader reader(daemon, "desk", kJoints);
  const std::string command =
      std::string(CELLMAP_TOOL) + " robot-pose --domain " + std::to_string(test::domain::kJointsCommand) +
      " --cell desk --joints j2=0.5,j1=-1,j3=2 --payload 0,0,0.1,0.2,0.15,0.1 --rate 50"
      " --duration 0.3 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  ASSERT_EQ(test::exit_code(::pclose(pipe)), 0) << output;
  const std::vector<RobotJoints> got = take_until(reader, 10);
  ASSERT_EQ(output, "sent " + std::to_string(got.size()) + " joint states\n");
  ASSERT_GE(got.size(), 10u);  // 50 Hz for 0.3 s
  for (const RobotJoints& joints : got) {
    EXPECT_EQ(joints.positions, (std::vector<double>{-1, 0.5, 2}));
    ASSERT_TRUE(joints.payload.has_value());
    EXPECT_EQ(joints.payload->half_extents, Eigen::Vector3d(0.2, 0.15, 0.1));
  }
  // Mixed forms and a payload without joints are one line naming the option.
  for (const char* bad :
       {" --joints j1=1,2", " --pose 1,2,3 --payload 0,0,0,1,1,1", " --pose 1,2,3 --joints 1"}) {
    pipe = ::popen((std::string(CELLMAP_TOOL) + " robot-pose --cell desk" + bad + " 2>&1").c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    output.clear();
    while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
    EXPECT_EQ(test::exit_code(::pclose(pipe)), 1);
    EXPECT_EQ(output.rfind("cellmap: ", 0), 0u) << output;
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
  }
}

}  // namespace
}  // namespace cellmap::transport
