// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sensor/v4l2_source.hpp"

#include <fcntl.h>
#include <libv4l2.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

double monotonic_seconds() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<double>(now.tv_sec) + static_cast<double>(now.tv_nsec) * 1e-9;
}

// ioctl through libv4l2, retried when a signal interrupts it.
int xioctl(int fd, unsigned long request, void* arg) {
  int result;
  do {
    result = v4l2_ioctl(fd, request, arg);
  } while (result == -1 && errno == EINTR);
  return result;
}

// Every (format, size, rate) the device enumerates. Stepwise sizes and rates contribute their end points.
std::vector<DepthMode> enumerate_modes(int fd) {
  std::vector<DepthMode> modes;
  v4l2_fmtdesc format{};
  format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  for (format.index = 0; xioctl(fd, VIDIOC_ENUM_FMT, &format) == 0; ++format.index) {
    const std::string name = fourcc_to_string(format.pixelformat);
    v4l2_frmsizeenum size{};
    size.pixel_format = format.pixelformat;
    for (size.index = 0; xioctl(fd, VIDIOC_ENUM_FRAMESIZES, &size) == 0; ++size.index) {
      std::vector<std::pair<int, int>> sizes;
      if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        sizes.emplace_back(size.discrete.width, size.discrete.height);
      } else {
        sizes.emplace_back(size.stepwise.min_width, size.stepwise.min_height);
        sizes.emplace_back(size.stepwise.max_width, size.stepwise.max_height);
      }
      for (const auto& [width, height] : sizes) {
        v4l2_frmivalenum interval{};
        interval.pixel_format = format.pixelformat;
        interval.width = static_cast<std::uint32_t>(width);
        interval.height = static_cast<std::uint32_t>(height);
        bool any_rate = false;
        for (interval.index = 0; xioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &interval) == 0; ++interval.index) {
          std::vector<v4l2_fract> periods;
          if (interval.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
            periods.push_back(interval.discrete);
          } else {
            periods.push_back(interval.stepwise.min);
            periods.push_back(interval.stepwise.max);
          }
          for (const v4l2_fract& period : periods) {
            if (period.numerator == 0) continue;
            modes.push_back(
                DepthMode{width, height, static_cast<double>(period.denominator) / period.numerator, name});
            any_rate = true;
          }
          if (interval.type != V4L2_FRMIVAL_TYPE_DISCRETE) break;
        }
        if (!any_rate) modes.push_back(DepthMode{width, height, 0.0, name});
      }
      if (size.type != V4L2_FRMSIZE_TYPE_DISCRETE) break;
    }
  }
  return modes;
}

// Checked with the plain ioctl before libv4l2 sees the descriptor: libv4l2 prints to stderr when a node is
// not a V4L2 device, and library code must not print.
bool is_capture_device(int fd, std::string* card = nullptr) {
  v4l2_capability caps{};
  int result;
  do {
    result = ::ioctl(fd, VIDIOC_QUERYCAP, &caps);
  } while (result == -1 && errno == EINTR);
  if (result != 0) return false;
  if (card) *card = reinterpret_cast<const char*>(caps.card);
  const std::uint32_t device_caps =
      (caps.capabilities & V4L2_CAP_DEVICE_CAPS) ? caps.device_caps : caps.capabilities;
  return (device_caps & V4L2_CAP_VIDEO_CAPTURE) && (device_caps & V4L2_CAP_STREAMING);
}

// Why one step of connecting failed: `retry` when the device may come (back) and a later attempt can succeed
// (missing, busy, out of buffers), not when retrying cannot help (not a capture device, no such mode).
struct ConnectFailure {
  bool retry = true;
  std::string reason;
};

[[noreturn]] void fail_connect(bool retry, const std::string& reason) {
  throw ConnectFailure{retry, reason};
}

}  // namespace

std::string fourcc_to_string(std::uint32_t fourcc) {
  std::string text;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xFF);
    text += (c >= 32 && c < 127) ? c : '?';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

