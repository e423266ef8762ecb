// SPDX-License-Identifier: Apache-2.0
#include "cellmap/io/cloud_file.hpp"

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "cellmap/common/error.hpp"
#include "cloud_header.hpp"

namespace cellmap {
namespace {

enum class Format { kPcd, kPly };

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& reason) {
  throw Error(path.string() + ": " + reason);
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

std::uint64_t checked_size(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, "no such file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot be read: " + ec.message());
  if (size == 0) fail(path, "is empty");
  return size;
}

// The first bytes of the file, enough for any header we accept.
std::string read_head(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot be opened");
  std::string head(cloud_header::kMaxHeaderBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.empty()) fail(path, "is empty");
  return head;
}

const pcl::PCLPointField* find_field(const pcl::PCLPointCloud2& blob, const std::string& name) {
  const auto it = std::find_if(blob.fields.begin(), blob.fields.end(),
                               [&](const pcl::PCLPointField& f) { return f.name == name; });
  return it == blob.fields.end() ? nullptr : &*it;
}

// What PCL read must match what the header promised before PCL's conversion walks it: the conversion trusts
// width, height, row_step and the field offsets (a PLY camera element may rewrite width and height from
// data).
void check_blob(const std::filesystem::path& path, pcl::PCLPointCloud2& blob) {
  const std::uint64_t points = std::uint64_t{blob.width} * blob.height;
  if (points == 0) fail(path, "has no points");
  if (blob.data.size() != points * blob.point_step)
    fail(path, "holds " + std::to_string(blob.data.size()) + " bytes of points, not " +
                   std::to_string(points) + " x " + std::to_string(blob.point_step));
  for (const pcl::PCLPointField& field : blob.fields) {
    const std::uint64_t end =
        field.offset + static_cast<std::uint64_t>(pcl::getFieldSize(field.datatype)) * field.count;
    if (end > blob.point_step) fail(path, "field '" + field.name + "' lies outside its point");
  }
  for (const char* name : {"x", "y", "z"}) {
    const pcl::PCLPointField* field = find_field(blob, name);
    if (field == nullptr) fail(path, "has no x, y, z fields");
    if (field->datatype != pcl::PCLPointField::FLOAT32 || field->count != 1)
      fail(path, std::string("field ") + name + " is not one 32-bit float");
  }
  const pcl::PCLPointField* label = find_field(blob, "label");
  if (label && (label->datatype != pcl::PCLPointField::UINT32 || label->count != 1))
    fail(path, "field label is not one 32-bit unsigned integer");
  // Organization is dropped below anyway; one row makes the conversion's row walk trivially in bounds.
  blob.width = static_cast<std::uint32_t>(points);
  blob.height = 1;
  blob.row_step = static_cast<std::uint32_t>(blob.data.size());
}

pcl::PCLPointCloud2 read_blob(const std::filesystem::path& path, Format format, Eigen::Vector4f& origin,
                              Eigen::Quaternionf& orientation) {
  // PCL reports failures on its console; we report them through the return code instead.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  pcl::PCLPointCloud2 blob;
  int status = -1;
  try {
    int version = 0;
    if (format == Format::kPcd) {
      status = pcl::PCDReader().read(path.string(), blob, origin, orientation, version);
    } else {
      status = pcl::PLYReader().read(path.string(), blob, origin, orientation, version);
    }
  } catch (const std::exception& e) {
    fail(path, std::string("cannot be read: ") + e.what());
  }
  if (status < 0) fail(path, "cannot be read (malformed or truncated)");
  check_blob(path, blob);
  return blob;
}

CloudFile finite_points(const std::filesystem::path& path, const pcl::PCLPointCloud2& blob,
                        const CloudFileOptions& options) {
  Cloud all;
  pcl::fromPCLPointCloud2(blob, all);
  pcl::PointCloud<pcl::Label> labels;
  const bool labelled = find_field(blob, "label") != nullptr;
  if (labelled) pcl::fromPCLPointCloud2(blob, labels);

  CloudFile file;
  file.points.reserve(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    const pcl::PointXYZ& p = all[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      ++file.non_finite;
      continue;
    }
    if (std::abs(p.x) > kMaxAbsCoordinate || std::abs(p.y) > kMaxAbsCoordinate ||
        std::abs(p.z) > kMaxAbsCoordinate) {
      std::ostringstream reason;
      reason << "point " << i << " has an absurd coordinate (" << p.x << ", " << p.y << ", " << p.z
             << "); |value| must be <= " << kMaxAbsCoordinate << " m";
      fail(path, reason.str());
    }
    file.points.push_back(p);
    if (labelled) file.labels.push_back(labels[i].label);
  }
  if (file.points.empty() && options.require_finite_points) {
    fail(path, "has no finite points (" + std::to_string(file.non_finite) + " NaN/inf points)");
  }
  return file;
}

}  // namespace

CloudFile load_cloud_file(const std::filesystem::path& path, const CloudFileOptions& options) {
  const std::string extension = lower(path.extension().string());
  Format format;
  if (extension == ".pcd") {
    format = Format::kPcd;
  } else if (extension == ".ply") {
    format = Format::kPly;
  } else {
    fail(path, "unknown point cloud format (expected .pcd or .ply)");
  }
  const std::uint64_t size = checked_size(path);
  try {
    if (format == Format::kPcd) {
      cloud_header::check_pcd(read_head(path), size);
    } else {
      cloud_header::check_ply(read_head(path), size);
    }
  } catch (const Error& e) {
    fail(path, e.what());
  }
  Eigen::Vector4f origin = Eigen::Vector4f::Zero();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  const pcl::PCLPointCloud2 blob = read_blob(path, format, origin, orientation);
  CloudFile file = finite_points(path, blob, options);
  file.points.sensor_origin_ = origin;
  file.points.sensor_origin_[3] = 0.0f;
  file.points.sensor_orientation_ = orientation;
  return file;
}

}  // namespace cellmap
