// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one interface every depth camera source implements (OpenNI2, V4L2, replay), and the value types they
// share: depth modes, source status, device descriptions.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/frame/frame.hpp"

namespace cellmap {

/// One video mode a depth device offers or a configuration asks for.
struct DepthMode final {
  int width = 0;   ///< pixels
  int height = 0;  ///< pixels
  double fps = 0;  ///< frames per second; in a request, 0 means "the highest offered at this size"
  /// Pixel format: "DEPTH_1_MM" or "DEPTH_100_UM" (OpenNI2), "Z16" (V4L2, 16-bit depth); other formats a
  /// device offers keep their own name (e.g. a V4L2 fourcc "YUYV") so error messages can list them.
  std::string format;

  /// "640x480@30 DEPTH_1_MM"
  [[nodiscard]] std::string to_string() const;
};

/// The offered mode that matches `wanted`: same format, width and height, and fps within 0.5 of the wanted
/// rate (or the highest offered rate when wanted.fps is 0). Pure function; used by every camera source.
/// @throws Error "<device>: no mode <wanted>; offers <list>" when nothing matches.
[[nodiscard]] DepthMode choose_depth_mode(const std::vector<DepthMode>& offered, const DepthMode& wanted,
                                          const std::string& device);

/// "640x480@30 DEPTH_1_MM, 320x240@60 DEPTH_1_MM" ("nothing" when empty).
[[nodiscard]] std::string describe_modes(const std::vector<DepthMode>& modes);

/// Connection state of a source.
enum class SourceState {
  kClosed,        ///< not opened yet, or closed
  kConnected,     ///< streaming
  kDisconnected,  ///< device missing, unplugged or silent; the source retries with back-off
  kError,         ///< a fault retrying cannot fix (the device does not offer the configured mode, a bad file)
  kEnded,         ///< a recording (replay directory, .oni file) has no more frames
};
[[nodiscard]] const char* to_string(SourceState state);

/// What a source reports about itself. Plain value, safe to copy to a status topic.
struct SourceStatus final {
  SourceState state = SourceState::kClosed;
  std::string reason;          ///< why it is not connected (empty when connected), one line naming the device
  std::uint64_t frames = 0;    ///< frames delivered since construction
  std::uint64_t attempts = 0;  ///< connection attempts since construction (1 = the first open)
};

/// A depth device found on this machine, with the depth modes it offers.
struct DepthDeviceInfo final {
  std::string driver;  ///< "openni2" or "v4l2"
  std::string uri;     ///< OpenNI2 URI, or the /dev/videoN path
  std::string name;    ///< vendor and product as the driver reports them
  std::vector<DepthMode> modes;
};

/// A depth camera or recording that yields frames in the sensor frame S. Sources fill Frame::sensor, stamp,
/// depth and points_S (valid points, via depth_to_points, or read from a PCD); they leave Frame::X_CS at
/// identity: the sensor pose comes from the robot (see SensorPoser). Stamps are seconds on the host's
/// CLOCK_REALTIME (the clock DDS samples carry), except replayed frames, which keep their recorded stamps.
///
/// Lifecycle: open() → next() … → close(). A missing or unplugged device is not an exception: the status
/// turns kDisconnected with the reason and next() retries with back-off. Not thread-safe: one thread drives a
/// source.
class DepthSource {
 public:
  virtual ~DepthSource() = default;
  DepthSource() = default;
  DepthSource(const DepthSource&) = delete;
  DepthSource& operator=(const DepthSource&) = delete;

  /// The sensor name from the configuration.
  [[nodiscard]] virtual const std::string& name() const = 0;
  /// Connects and starts streaming; returns the resulting status (kConnected, kDisconnected or kError).
  virtual SourceStatus open() = 0;
  /// Waits at most `timeout` for the next frame. Returns nothing on timeout, while disconnected (after a
  /// reconnect attempt if one was due), in kError and at the end of a recording.
  virtual std::optional<Frame> next(std::chrono::milliseconds timeout) = 0;
  [[nodiscard]] virtual SourceStatus status() const = 0;
  /// Stops streaming and releases the device; the status turns kClosed. Safe to call twice.
  virtual void close() = 0;
};

/// Maps a device's own timestamps (microseconds since it started) to host seconds. Keeps the smallest
/// host-minus-device offset seen: the frame that arrived with the least transport delay bounds the offset
/// best, and later frames never move the mapping by their own jitter. Hand-written because neither OpenNI2
/// nor V4L2 offers it; a few lines. Not thread-safe.
class DeviceClock final {
 public:
  /// Host seconds for a frame stamped `device_us` by the device and received at `host_seconds`.
  [[nodiscard]] double to_host(std::uint64_t device_us, double host_seconds);
  /// Forget the mapping (the device restarted its clock, e.g. after a reconnect).
  void reset() { have_offset_ = false; }

 private:
  bool have_offset_ = false;
  double offset_ = 0.0;
};

/// Seconds on CLOCK_REALTIME now (the stamp clock of live sources).
[[nodiscard]] double realtime_seconds();
/// Seconds on std::chrono::steady_clock now (the clock sources time their timeouts and retries with).
[[nodiscard]] double steady_seconds();

}  // namespace cellmap
