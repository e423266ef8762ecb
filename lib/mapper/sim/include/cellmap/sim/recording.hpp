// SPDX-License-Identifier: Apache-2.0
#pragma once
// Files of a simulated sweep beside the replay directory format of the sensor stage (replay_source.hpp, whose
// depth PNG writer and poses.csv we reuse): the frames file with sensor poses and joint vectors, intrinsics,
// and clouds with their sensor origins.

#include <Eigen/Geometry>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "cellmap/frame/frame.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap::sim {

/// One line of the frames file: when and from where a frame was taken.
struct PoseRecord final {
  std::uint64_t frame = 0;  ///< index of the frame in its sweep
  std::string sensor;       ///< sensor name
  double stamp = 0.0;       ///< seconds
  std::string file;         ///< the frame's data file, relative to the poses file
  Eigen::Isometry3d X_CS = Eigen::Isometry3d::Identity();  ///< sensor pose in the cell frame
  Eigen::VectorXd q;                                       ///< robot joint vector
};

/// Writes the frames file as CSV: a header `frame,sensor,stamp,file,x,y,z,qw,qx,qy,qz,q:<joint>...` and one
/// line per record; position in metres, orientation as a unit quaternion [w, x, y, z], joints in metres or
/// radians. Numbers are written with 17 significant digits, so reading gives back the same doubles.
/// @throws Error if records disagree in joint count with `joint_names`, a name holds a comma or a line break,
/// or the file cannot be written.
void write_poses(const std::filesystem::path& path, const std::vector<PoseRecord>& records,
                 const std::vector<std::string>& joint_names);

/// Reads a frames file written by write_poses. @throws Error naming the file and line on a malformed line.
[[nodiscard]] std::vector<PoseRecord> read_poses(const std::filesystem::path& path);

/// Writes intrinsics as a small YAML map (width, height, fx, fy, cx, cy, depth_scale, min_range, max_range),
/// as read_intrinsics_yaml (sensor stage) reads them. @throws Error on I/O failure.
void write_intrinsics(const std::filesystem::path& path, const PinholeIntrinsics& intrinsics);

/// Writes a cloud as binary PCD (fields x y z). @throws Error on I/O failure.
void write_pcd(const std::filesystem::path& path, const Cloud& cloud);

/// Writes a sweep's merged cloud as binary PCD with fields x y z vp_x vp_y vp_z (PCL's PointWithViewpoint):
/// every point in the cell frame with the sensor origin it was seen from; the header's VIEWPOINT is their
/// mean. Readers that want only x y z can load it as a plain cloud (normals then face the mean origin).
/// @throws Error on I/O failure.
void write_sweep_pcd(const std::filesystem::path& path, const Sweep& sweep);

}  // namespace cellmap::sim
