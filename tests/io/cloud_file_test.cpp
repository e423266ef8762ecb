#include "cellmap/io/cloud_file.hpp"

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;

class CloudFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("cellmap_io_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write_text(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  // Expects load_cloud_file to throw an Error whose one-line message names the file and contains `reason`.
  void expect_rejected(const fs::path& path, const std::string& reason) {
    try {
      (void)load_cloud_file(path);
      FAIL() << path << " was accepted";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path.string()), std::string::npos) << message;
      EXPECT_NE(message.find(reason), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
  fs::path dir_;
};

Cloud grid_with_nans(std::size_t* nan_count) {
  Cloud cloud;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  *nan_count = 0;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) {
      if ((i + j) % 7 == 0) {
        cloud.push_back({nan, nan, nan});
        ++*nan_count;
      } else {
        cloud.push_back({0.1f * i, 0.1f * j, 1.0f});
      }
    }
  }
  cloud.push_back({std::numeric_limits<float>::infinity(), 0.0f, 0.0f});
  ++*nan_count;
  return cloud;
}

TEST_F(CloudFileTest, LoadsPcdAndDropsNonFinitePoints) {
  std::size_t nans = 0;
  const Cloud cloud = grid_with_nans(&nans);
  const fs::path path = dir_ / "grid.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinary(path.string(), cloud), 0);
  const CloudFile file = load_cloud_file(path);
  EXPECT_EQ(file.non_finite, nans);
  EXPECT_EQ(file.points.size(), cloud.size() - nans);
  EXPECT_TRUE(file.labels.empty());
  for (const auto& p : file.points)
    EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
}

TEST_F(CloudFileTest, LoadsPlyAndLabels) {
  pcl::PointCloud<pcl::PointXYZL> cloud;
  for (int i = 0; i < 20; ++i) {
    pcl::PointXYZL p;
    p.x = 0.01f * i;
    p.y = -0.5f;
    p.z = 2.0f;
    p.label = 20 + i % 3;
    cloud.push_back(p);
  }
  const fs::path ply = dir_ / "line.ply";
  ASSERT_EQ(pcl::io::savePLYFileASCII(ply.string(), cloud), 0);
  const CloudFile from_ply = load_cloud_file(ply);
  ASSERT_EQ(from_ply.points.size(), 20u);
  EXPECT_FLOAT_EQ(from_ply.points[7].x, 0.07f);
  EXPECT_FLOAT_EQ(from_ply.points[7].z, 2.0f);

  const fs::path pcd = dir_ / "line.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(pcd.string(), cloud), 0);
  const CloudFile from_pcd = load_cloud_file(pcd);
  ASSERT_EQ(from_pcd.labels.size(), 20u);
  EXPECT_EQ(from_pcd.labels[5], 22u);
}

TEST_F(CloudFileTest, RejectsEmptyFile) {
  expect_rejected(write_text("empty.pcd", ""), "is empty");
}

TEST_F(CloudFileTest, RejectsTextGarbageNamedPcd) {
  expect_rejected(write_text("garbage.pcd", "this is not a point cloud\n\x01\x02 at all\n"),
                  "not a PCD file");
  expect_rejected(write_text("garbage.ply", "hello\nworld\n"), "not a PLY file");
  // A plausible header whose body is missing: PCL's reader must fail and we must say so.
  expect_rejected(
      write_text("truncated.pcd",
                 "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1000\nHEIGHT 1\n"
                 "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1000\nDATA binary\nabc"),
      "cannot be read");
}

TEST_F(CloudFileTest, RejectsMissingFileAndUnknownExtension) {
  expect_rejected(dir_ / "absent.pcd", "no such file");
  expect_rejected(write_text("cloud.xyz", "1 2 3\n"), "unknown point cloud format");
}

TEST_F(CloudFileTest, RejectsAllNanCloud) {
  Cloud cloud;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int i = 0; i < 50; ++i) cloud.push_back({nan, nan, nan});
  const fs::path path = dir_ / "nan.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinary(path.string(), cloud), 0);
  expect_rejected(path, "has no finite points (50 NaN/inf points)");
}

TEST_F(CloudFileTest, RejectsAbsurdCoordinates) {
  Cloud cloud;
  cloud.push_back({0.0f, 0.0f, 1.0f});
  cloud.push_back({1e30f, 0.0f, 1.0f});
  const fs::path path = dir_ / "far.pcd";
  ASSERT_EQ(pcl::io::savePCDFileASCII(path.string(), cloud), 0);
  expect_rejected(path, "absurd coordinate");
}

TEST_F(CloudFileTest, RejectsHeaderWithoutXyz) {
  expect_rejected(write_text("rgb.pcd",
                             "VERSION .7\nFIELDS rgb\nSIZE 4\nTYPE F\nCOUNT 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n"
                             "DATA ascii\n1\n"),
                  "has no x, y, z fields");
}

}  // namespace
}  // namespace cellmap
