// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/recording.hpp"

#include <pcl/io/pcd_io.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"

namespace cellmap::sim {
namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

}  // namespace

void write_poses(const std::filesystem::path& path, const std::vector<PoseRecord>& records,
                 const std::vector<std::string>& joint_names) {
  auto check_name = [&](const std::string& name) {
    if (name.find_first_of(",\n\r") != std::string::npos) {
      throw Error(path.string() + ": '" + name + "' holds a comma or line break");
    }
  };
  std::string out = "frame,sensor,stamp,file,x,y,z,qw,qx,qy,qz";
  for (const std::string& joint : joint_names) {
    check_name(joint);
    out += ",q:" + joint;
  }
  out += "\n";
  for (const PoseRecord& r : records) {
    check_name(r.sensor);
    check_name(r.file);
    if (r.q.size() != static_cast<Eigen::Index>(joint_names.size())) {
      throw Error(path.string() + ": frame " + std::to_string(r.frame) + " has " +
                  std::to_string(r.q.size()) + " joints, the header " + std::to_string(joint_names.size()));
    }
    const Eigen::Vector3d p = r.X_CS.translation();
    const Eigen::Quaterniond q(r.X_CS.linear());
    out += std::to_string(r.frame) + "," + r.sensor + "," + number(r.stamp) + "," + r.file;
    for (double v : {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z()}) out += "," + number(v);
    for (Eigen::Index j = 0; j < r.q.size(); ++j) out += "," + number(r.q[j]);
    out += "\n";
  }
  write_file_atomically(path, out);
}

std::vector<PoseRecord> read_poses(const std::filesystem::path& path) {
  std::stringstream text(read_file(path));
  std::string line;
  if (!std::getline(text, line)) throw Error(path.string() + ": empty poses file");
  const std::vector<std::string> header = split(line, ',');
  const std::vector<std::string> fixed = {"frame", "sensor", "stamp", "file", "x", "y",
                                          "z",     "qw",     "qx",    "qy",   "qz"};
  if (header.size() < fixed.size() || !std::equal(fixed.begin(), fixed.end(), header.begin())) {
    throw Error(path.string() + ": line 1: header must start with frame,sensor,stamp,file,x,y,z,qw,qx,qy,qz");
  }
  const std::size_t joints = header.size() - fixed.size();
  std::vector<PoseRecord> records;
  for (int number = 2; std::getline(text, line); ++number) {
    if (line.empty()) continue;
    const std::string where = path.string() + ": line " + std::to_string(number);
    const std::vector<std::string> items = split(line, ',');
    if (items.size() != header.size()) {
      throw Error(where + ": " + std::to_string(items.size()) + " fields, header has " +
                  std::to_string(header.size()));
    }
    PoseRecord r;
    const double frame = parse_finite(items[0], where + ": frame");
    if (frame < 0 || frame != std::floor(frame))
      throw Error(where + ": frame must be a non-negative integer");
    r.frame = static_cast<std::uint64_t>(frame);
    r.sensor = items[1];
    r.stamp = parse_finite(items[2], where + ": stamp");
    r.file = items[3];
    double v[7];
    for (int i = 0; i < 7; ++i) v[i] = parse_finite(items[4 + i], where + ": " + fixed[4 + i]);
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-6) throw Error(where + ": orientation is not a unit quaternion");
    r.X_CS = Eigen::Isometry3d::Identity();
    r.X_CS.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    r.X_CS.linear() = q.normalized().toRotationMatrix();
    r.q.resize(static_cast<Eigen::Index>(joints));
    for (std::size_t j = 0; j < joints; ++j) {
      r.q[static_cast<Eigen::Index>(j)] =
          parse_finite(items[fixed.size() + j], where + ": " + header[fixed.size() + j]);
    }
    records.push_back(std::move(r));
  }
  return records;
}

void write_intrinsics(const std::filesystem::path& path, const PinholeIntrinsics& k) {
  std::string out = "# pinhole depth intrinsics: pixels, metres per depth unit, metres\n";
  out += "width: " + std::to_string(k.width) + "\nheight: " + std::to_string(k.height) + "\n";
  out += "fx: " + number(k.fx) + "\nfy: " + number(k.fy) + "\ncx: " + number(k.cx) + "\ncy: " + number(k.cy) +
         "\n";
  out += "depth_scale: " + number(k.depth_scale) + "\nmin_range: " + number(k.min_range) +
         "\nmax_range: " + number(k.max_range) + "\nmax_depth_jump: " + number(k.max_depth_jump) +
         "\nsmoothing_radius: " + std::to_string(k.smoothing_radius) + "\n";
  write_file_atomically(path, out);
}

namespace {

template <typename Point>
void save_binary_pcd(const std::filesystem::path& path, const pcl::PointCloud<Point>& cloud) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  int status = -1;
  try {
    status = cloud.empty() ? -2 : pcl::io::savePCDFileBinary(path.string(), cloud);
  } catch (const std::exception& e) {
    throw Error(path.string() + ": cannot write PCD: " + e.what());
  }
  if (status == -2) {
    // PCL refuses to write empty clouds; an empty sweep is still a valid recording.
    write_file_atomically(
        path,
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
        "TYPE F F F\nCOUNT 1 1 1\nWIDTH 0\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 0\nDATA ascii\n");
    return;
  }
  if (status < 0) throw Error(path.string() + ": cannot write PCD");
}

}  // namespace

void write_pcd(const std::filesystem::path& path, const Cloud& cloud) {
  save_binary_pcd(path, cloud);
}

void write_sweep_pcd(const std::filesystem::path& path, const Sweep& sweep) {
  pcl::PointCloud<pcl::PointWithViewpoint> cloud;
  cloud.reserve(sweep.point_count());
  for (const Scan& scan : sweep.scans) {
    for (const pcl::PointXYZ& p : scan.points_C) {
      cloud.push_back(pcl::PointWithViewpoint(p.x, p.y, p.z, static_cast<float>(scan.origin_C.x()),
                                              static_cast<float>(scan.origin_C.y()),
                                              static_cast<float>(scan.origin_C.z())));
    }
  }
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Scan& scan : sweep.scans) mean += scan.origin_C / static_cast<double>(sweep.scans.size());
  cloud.sensor_origin_ = Eigen::Vector4f(static_cast<float>(mean.x()), static_cast<float>(mean.y()),
                                         static_cast<float>(mean.z()), 0.0f);
  save_binary_pcd(path, cloud);
}

}  // namespace cellmap::sim
