// SPDX-License-Identifier: Apache-2.0
#pragma once
// Replay of recorded frames from a directory: reproduces a field problem on a desk.
//
// clang-format off
// Replay directory format (version 1):
//
//   DIR/poses.csv   one row per frame, in time order, after one header line that must read exactly
//                     file,stamp,x,y,z,qw,qx,qy,qz
//                   Blank lines and lines starting with '#' are skipped.
//     file    the frame, relative to DIR (or absolute), one of
//             - a depth image: single-channel 16-bit grayscale PNG (.png) or TIFF (.tif, .tiff), raw sensor
//               units (0 = no return), converted with the intrinsics below;
//             - a point cloud (.pcd, any PCL point type with x y z) already in the sensor frame (metres,
//               x right, y down, z forward), read by load_cloud_file (cellmap/io/cloud_file.hpp), which
//               refuses a malformed or absurd file before allocating for it; NaN points are skipped.
//     stamp   seconds, strictly increasing, any epoch (frames keep it as Frame::stamp)
//     x,y,z   position of the END-EFFECTOR (tool) in the cell frame, metres: X_CE
//     qw..qz  its orientation, unit quaternion [w, x, y, z]
//             A recorder that knows sensor poses instead writes X_CS here and configures the sensor with an
//             identity hand-eye extrinsic.
//   Intrinsics of a depth image, the first found of
//     <image folder>/<image stem without a trailing "_depth">.xml
//             PCL grabber format (<depth><focal_length_x> … <z_multiplication_factor>), as PCL's
//             ImageGrabber writes beside frame_<time>_depth.tiff;
//     DIR/intrinsics.yaml
//             width, height, fx, fy, cx, cy, depth_scale [, min_range, max_range, max_depth_jump,
//             smoothing_radius]
//             (read_intrinsics_yaml). Either way the flying-pixel filter is on (max_depth_jump 0.02) unless
//             intrinsics.yaml says otherwise.
//
// Example: pcl/grabber_sequence (frame_<t>_depth.tiff + frame_<t>.xml) plus a poses.csv is a replay folder.
// clang-format on

#include <Eigen/Geometry>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/common/steady_clock.hpp"
#include "cellmap/frame/pose_buffer.hpp"
#include "cellmap/sensor/depth_source.hpp"

namespace cellmap {

/// One row of poses.csv.
struct ReplayEntry final {
  std::string file;  ///< as written in the file (relative to the directory or absolute)
  double stamp = 0.0;
  Eigen::Isometry3d X_CE = Eigen::Isometry3d::Identity();
};

/// Reads poses.csv. @throws Error naming the file and line on a wrong header, a malformed or non-finite
/// number, a quaternion whose norm is not 1 ± 1e-3 (a hint of swapped columns), or a stamp not after the
/// previous one.
[[nodiscard]] std::vector<ReplayEntry> read_replay_poses(const std::string& path);
/// Writes poses.csv in the format above (17 significant digits), crash-safely. @throws Error if writing
/// fails.
void write_replay_poses(const std::string& path, const std::vector<ReplayEntry>& entries);

struct ReplayConfig final {
  std::string name = "replay";  ///< sensor name given to the frames
  std::string directory;
  enum class Playback {
    kRecorded,  ///< frames are due at their recorded stamp intervals (times `speed`)
    kFixed,     ///< frames are due every 1 / rate_hz seconds
    kFastest,   ///< frames are due at once
  };
  Playback playback = Playback::kRecorded;
  double speed = 1.0;     ///< kRecorded: 2 plays twice as fast
  double rate_hz = 10.0;  ///< kFixed
  /// When the first frame is due (kRecorded, kFixed), on the source's clock; none: when open() succeeds.
  /// Replays given the same start play on one clock, as their cameras did, whatever the order they open in
  /// (not in the configuration files: for programs that play recordings against a clock of their own).
  std::optional<SteadyClock::time_point> start;
};

/// Plays a replay directory through the DepthSource interface. open() reads poses.csv and checks that every
/// frame file exists (kError naming the first problem otherwise); next() returns each frame when it is
/// due, its pixels converted to points then, and turns kEnded after the last. The files are read ahead on a
/// thread of the source's own at the lowest CPU priority (SCHED_IDLE), so a frame comes at its recorded time
/// as a camera's does and decoding a recording takes only CPU time the frames' processing leaves (it is
/// the recording's cost, not the frame's; a camera delivers pixels); a frame whose file is still being
/// read when it is due comes late, and a file that cannot be read turns kError when its frame is due.
/// Stamps are the recorded ones; feed poses() to the sensor's PoseBuffer so frames and poses meet exactly
/// as recorded. Frames fall due on the source's clock, and next() sleeps on that clock; reading a frame's
/// file is real work, so next() then waits for the read up to `timeout` of real time. Not thread-safe (one
/// thread calls it; the reader thread is internal).
class ReplaySource final : public DepthSource {
 public:
  /// `clock` (which must outlive the source) times the playback; a test passes one it drives.
  /// @throws Error if speed or rate_hz is not positive.
  explicit ReplaySource(ReplayConfig config, SteadyClock& clock = SteadyClock::real());
  ~ReplaySource() override;
  ReplaySource(const ReplaySource&) = delete;
  ReplaySource& operator=(const ReplaySource&) = delete;

  [[nodiscard]] const std::string& name() const override { return config_.name; }
  SourceStatus open() override;
  std::optional<Frame> next(std::chrono::milliseconds timeout) override;
  [[nodiscard]] SourceStatus status() const override { return status_; }
  void close() override;

  /// The recorded tool poses (valid after a successful open()).
  [[nodiscard]] std::vector<StampedPose> poses() const;
  /// Loads frame `index` of the recording, independent of playback timing. @throws Error naming the file.
  [[nodiscard]] Frame load(std::size_t index) const;
  [[nodiscard]] std::size_t size() const { return entries_.size(); }
  /// Whether the next frame's file was read and the frame waits for its time (or the read failed).
  [[nodiscard]] bool next_frame_read() const;

 private:
  [[nodiscard]] std::string resolve(const std::string& file) const;
  // Frame `index` as its file holds it: its depth image (points not yet computed) or its cloud.
  [[nodiscard]] Frame read_recorded(std::size_t index) const;
  // The points of a frame read by read_recorded. @throws Error if its image and intrinsics disagree.
  static void to_points(Frame& frame);
  void fail(const std::string& reason);
  class Reader;
  [[nodiscard]] PinholeIntrinsics intrinsics_for(const std::string& image_path, int width, int height) const;

  ReplayConfig config_;
  SteadyClock& clock_;
  SourceStatus status_;
  std::vector<ReplayEntry> entries_;
  std::size_t next_index_ = 0;
  std::unique_ptr<Reader> reader_;  // while open; reads frame next_index_ before it is due
  SteadyClock::time_point start_;   // on clock_
};

}  // namespace cellmap
