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
#include <set>
#include <sstream>
#include <string>

#include "cellmap/common/error.hpp"

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

// The first bytes of the file, enough for any header we accept.
std::string read_head(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot be opened");
  std::string head(64 * 1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.empty()) fail(path, "is empty");
  return head;
}

// PCL's PCD parser prints and may misread arbitrary bytes, so we accept only a header made of PCD keywords
// that names x, y and z and ends in a DATA line.
void check_pcd_header(const std::filesystem::path& path, const std::string& head) {
  static const std::set<std::string> kKeywords = {"VERSION", "FIELDS", "COLUMNS",   "SIZE",   "TYPE", "COUNT",
                                                  "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
  std::istringstream lines(head);
  std::string line;
  std::set<std::string> fields;
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (kKeywords.count(keyword) == 0)
      fail(path, "not a PCD file (unexpected header line '" + line.substr(0, 40) + "')");
    if (keyword == "FIELDS" || keyword == "COLUMNS") {
      for (std::string field; words >> field;) fields.insert(field);
    }
    if (keyword == "DATA") {
      std::string kind;
      words >> kind;
      if (kind != "ascii" && kind != "binary" && kind != "binary_compressed") {
        fail(path, "not a PCD file (unknown DATA kind '" + kind + "')");
      }
      if (!fields.count("x") || !fields.count("y") || !fields.count("z")) fail(path, "has no x, y, z fields");
      return;
    }
  }
  fail(path, "not a PCD file (no DATA line in the header)");
}

void check_ply_header(const std::filesystem::path& path, const std::string& head) {
  std::istringstream lines(head);
  std::string line;
  std::getline(lines, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "ply") fail(path, "not a PLY file (first line is not 'ply')");
  bool has_x = false, has_y = false, has_z = false;
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "property") {
      std::string type, name;
      words >> type >> name;
      if (type == "list") continue;
      has_x |= name == "x";
      has_y |= name == "y";
      has_z |= name == "z";
    } else if (keyword == "end_header") {
      if (!has_x || !has_y || !has_z) fail(path, "has no x, y, z properties");
      return;
    }
  }
  fail(path, "not a PLY file (no end_header)");
}

bool has_field(const pcl::PCLPointCloud2& blob, const std::string& name) {
  return std::any_of(blob.fields.begin(), blob.fields.end(),
                     [&](const pcl::PCLPointField& f) { return f.name == name; });
}

}  // namespace

CloudFile load_cloud_file(const std::filesystem::path& path) {
  const std::string extension = lower(path.extension().string());
  Format format;
  if (extension == ".pcd") {
    format = Format::kPcd;
  } else if (extension == ".ply") {
    format = Format::kPly;
  } else {
    fail(path, "unknown point cloud format (expected .pcd or .ply)");
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, "no such file");
  const std::string head = read_head(path);
  if (format == Format::kPcd) {
    check_pcd_header(path, head);
  } else {
    check_ply_header(path, head);
  }

  // PCL reports failures on its console; we report them through the return code instead.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin = Eigen::Vector4f::Zero();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  int status = -1;
  try {
    if (format == Format::kPcd) {
      pcl::PCDReader reader;
      int pcd_version = 0;
      status = reader.read(path.string(), blob, origin, orientation, pcd_version);
    } else {
      pcl::PLYReader reader;
      int ply_version = 0;
      status = reader.read(path.string(), blob, origin, orientation, ply_version);
    }
  } catch (const std::exception& e) {
    fail(path, std::string("cannot be read: ") + e.what());
  }
  if (status < 0) fail(path, "cannot be read (malformed or truncated)");
  if (blob.width * blob.height == 0) fail(path, "has no points");
  if (!has_field(blob, "x") || !has_field(blob, "y") || !has_field(blob, "z"))
    fail(path, "has no x, y, z fields");

  Cloud all;
  pcl::fromPCLPointCloud2(blob, all);
  pcl::PointCloud<pcl::Label> labels;
  const bool labelled = has_field(blob, "label");
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
  if (file.points.empty()) {
    fail(path, "has no finite points (" + std::to_string(file.non_finite) + " NaN/inf points)");
  }
  file.points.sensor_origin_ = origin;
  file.points.sensor_origin_[3] = 0.0f;
  file.points.sensor_orientation_ = orientation;
  return file;
}

}  // namespace cellmap
