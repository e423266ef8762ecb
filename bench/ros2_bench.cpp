// SPDX-License-Identifier: Apache-2.0
// cellmap bench ros2: ROS 2 sensor input read straight off DDS (lib/ros2), against its own anchor.
//
// 1. Conversion (Google Benchmark, the ratio lines): sensor_msgs/msg/PointCloud2 bytes to points, ours
//    (ros2::to_points) against what a ROS user's node does with the same bytes: pcl::fromPCLPointCloud2
//    into pcl::PointCloud<pcl::PointXYZ>, then pcl::removeNaNFromPointCloud in place. The anchor's
//    pcl::PCLPointCloud2 is built once, outside the timing (pcl_conversions::toPCL would copy the data into
//    it for every message). Both keep the points whose x, y and z are finite, in row order; the program
//    checks once that both give the same points and stops if not. Two layouts:
//    - an organized 848 × 480 cloud of a RealSense D435, NaN for pixels without depth: x, y, z FLOAT32 at
//      0/4/8, rgb FLOAT32 at 16, point_step 32, as depth_image_proc's point_cloud_xyzrgb publishes it from
//      the camera's depth and colour images (sensor_msgs' setPointCloud2FieldsByString(2, "xyz", "rgb") pads
//      x, y, z to 16 bytes and rgb to 16). realsense-ros's own point cloud filter puts rgb at 16 with
//      point_step 20, and with ordered_pc marks pixels without depth (0, 0, 0) instead of NaN; --point-step
//      20 gives the cloud that layout, 16 x, y, z and rgb packed (rgb at 12), both still with NaN;
//    - a 128 × 1024 3D lidar, NaN where a beam saw nothing: x, y, z, intensity FLOAT32 at 0/4/8/16, ring
//      UINT16 at 20, timestamp FLOAT64 at 24, point_step 32 (a PCL point type of PCL_ADD_POINT4D, intensity,
//      ring and a double timestamp as pcl::toROSMsg lays it out, as several lidar drivers publish).
//
// 2. Input at camera rate through Cyclone DDS (printed after the benchmarks): a writer publishes the 848 ×
//    480 cloud at --rate Hz for --seconds, each with a fresh header.stamp in frame "camera", into
//    make_point_cloud2_source, driven by a thread of its own as cellmapd's camera thread drives it (open(),
//    then next(100 ms) in a loop). The writer runs in a child process, as a ROS 2 driver does, so that its
//    samples cross loopback UDP: two participants of one process share Cyclone's domain instance, which
//    hands their samples over in memory; that variant is run too. Per variant: frames sent, received,
//    dropped (sent - received), the rate achieved, the receiving thread's CPU per frame received (DDS take
//    and conversion) and the conversion alone (the same thread converting the same cloud afterwards), the
//    delivery latency (header.stamp to next() returning the frame), the CPU of this process's other
//    threads (Cyclone's) per frame sent, the UDP datagrams the kernel dropped for a full socket receive
//    buffer (the network namespace's count, /proc/net/snmp), loopback bytes per frame and the receive buffer
//    Cyclone's sockets got. Run it in a network namespace of its own for counts that are its own.
#include <benchmark/benchmark.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>
#include <pcl/filters/filter.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cellmap/common/error.hpp"
#include "cellmap/common/wall_clock.hpp"
#include "cellmap/ros2/point_cloud2.hpp"
#include "cellmap/ros2/sensor_sources.hpp"
#include "cellmap/ros2/topics.hpp"
#include "cellmap/ros2/type_hash.hpp"
#include "ratio_report.hpp"
#include "sensor_msgs/msg/PointCloud2.h"
#include "subscriber_arrivals.hpp"

namespace {

using namespace cellmap;
using Clock = std::chrono::steady_clock;

constexpr auto kFloat32 = static_cast<std::uint8_t>(ros2::PointFieldType::kFloat32);
constexpr auto kFloat64 = static_cast<std::uint8_t>(ros2::PointFieldType::kFloat64);
constexpr auto kUint16 = static_cast<std::uint8_t>(ros2::PointFieldType::kUint16);
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr const char* kTopic = "/camera/depth/points";
constexpr const char* kFrameId = "camera";

// --- clouds as drivers send them ----------------------------------------------------------------------

/// A sensor_msgs/msg/PointCloud2 body whose bytes it owns (little-endian, rows without padding).
struct CloudBytes {
  std::uint32_t height = 0;
  std::uint32_t width = 0;
  std::uint32_t point_step = 0;
  std::vector<ros2::PointField> fields;
  std::vector<std::uint8_t> data;

  CloudBytes(std::uint32_t rows, std::uint32_t columns, std::uint32_t step, std::vector<ros2::PointField> f)
      : height(rows),
        width(columns),
        point_step(step),
        fields(std::move(f)),
        data(std::size_t{rows} * columns * step) {}

