// SPDX-License-Identifier: Apache-2.0
// cellmap/robot_state on real Cyclone DDS participants (loopback): the robot controller's side writes tool
// poses, the daemon's side reads them for its cell.
#include "cellmap/transport/robot_state.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <utility>

#include "cellmap/common/error.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "loopback.hpp"
#include "support/dds_domains.hpp"
#include "support/test_support.hpp"

namespace cellmap::transport {
namespace {

using namespace std::chrono_literals;
using test::kPatience;

RobotState state_at(const std::string& cell, std::int64_t stamp_ns, double x, double yaw) {
  RobotState state;
  state.cell = cell;
  state.stamp_ns = stamp_ns;
  state.X_CE.translation() = Eigen::Vector3d(x, 0.25, 1.5);
  state.X_CE.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return state;
}

// Takes until `count` states arrived or the patience ran out.
std::vector<RobotState> take_until(RobotStateReader& reader, std::size_t count) {
  std::vector<RobotState> all;
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (all.size() < count && std::chrono::steady_clock::now() < deadline) {
    for (RobotState& s : reader.take(100ms)) all.push_back(std::move(s));
  }
  return all;
}

TEST(RobotStateTest, ReaderGetsItsCellsPosesInOrder) {
  test::use_loopback();
  dds::Participant controller(test::domain::kPosesInOrder);
  dds::Participant daemon(test::domain::kPosesInOrder);
  RobotStateReader reader(daemon, "cell-a");
  RobotStateWriter writer(controller, "cell-a");
  RobotStateWriter other_cell(controller, "cell-b");  // another cell on the same domain
  ASSERT_TRUE(writer.wait_for_reader(kPatience));
  EXPECT_FALSE(other_cell.wait_for_reader(0s)) << "cell-a's reader matched cell-b's partition";
  for (int i = 0; i < 50; ++i) {
    writer.write(state_at("cell-a", 1'000'000'000LL + i * 4'000'000LL, 0.01 * i, 0.02 * i));
    other_cell.write(state_at("cell-b", 7, 9.0, 0.0));
  }
  ASSERT_TRUE(writer.wait_for_acks(kPatience));
  EXPECT_NE(test::error_of([&] { writer.write(state_at("cell-b", 7, 9.0, 0.0)); }).find("for cell 'cell-a'"),
            std::string::npos);
  const std::vector<RobotState> got = take_until(reader, 50);
  ASSERT_EQ(got.size(), 50u);
  for (int i = 0; i < 50; ++i) {
    const RobotState expected = state_at("cell-a", 1'000'000'000LL + i * 4'000'000LL, 0.01 * i, 0.02 * i);
    EXPECT_EQ(got[i].cell, "cell-a");
    EXPECT_EQ(got[i].stamp_ns, expected.stamp_ns);
    EXPECT_TRUE(got[i].X_CE.isApprox(expected.X_CE, 1e-12)) << i;
  }
  EXPECT_TRUE(reader.take().empty());  // cell-b's poses were skipped
  EXPECT_EQ(reader.rejected(), 0u);
}

TEST(RobotStateTest, MalformedPosesAreRejectedNotFused) {
  test::use_loopback();
  dds::Participant controller(test::domain::kPosesRejected);
  dds::Participant daemon(test::domain::kPosesRejected);
  RobotStateReader reader(daemon, "cell-a");
  RobotStateWriter writer(controller, "cell-a");
  ASSERT_TRUE(writer.wait_for_reader(kPatience));
  RobotState scaled = state_at("cell-a", 1, 0, 0);
  scaled.X_CE.linear() *= 2.0;  // quaternion norm 2: a swapped or scaled orientation
  writer.write(scaled);
  writer.write(state_at("cell-a", 2, 0.5, 0.1));
  ASSERT_TRUE(writer.wait_for_acks(kPatience));
  const std::vector<RobotState> got = take_until(reader, 1);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].stamp_ns, 2);
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (reader.rejected() == 0 && std::chrono::steady_clock::now() < deadline) (void)reader.take(100ms);
  EXPECT_EQ(reader.rejected(), 1u);

  EXPECT_NE(test::error_of([&] { writer.write(state_at("", 1, 0, 0)); }).find("cell"), std::string::npos);
  RobotState nan = state_at("cell-a", 1, 0, 0);
  nan.X_CE.translation().x() = std::nan("");
  EXPECT_NE(test::error_of([&] { writer.write(nan); }).find("not finite"), std::string::npos);
}

TEST(RobotStateTest, RobotPoseCommandPublishesAStandingToolPose) {
  test::use_loopback();
  dds::Participant daemon(test::domain::kPoseCommand);
  RobotStateReader reader(daemon, "desk");
  const std::string command = std::string(CELLMAP_TOOL) + " robot-pose --domain " +
                              std::to_string(test::domain::kPoseCommand) +
                              " --cell desk --pose 1,2,1.5,0.5,-0.5,0.5,-0.5 --rate 50 --duration 0.5 2>&1";
  const auto before_ns = wall_clock_ns();
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  ASSERT_EQ(test::exit_code(::pclose(pipe)), 0) << output;
  const std::vector<RobotState> got = take_until(reader, 25);
  ASSERT_EQ(output, "sent " + std::to_string(got.size()) + " poses\n");
  ASSERT_GE(got.size(), 20u);  // 50 Hz for 0.5 s
  ASSERT_LE(got.size(), 26u);
  Eigen::Isometry3d X_CE = Eigen::Isometry3d::Identity();
  X_CE.translation() = Eigen::Vector3d(1, 2, 1.5);
  X_CE.linear() = Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5).toRotationMatrix();
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_TRUE(got[i].X_CE.isApprox(X_CE, 1e-12));
    EXPECT_GE(got[i].stamp_ns, before_ns);  // stamped now, on the frames' clock
    if (i > 0) {
      EXPECT_GT(got[i].stamp_ns, got[i - 1].stamp_ns);
    }
  }
  // A bad pose is one line naming the option.
  pipe = ::popen((std::string(CELLMAP_TOOL) + " robot-pose --cell desk --pose 1,2 2>&1").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  output.clear();
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  EXPECT_EQ(test::exit_code(::pclose(pipe)), 1);
  EXPECT_EQ(output.rfind("cellmap: --pose", 0), 0u) << output;
}

// The tools that need a daemon on the other end say so and exit 1 when there is none (nobody joins the
// domain).
TEST(RobotStateTest, RobotPoseAndInjectWithNobodyListeningFailWithTheirMessage) {
  test::use_loopback();
  const auto run = [](const std::string& arguments) {
    FILE* pipe = ::popen((std::string(CELLMAP_TOOL) + " " + arguments + " 2>&1").c_str(), "r");
    std::string output;
    char buffer[256];
    while (pipe != nullptr && std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
    const int code = pipe == nullptr ? -1 : test::exit_code(::pclose(pipe));
    return std::make_pair(code, output);
  };
  const std::string domain = std::to_string(test::domain::kNobodyListening);
  const auto [pose_code, pose_output] =
      run("robot-pose --domain " + domain + " --cell desk --pose 1,2,3 --wait 1");
  EXPECT_EQ(pose_code, 1) << pose_output;
  EXPECT_EQ(pose_output,
            "cellmap: robot-pose: no cellmapd reading robot poses on domain " + domain + " within 1 s\n");
  const auto [inject_code, inject_output] =
      run("inject --domain " + domain + " --wait 1 add-box --center 1,1,1 --half-extents 0.1,0.1,0.1");
  EXPECT_EQ(inject_code, 1) << inject_output;
  EXPECT_EQ(inject_output, "cellmap: inject: no simulating cellmapd on domain " + domain + " within 1 s\n");
}

}  // namespace
}  // namespace cellmap::transport
