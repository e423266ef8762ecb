// SPDX-License-Identifier: Apache-2.0
// Writes the seeds that programs write (the YAML, CSV, URDF and mesh seeds are written by hand): point clouds
// as PCL's writers save them, depth images as cellmap and libtiff write them, DDS samples as Cyclone
// serializes them, a state directory's snapshot and blob as VersionStore saves them, and map states as the
// cell pipeline saves them. Usage: fuzz_make_seeds CORPUS_DIR (writes CORPUS_DIR/<target>/<name>).
#include <dds/ddsi/ddsi_cdrstream.h>
#include <pcl/common/io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#include <tiffio.h>

#include <cmath>
#include <limits>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cellmap.h"
#include "cellmap/cell/cell_pipeline.hpp"
#include "cellmap/common/atomic_file.hpp"
#include "cellmap/environment/version_store.hpp"
#include "cellmap/sensor/depth_io.hpp"
#include "daemon_config.hpp"
#include "sensor_msgs/msg/JointState.h"
#include "sensor_msgs/msg/LaserScan.h"
#include "sensor_msgs/msg/PointCloud2.h"
#include "wire.hpp"

namespace {

using namespace cellmap;
namespace fs = std::filesystem;

void write(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Ten points of a small tilted grid, one of them NaN, labelled by row.
pcl::PointCloud<pcl::PointXYZL> grid() {
  pcl::PointCloud<pcl::PointXYZL> cloud;
  for (int i = 0; i < 10; ++i) {
    pcl::PointXYZL p;
    p.x = 0.1f * static_cast<float>(i % 5);
    p.y = 0.1f * static_cast<float>(i / 5);
    p.z = 1.0f + 0.01f * static_cast<float>(i);
    p.label = static_cast<std::uint32_t>(20 + i / 5);
    cloud.push_back(p);
  }
  cloud[3].z = std::numeric_limits<float>::quiet_NaN();
  return cloud;
}

void cloud_seeds(const fs::path& pcd, const fs::path& ply) {
  fs::create_directories(pcd);
  fs::create_directories(ply);
  const pcl::PointCloud<pcl::PointXYZL> labelled = grid();
  pcl::PointCloud<pcl::PointXYZ> plain;
  pcl::copyPointCloud(labelled, plain);
  pcl::io::savePCDFileASCII((pcd / "ascii.pcd").string(), plain);
  pcl::io::savePCDFileBinary((pcd / "binary_labelled.pcd").string(), labelled);
  pcl::io::savePCDFileBinaryCompressed((pcd / "compressed_labelled.pcd").string(), labelled);
  pcl::PointCloud<pcl::PointXYZ> organized = plain;
  organized.width = 5;
  organized.height = 2;
  pcl::io::savePCDFileBinaryCompressed((pcd / "compressed_organized.pcd").string(), organized);
  pcl::io::savePLYFileASCII((ply / "ascii.ply").string(), plain);
  pcl::io::savePLYFileBinary((ply / "binary_labelled.ply").string(), labelled);
  pcl::PLYWriter writer;  // PCL's other layout: obj_info lines, no camera element
  writer.write((ply / "binary_obj_info.ply").string(), plain, true, false);
}

// The first byte picks the format in the harness: 0 = PNG, 1 = TIFF.
void depth_image_seeds(const fs::path& dir) {
  fs::create_directories(dir);
  RawDepth image;
  image.width = 4;
  image.height = 3;
  image.depth = {0, 500, 1000, 1500, 2000, 2500, 3000, 3500, 4000, 4500, 5000, 65535};
  const fs::path png = dir / "frame_depth.png";
  write_depth_png(png.string(), image);
  write(png, std::string(1, '\0') + read_file(png));
  const fs::path tiff_path = dir / "frame_depth.tiff";
  TIFF* tiff = TIFFOpen(tiff_path.c_str(), "w");
  TIFFSetField(tiff, TIFFTAG_IMAGEWIDTH, 4);
  TIFFSetField(tiff, TIFFTAG_IMAGELENGTH, 3);
  TIFFSetField(tiff, TIFFTAG_BITSPERSAMPLE, 16);
  TIFFSetField(tiff, TIFFTAG_SAMPLESPERPIXEL, 1);
  TIFFSetField(tiff, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
  TIFFSetField(tiff, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  for (std::uint32_t row = 0; row < 3; ++row) TIFFWriteScanline(tiff, image.depth.data() + 4 * row, row, 0);
  TIFFClose(tiff);
  write(tiff_path, std::string(1, '\1') + read_file(tiff_path));
}

// kind byte, encapsulation header (XCDR1, little- or big-endian), CDR as a writer puts it on the wire.
std::string serialized(char kind, const dds_topic_descriptor_t& type, const void* sample, bool big_endian) {
  dds_ostream_t out;
  dds_ostream_init(&out, 0, 1);
  if (big_endian) {
    dds_stream_writeBE(reinterpret_cast<dds_ostreamBE_t*>(&out), static_cast<const char*>(sample),
                       type.m_ops);
  } else {
    dds_stream_writeLE(reinterpret_cast<dds_ostreamLE_t*>(&out), static_cast<const char*>(sample),
                       type.m_ops);
  }
  const char header[4] = {0, big_endian ? '\x00' : '\x01', 0, 0};
  std::string bytes(1, kind);
  bytes.append(header, 4);
  bytes.append(reinterpret_cast<const char*>(out.m_buffer), out.m_index);
  dds_ostream_fini(&out);
  return bytes;
}

Box box(std::uint64_t id, double x) {
  Box b;
  b.id = id;
  b.center = {x, 0.5, 0.25};
  b.half_extents = {0.1, 0.2, 0.3};
  b.points = 40;
  return b;
}

void dds_seeds(const fs::path& dir) {
  transport::SceneEdit edit;
  edit.cell = "cell-1";
  edit.name = "crate";
  edit.center = {1.0, 0.5, 0.2};
  edit.half_extents = {0.2, 0.2, 0.2};
  edit.yaw = 0.3;
  const transport::wire::SceneEditSample scene_edit(edit);
  transport::RobotState state;
  state.cell = "cell-1";
  state.stamp_ns = 1'700'000'000'000'000'000;
  state.X_CE.translation() = Eigen::Vector3d(0.4, 0.2, 1.5);
  const transport::wire::RobotStateSample robot_state(state);
  const Environment env("cell-1", 3, 1'700'000'000'000'000'000, {box(1, 0.5), box(4, 1.5)});
  const transport::wire::EnvironmentSample environment(env);
  const EnvironmentDelta delta = diff(Environment("cell-1", 2, 0, {box(1, 0.4), box(2, 1.0)}), env);
  const transport::wire::DeltaSample delta_sample(delta);
  transport::CellStatus status;
  status.cell = "cell-1";
  status.state = "running";
  status.sensors = {{"kinect", "streaming"}};
  const transport::wire::StatusSample status_sample(status);
  transport::RobotJoints joints;  // the SCARA arm of config/scenes/, named joints and a payload
  joints.cell = "cell-1";
  joints.stamp_ns = 1'700'000'000'000'000'000;
  joints.names = {"elbow", "shoulder", "lift"};
  joints.positions = {0.5, -0.3, 0.1};
  joints.payload = Payload{Eigen::Isometry3d::Identity(), Eigen::Vector3d(0.1, 0.1, 0.05)};
  const transport::wire::RobotJointsSample robot_joints(joints);
  for (const bool big : {false, true}) {
    const std::string suffix = big ? "_be" : "";
    write(dir / ("scene_edit" + suffix), serialized(0, cellmap_msg_SceneEdit_desc, scene_edit.get(), big));
    write(dir / ("robot_state" + suffix), serialized(1, cellmap_msg_RobotState_desc, robot_state.get(), big));
    write(dir / ("environment" + suffix),
          serialized(2, cellmap_msg_Environment_desc, environment.get(), big));
    write(dir / ("delta" + suffix),
          serialized(3, cellmap_msg_EnvironmentDelta_desc, delta_sample.get(), big));
    write(dir / ("status" + suffix), serialized(4, cellmap_msg_Status_desc, status_sample.get(), big));
    write(dir / ("robot_joints" + suffix),
          serialized(5, cellmap_msg_RobotJoints_desc, robot_joints.get(), big));
  }
}

// The snapshot of version 7 as VersionStore writes it, then a NUL, then its blob (the harness's layout).
void version_store_seeds(const fs::path& dir, const fs::path& scratch) {
  const std::string blob = "cellmap-map-state 2\n5\n0 0 0\n";
  for (const bool with_blob : {false, true}) {
    fs::remove_all(scratch);
    VersionStore store(scratch, "cell-1");
    store.save(Environment("cell-1", 7, 1'700'000'000'000'000'000, {box(1, 0.5), box(4, 1.5)}),
               with_blob ? std::optional<std::string_view>(blob) : std::nullopt);
    std::string bytes = read_file(scratch / "environment-00000000000000000007.json");
    if (with_blob) bytes += std::string(1, '\0') + blob;
    write(dir / (with_blob ? "snapshot_with_blob" : "snapshot"), bytes);
  }
  fs::remove_all(scratch);
}

// An empty map and one that saw a few points in two sweeps (their voxels flipped, waiting for confirmation),
// as the daemon saves them.
void map_blob_seeds(const fs::path& dir) {
  const daemon::DaemonConfig config = daemon::DaemonConfig::parse("", "defaults", ".");
  const CellPipeline empty(config.pipeline, {}, 1);
  write(dir / "empty_map", empty.map_state());
  CellPipeline seen(config.pipeline, {}, 1);
  Sweep sweep;
  Scan scan;
  scan.origin_C = {1.0, 1.0, 2.0};
  for (int i = 0; i < 20; ++i) scan.points_C.push_back(pcl::PointXYZ(0.8f + 0.02f * i, 1.0f, 0.3f));
  sweep.scans.push_back(scan);
  (void)seen.process(sweep);
  (void)seen.process(sweep);
  write(dir / "small_map", seen.map_state());
}

}  // namespace

// ROS 2 sensor samples as a driver sends them: a packed FLOAT32 cloud with a NaN point, an organized FLOAT64
// one with padding, a scan with inf and NaN ranges, the SCARA arm's joint states with a gripper's joint.
void ros2_seeds(const fs::path& dir) {
  char x[] = "x", y[] = "y", z[] = "z", frame[] = "camera", laser[] = "laser", empty[] = "";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<sensor_msgs_msg_dds__PointField_> packed_fields{{x, 0, 7, 1}, {y, 4, 7, 1}, {z, 8, 7, 1}};
  std::vector<float> packed_points{0.5f, -1.0f, 2.0f, nan, nan, nan, 1.0f, 2.0f, 3.0f};
  sensor_msgs_msg_dds__PointCloud2_ packed{};
  packed.header = {{1'700'000'000, 5}, frame};
  packed.height = 1;
  packed.width = 3;
  packed.fields = {3, 3, packed_fields.data(), false};
  packed.point_step = 12;
  packed.row_step = 36;
  packed.data = {36, 36, reinterpret_cast<std::uint8_t*>(packed_points.data()), false};
  write(dir / "cloud_packed", serialized(0, sensor_msgs_msg_dds__PointCloud2__desc, &packed, false));
  write(dir / "cloud_packed_be", serialized(0, sensor_msgs_msg_dds__PointCloud2__desc, &packed, true));

  std::vector<sensor_msgs_msg_dds__PointField_> wide_fields{{z, 0, 8, 1}, {x, 8, 8, 1}, {y, 16, 8, 1}};
  std::vector<double> wide_points(2 * 2 * 4, 0.25);  // 2 × 2 points of 32 bytes (8 of padding)
  wide_points[1] = std::numeric_limits<double>::infinity();
  sensor_msgs_msg_dds__PointCloud2_ organized = packed;
  organized.height = 2;
  organized.width = 2;
  organized.fields = {3, 3, wide_fields.data(), false};
  organized.point_step = 32;
  organized.row_step = 64;
  organized.data = {128, 128, reinterpret_cast<std::uint8_t*>(wide_points.data()), false};
  write(dir / "cloud_organized", serialized(0, sensor_msgs_msg_dds__PointCloud2__desc, &organized, false));

  std::vector<float> ranges{1.0f, std::numeric_limits<float>::infinity(), nan, 0.01f, 3.5f};
  sensor_msgs_msg_dds__LaserScan_ scan{};
  scan.header = {{1'700'000'000, 5}, laser};
  scan.angle_min = -1.0f;
  scan.angle_max = 1.0f;
  scan.angle_increment = 0.5f;
  scan.range_min = 0.05f;
  scan.range_max = 4.0f;
  scan.ranges = {5, 5, ranges.data(), false};
  write(dir / "scan", serialized(1, sensor_msgs_msg_dds__LaserScan__desc, &scan, false));
  write(dir / "scan_be", serialized(1, sensor_msgs_msg_dds__LaserScan__desc, &scan, true));

  char shoulder[] = "shoulder", elbow[] = "elbow", lift[] = "lift", finger[] = "finger";
  std::vector<char*> names{finger, lift, shoulder, elbow};
  std::vector<double> positions{0.01, 0.1, 0.5, -0.25};
  sensor_msgs_msg_dds__JointState_ joints{};
  joints.header = {{1'700'000'000, 5}, empty};
  joints.name = {4, 4, names.data(), false};
  joints.position = {4, 4, positions.data(), false};
  write(dir / "joint_states", serialized(2, sensor_msgs_msg_dds__JointState__desc, &joints, false));
  write(dir / "joint_states_be", serialized(2, sensor_msgs_msg_dds__JointState__desc, &joints, true));
}

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_make_seeds CORPUS_DIR\n");
    return 2;
  }
  const fs::path corpus = argv[1];
  cloud_seeds(corpus / "pcd", corpus / "ply");
  depth_image_seeds(corpus / "depth_image");
  dds_seeds(corpus / "dds_samples");
  ros2_seeds(corpus / "ros2_samples");
  version_store_seeds(corpus / "version_store", fs::temp_directory_path() / "cellmap_fuzz_make_seeds");
  map_blob_seeds(corpus / "map_blob");
  return 0;
}
