// SPDX-License-Identifier: Apache-2.0
#include "cellmap/ros2/type_hash.hpp"

#include <dds/dds.h>
#include <gtest/gtest.h>

#include <string>

#include "cellmap/transport/dds.hpp"
#include "support/test_support.hpp"

namespace cellmap::ros2 {
namespace {

using test::error_of;

struct KnownHash {
  const char* ros_type;
  const char* hash;
};

// The hashes ROS 2's code generator (rosidl) gave these types, as public sources hold them:
//  [rcl]     ros2/rcl, tag 9.2.0 (Jazzy), rcl/test/rcl/test_type_hash.cpp: PointCloud2's, as the bytes that
//            test took from rosidl's generated code.
//  [moveit]  orka375/moveit2, install/moveit_msgs/share/moveit_msgs/msg/CollisionObject.json and
//            .../srv/GetPlanningScene.json: rosidl's type descriptions, with the hashes of every type they
//            reference ("type_hashes").
//  [rtabmap] Zuhaib-Saadat/fyp-ros2, build/rtabmap_msgs/rosidl_generator_c/rtabmap_msgs/msg/detail/
//            scan_descriptor__description.c: the expected hashes of the types ScanDescriptor references.
//  [viz]     Wankeur/blipbloup, build/visualization_msgs/rosidl_generator_c/visualization_msgs/msg/detail/
//            marker_array__description.c: MarkerArray's hash and those of the types it references.
// A hash covers the names, types, order, sizes and bounds of the fields of the type and of every type it
// references, so an equal hash also shows that the definitions they were made from equal ours, which
// idl_matches_msg_test.py holds to ROS 2 Jazzy's .msg files.
constexpr KnownHash kKnownHashes[] = {
    {"builtin_interfaces/msg/Duration",  // [moveit] GetPlanningScene.json, [viz]
     "RIHS01_e8d009f659816f758b75334ee1a9ca5b5c0b859843261f14c7f937349599d93b"},
    {"builtin_interfaces/msg/Time",  // [moveit], [rtabmap], [viz]
     "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197"},
    {"geometry_msgs/msg/Point",  // [moveit], [viz]
     "RIHS01_6963084842a9b04494d6b2941d11444708d892da2f4b09843b9c43f42a7f6881"},
    {"geometry_msgs/msg/Point32",  // [moveit]
     "RIHS01_2fc4db7cae16a4582c79a56b66173a8d48d52c7dc520ddc55a0d4bcf2a4bfdbc"},
    {"geometry_msgs/msg/Polygon",  // [moveit]
     "RIHS01_3782f9f0bf044964d692d6c017d705e37611afb1f0bf6a9dee248a7dda0f784a"},
    {"geometry_msgs/msg/Pose",  // [moveit], [viz]
     "RIHS01_d501954e9476cea2996984e812054b68026ae0bfae789d9a10b23daf35cc90fa"},
    {"geometry_msgs/msg/Quaternion",  // [moveit], [viz]
     "RIHS01_8a765f66778c8ff7c8ab94afcc590a2ed5325a1d9a076ffff38fbce36f458684"},
    {"geometry_msgs/msg/Vector3",  // [moveit] GetPlanningScene.json, [viz]
     "RIHS01_cc12fe83e4c02719f1ce8070bfd14aecd40f75a96696a67a2a1f37f7dbb0765d"},
    {"moveit_msgs/msg/CollisionObject",  // [moveit] CollisionObject.json
     "RIHS01_74b0acd6d56be032bf4f764b2c2633f50588b5fb2bd71e97206c59052747cf7e"},
    {"object_recognition_msgs/msg/ObjectType",  // [moveit]
     "RIHS01_5eb3ee3976403366d7c50d7dbee8bec96b3bced1e752674a7194a35841632134"},
    {"sensor_msgs/msg/CompressedImage",  // [viz]
     "RIHS01_15640771531571185e2efc8a100baf923961a4d15d5569652e6cb6691e8e371a"},
    {"sensor_msgs/msg/JointState",  // [moveit] GetPlanningScene.json
     "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e"},
    {"sensor_msgs/msg/LaserScan",  // [rtabmap]
     "RIHS01_64c191398013af96509d518dac71d5164f9382553fce5c1f8cca5be7924bd828"},
    {"sensor_msgs/msg/PointCloud2",  // [rcl], [rtabmap]
     "RIHS01_9198cabf7da3796ae6fe19c4cb3bdd3525492988c70522628af5daa124bae2b5"},
    {"sensor_msgs/msg/PointField",  // [rtabmap]
     "RIHS01_5c6a4750728c2bcfbbf7037225b20b02d4429634732146b742dee1726637ef01"},
    {"shape_msgs/msg/Mesh",  // [moveit]
     "RIHS01_f2150b82d8ee7e8bc3f396a2b158aefb4b9a5510a474be271ba1268aebb55289"},
    {"shape_msgs/msg/MeshTriangle",  // [moveit]
     "RIHS01_618e5c073eeb729e433ef6226e72c01d995c459fb7d76348c9700409a5020bd0"},
    {"shape_msgs/msg/Plane",  // [moveit]
     "RIHS01_dfbfe8314689c850615d4a727af017e9aa86c10e369a606c8c851ef8f16c58c8"},
    {"shape_msgs/msg/SolidPrimitive",  // [moveit]
     "RIHS01_2802a15190aadc3f496584df4b0b4c5824d8a0b31aaef839faa75bc34dda38ac"},
    {"std_msgs/msg/ColorRGBA",  // [moveit] GetPlanningScene.json, [viz]
     "RIHS01_77a7a5b9ae477306097665106e0413ba74440245b1f3d0c6d6405fe5c7813fe8"},
    {"std_msgs/msg/Header",  // [moveit], [rtabmap], [viz]
     "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01"},
    {"visualization_msgs/msg/Marker",  // [viz]
     "RIHS01_45b13ccf791f225962bf74e746f9644518855d783a6f42ba0cc14fde2b4f3ce0"},
    {"visualization_msgs/msg/MarkerArray",  // [viz]
     "RIHS01_86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf"},
    {"visualization_msgs/msg/MeshFile",  // [viz]
     "RIHS01_7710ece15a148fb7c9b546364cfb215bb06098087bd6394fe5b73a493508f8c4"},
    {"visualization_msgs/msg/UVCoordinate",  // [viz]
     "RIHS01_f27f7ed21fe360c6066944f856b801a0c0d1e94e815b6886444b42d90b196a26"},
};

TEST(TypeHashTest, EveryTypeHashesAsRos2JazzyDoes) {
  for (const KnownHash& known : kKnownHashes) {
    EXPECT_EQ(type_hash(known.ros_type), known.hash) << known.ros_type;
  }
}

TEST(TypeHashTest, UserDataIsWhatRos2EndpointsAnnounce) {
  EXPECT_EQ(type_hash_user_data("std_msgs/msg/Header"),
            "typehash=RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01;");
}

TEST(TypeHashTest, TypesOutsideIdlRos2AreRefusedByName) {
  EXPECT_EQ(error_of([] { (void)type_hash("std_msgs/msg/String"); }),
            "ROS 2 type 'std_msgs/msg/String' has no type hash: idl/ros2 does not define it");
  EXPECT_EQ(error_of([] { (void)type_hash_user_data("sensor_msgs/PointCloud2"); }),
            "ROS 2 type 'sensor_msgs/PointCloud2' has no type hash: idl/ros2 does not define it");
}

TEST(TypeHashTest, QosCarriesTheUserDataAsRmwCycloneDdsDoes) {
  // rmw_cyclonedds sets the text's bytes without a terminating NUL; a reader of USER_DATA sees exactly these.
  const std::string text = type_hash_user_data("sensor_msgs/msg/PointCloud2");
  dds::Qos qos;
  qos.user_data(text);
  void* value = nullptr;
  std::size_t size = 0;
  ASSERT_TRUE(dds_qget_userdata(qos.get(), &value, &size));
  EXPECT_EQ(std::string(static_cast<const char*>(value), size), text);
  dds_free(value);
}

}  // namespace
}  // namespace cellmap::ros2
