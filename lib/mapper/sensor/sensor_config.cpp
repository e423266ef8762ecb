// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sensor/sensor_config.hpp"

#include <vector>

#include "cellmap/common/error.hpp"

namespace cellmap {

namespace {

DepthMode read_mode(YamlMap& map, const DepthMode& fallback) {
  DepthMode mode = fallback;
  mode.width = static_cast<int>(map.integer("width", fallback.width, 1, 100000));
  mode.height = static_cast<int>(map.integer("height", fallback.height, 1, 100000));
  mode.fps = map.number("fps", fallback.fps, 0, 10000);
  return mode;
}

ReconnectParams read_reconnect(YamlMap& map) {
  ReconnectParams policy;
  policy.frame_timeout = map.number("frame_timeout", policy.frame_timeout, 1e-3, 3600);
  YamlMap reconnect = map.child("reconnect");
  policy.initial_backoff = reconnect.number("initial_backoff", policy.initial_backoff, 1e-3, 3600);
  policy.max_backoff = reconnect.number("max_backoff", policy.max_backoff, policy.initial_backoff, 3600);
  reconnect.expect_all_read();
  return policy;
}

// Pinhole parameters from a config map; the size comes from the mode.
PinholeIntrinsics read_intrinsics(YamlMap map, const DepthMode& mode, bool with_depth_scale) {
  PinholeIntrinsics k;
  k.width = mode.width;
  k.height = mode.height;
  k.fx = map.require<double>("fx");
  k.fy = map.require<double>("fy");
  k.cx = map.require<double>("cx");
  k.cy = map.require<double>("cy");
  if (with_depth_scale) k.depth_scale = map.number("depth_scale", 0.001, 1e-9, 1.0);
  if (!(k.fx > 0)) map.fail("fx", "must be > 0");
  if (!(k.fy > 0)) map.fail("fy", "must be > 0");
  map.expect_all_read();
  return k;
}

}  // namespace

OpenNI2Config read_openni2_config(YamlMap settings, const std::string& name) {
  OpenNI2Config openni2;
  openni2.name = name;
  openni2.uri = settings.get<std::string>("uri", "");
  openni2.mode = read_mode(settings, openni2.mode);
  openni2.mode.format = settings.get<std::string>("format", openni2.mode.format);
  if (openni2.mode.format != "DEPTH_1_MM" && openni2.mode.format != "DEPTH_100_UM") {
    settings.fail("format", "must be DEPTH_1_MM or DEPTH_100_UM");
  }
  if (settings.has("intrinsics"))
    openni2.intrinsics = read_intrinsics(settings.child("intrinsics"), openni2.mode, false);
  openni2.min_range = settings.number("min_range", openni2.min_range, 0, 1000);
  openni2.max_range = settings.number("max_range", openni2.max_range, openni2.min_range + 1e-6, 1000);
  openni2.max_depth_jump = settings.number("max_depth_jump", openni2.max_depth_jump, 0, 10);
  openni2.smoothing_radius = static_cast<int>(
      settings.integer("smoothing_radius", openni2.smoothing_radius, 0, kMaxSmoothingRadius));
  openni2.realtime_playback = settings.get<bool>("realtime_playback", true);
  openni2.reconnect = read_reconnect(settings);
  settings.expect_all_read();
  return openni2;
}

V4l2Config read_v4l2_config(YamlMap settings, const std::string& name) {
  V4l2Config v4l2;
  v4l2.name = name;
  v4l2.device = settings.get<std::string>("device", v4l2.device);
  v4l2.mode = read_mode(settings, v4l2.mode);
  PinholeIntrinsics k;
  if (settings.has("intrinsics")) {
    k = read_intrinsics(settings.child("intrinsics"), v4l2.mode, true);
  } else {
    try {
      k = realsense_d435_intrinsics(v4l2.mode.width, v4l2.mode.height);
    } catch (const Error& e) {
      settings.fail("intrinsics", e.what());
    }
  }
  k.min_range = settings.number("min_range", 0.3, 0, 1000);
  k.max_range = settings.number("max_range", 10.0, k.min_range + 1e-6, 1000);
  k.max_depth_jump = settings.number("max_depth_jump", kStereoMaxDepthJump, 0, 10);
  k.smoothing_radius =
      static_cast<int>(settings.integer("smoothing_radius", kStereoSmoothingRadius, 0, kMaxSmoothingRadius));
  v4l2.intrinsics = k;
  v4l2.buffers = static_cast<int>(settings.integer("buffers", v4l2.buffers, 2, 32));
  v4l2.reconnect = read_reconnect(settings);
  settings.expect_all_read();
  return v4l2;
}

ReplayConfig read_replay_config(YamlMap settings, const std::string& name) {
  ReplayConfig replay;
  replay.name = name;
  replay.directory = settings.get<std::string>("directory", "");
  const std::string playback = settings.get<std::string>("playback", "recorded");
  if (playback == "recorded") {
    replay.playback = ReplayConfig::Playback::kRecorded;
  } else if (playback == "fixed") {
    replay.playback = ReplayConfig::Playback::kFixed;
  } else if (playback == "fastest") {
    replay.playback = ReplayConfig::Playback::kFastest;
  } else {
    settings.fail("playback", "must be recorded, fixed or fastest, got '" + playback + "'");
  }
  replay.speed = settings.number("speed", replay.speed, 1e-3, 1000);
  replay.rate_hz = settings.number("rate_hz", replay.rate_hz, 1e-3, 10000);
  settings.expect_all_read();
  return replay;
}

SensorConfig read_sensor_config(YamlMap& map, const std::string& name) {
  SensorConfig config;
  config.name = name;
  const std::string source = map.require<std::string>("source");
  config.X_ES = map.pose("X_ES");
  config.pose_tolerance = map.number("pose_tolerance", config.pose_tolerance, 1e-6, 10.0);
  if (source == "openni2") {
    config.source = read_openni2_config(map.child("openni2"), name);
  } else if (source == "v4l2") {
    config.source = read_v4l2_config(map.child("v4l2"), name);
  } else if (source == "replay") {
    YamlMap settings = map.child("replay");
    const ReplayConfig replay = read_replay_config(settings, name);
    if (replay.directory.empty()) (void)settings.require<std::string>("directory");  // names the key
    config.source = replay;
  } else {
    map.fail("source", "must be openni2, v4l2 or replay, got '" + source + "'");
  }
  map.expect_all_read();
  return config;
}

std::unique_ptr<DepthSource> make_depth_source(const SensorConfig& config) {
  if (const auto* openni2 = std::get_if<OpenNI2Config>(&config.source))
    return std::make_unique<OpenNI2Source>(*openni2);
  if (const auto* v4l2 = std::get_if<V4l2Config>(&config.source)) return std::make_unique<V4l2Source>(*v4l2);
  return std::make_unique<ReplaySource>(std::get<ReplayConfig>(config.source));
}

}  // namespace cellmap
