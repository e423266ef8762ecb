// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sensor/openni2_source.hpp"

#include <OpenNI.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <optional>
#include <thread>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

// OpenNI2's extended error text, on one line ("\tDeviceOpen using default: no devices found\n").
std::string openni_error() {
  std::string text = openni::OpenNI::getExtendedError();
  for (char& c : text) {
    if (c == '\n' || c == '\t' || c == '\r') c = ' ';
  }
  const auto first = text.find_first_not_of(' ');
  if (first == std::string::npos) return "unknown error";
  return text.substr(first, text.find_last_not_of(' ') - first + 1);
}

std::string format_name(openni::PixelFormat format) {
  switch (format) {
    case openni::PIXEL_FORMAT_DEPTH_1_MM:
      return "DEPTH_1_MM";
    case openni::PIXEL_FORMAT_DEPTH_100_UM:
      return "DEPTH_100_UM";
    case openni::PIXEL_FORMAT_SHIFT_9_2:
      return "SHIFT_9_2";
    case openni::PIXEL_FORMAT_SHIFT_9_3:
      return "SHIFT_9_3";
    default:
      return "FORMAT_" + std::to_string(static_cast<int>(format));
  }
}

DepthMode to_mode(const openni::VideoMode& mode) {
  return DepthMode{mode.getResolutionX(), mode.getResolutionY(), static_cast<double>(mode.getFps()),
                   format_name(mode.getPixelFormat())};
}

std::vector<DepthMode> depth_modes(const openni::VideoStream& stream) {
  std::vector<DepthMode> modes;
  const openni::Array<openni::VideoMode>& offered = stream.getSensorInfo().getSupportedVideoModes();
  for (int i = 0; i < offered.getSize(); ++i) modes.push_back(to_mode(offered[i]));
  return modes;
}

bool is_oni_file(const std::string& uri) {
  const std::string ext = std::filesystem::path(uri).extension().string();
  return ext == ".oni" || ext == ".ONI";
}

// Initialises OpenNI2 once per process and never shuts it down. OpenNI2's context is process-wide anyway, and
// OpenNI::shutdown() unloads the driver libraries while driver threads may still be winding down: Debian's
// DummyDevice driver does not join its frame thread, and a shutdown right after closing its stream crashed
// the process here (SIGSEGV in unmapped driver code). @throws Error with OpenNI2's reason (retried next
// call).
void ensure_openni() {
  static std::mutex mutex;
  static bool initialised = false;
  std::lock_guard<std::mutex> lock(mutex);
  if (initialised) return;
  if (openni::OpenNI::initialize() != openni::STATUS_OK)
    throw Error("openni2: cannot initialise: " + openni_error());
  initialised = true;
}

}  // namespace

PinholeIntrinsics intrinsics_from_fov(int width, int height, double hfov, double vfov) {
  if (width <= 0 || height <= 0) throw Error("intrinsics from field of view: image size must be positive");
  if (!(hfov > 0 && hfov < M_PI) || !(vfov > 0 && vfov < M_PI)) {
    throw Error("intrinsics from field of view: fields of view must be in (0, pi) rad, got " +
                std::to_string(hfov) + " and " + std::to_string(vfov));
  }
  PinholeIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = 0.5 * width / std::tan(0.5 * hfov);
  k.fy = 0.5 * height / std::tan(0.5 * vfov);
  k.cx = 0.5 * (width - 1);
  k.cy = 0.5 * (height - 1);
  return k;
}