  [[nodiscard]] std::uint32_t row_step() const { return width * point_step; }
  [[nodiscard]] std::size_t points() const { return std::size_t{width} * height; }
  template <typename T>
  void put(std::size_t point, std::uint32_t offset, T value) {
    std::memcpy(data.data() + point * point_step + offset, &value, sizeof(T));
  }
  /// As a received sample is read: the data borrowed.
  [[nodiscard]] ros2::PointCloud2View view() const {
    return {height, width, fields, false, point_step, row_step(), data.data(), data.size()};
  }
  /// The same fields, step and bytes as PCL's message type (what pcl_conversions::toPCL makes of it).
  [[nodiscard]] pcl::PCLPointCloud2 pcl() const {
    pcl::PCLPointCloud2 msg;
    msg.height = height;
    msg.width = width;
    for (const ros2::PointField& f : fields) {
      pcl::PCLPointField field;
      field.name = f.name;
      field.offset = f.offset;
      field.datatype = f.datatype;
      field.count = f.count;
      msg.fields.push_back(field);
    }
    msg.is_bigendian = false;
    msg.point_step = point_step;
    msg.row_step = row_step();
    msg.data = data;
    msg.is_dense = false;
    return msg;
  }
  /// Share of the points without a return (x is NaN).
  [[nodiscard]] double invalid_share() const {
    std::size_t invalid = 0;
    for (std::size_t i = 0; i < points(); ++i) {
      float x;
      std::memcpy(&x, data.data() + i * point_step, sizeof x);
      invalid += std::isnan(x) ? 1 : 0;
    }
    return static_cast<double>(invalid) / static_cast<double>(points());
  }
};

// The D435's 848 × 480 depth mode as bench/native_modes.hpp gives it (fx = fy = 430 px), its stereo baseline
// and its depth unit.
constexpr int kCameraWidth = 848;
constexpr int kCameraHeight = 480;
constexpr double kFx = 430.0, kCx = 423.5, kCy = 239.5;
constexpr double kBaseline = 0.050;   // m
constexpr double kDepthUnit = 0.001;  // m

// An axis-aligned box in the cell frame (x right, y forward, z up).
struct Solid {
  double lo[3];
  double hi[3];
};

// Distance along `d` (from `o`) to the box, or infinity.
double hit(const Solid& s, const double o[3], const double d[3]) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (o[k] < s.lo[k] || o[k] > s.hi[k]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double a = (s.lo[k] - o[k]) / d[k], b = (s.hi[k] - o[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 <= t1 && t0 > 0.0 ? t0 : std::numeric_limits<double>::infinity();
}

/// The organized 848 × 480 cloud of a D435 1.2 m above a floor, pitched 35° down: the floor, a wall 4.5 m
/// ahead, a table and two crates; stereo noise growing with z², depths in whole millimetres. Pixels without
/// depth are NaN where a D435 gives none: the band at the image's left edge that only the left imager sees,
/// the shadows its right imager cannot see left of a nearer surface's edge, a dark mat on the floor and
/// scattered small holes (together about 10 %). rgb holds a colour. Deterministic.
CloudBytes camera_cloud(std::uint32_t point_step) {
  const std::uint32_t rgb_offset = point_step >= 20 ? 16 : 12;
  CloudBytes c(kCameraHeight, kCameraWidth, point_step,
               {{"x", 0, kFloat32, 1},
                {"y", 4, kFloat32, 1},
                {"z", 8, kFloat32, 1},
                {"rgb", rgb_offset, kFloat32, 1}});
  const double pitch = 35.0 * M_PI / 180.0, height = 1.2;
  const double origin[3] = {0.0, 0.0, height};
  const std::vector<Solid> solids = {
      {{-2.5, 4.5, 0.0}, {2.5, 4.7, 3.0}},   // the wall
      {{-0.9, 1.6, 0.0}, {0.1, 2.4, 0.75}},  // a table
      {{0.4, 1.5, 0.0}, {0.8, 1.9, 0.45}},   // a crate
      {{-0.3, 2.8, 0.0}, {0.5, 3.3, 0.9}},   // a bigger one behind the table
  };
  const Solid dark_mat{{0.9, 0.7, -0.01}, {1.5, 1.3, 0.01}};  // black rubber: no texture, no depth
  std::mt19937 random(848480);
  std::normal_distribution<double> unit_noise(0.0, 1.0);
  std::vector<double> depth(c.points(), 0.0);  // 0: no depth
  for (int v = 0; v < kCameraHeight; ++v) {
    for (int u = 0; u < kCameraWidth; ++u) {
      // Optical ray (x right, y down, z ahead) in the cell frame: the camera's z pitched down.
      const double rx = (u - kCx) / kFx, ry = (v - kCy) / kFx;
      const double d[3] = {rx, std::cos(pitch) - ry * std::sin(pitch),
                           -std::sin(pitch) - ry * std::cos(pitch)};
      double t = d[2] < 0.0 ? -height / d[2] : std::numeric_limits<double>::infinity();  // the floor
      bool on_mat = false;
      if (std::isfinite(t)) {
        const double x = origin[0] + t * d[0], y = origin[1] + t * d[1];
        on_mat = x > dark_mat.lo[0] && x < dark_mat.hi[0] && y > dark_mat.lo[1] && y < dark_mat.hi[1];
      }
      for (const Solid& s : solids) {
        const double ts = hit(s, origin, d);
        if (ts < t) {
          t = ts;
          on_mat = false;
        }
      }
      if (!std::isfinite(t) || t > 10.0 || on_mat) continue;
      const double z = t;                                     // the optical ray has unit z, so t is the depth
      const double sigma = 0.08 * z * z / (kFx * kBaseline);  // 0.08 px subpixel disparity noise
      depth[std::size_t(v) * kCameraWidth + u] =
          std::round((z + sigma * unit_noise(random)) / kDepthUnit) * kDepthUnit;
    }
  }
  std::vector<char> invalid(c.points(), 0);
  for (int v = 0; v < kCameraHeight; ++v) {
    double* row = &depth[std::size_t(v) * kCameraWidth];
    for (int u = 0; u < kCameraWidth; ++u) {
      // Left of a nearer surface's edge, the right imager sees behind it: fx·B·(1/z_near − 1/z_far) pixels.
      if (u > 0 && row[u] > 0.0 && row[u - 1] > row[u] + 0.05) {
        const int shadow = static_cast<int>(kFx * kBaseline * (1.0 / row[u] - 1.0 / row[u - 1]));
        for (int k = 1; k <= shadow && u - k >= 0; ++k) invalid[std::size_t(v) * kCameraWidth + u - k] = 1;
      }
      // The left edge's band that the right imager does not see: fx·B / z pixels.
      if (row[u] > 0.0 && u < kFx * kBaseline / row[u]) invalid[std::size_t(v) * kCameraWidth + u] = 1;
    }
  }
  std::uniform_int_distribution<int> pixel(0, kCameraWidth * kCameraHeight - 1), size(1, 4);
  for (int hole = 0; hole < 2500; ++hole) {  // small holes where matching failed
    const int at = pixel(random), w = size(random), h = size(random);
    for (int dv = 0; dv < h; ++dv)
      for (int du = 0; du < w; ++du) {
        const int u = at % kCameraWidth + du, v = at / kCameraWidth + dv;
        if (u < kCameraWidth && v < kCameraHeight) invalid[std::size_t(v) * kCameraWidth + u] = 1;
      }
  }
  for (int v = 0; v < kCameraHeight; ++v) {
    for (int u = 0; u < kCameraWidth; ++u) {
      const std::size_t i = std::size_t(v) * kCameraWidth + u;
      const double z = depth[i];
      const bool valid = z > 0.0 && !invalid[i];
      c.put<float>(i, 0, valid ? static_cast<float>((u - kCx) * z / kFx) : kNaN);
      c.put<float>(i, 4, valid ? static_cast<float>((v - kCy) * z / kFx) : kNaN);
      c.put<float>(i, 8, valid ? static_cast<float>(z) : kNaN);
      const std::uint32_t rgb =
          0x808080u + static_cast<std::uint32_t>(u % 64) * 0x010000u + (v % 64) * 0x0100u;
      c.put<std::uint32_t>(i, rgb_offset, rgb);  // the float's bits, as drivers pack it
    }
  }
  return c;
}

/// The organized 128 × 1024 cloud of a 3D lidar (45° vertical field of view, 10 Hz) 1 m above the floor of a
/// 24 × 16 m hall with 3 m walls and no roof within range: beams above the walls see nothing (NaN), as do
/// 2 % of the others (dark or glancing surfaces). Deterministic.
CloudBytes lidar_cloud() {
  constexpr std::uint32_t kRings = 128, kColumns = 1024;
  CloudBytes c(kRings, kColumns, 32,
               {{"x", 0, kFloat32, 1},
                {"y", 4, kFloat32, 1},
                {"z", 8, kFloat32, 1},
                {"intensity", 16, kFloat32, 1},
                {"ring", 20, kUint16, 1},
                {"timestamp", 24, kFloat64, 1}});
  const double origin[3] = {0.0, 0.0, 1.0};
  const std::vector<Solid> walls = {{{-12.0, -8.2, 0.0}, {12.0, -8.0, 3.0}},
                                    {{-12.0, 8.0, 0.0}, {12.0, 8.2, 3.0}},
                                    {{-12.2, -8.0, 0.0}, {-12.0, 8.0, 3.0}},
                                    {{12.0, -8.0, 0.0}, {12.2, 8.0, 3.0}},
                                    {{2.0, 1.0, 0.0}, {3.0, 2.5, 1.6}}};  // a machine
  std::mt19937 random(1281024);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double scan_start = 1.7e9;
  for (std::uint32_t ring = 0; ring < kRings; ++ring) {
    const double elevation = (22.5 - 45.0 * ring / (kRings - 1)) * M_PI / 180.0;  // ring 0 looks up
    for (std::uint32_t column = 0; column < kColumns; ++column) {
      const double azimuth = 2.0 * M_PI * column / kColumns;
      const double d[3] = {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                           std::sin(elevation)};
      double t = d[2] < 0.0 ? -origin[2] / d[2] : std::numeric_limits<double>::infinity();
      for (const Solid& s : walls) t = std::min(t, hit(s, origin, d));
      const bool valid = std::isfinite(t) && t < 100.0 && unit(random) > 0.02;
      const std::size_t i = std::size_t{ring} * kColumns + column;
      c.put<float>(i, 0, valid ? static_cast<float>(t * d[0]) : kNaN);
      c.put<float>(i, 4, valid ? static_cast<float>(t * d[1]) : kNaN);
      c.put<float>(i, 8, valid ? static_cast<float>(t * d[2]) : kNaN);
      c.put<float>(i, 16, valid ? static_cast<float>(100.0 / (1.0 + t)) : 0.0f);
      c.put<std::uint16_t>(i, 20, static_cast<std::uint16_t>(ring));
      c.put<double>(i, 24, scan_start + 0.1 * column / kColumns);
    }
  }
  return c;
}

// --- conversion: ours against PCL ---------------------------------------------------------------------

/// What a ROS user's node does with a received cloud: PCL's conversion, then NaN points removed in place.
Cloud pcl_valid_points(const pcl::PCLPointCloud2& msg) {
  Cloud cloud;
  pcl::fromPCLPointCloud2(msg, cloud);
  pcl::Indices kept;
  pcl::removeNaNFromPointCloud(cloud, cloud, kept);
  return cloud;
}

struct Layout {
  std::string name;  // as in the benchmark names and ratio lines
  CloudBytes cloud;
  pcl::PCLPointCloud2 pcl;
};

std::map<std::string, Layout>& layouts() {
  static std::map<std::string, Layout> by_name;
  return by_name;
}

void BM_Ros2ToPoints(benchmark::State& state, const std::string& name) {
  const Layout& layout = layouts().at(name);
  const ros2::PointCloud2View view = layout.cloud.view();
  std::size_t points = 0;
  for (auto _ : state) {
    const Cloud cloud = ros2::to_points(view);
    points = cloud.size();
    benchmark::DoNotOptimize(cloud.points.data());
  }
  state.counters["points_out"] = static_cast<double>(points);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * layout.cloud.data.size()));
}

void BM_PclFromPCLPointCloud2(benchmark::State& state, const std::string& name) {
  const Layout& layout = layouts().at(name);
  std::size_t points = 0;
  for (auto _ : state) {
    const Cloud cloud = pcl_valid_points(layout.pcl);
    points = cloud.size();
    benchmark::DoNotOptimize(cloud.points.data());
  }
  state.counters["points_out"] = static_cast<double>(points);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * layout.cloud.data.size()));
}

