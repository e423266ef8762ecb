// SPDX-License-Identifier: Apache-2.0
#pragma once
// The per-frame part of the cell pipeline: each frame of a sweep cut (self filter), converted to its scan
// and its observed voxels gathered as it arrives, so that the end of a sweep leaves only the map update,
// change detection and re-segmentation (CellPipeline::process(GatheredSweep&)).

#include <Eigen/Core>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "cellmap/frame/frame.hpp"
#include "cellmap/occupancy/occupancy_map.hpp"
#include "cellmap/preprocess/workspace.hpp"
#include "cellmap/robot/robot.hpp"
#include "cellmap/self_filter/self_filter.hpp"

namespace cellmap {

/// One frame of a sweep window: posed in the cell (frame.X_CS set; cameras keep depth->intrinsics for the
/// self filter) with the robot as it stood at the frame's stamp (JointBuffer::at); nullopt: the cell has no
/// robot model, the frame is fused as it is.
struct SweepFrame final {
  Frame frame;
  std::optional<RobotAt> robot;
  /// Metres along its line of sight that a pixel without a return clears (the source's `no_return_range`;
  /// cameras whose frame keeps its depth image; 0 = none). A time-of-flight camera returns from every
  /// surface within its range but the darkest and the shiniest, so no return says the line of sight is free
  /// that far: the only evidence that clears space in front of what lies beyond the camera's range (an
  /// object taken away whose top the camera saw against the cell's far side). Such rays are not stopped at
  /// the robot: a line of sight with no return passed it. Off for stereo cameras (no return on plain
  /// surfaces) and where dark or mirror-like obstacles may stand. Each frame casts the rays of one pixel of
  /// every 2 × 2 block, the next frame (of any such camera) the next pixel: a quarter of the cost, every
  /// pixel used within four frames.
  double no_return_range = 0.0;
};

/// The frames of every sensor in one sweep window, in the order taken. `stamp`: the last frame's, seconds.
struct FrameSweep final {
  double stamp = 0.0;
  std::vector<SweepFrame> frames;
};

/// A sweep whose frames were all gathered (OpenSweep::close), ready for CellPipeline::process.
struct GatheredSweep final {
  /// The frames as taken, each without its points and depth pixels (they went into `voxels`): sensor,
  /// stamp, pose, depth intrinsics, field of view and the robot's pose remain, for the layers and logs.
  FrameSweep frames;
  ObservedVoxels voxels;                                  ///< what the frames observed
  Eigen::Vector3d viewpoint_C = Eigen::Vector3d::Zero();  ///< mean of the frames' scan origins, metres
  std::size_t points = 0;                                 ///< points fused as hits (after the self filter)
  std::size_t robot_points = 0;    ///< points the self filter found on the robot (fused as clear-only rays)
  std::size_t no_return_rays = 0;  ///< clear-only rays of pixels without a return
  /// Seconds (wall, and CPU with helper threads) of the self filter with the frames' conversion to scans,
  /// and of gathering the scans' voxels, summed over the frames (frames gathered side by side each count).
  double t_filter = 0, cpu_filter = 0, t_gather = 0, cpu_gather = 0;
  /// Wall seconds the gathering of the frames took (frames gathered side by side counted once).
  double t_gathering = 0;
};

/// The sweep whose frames are still coming. Not thread-safe: one thread adds and closes; it may be another
/// than the one that runs the CellPipeline, which never touches an OpenSweep (the two share only the
/// immutable self filter).
class OpenSweep final {
 public:
  /// Voxels at `occupancy`'s resolution and range; frames that come with the robot's pose are cut by
  /// `filter` (nullptr: frames pass as they are); points outside `workspace` (the config's
  /// segment.workspace; none: no crop) only clear the free space up to them, as points beyond max_range do:
  /// nothing outside what can matter to the robot becomes an obstacle. `filter` must outlive this.
  /// @throws Error if `occupancy` is invalid.
  explicit OpenSweep(const OccupancyConfig& occupancy, const SelfFilter* filter = nullptr,
                     std::optional<Workspace> workspace = std::nullopt);

  /// Cuts the robot out of `frame` (when it comes with the robot's pose and a filter is set), converts it to
  /// its scan (its points moved, not copied; clear-only rays for its pixels without a return) and gathers
  /// the voxels that scan observes, on the occupancy config's `threads`. @throws Error as SelfFilter::filter
  /// or ObservedVoxels::add (the frame is then not part of the sweep).
  void add(SweepFrame frame);
  /// add() for each frame of `batch` (frames of this sweep that wait, in the order taken), up to `threads`
  /// of them side by side on one thread each: frames that wait are gathered faster that way than one after
  /// the other on split threads. A frame that cannot be gathered is left out; the others are not affected.
  /// @return one line per frame left out ("frame of 'wrist' at 12.345 s: reason").
  [[nodiscard]] std::vector<std::string> add(std::vector<SweepFrame> batch);
  /// Frames added since the last close().
  [[nodiscard]] std::size_t frames() const { return open_.frames.frames.size(); }
  /// The gathered sweep, stamped with its last frame's stamp; the next frame opens a new sweep.
  [[nodiscard]] GatheredSweep close();

 private:
  // What gathering one frame brought.
  struct Gathered {
    SweepFrame frame;
    std::size_t points = 0, robot_points = 0, no_return_rays = 0;
    Eigen::Vector3d origin_C = Eigen::Vector3d::Zero();
    double t_filter = 0, cpu_filter = 0, t_gather = 0, cpu_gather = 0;
  };
  // Gathers `frame` into `voxels` on `threads` threads, its no-return rays with `phase`.
  [[nodiscard]] Gathered gather(SweepFrame frame, unsigned phase, ObservedVoxels& voxels, int threads) const;
  void record(Gathered gathered);
  // The no-return phase of `frame`: the next one for a frame that casts no-return rays.
  [[nodiscard]] unsigned next_phase(const SweepFrame& frame);
  [[nodiscard]] GatheredSweep fresh() const;

  OccupancyConfig occupancy_;
  const SelfFilter* filter_;
  std::optional<Workspace> workspace_;
  GatheredSweep open_;
  std::vector<ObservedVoxels> side_by_side_;  // one per thread of a batch; merged into open_ at close()
  Eigen::Vector3d origin_sum_C_ = Eigen::Vector3d::Zero();
  unsigned no_return_phase_ = 0;  // which pixel of each 2 × 2 block the next frame's no-return rays use
};

}  // namespace cellmap
