#pragma once
// Helpers shared by the sensor tests: a temporary folder and a synthetic depth image.

#include <unistd.h>

#include <filesystem>
#include <string>

#include "cellmap/sensor/depth_io.hpp"

namespace cellmap::test {

namespace fs = std::filesystem;

/// A fresh folder under the system temp folder, removed with its contents on destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& tag)
      : path_(fs::temp_directory_path() / ("cellmap_" + tag + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  [[nodiscard]] const fs::path& path() const { return path_; }
  [[nodiscard]] std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

/// width × height raw depth: column 0 without returns, elsewhere 1000 + 300 v + u.
inline RawDepth ramp(int width, int height) {
  RawDepth image;
  image.width = width;
  image.height = height;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u)
      image.depth.push_back(static_cast<std::uint16_t>(u == 0 ? 0 : 1000 + 300 * v + u));
  }
  return image;
}

}  // namespace cellmap::test