// Both conversions must give the same points, bit for bit, in the same order: a ratio of different
// results would mean nothing.
void check_same_points(const Layout& layout) {
  const Cloud ours = ros2::to_points(layout.cloud.view());
  const Cloud anchor = pcl_valid_points(layout.pcl);
  bool same = ours.size() == anchor.size();
  for (std::size_t i = 0; same && i < ours.size(); ++i)
    same = std::memcmp(ours[i].data, anchor[i].data, 3 * sizeof(float)) == 0;
  if (!same) {
    std::fprintf(stderr, "cellmap-bench-ros2: %s: ros2::to_points gives %zu points, PCL %zu, not the same\n",
                 layout.name.c_str(), ours.size(), anchor.size());
    std::exit(2);
  }
  std::printf("%s: %u x %u, point_step %u, %.1f %% without a return; both give the same %zu points\n",
              layout.name.c_str(), layout.cloud.width, layout.cloud.height, layout.cloud.point_step,
              100.0 * layout.cloud.invalid_share(), ours.size());
}

// --- input at camera rate -----------------------------------------------------------------------------

struct InputOptions {
  double seconds = 10.0;
  double rate = 30.0;
  std::uint32_t domain = 145;
  std::uint32_t point_step = 32;
  std::string socket_receive_buffer;  // Cyclone's Internal/SocketReceiveBufferSize@min; empty: its default
  std::string max_message_size;       // Cyclone's General/MaxMessageSize (and FragmentSize); empty: default
};

