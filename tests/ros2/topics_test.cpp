// SPDX-License-Identifier: Apache-2.0
// ROS 2 topic names on DDS.
#include "cellmap/ros2/topics.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"

namespace cellmap::ros2 {
namespace {

TEST(Ros2TopicsTest, RosTopicsGetTheRtPrefix) {
  EXPECT_EQ(dds_topic("/camera/depth/points"), "rt/camera/depth/points");
  EXPECT_EQ(dds_topic("/joint_states"), "rt/joint_states");
}

TEST(Ros2TopicsTest, NamesRosWouldRefuseAreRefused) {
  for (const char* bad : {"", "camera", "/", "/a//b", "/a/", "/1a", "/a/2b", "/a b", "/a-b", "rt/a"}) {
    EXPECT_THROW((void)dds_topic(bad), Error) << bad;
  }
  EXPECT_THAT([] { (void)dds_topic("/a//b"); },
              ::testing::ThrowsMessage<Error>(::testing::HasSubstr("'/a//b' is not a ROS 2 topic name")));
}

}  // namespace
}  // namespace cellmap::ros2