struct OpenNI2Source::Device {
  openni::Device device;
  openni::VideoStream stream;
  int frame_count = -1;  // frames in an .oni file, -1 for live devices
  ~Device() {
    if (stream.isValid()) {
      stream.stop();
      // Some drivers' frame threads poll a stop flag and are never joined (Debian's DummyDevice checks it
      // every 33 ms); freeing the stream at once let such a thread run on freed memory and crash here. 50 ms
      // was not enough on a loaded machine under ASan (the thread was not scheduled in time); 200 ms on close
      // or reconnect is still cheap.
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    stream.destroy();
    device.close();
  }
};

OpenNI2Source::OpenNI2Source(OpenNI2Config config)
    : config_(std::move(config)), reconnector_(config_.reconnect) {
  const std::string& format = config_.mode.format;
  if (format != "DEPTH_1_MM" && format != "DEPTH_100_UM") {
    throw Error("openni2 " + config_.name + ": format must be DEPTH_1_MM or DEPTH_100_UM, got '" + format +
                "'");
  }
  if (config_.mode.width <= 0 || config_.mode.height <= 0 || config_.mode.fps < 0) {
    throw Error("openni2 " + config_.name + ": mode width and height must be positive, fps >= 0");
  }
  if (!(config_.min_range >= 0) || !(config_.max_range > config_.min_range)) {
    throw Error("openni2 " + config_.name + ": need 0 <= min_range < max_range");
  }
  if (config_.intrinsics && (config_.intrinsics->width != config_.mode.width ||
                             config_.intrinsics->height != config_.mode.height)) {
    throw Error("openni2 " + config_.name + ": intrinsics size differs from the mode " +
                config_.mode.to_string());
  }
}

OpenNI2Source::~OpenNI2Source() {
  release();
}

void OpenNI2Source::release() {
  device_.reset();
  clock_.reset();
}

namespace {

// Sets `chosen` on the stream unless it is already the offered mode; an error text, or empty.
std::string use_mode(openni::VideoStream& stream, const DepthMode& chosen) {
  if (to_mode(stream.getVideoMode()).to_string() == chosen.to_string()) return {};
  openni::VideoMode mode;
  mode.setResolution(chosen.width, chosen.height);
  mode.setFps(static_cast<int>(std::lround(chosen.fps)));
  mode.setPixelFormat(chosen.format == "DEPTH_1_MM" ? openni::PIXEL_FORMAT_DEPTH_1_MM
                                                    : openni::PIXEL_FORMAT_DEPTH_100_UM);
  if (stream.setVideoMode(mode) == openni::STATUS_OK) return {};
  return "cannot set mode " + chosen.to_string() + ": " + openni_error();
}

// The configured intrinsics, else those of the field of view the device reports, with the mode's depth
// scale and the configured ranges; nullopt (and `error`) when the device reports no field of view.
std::optional<PinholeIntrinsics> intrinsics_for(openni::VideoStream& stream, const DepthMode& chosen,
                                                const OpenNI2Config& config, std::string& error) {
  PinholeIntrinsics k;
  if (config.intrinsics) {
    k = *config.intrinsics;
  } else {
    const double hfov = stream.getHorizontalFieldOfView();
    const double vfov = stream.getVerticalFieldOfView();
    if (!(hfov > 0 && hfov < M_PI) || !(vfov > 0 && vfov < M_PI)) {
      error = "reports no field of view (" + std::to_string(hfov) + ", " + std::to_string(vfov) +
              " rad); set intrinsics in the config";
      return std::nullopt;
    }
    k = intrinsics_from_fov(chosen.width, chosen.height, hfov, vfov);
  }
  k.depth_scale = chosen.format == "DEPTH_1_MM" ? 0.001 : 0.0001;
  k.min_range = config.min_range;
  k.max_range = config.max_range;
  k.max_depth_jump = config.max_depth_jump;
  k.smoothing_radius = config.smoothing_radius;
  return k;
}

}  // namespace

void OpenNI2Source::connect(double now) {
  release();
  ++attempts_;
  const std::string device_name =
      "openni2 " + (config_.uri.empty() ? std::string("first device") : config_.uri);
  if (is_oni_file(config_.uri) && !std::filesystem::is_regular_file(config_.uri)) {
    reconnector_.failed(device_name + ": no such recording");
    return;
  }
  try {
    ensure_openni();
    auto device = std::make_unique<Device>();
    if (device->device.open(config_.uri.empty() ? openni::ANY_DEVICE : config_.uri.c_str()) !=
        openni::STATUS_OK) {
      reconnector_.lost(now, device_name + ": " + openni_error());
      return;
    }
    if (device->stream.create(device->device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
      reconnector_.lost(now, device_name + ": no depth stream: " + openni_error());
      return;
    }
    const DepthMode chosen = choose_depth_mode(depth_modes(device->stream), config_.mode, device_name);
    std::string error = use_mode(device->stream, chosen);
    const std::optional<PinholeIntrinsics> intrinsics =
        error.empty() ? intrinsics_for(device->stream, chosen, config_, error) : std::nullopt;
    if (!intrinsics) {
      reconnector_.failed(device_name + ": " + error);
      return;
    }
    intrinsics_ = *intrinsics;
    if (openni::PlaybackControl* playback = device->device.getPlaybackControl()) {
      playback->setRepeatEnabled(false);
      playback->setSpeed(config_.realtime_playback ? 1.0f : 0.0f);
      device->frame_count = playback->getNumberOfFrames(device->stream);
    }
    if (device->stream.start() != openni::STATUS_OK) {
      reconnector_.lost(now, device_name + ": cannot start the depth stream: " + openni_error());
      return;
    }
    device_ = std::move(device);
    ended_ = false;
    reconnector_.connected(now);
  } catch (const Error& e) {
    reconnector_.failed(
        e.what());  // no matching mode, or OpenNI2 itself cannot start: retrying will not help
  }
}

SourceStatus OpenNI2Source::open() {
  connect(steady_seconds());
  return status();
}

std::optional<Frame> OpenNI2Source::next(std::chrono::milliseconds timeout) {
  const SourceState state = reconnector_.state();
  if (ended_ || state == SourceState::kError || state == SourceState::kClosed) return std::nullopt;
  if (state == SourceState::kDisconnected) {
    reconnector_.retry_or_wait(timeout, [this](double now) { connect(now); });
    return std::nullopt;
  }
  openni::VideoStream* streams[] = {&device_->stream};
  int ready = -1;
  const auto waited_since = std::chrono::steady_clock::now();
  const openni::Status waited =
      openni::OpenNI::waitForAnyStream(streams, 1, &ready, static_cast<int>(timeout.count()));
  if (waited != openni::STATUS_OK) {
    // A failing device can return at once; wait out the timeout so callers never spin.
    if (waited != openni::STATUS_TIME_OUT) std::this_thread::sleep_until(waited_since + timeout);
    if (reconnector_.check(steady_seconds())) {
      if (device_->frame_count >= 0) {
        ended_ = true;  // an .oni file that stops delivering has been played to its end
      }
      release();
    }
    return std::nullopt;
  }
  openni::VideoFrameRef image;
  if (device_->stream.readFrame(&image) != openni::STATUS_OK || !image.isValid()) {
    return std::nullopt;
  }
  const double host_now = realtime_seconds();
  reconnector_.frame(steady_seconds());
  if (image.getWidth() != intrinsics_.width || image.getHeight() != intrinsics_.height) {
    reconnector_.failed("openni2 " + config_.name + ": frame is " + std::to_string(image.getWidth()) + "x" +
                        std::to_string(image.getHeight()) + ", expected " +
                        std::to_string(intrinsics_.width) + "x" + std::to_string(intrinsics_.height));
    release();
    return std::nullopt;
  }
  Frame frame;
  frame.sensor = config_.name;
  frame.stamp = clock_.to_host(image.getTimestamp(), host_now);
  DepthImage depth;
  depth.intrinsics = intrinsics_;
  depth.depth.resize(static_cast<std::size_t>(intrinsics_.width) * intrinsics_.height);
  const auto* bytes = static_cast<const std::uint8_t*>(image.getData());
  const std::size_t row_bytes = static_cast<std::size_t>(intrinsics_.width) * sizeof(std::uint16_t);
  for (int row = 0; row < intrinsics_.height; ++row) {
    std::memcpy(depth.depth.data() + static_cast<std::size_t>(row) * intrinsics_.width,
                bytes + static_cast<std::size_t>(row) * image.getStrideInBytes(), row_bytes);
  }
  frame.points_S = depth_to_points(depth);
  frame.depth = std::move(depth);
  ++frames_;
  if (device_->frame_count > 0 && image.getFrameIndex() >= device_->frame_count) {
    ended_ = true;  // last frame of an .oni file; OpenNI2 numbers them from 1
    release();
  }
  return frame;
}

SourceStatus OpenNI2Source::status() const {
  SourceStatus status;
  status.state = ended_ ? SourceState::kEnded : reconnector_.state();
  status.reason = ended_ ? config_.uri + ": end of recording" : reconnector_.reason();
  status.frames = frames_;
  status.attempts = attempts_;
  return status;
}

void OpenNI2Source::close() {
  release();
  reconnector_.closed();
  ended_ = false;
}

namespace {

// Opens `uri` and reads its depth modes; nullopt with `reason` set when it does not open.
std::string vendor_and_name(const char* vendor, const char* name) {
  const std::string a = vendor ? vendor : "";
  const std::string b = name ? name : "";
  return a.empty() ? b : b.empty() ? a : a + " " + b;
}

std::optional<DepthDeviceInfo> describe_device(const std::string& uri, std::string& reason) {
  openni::Device device;
  if (device.open(uri.c_str()) != openni::STATUS_OK) {
    reason = openni_error();
    return std::nullopt;
  }
  DepthDeviceInfo info;
  info.driver = "openni2";
  info.uri = uri;
  const openni::DeviceInfo& about = device.getDeviceInfo();
  info.name = vendor_and_name(about.getVendor(), about.getName());
  if (const openni::SensorInfo* sensor = device.getSensorInfo(openni::SENSOR_DEPTH)) {
    const openni::Array<openni::VideoMode>& modes = sensor->getSupportedVideoModes();
    for (int m = 0; m < modes.getSize(); ++m) info.modes.push_back(to_mode(modes[m]));
  }
  device.close();
  return info;
}

}  // namespace

std::vector<DepthDeviceInfo> list_openni2_devices() {
  ensure_openni();
  openni::Array<openni::DeviceInfo> found;
  openni::OpenNI::enumerateDevices(&found);
  std::vector<DepthDeviceInfo> devices;
  for (int i = 0; i < found.getSize(); ++i) {
    std::string reason;
    if (auto info = describe_device(found[i].getUri(), reason)) {
      devices.push_back(std::move(*info));
    } else {
      // Listed by the driver but busy or gone: still show it, without modes.
      DepthDeviceInfo listed;
      listed.driver = "openni2";
      listed.uri = found[i].getUri();
      listed.name =
          std::string(found[i].getVendor()) + " " + found[i].getName() + " (cannot open: " + reason + ")";
      devices.push_back(std::move(listed));
    }
  }
  return devices;
}

DepthDeviceInfo probe_openni2_device(const std::string& uri) {
  if (is_oni_file(uri) && !std::filesystem::is_regular_file(uri))
    throw Error("openni2 " + uri + ": no such recording");
  ensure_openni();
  std::string reason;
  std::optional<DepthDeviceInfo> info = describe_device(uri, reason);
  if (!info) throw Error("openni2 " + uri + ": " + reason);
  return std::move(*info);
}

}  // namespace cellmap