/// The loopback-only configuration of the DDS benchmarks with the options' Cyclone settings.
std::string cyclone_config(const InputOptions& options) {
  std::string config = bench::kLoopbackConfig;
  std::string extra;
  if (!options.max_message_size.empty()) {
    extra += "<General><MaxMessageSize>" + options.max_message_size + "</MaxMessageSize><FragmentSize>" +
             options.max_message_size + "</FragmentSize></General>";
  }
  if (!options.socket_receive_buffer.empty())
    extra += "<Internal><SocketReceiveBufferSize min=\"" + options.socket_receive_buffer + "\"/></Internal>";
  config.insert(config.find("</Domain>"), extra);
  return config;
}

/// What a writer of clouds reports when it is done.
struct WriterReport {
  std::uint64_t sent = 0;
  std::uint64_t refused = 0;  // writes that failed (a reliable writer's history full for 1 s)
  std::int64_t cpu_ns = 0;    // the writing thread's CPU
};

std::int64_t thread_cpu_ns() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec;
}

std::int64_t process_cpu_ns() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec;
}

/// A ROS 2 driver's publisher: `cloud` on kTopic at `rate` Hz for `seconds`, each sample stamped now, once
/// a reader matched (up to 20 s). Reliable: ROS's default QoS (KEEP_LAST 10); best effort: SensorDataQoS
/// (KEEP_LAST 5).
WriterReport publish_clouds(const dds::Participant& participant, const CloudBytes& cloud, bool reliable,
                            double seconds, double rate) {
  const dds::Topic topic(participant, &sensor_msgs_msg_dds__PointCloud2__desc, ros2::dds_topic(kTopic));
  dds::Qos qos = dds::Qos::make(false, reliable ? 10 : 5);
  if (!reliable) qos.best_effort();
  qos.user_data(ros2::type_hash_user_data("sensor_msgs/msg/PointCloud2"));
  const dds::Writer writer(participant, topic, qos);
  WriterReport report;
  if (!writer.wait_for_readers(1, std::chrono::seconds(20))) return report;

  std::vector<sensor_msgs_msg_dds__PointField_> fields;
  for (const ros2::PointField& f : cloud.fields)
    fields.push_back({const_cast<char*>(f.name.c_str()), f.offset, f.datatype, f.count});
  sensor_msgs_msg_dds__PointCloud2_ msg{};
  msg.header.frame_id = const_cast<char*>(kFrameId);
  msg.height = cloud.height;
  msg.width = cloud.width;
  msg.fields = {static_cast<std::uint32_t>(fields.size()), static_cast<std::uint32_t>(fields.size()),
                fields.data(), false};
  msg.point_step = cloud.point_step;
  msg.row_step = cloud.row_step();
  msg.data = {static_cast<std::uint32_t>(cloud.data.size()), static_cast<std::uint32_t>(cloud.data.size()),
              const_cast<std::uint8_t*>(cloud.data.data()), false};
  msg.is_dense = false;

  const std::int64_t cpu_start = thread_cpu_ns();
  const auto start = Clock::now();
  const auto frames = static_cast<std::uint64_t>(std::llround(seconds * rate));
  for (std::uint64_t i = 0; i < frames; ++i) {
    std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>(static_cast<double>(i) / rate)));
    const std::int64_t now = wall_clock_ns();
    msg.header.stamp = {static_cast<std::int32_t>(now / 1'000'000'000),
                        static_cast<std::uint32_t>(now % 1'000'000'000)};
    try {
      writer.write(&msg);
      ++report.sent;
    } catch (const Error&) {
      ++report.refused;
    }
  }
  if (reliable) (void)writer.wait_for_acks(std::chrono::seconds(5));
  report.cpu_ns = thread_cpu_ns() - cpu_start;
  return report;
}

// The child process's side: publishes, then reports to the parent through stdout.
int run_publisher(char** argv) {
  const auto domain = static_cast<std::uint32_t>(std::stoul(argv[2]));
  const bool reliable = std::strcmp(argv[3], "reliable") == 0;
  const double seconds = std::stod(argv[4]), rate = std::stod(argv[5]);
  const auto point_step = static_cast<std::uint32_t>(std::stoul(argv[6]));
  const CloudBytes cloud = camera_cloud(point_step);
  const dds::Participant participant(domain);
  const WriterReport report = publish_clouds(participant, cloud, reliable, seconds, rate);
  if (::write(STDOUT_FILENO, &report, sizeof report) != sizeof report) return 3;
  return 0;
}

/// One way of feeding the source.
struct Variant {
  const char* label;
  bool writer_reliable;
  ros2::Reliability reader;
  bool writer_in_process;
};

// Counters of the network namespace and of this process's sockets, read before and after a run.
std::uint64_t udp_receive_buffer_errors() {
  std::ifstream in("/proc/net/snmp");
  std::string line, header;
  while (std::getline(in, line)) {
    if (line.rfind("Udp:", 0) != 0) continue;
    if (header.empty()) {
      header = line;
      continue;
    }
    std::istringstream names(header), values(line);
    std::string name, value;
    while (names >> name && values >> value)
      if (name == "RcvbufErrors") return std::stoull(value);
  }
  return 0;
}

// Bytes through the loopback interface of this network namespace (/proc/net/dev follows the namespace,
// /sys/class/net only the one sysfs was mounted in).
std::uint64_t loopback_bytes() {
  std::ifstream in("/proc/net/dev");
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::istringstream name_field(line.substr(0, colon)), fields(line.substr(colon + 1));
    std::string name;
    name_field >> name;
    if (name != "lo") continue;
    std::uint64_t received = 0;
    fields >> received;
    return received;
  }
  return 0;
}

