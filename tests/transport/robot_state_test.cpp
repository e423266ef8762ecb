// cellmap/robot_state on real Cyclone DDS participants (loopback): the robot controller's side writes tool
// poses, the daemon's side reads them for its cell.
#include "cellmap/transport/robot_state.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

#include "cellmap/common/error.hpp"
#include "loopback.hpp"
#include "support/test_support.hpp"

namespace cellmap::transport {
namespace {

using namespace std::chrono_literals;
constexpr auto kPatience = 30s;  // generous: the machine is shared; passing runs take milliseconds

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
  dds::Participant controller(180);
  dds::Participant daemon(180);
  RobotStateReader reader(daemon, "cell-a");
  RobotStateWriter writer(controller);
  ASSERT_TRUE(writer.wait_for_reader(kPatience));
  for (int i = 0; i < 50; ++i) {
    writer.write(state_at("cell-a", 1'000'000'000LL + i * 4'000'000LL, 0.01 * i, 0.02 * i));
    writer.write(state_at("cell-b", 7, 9.0, 0.0));  // another cell on the same domain
  }
  ASSERT_TRUE(writer.wait_for_acks(kPatience));
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
  dds::Participant controller(181);
  dds::Participant daemon(181);
  RobotStateReader reader(daemon, "cell-a");
  RobotStateWriter writer(controller);
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
  dds::Participant daemon(185);
  RobotStateReader reader(daemon, "desk");
  const std::string command =
      std::string(CELLMAP_TOOL) +
      " robot-pose --domain 185 --cell desk --pose 1,2,1.5,0.5,-0.5,0.5,-0.5 --rate 50"
      " --duration 0.5 2>&1";
  const auto before_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                             std::chrono::system_clock::now().time_since_epoch())
                             .count();
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  ASSERT_EQ(::pclose(pipe), 0) << output;
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
  EXPECT_NE(::pclose(pipe), 0);
  EXPECT_EQ(output.rfind("cellmap: --pose", 0), 0u) << output;
}

}  // namespace
}  // namespace cellmap::transport
