// SPDX-License-Identifier: Apache-2.0
// Depth image files (16-bit PNG and TIFF) and intrinsics files, on files the test writes itself.
#include "cellmap/sensor/depth_io.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "sensor/sensor_test_util.hpp"

namespace cellmap {
namespace {

using test::ramp;
using test::TempDir;

TEST(DepthIoTest, PngRoundTripKeepsEverySixteenBitValue) {
  TempDir dir("png");
  RawDepth image = ramp(5, 3);
  image.depth[1] = 65535;  // high byte and low byte both matter
  image.depth[2] = 256;
  write_depth_png(dir / "d.png", image);
  const RawDepth back = read_depth_image(dir / "d.png");
  EXPECT_EQ(back.width, 5);
  EXPECT_EQ(back.height, 3);
  EXPECT_EQ(back.depth, image.depth);
}

TEST(DepthIoTest, RefusesWhatIsNotSixteenBitDepth) {
  TempDir dir("bad");
  write_file_atomically(dir / "noise.png", "not a png at all");
  EXPECT_THROW((void)read_depth_image(dir / "noise.png"), Error);
  write_file_atomically(dir / "noise.tiff", "II*\0garbage");
  EXPECT_THROW((void)read_depth_image(dir / "noise.tiff"), Error);
  EXPECT_THROW((void)read_depth_image(dir / "missing.png"), Error);
  EXPECT_THROW((void)read_depth_image(dir / "depth.jpg"), Error);
  RawDepth wrong = ramp(4, 2);
  wrong.depth.pop_back();
  EXPECT_THROW(write_depth_png(dir / "w.png", wrong), Error);
  try {
    (void)read_depth_image(dir / "noise.png");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("noise.png"), std::string::npos) << e.what();
  }
}

TEST(DepthIoTest, IntrinsicsYamlIsStrict) {
  TempDir dir("yaml");
  write_file_atomically(dir / "k.yaml",
                        "width: 4\nheight: 3\nfx: 2\nfy: 2\ncx: 1.5\ncy: 1\ndepth_scale: 0.0001\n");
  const PinholeIntrinsics k = read_intrinsics_yaml(dir / "k.yaml");
  EXPECT_EQ(k.width, 4);
  EXPECT_DOUBLE_EQ(k.depth_scale, 0.0001);
  EXPECT_DOUBLE_EQ(k.max_depth_jump, kDefaultMaxDepthJump);  // a camera's flying-pixel filter is on
  write_file_atomically(dir / "off.yaml",
                        "width: 4\nheight: 3\nfx: 2\nfy: 2\ncx: 1.5\ncy: 1\nmax_depth_jump: 0\n");
  EXPECT_DOUBLE_EQ(read_intrinsics_yaml(dir / "off.yaml").max_depth_jump, 0.0);
  EXPECT_EQ(k.smoothing_radius, 0);  // smoothing is the recorder's to ask for
  write_file_atomically(dir / "smooth.yaml",
                        "width: 4\nheight: 3\nfx: 2\nfy: 2\ncx: 1.5\ncy: 1\nsmoothing_radius: 2\n");
  EXPECT_EQ(read_intrinsics_yaml(dir / "smooth.yaml").smoothing_radius, 2);
  write_file_atomically(dir / "wide.yaml",
                        "width: 4\nheight: 3\nfx: 2\nfy: 2\ncx: 1.5\ncy: 1\nsmoothing_radius: 17\n");
  EXPECT_THROW((void)read_intrinsics_yaml(dir / "wide.yaml"), Error);
  write_file_atomically(dir / "typo.yaml", "width: 4\nheight: 3\nfx: 2\nfy: 2\ncx: 1.5\ncy: 1\nfocal: 3\n");
  EXPECT_THROW((void)read_intrinsics_yaml(dir / "typo.yaml"), Error);
  write_file_atomically(dir / "nofx.yaml", "width: 4\nheight: 3\nfy: 2\ncx: 1.5\ncy: 1\n");
  EXPECT_THROW((void)read_intrinsics_yaml(dir / "nofx.yaml"), Error);
}

// Found by fuzzing (fuzz_intrinsics): the YAML syntax error quoted a newline and took two lines.
TEST(DepthIoTest, FuzzFindingsAreRefusedWithOneLine) {
  const std::string file = test::fuzz_regression("intrinsics", "unknown_escape.yaml");
  EXPECT_EQ(test::one_line_error_of([&] {
              (void)read_intrinsics_yaml(file);
            }).rfind(file + ": YAML syntax error at line 8, column 1: unknown escape character", 0),
            0u);
}

// libtiff's message about an InkNames tag that disagrees with the samples per pixel spans two lines; the
// refusal quoting it must not. The fuzz input's first byte picks TIFF, the rest is the file.
TEST(DepthIoTest, ATiffFuzzFindingIsRefusedWithOneLine) {
  TempDir dir("ink");
  std::ifstream in(test::fuzz_regression("depth_image", "tiff-warning-message-over-two-lines"),
                   std::ios::binary);
  const std::string input((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(input.size(), 1u);
  write_file_atomically(dir / "ink.tiff", input.substr(1));
  const std::string message = test::one_line_error_of([&] { (void)read_depth_image(dir / "ink.tiff"); });
  EXPECT_NE(message.find("ink.tiff: cannot read TIFF"), std::string::npos) << message;
}

// A header of a few bytes claiming a huge image made the reader allocate it before reading a row (1.5 GB:
// fuzz_depth_image). Found for a TIFF; PNG's reader had the same gap.
TEST(DepthIoTest, ImagesLargerThanTheLimitAreRefusedBeforeTheyAreAllocated) {
  TempDir dir("huge");
  std::ifstream in(test::fuzz_regression("depth_image", "tiff_claiming_a_huge_image"), std::ios::binary);
  const std::string input((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(input.size(), 1u);
  write_file_atomically(dir / "huge.tiff", input.substr(1));
  const std::string tiff = test::one_line_error_of([&] { (void)read_depth_image(dir / "huge.tiff"); });
  EXPECT_NE(tiff.find("pixels is more than a depth image may have (16777216)"), std::string::npos) << tiff;

  RawDepth image;
  image.width = 4097;  // 4097 x 4096: one row more than the limit allows
  image.height = 4096;
  image.depth.assign(std::size_t{4097} * 4096, 1000);
  write_depth_png(dir / "huge.png", image);
  EXPECT_EQ(test::one_line_error_of([&] { (void)read_depth_image(dir / "huge.png"); }),
            dir / "huge.png" + ": 4097 x 4096 pixels is more than a depth image may have (16777216)");
  image.width = 4096;  // at the limit
  image.depth.resize(std::size_t{4096} * 4096);
  write_depth_png(dir / "limit.png", image);
  EXPECT_EQ(read_depth_image(dir / "limit.png").depth.size(), std::size_t{4096} * 4096);
}

}  // namespace
}  // namespace cellmap