std::vector<std::uint16_t> decode_z16(const std::uint8_t* data, std::size_t size, int width, int height,
                                      std::size_t bytes_per_line) {
  if (width <= 0 || height <= 0) throw Error("Z16: image size must be positive");
  const std::size_t row_bytes = 2 * static_cast<std::size_t>(width);
  if (bytes_per_line < row_bytes) {
    throw Error("Z16: bytes per line " + std::to_string(bytes_per_line) + " < 2 x width " +
                std::to_string(width));
  }
  const std::size_t needed = (static_cast<std::size_t>(height) - 1) * bytes_per_line + row_bytes;
  if (size < needed) {
    throw Error("Z16: buffer holds " + std::to_string(size) + " bytes, " + std::to_string(width) + "x" +
                std::to_string(height) + " needs " + std::to_string(needed));
  }
  std::vector<std::uint16_t> depth(static_cast<std::size_t>(width) * height);
  for (int v = 0; v < height; ++v) {
    const std::uint8_t* row = data + static_cast<std::size_t>(v) * bytes_per_line;
    std::uint16_t* out = depth.data() + static_cast<std::size_t>(v) * width;
    // Byte by byte, so the result does not depend on the host's byte order.
    for (int u = 0; u < width; ++u) out[u] = static_cast<std::uint16_t>(row[2 * u] | (row[2 * u + 1] << 8));
  }
  return depth;
}

PinholeIntrinsics realsense_d435_intrinsics(int width, int height) {
  PinholeIntrinsics k;
  k.width = width;
  k.height = height;
  if (width == 848 && height == 480) {
    k.fx = k.fy = 425.0;
  } else if (width == 640 && height == 480) {
    k.fx = k.fy = 383.0;
  } else if (width == 1280 && height == 720) {
    k.fx = k.fy = 640.0;
  } else {
    throw Error("no RealSense D435 default intrinsics for " + std::to_string(width) + "x" +
                std::to_string(height) +
                " (known: 848x480, 640x480, 1280x720); set intrinsics in the config");
  }
  k.cx = 0.5 * width;
  k.cy = 0.5 * height;
  k.depth_scale = 0.001;
  k.min_range = 0.3;
  k.max_range = 10.0;
  k.max_depth_jump = kStereoMaxDepthJump;
  k.smoothing_radius = kStereoSmoothingRadius;
  return k;
}

// The device's stream while connected; each step of connecting throws ConnectFailure naming `where`, and the
// destructor releases whatever the steps so far acquired.
struct V4l2Source::Stream {
  int fd = -1;
  struct Buffer {
    void* start = MAP_FAILED;
    std::size_t length = 0;
  };
  std::vector<Buffer> buffers;
  std::size_t bytes_per_line = 0;
  bool streaming = false;

  void open(const std::string& device, const std::string& where);
  void set_z16_format(const DepthMode& mode, const std::string& where);
  void set_frame_rate(double fps);
  void map_buffers(int count, const std::string& where);
  void start(const std::string& where);

  ~Stream() {
    if (streaming) {
      v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      xioctl(fd, VIDIOC_STREAMOFF, &type);
    }
    for (Buffer& buffer : buffers) {
      if (buffer.start != MAP_FAILED) v4l2_munmap(buffer.start, buffer.length);
    }
    if (!buffers.empty()) {
      v4l2_requestbuffers request{};
      request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      request.memory = V4L2_MEMORY_MMAP;
      xioctl(fd, VIDIOC_REQBUFS, &request);  // count 0 frees the driver's buffers
    }
    if (fd >= 0) v4l2_close(fd);
  }
};

V4l2Source::V4l2Source(V4l2Config config) : config_(std::move(config)), reconnector_(config_.reconnect) {
  if (config_.mode.format != "Z16") {
    throw Error("v4l2 " + config_.device + ": format must be Z16, got '" + config_.mode.format + "'");
  }
  if (config_.buffers < 2 || config_.buffers > 32)
    throw Error("v4l2 " + config_.device + ": buffers must be 2..32");
  intrinsics_ = config_.intrinsics ? *config_.intrinsics
                                   : realsense_d435_intrinsics(config_.mode.width, config_.mode.height);
  if (intrinsics_.width != config_.mode.width || intrinsics_.height != config_.mode.height) {
    throw Error("v4l2 " + config_.device + ": intrinsics size differs from the mode " +
                config_.mode.to_string());
  }
  intrinsics_.validate();
}

V4l2Source::~V4l2Source() {
  release();
}

