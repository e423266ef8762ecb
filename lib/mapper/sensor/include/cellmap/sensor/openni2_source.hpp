// SPDX-License-Identifier: Apache-2.0
#pragma once
// Kinect-class depth cameras (PrimeSense, Xtion, Kinect via its OpenNI2 driver) and .oni recordings, through
// OpenNI2 (Debian libopenni2; drivers in /usr/lib/x86_64-linux-gnu/OpenNI2/Drivers).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/sensor/depth_source.hpp"
#include "cellmap/sensor/reconnect.hpp"

namespace cellmap {

struct OpenNI2Config final {
  std::string name = "openni2";  ///< sensor name given to the frames
  /// Device URI as OpenNI2 lists it, a path to an .oni recording (played through OpenNI2's OniFile driver),
  /// or empty for the first device found.
  std::string uri;
  /// Depth mode to stream; format "DEPTH_1_MM" (depth_scale 1 mm) or "DEPTH_100_UM" (0.1 mm).
  DepthMode mode{640, 480, 30, "DEPTH_1_MM"};
  /// Replaces the intrinsics derived from the device's field of view (fx, fy, cx, cy; width and height must
  /// match the mode). Needed for devices that report no field of view.
  std::optional<PinholeIntrinsics> intrinsics;
  double min_range = 0.0;   ///< metres; depths outside [min_range, max_range] are no return
  double max_range = 10.0;  ///< metres
  double max_depth_jump = kDefaultMaxDepthJump;  ///< flying-pixel filter (PinholeIntrinsics), 0 = off
  int smoothing_radius = 0;                      ///< depth smoothing, pixels (PinholeIntrinsics), 0 = off
  ReconnectParams reconnect;
  /// .oni playback: true plays at the recorded rate, false as fast as frames are read.
  bool realtime_playback = true;
};

/// Intrinsics of a pinhole camera from its fields of view (radians):
/// fx = (width / 2) / tan(hfov / 2), fy = (height / 2) / tan(vfov / 2), principal point at the image centre
/// ((width - 1) / 2, (height - 1) / 2). @throws Error if a field of view is not in (0, π) or a size not
/// positive.
[[nodiscard]] PinholeIntrinsics intrinsics_from_fov(int width, int height, double hfov, double vfov);

/// A depth stream of one OpenNI2 device or .oni file. open() with no device present leaves the source
/// kDisconnected with OpenNI2's reason ("no devices found"); a device that does not offer the configured
/// mode, or that reports no field of view while the config gives no intrinsics, is kError with a reason that
/// lists what it offers. While streaming, no frame for reconnect.frame_timeout turns it kDisconnected and
/// next() reopens with back-off. An .oni file ends with kEnded. Stamps: the device clock mapped to the host's
/// CLOCK_REALTIME by DeviceClock. Not thread-safe.
class OpenNI2Source final : public DepthSource {
 public:
  /// @throws Error if the config is invalid (mode format not DEPTH_1_MM / DEPTH_100_UM, bad range or policy).
  explicit OpenNI2Source(OpenNI2Config config);
  ~OpenNI2Source() override;

  [[nodiscard]] const std::string& name() const override { return config_.name; }
  SourceStatus open() override;
  std::optional<Frame> next(std::chrono::milliseconds timeout) override;
  [[nodiscard]] SourceStatus status() const override;
  void close() override;

  /// The intrinsics in use (valid while connected).
  [[nodiscard]] const PinholeIntrinsics& intrinsics() const { return intrinsics_; }

 private:
  struct Device;
  void release();
  void connect(double now);

  OpenNI2Config config_;
  Reconnector reconnector_;
  std::unique_ptr<Device> device_;
  PinholeIntrinsics intrinsics_;
  DeviceClock clock_;
  std::uint64_t frames_ = 0;
  std::uint64_t attempts_ = 0;
  bool ended_ = false;
};

/// The OpenNI2 devices present, each with its depth modes. Empty when there are none.
/// @throws Error if OpenNI2 cannot initialise (its reason, e.g. no drivers found).
[[nodiscard]] std::vector<DepthDeviceInfo> list_openni2_devices();

/// Opens one OpenNI2 URI that enumeration does not list (an .oni recording, a driver's named virtual device
/// such as "Dummy") and reports its depth modes. @throws Error "openni2 <uri>: <OpenNI2's reason>" if it does
/// not open.
[[nodiscard]] DepthDeviceInfo probe_openni2_device(const std::string& uri);

}  // namespace cellmap