// The largest receive buffer of this process's UDP sockets (Cyclone's), as the kernel reports it: twice
// what was asked, its bookkeeping included.
int largest_udp_receive_buffer() {
  int largest = 0;
  for (int fd = 0; fd < 1024; ++fd) {
    int type = 0, size = 0;
    socklen_t length = sizeof type;
    if (::getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &length) != 0 || type != SOCK_DGRAM) continue;
    length = sizeof size;
    if (::getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size, &length) == 0) largest = std::max(largest, size);
  }
  return largest;
}

struct InputResult {
  WriterReport writer;
  bool writer_done = false;
  std::uint64_t received = 0;
  std::uint64_t refused = 0;
  double rate = 0.0;               // frames received per second, first to last
  double receive_cpu_ms = 0.0;     // the camera thread, per frame received
  double conversion_cpu_ms = 0.0;  // ros2::to_points of the same cloud on that thread
  double cyclone_cpu_ms = 0.0;     // this process's other threads, per frame sent
  double latency_p50_ms = 0.0, latency_max_ms = 0.0;
  std::uint64_t udp_drops = 0;
  double loopback_mb_per_frame = 0.0;
  int receive_buffer = 0;
};

// The camera thread of cellmapd, reduced to what it costs: open(), then next(100 ms) until told to stop;
// afterwards the conversion alone, on the same thread.
class CameraThread {
 public:
  CameraThread(DepthSource& source, const CloudBytes& cloud) : source_(source), cloud_(cloud) {
    thread_ = std::thread([this] { run(); });
  }
  ~CameraThread() { stop(); }
  CameraThread(const CameraThread&) = delete;
  CameraThread& operator=(const CameraThread&) = delete;

  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  [[nodiscard]] std::uint64_t frames() const { return frames_; }
  [[nodiscard]] Clock::time_point last_frame() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return last_;
  }
  /// After stop().
  void fill(InputResult& result) const {
    result.received = frames_;
    const double frames = static_cast<double>(std::max<std::uint64_t>(frames_, 1));
    result.receive_cpu_ms = static_cast<double>(receive_cpu_ns_) / 1e6 / frames;
    result.conversion_cpu_ms = conversion_cpu_ms_;
    if (frames_ > 1)
      result.rate = static_cast<double>(frames_ - 1) / std::chrono::duration<double>(last_ - first_).count();
    std::vector<double> latencies = latencies_ms_;
    std::sort(latencies.begin(), latencies.end());
    if (!latencies.empty()) {
      result.latency_p50_ms = latencies[latencies.size() / 2];
      result.latency_max_ms = latencies.back();
    }
  }
  [[nodiscard]] std::int64_t receive_cpu_ns() const { return receive_cpu_ns_; }

 private:
  void run() {
    const std::int64_t start = thread_cpu_ns();
    (void)source_.open();
    while (!stop_) {
      const std::optional<Frame> frame = source_.next(std::chrono::milliseconds(100));
      if (!frame) continue;
      const auto now = Clock::now();
      latencies_ms_.push_back((static_cast<double>(wall_clock_ns()) * 1e-9 - frame->stamp) * 1e3);
      const std::lock_guard<std::mutex> lock(mutex_);
      if (frames_ == 0) first_ = now;
      last_ = now;
      ++frames_;
    }
    receive_cpu_ns_ = thread_cpu_ns() - start;
    constexpr int kConversions = 10;
    const ros2::PointCloud2View view = cloud_.view();
    const std::int64_t conversion_start = thread_cpu_ns();
    for (int i = 0; i < kConversions; ++i) benchmark::DoNotOptimize(ros2::to_points(view).size());
    conversion_cpu_ms_ = static_cast<double>(thread_cpu_ns() - conversion_start) / 1e6 / kConversions;
  }

  DepthSource& source_;
  const CloudBytes& cloud_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> frames_{0};
  mutable std::mutex mutex_;
  Clock::time_point first_, last_;
  std::vector<double> latencies_ms_;
  std::int64_t receive_cpu_ns_ = 0;
  double conversion_cpu_ms_ = 0.0;
  std::thread thread_;
};

