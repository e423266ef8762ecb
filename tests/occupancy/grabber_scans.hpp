// SPDX-License-Identifier: Apache-2.0
#pragma once
// Test and benchmark support: the real Kinect frames of ../shared/data/pcl/grabber_sequence as scans taken
// from the cell origin (camera frame = cell frame), in file-name order.

#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "cellmap/common/error.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap::testing {

/// The grabber PCD frames of the shared data folder `shared_data`, or none when they are absent.
/// @throws Error if a frame is present but unreadable.
inline std::vector<Scan> grabber_scans(const std::filesystem::path& shared_data) {
  const std::filesystem::path dir = shared_data / "pcl" / "grabber_sequence";
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(dir)) {
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      if (entry.path().extension() == ".pcd") files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<Scan> scans;
  for (const auto& file : files) {
    Scan scan;  // identity pose, origin at the camera
    if (pcl::io::loadPCDFile(file.string(), scan.points_C) != 0) throw Error("cannot read " + file.string());
    scans.push_back(std::move(scan));
  }
  return scans;
}

}  // namespace cellmap::testing