void V4l2Source::release() {
  stream_.reset();
}

void V4l2Source::Stream::open(const std::string& device, const std::string& where) {
  const int raw = ::open(device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (raw < 0) {
    const int error = errno;
    fail_connect(true, where + ": cannot open: " + std::strerror(error));
  }
  if (!is_capture_device(raw)) {
    ::close(raw);
    fail_connect(false, where + ": not a streaming video capture device");
  }
  fd = v4l2_fd_open(raw, 0);
  if (fd < 0) {
    const int error = errno;
    ::close(raw);
    fail_connect(true, where + ": libv4l2 cannot use it: " + std::strerror(error));
  }
}

void V4l2Source::Stream::set_z16_format(const DepthMode& mode, const std::string& where) {
  v4l2_format format{};
  format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  format.fmt.pix.width = static_cast<std::uint32_t>(mode.width);
  format.fmt.pix.height = static_cast<std::uint32_t>(mode.height);
  format.fmt.pix.pixelformat = V4L2_PIX_FMT_Z16;
  format.fmt.pix.field = V4L2_FIELD_NONE;
  if (xioctl(fd, VIDIOC_S_FMT, &format) != 0 || format.fmt.pix.pixelformat != V4L2_PIX_FMT_Z16 ||
      static_cast<int>(format.fmt.pix.width) != mode.width ||
      static_cast<int>(format.fmt.pix.height) != mode.height) {
    fail_connect(false, where + ": refused format " + mode.to_string() + ", gave " +
                            std::to_string(format.fmt.pix.width) + "x" +
                            std::to_string(format.fmt.pix.height) + " " +
                            fourcc_to_string(format.fmt.pix.pixelformat));
  }
  bytes_per_line = std::max<std::size_t>(format.fmt.pix.bytesperline, 2u * format.fmt.pix.width);
}

void V4l2Source::Stream::set_frame_rate(double fps) {
  if (fps <= 0) return;
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  parm.parm.capture.timeperframe.numerator = 1000;
  parm.parm.capture.timeperframe.denominator = static_cast<std::uint32_t>(std::lround(fps * 1000));
  xioctl(fd, VIDIOC_S_PARM, &parm);  // drivers without rate control keep their one rate
}

void V4l2Source::Stream::map_buffers(int count, const std::string& where) {
  v4l2_requestbuffers request{};
  request.count = static_cast<std::uint32_t>(count);
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (xioctl(fd, VIDIOC_REQBUFS, &request) != 0 || request.count < 2) {
    const int error = errno;
    fail_connect(true, where + ": cannot get mmap buffers: " + std::strerror(error));
  }
  buffers.resize(request.count);
  for (std::uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    buffer.index = i;
    if (xioctl(fd, VIDIOC_QUERYBUF, &buffer) != 0) {
      fail_connect(true, where + ": cannot query buffer " + std::to_string(i));
    }
    buffers[i].length = buffer.length;
    buffers[i].start =
        v4l2_mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, buffer.m.offset);
    if (buffers[i].start == MAP_FAILED || xioctl(fd, VIDIOC_QBUF, &buffer) != 0) {
      const int error = errno;
      fail_connect(true, where + ": cannot map buffer " + std::to_string(i) + ": " + std::strerror(error));
    }
  }
}

void V4l2Source::Stream::start(const std::string& where) {
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(fd, VIDIOC_STREAMON, &type) != 0) {
    const int error = errno;
    fail_connect(true, where + ": cannot start streaming: " + std::strerror(error));
  }
  streaming = true;
}

void V4l2Source::connect(double now) {
  release();
  ++attempts_;
  const std::string where = "v4l2 " + config_.device;
  auto stream = std::make_unique<Stream>();
  try {
    stream->open(config_.device, where);
    DepthMode chosen;
    try {
      chosen = choose_depth_mode(enumerate_modes(stream->fd), config_.mode, where);
    } catch (const Error& e) {
      fail_connect(false, e.what());
    }
    stream->set_z16_format(chosen, where);
    stream->set_frame_rate(chosen.fps);
    stream->map_buffers(config_.buffers, where);
    stream->start(where);
  } catch (const ConnectFailure& failure) {
    if (failure.retry) {
      reconnector_.lost(now, failure.reason);
    } else {
      reconnector_.failed(failure.reason);
    }
    return;
  }
  stream_ = std::move(stream);
  reconnector_.connected(now);
}

