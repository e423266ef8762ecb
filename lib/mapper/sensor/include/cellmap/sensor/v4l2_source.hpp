// SPDX-License-Identifier: Apache-2.0
#pragma once
// Depth cameras that expose 16-bit depth as a V4L2 video device (Intel RealSense D4xx through the uvcvideo
// driver: one of its /dev/videoN nodes offers the Z16 pixel format), through libv4l2.
//
// RealSense D435 defaults (typical values; every unit differs by a few pixels — print the real ones with
// `rs-enumerate-devices -c` and put them in the config):
//   848×480 @ 30/60/90 fps, Z16: fx ≈ fy ≈ 425 px, cx ≈ 424, cy ≈ 240   (the recommended depth mode)
//   640×480 @ 30/60/90 fps, Z16: fx ≈ fy ≈ 383 px, cx ≈ 320, cy ≈ 240
//   1280×720 @ 30 fps,      Z16: fx ≈ fy ≈ 640 px, cx ≈ 640, cy ≈ 360
//   depth unit 1 mm (depth_scale 0.001), useful range about 0.3 m to 10 m.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/sensor/depth_source.hpp"
#include "cellmap/sensor/reconnect.hpp"

namespace cellmap {

/// "Z16", "YUYV", … : a V4L2 fourcc as text, trailing spaces dropped (so Z16's "Z16 " reads "Z16").
[[nodiscard]] std::string fourcc_to_string(std::uint32_t fourcc);

/// Decodes one Z16 image: little-endian 16-bit depth values, rows `bytes_per_line` apart (≥ 2 × width;
/// drivers may pad rows). Pure function. @throws Error if a size is not positive, bytes_per_line < 2 × width,
/// or `size` is smaller than (height - 1) × bytes_per_line + 2 × width.
[[nodiscard]] std::vector<std::uint16_t> decode_z16(const std::uint8_t* data, std::size_t size, int width,
                                                    int height, std::size_t bytes_per_line);

/// The D435 intrinsics listed above for 848×480, 640×480 and 1280×720 (depth_scale 0.001, range 0.3–10 m,
/// max_depth_jump kStereoMaxDepthJump, smoothing_radius kStereoSmoothingRadius).
/// @throws Error for other sizes (their intrinsics must come from the config).
[[nodiscard]] PinholeIntrinsics realsense_d435_intrinsics(int width, int height);

struct V4l2Config final {
  std::string name = "v4l2";            ///< sensor name given to the frames
  std::string device = "/dev/video0";   ///< the node that offers Z16
  DepthMode mode{848, 480, 30, "Z16"};  ///< format must be "Z16"
  /// Intrinsics, depth_scale and range; when absent, realsense_d435_intrinsics(mode.width, mode.height).
  std::optional<PinholeIntrinsics> intrinsics;
  ReconnectParams reconnect;
  int buffers = 4;  ///< mmap streaming buffers (2..32)
};

/// A Z16 depth stream of one V4L2 device: negotiates the configured size and rate (choose_depth_mode over the
/// modes the device enumerates), streams through mmap buffers and stamps frames with the driver's timestamp
/// (CLOCK_MONOTONIC buffers are moved to CLOCK_REALTIME). A missing device node or an unplugged camera is
/// kDisconnected (retried with back-off); a device without the configured Z16 mode is kError naming the
/// device and what it offers. Not thread-safe.
class V4l2Source final : public DepthSource {
 public:
  /// @throws Error if the config is invalid (format not Z16, no intrinsics for the size, buffers out of
  /// range).
  explicit V4l2Source(V4l2Config config);
  ~V4l2Source() override;

  [[nodiscard]] const std::string& name() const override { return config_.name; }
  SourceStatus open() override;
  std::optional<Frame> next(std::chrono::milliseconds timeout) override;
  [[nodiscard]] SourceStatus status() const override;
  void close() override;

  [[nodiscard]] const PinholeIntrinsics& intrinsics() const { return intrinsics_; }

 private:
  struct Stream;
  void connect(double now);
  void release();

  V4l2Config config_;
  PinholeIntrinsics intrinsics_;
  Reconnector reconnector_;
  std::unique_ptr<Stream> stream_;
  std::uint64_t frames_ = 0;
  std::uint64_t attempts_ = 0;
};

/// The V4L2 capture devices under `dev_dir` (/dev/video*) that offer Z16 depth, each with its Z16 modes.
/// Devices that cannot be opened or offer no Z16 are skipped. Never throws for a missing directory.
[[nodiscard]] std::vector<DepthDeviceInfo> list_v4l2_devices(const std::string& dev_dir = "/dev");

}  // namespace cellmap