InputResult run_input(const Variant& variant, const InputOptions& options, const CloudBytes& cloud) {
  InputResult result;
  const dds::Participant daemon(options.domain);
  std::atomic<std::uint64_t> refused{0};
  ros2::TopicInput input;
  input.topic = kTopic;
  input.frame_id = kFrameId;
  input.reliability = variant.reader;
  std::unique_ptr<DepthSource> source =
      ros2::make_point_cloud2_source(daemon, "camera", input, [&](const std::string& line) {
        if (refused++ == 0) std::fprintf(stderr, "cellmap-bench-ros2: refused: %s\n", line.c_str());
      });

  const std::int64_t cpu_start = process_cpu_ns();
  const std::uint64_t drops_start = udp_receive_buffer_errors(), loopback_start = loopback_bytes();
  CameraThread camera(*source, cloud);
  const double patience = options.seconds + 40.0;  // discovery, the stream, a reliable writer's last acks
  if (variant.writer_in_process) {
    // Its own participant, on the same domain: Cyclone delivers to the reader in memory.
    const dds::Participant driver(options.domain);
    result.writer = publish_clouds(driver, cloud, variant.writer_reliable, options.seconds, options.rate);
    result.writer_done = true;
  } else {
    bench::ReportingChild child({"cellmap-bench-ros2", "--publisher", std::to_string(options.domain),
                                 variant.writer_reliable ? "reliable" : "best_effort",
                                 std::to_string(options.seconds), std::to_string(options.rate),
                                 std::to_string(options.point_step)});
    pollfd p{child.in_fd(), POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(patience * 1000)) > 0 &&
        ::read(child.in_fd(), &result.writer, sizeof result.writer) == sizeof result.writer)
      result.writer_done = true;
  }
  result.receive_buffer = largest_udp_receive_buffer();
  // Frames still on their way: wait until all arrived or none came for a second.
  const auto done = Clock::now();
  while (camera.frames() < result.writer.sent &&
         Clock::now() - std::max(done, camera.last_frame()) < std::chrono::seconds(1))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::int64_t cpu = process_cpu_ns() - cpu_start;
  result.udp_drops = udp_receive_buffer_errors() - drops_start;
  const std::uint64_t loopback = loopback_bytes() - loopback_start;
  camera.stop();
  camera.fill(result);
  result.refused = refused;
  const std::int64_t writer_cpu = variant.writer_in_process ? result.writer.cpu_ns : 0;
  // Per frame sent: Cyclone's receiving threads handle the datagrams of frames that never arrive too.
  const double sent = static_cast<double>(std::max<std::uint64_t>(result.writer.sent, 1));
  result.cyclone_cpu_ms = static_cast<double>(cpu - camera.receive_cpu_ns() - writer_cpu) / 1e6 / sent;
  result.loopback_mb_per_frame = static_cast<double>(loopback) / 1e6 / sent;
  return result;
}