SourceStatus V4l2Source::open() {
  connect(steady_seconds());
  return status();
}

std::optional<Frame> V4l2Source::next(std::chrono::milliseconds timeout) {
  const SourceState state = reconnector_.state();
  if (state == SourceState::kError || state == SourceState::kClosed) return std::nullopt;
  if (state == SourceState::kDisconnected) {
    reconnector_.retry_or_wait(timeout, [this](double now) { connect(now); });
    return std::nullopt;
  }
  pollfd ready{stream_->fd, POLLIN, 0};
  const int polled = ::poll(&ready, 1, static_cast<int>(timeout.count()));
  if (polled <= 0 || (ready.revents & (POLLERR | POLLHUP))) {
    if (polled > 0) {
      reconnector_.lost(steady_seconds(), "v4l2 " + config_.device + ": device went away");
      release();
    } else if (reconnector_.check(steady_seconds())) {
      release();
    }
    return std::nullopt;
  }
  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  if (xioctl(stream_->fd, VIDIOC_DQBUF, &buffer) != 0) {
    const int error = errno;
    if (error != EAGAIN) {
      reconnector_.lost(steady_seconds(), "v4l2 " + config_.device + ": " + std::strerror(error));
      release();
    }
    return std::nullopt;
  }
  const double host_realtime = realtime_seconds();
  Frame frame;
  frame.sensor = config_.name;
  const double driver_time = static_cast<double>(buffer.timestamp.tv_sec) + buffer.timestamp.tv_usec * 1e-6;
  if ((buffer.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC && driver_time > 0) {
    frame.stamp = driver_time + (host_realtime - monotonic_seconds());
  } else {
    frame.stamp = host_realtime;
  }
  std::optional<Error> failure;
  try {
    DepthImage depth;
    depth.intrinsics = intrinsics_;
    const auto* data = static_cast<const std::uint8_t*>(stream_->buffers.at(buffer.index).start);
    depth.depth =
        decode_z16(data, buffer.bytesused, intrinsics_.width, intrinsics_.height, stream_->bytes_per_line);
    frame.points_S = depth_to_points(depth);
    frame.depth = std::move(depth);
  } catch (const Error& e) {
    failure = e;  // a short buffer (the driver dropped data): skip the frame, keep streaming
  } catch (const std::out_of_range&) {
    failure = Error("v4l2 " + config_.device + ": driver returned an unknown buffer index");
  }
  xioctl(stream_->fd, VIDIOC_QBUF, &buffer);
  if (failure) return std::nullopt;
  reconnector_.frame(steady_seconds());
  ++frames_;
  return frame;
}

SourceStatus V4l2Source::status() const {
  SourceStatus status;
  status.state = reconnector_.state();
  status.reason = reconnector_.reason();
  status.frames = frames_;
  status.attempts = attempts_;
  return status;
}

void V4l2Source::close() {
  release();
  reconnector_.closed();
}

std::vector<DepthDeviceInfo> list_v4l2_devices(const std::string& dev_dir) {
  std::vector<DepthDeviceInfo> devices;
  std::error_code error;
  std::vector<std::string> nodes;
  for (const auto& entry : std::filesystem::directory_iterator(dev_dir, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("video", 0) == 0) nodes.push_back(entry.path().string());
  }
  std::sort(nodes.begin(), nodes.end());
  for (const std::string& node : nodes) {
    const int raw_fd = ::open(node.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (raw_fd < 0) continue;
    DepthDeviceInfo info;
    info.driver = "v4l2";
    info.uri = node;
    if (!is_capture_device(raw_fd, &info.name)) {
      ::close(raw_fd);
      continue;
    }
    const int fd = v4l2_fd_open(raw_fd, 0);
    if (fd < 0) {
      ::close(raw_fd);
      continue;
    }
    for (const DepthMode& mode : enumerate_modes(fd)) {
      if (mode.format == "Z16") info.modes.push_back(mode);
    }
    v4l2_close(fd);
    if (!info.modes.empty()) devices.push_back(std::move(info));
  }
  return devices;
}

}  // namespace cellmap