int run_inputs(const InputOptions& options) {
  const CloudBytes cloud = camera_cloud(options.point_step);
  const Variant variants[] = {
      {"best_effort", false, ros2::Reliability::kBestEffort, false},
      {"reliable writer, best_effort reader", true, ros2::Reliability::kBestEffort, false},
      {"reliable", true, ros2::Reliability::kReliable, false},
      {"best_effort, writer in this process", false, ros2::Reliability::kBestEffort, true},
  };
  std::printf("ros2 input: %u x %u, point_step %u, %.1f MB a sample; Cyclone DDS: %s\n", cloud.width,
              cloud.height, cloud.point_step, static_cast<double>(cloud.data.size()) / 1e6,
              std::getenv("CYCLONEDDS_URI"));
  int status = 0;
  for (const Variant& variant : variants) {
    InputResult r;
    try {
      r = run_input(variant, options, cloud);
    } catch (const Error& e) {
      std::printf("ros2 input %ux%u @%g Hz (%s): failed: %s\n", cloud.width, cloud.height, options.rate,
                  variant.label, e.what());
      status = 1;
      continue;
    }
    if (!r.writer_done || r.writer.sent == 0) status = 1;
    const std::uint64_t dropped = r.writer.sent > r.received ? r.writer.sent - r.received : 0;
    char cpu[32] = "-";  // no frame, no CPU per frame
    if (r.received > 0) std::snprintf(cpu, sizeof cpu, "%.2f", r.receive_cpu_ms);
    std::printf(
        "ros2 input %ux%u @%g Hz (%s): %llu sent, %llu received, %llu dropped, %.1f Hz achieved, CPU %s "
        "ms/frame (conversion %.2f ms)%s\n",
        cloud.width, cloud.height, options.rate, variant.label,
        static_cast<unsigned long long>(r.writer.sent), static_cast<unsigned long long>(r.received),
        static_cast<unsigned long long>(dropped), r.rate, cpu, r.conversion_cpu_ms,
        r.writer_done ? "" : " (the writer never reported)");
    std::printf(
        "  latency stamp -> next() p50 %.1f ms, max %.1f ms; Cyclone's threads here %.2f ms CPU/frame sent; "
        "UDP datagrams dropped for a full receive buffer %llu; loopback %.1f MB/frame",
        r.latency_p50_ms, r.latency_max_ms, r.cyclone_cpu_ms, static_cast<unsigned long long>(r.udp_drops),
        r.loopback_mb_per_frame);
    if (r.receive_buffer > 0) std::printf("; socket receive buffer %.1f MiB", r.receive_buffer / 1048576.0);
    if (r.writer.refused > 0)
      std::printf("; %llu writes failed", static_cast<unsigned long long>(r.writer.refused));
    if (r.refused > 0) std::printf("; %llu samples refused", static_cast<unsigned long long>(r.refused));
    std::printf("\n");
    std::fflush(stdout);
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 7 && std::strcmp(argv[1], "--publisher") == 0) {
    try {
      return run_publisher(argv);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "cellmap-bench-ros2 publisher: %s\n", e.what());
      return 1;
    }
  }
  InputOptions options;
  CLI::App app("cellmap-bench-ros2: PointCloud2 conversion against PCL, then input at camera rate over DDS");
  app.add_option("--seconds", options.seconds, "seconds of clouds published per input variant")
      ->check(CLI::Range(0.1, 3600.0));
  app.add_option("--rate", options.rate, "clouds per second")->check(CLI::Range(0.1, 1000.0));
  app.add_option("--domain", options.domain, "DDS domain of the input runs")->check(CLI::Range(0, 232));
  app.add_option("--point-step", options.point_step, "point_step of the 848x480 camera cloud: 32, 20 or 16")
      ->check(CLI::IsMember({32u, 20u, 16u}));
  app.add_option(
      "--socket-receive-buffer", options.socket_receive_buffer,
      "Cyclone's Internal/SocketReceiveBufferSize min, e.g. 8MiB (default: Cyclone's, 1 MiB asked)");
  app.add_option(
      "--max-message-size", options.max_message_size,
      "Cyclone's General/MaxMessageSize and FragmentSize, e.g. 65000B (default 14720 B and 1344 B)");
  app.allow_extras();  // --benchmark_* flags go to Google Benchmark
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  std::vector<std::string> rest = app.remaining();
  for (const std::string& flag : rest) {
    if (flag.rfind("--benchmark_", 0) != 0) {
      std::fprintf(stderr, "cellmap-bench-ros2: unknown option %s\n", flag.c_str());
      return 2;
    }
  }
  // Explicit Cyclone settings replace the caller's configuration; otherwise the caller's is kept.
  const bool configured = !options.socket_receive_buffer.empty() || !options.max_message_size.empty();
  ::setenv("CYCLONEDDS_URI", cyclone_config(options).c_str(), configured ? 1 : 0);

  layouts().emplace("848x480", Layout{"848x480", camera_cloud(options.point_step), {}});
  layouts().emplace("lidar", Layout{"lidar", lidar_cloud(), {}});
  std::vector<bench::Ratio> ratios;
  for (auto& [name, layout] : layouts()) {
    layout.pcl = layout.cloud.pcl();
    check_same_points(layout);
    const std::string ours = "BM_Ros2ToPoints/" + name, anchor = "BM_PclFromPCLPointCloud2/" + name;
    benchmark::RegisterBenchmark(ours.c_str(), BM_Ros2ToPoints, name)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(anchor.c_str(), BM_PclFromPCLPointCloud2, name)
        ->Unit(benchmark::kMillisecond);
    ratios.push_back({"ros2 pointcloud2 " + name, ours, anchor});
  }
  std::vector<char*> benchmark_argv{argv[0]};
  for (std::string& flag : rest) benchmark_argv.push_back(flag.data());
  int benchmark_argc = static_cast<int>(benchmark_argv.size());
  benchmark_argv.push_back(nullptr);
  const int status = bench::run_and_report(benchmark_argc, benchmark_argv.data(), ratios);
  const int input_status = run_inputs(options);
  return status != 0 ? status : input_status;
}
