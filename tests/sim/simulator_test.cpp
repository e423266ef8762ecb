// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/simulator.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/sim/default_scene.hpp"
#include "cellmap/sim/recording.hpp"
#include "cellmap/sweep/sweep.hpp"

namespace cellmap::sim {
namespace {

constexpr double kHalfUnit = 0.0005;  // half of the 1 mm depth unit: the quantization bound

int sensor_index(const Scene& scene, const std::string& model) {
  const int index = scene.find_sensor(model);
  EXPECT_GE(index, 0) << model;
  return index;
}

Eigen::Vector3d pixel_ray(const PinholeIntrinsics& k, std::size_t p) {
  const int u = static_cast<int>(p % static_cast<std::size_t>(k.width));
  const int v = static_cast<int>(p / static_cast<std::size_t>(k.width));
  return {(u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0};
}

double nearest_surface(const Scene& scene, const Eigen::Vector3d& p_C) {
  double best = INFINITY;
  for (const Obstacle& o : scene.obstacles) best = std::min(best, std::abs(o.signed_distance(p_C)));
  return best;
}

// σ(z) as docs/simulator.md's sensor table documents it, written out here rather than taken from the model under
// test: kinect_v2 1 mm + 0.5 mm·z², realsense_d435 z²·0.08 px/(fx·50 mm), os32c 2 mm.
double documented_sigma(SensorModel model, const PinholeIntrinsics& k, double z) {
  switch (model) {
    case SensorModel::kKinectV2:
      return 0.001 + 0.0005 * z * z;
    case SensorModel::kRealsenseD435:
      return z * z * 0.08 / (k.fx * 0.050);
    case SensorModel::kOs32c:
      return 0.002;
  }
  return NAN;
}

// The documented hard bound: σ truncated at 3σ, plus the stereo camera's waviness of 1.5σ.
double documented_bound(SensorModel model, const PinholeIntrinsics& k, double z) {
  const double waviness = model == SensorModel::kRealsenseD435 ? 1.5 : 0.0;
  return (3.0 + waviness) * documented_sigma(model, k, z);
}

std::filesystem::path temp_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("cellmap_sim_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(SimulatorTest, ZeroNoiseDepthIsTheExactSurfaceQuantizedToTheDepthUnit) {
  const Scene scene = without_depth_filter(default_scene());  // every valid pixel a point
  const Simulator simulator(scene, SimOptions{false, 2});
  const int cam = sensor_index(scene, "kinect_v2");
  const SimFrame f = simulator.render(cam, scene.sweep.stops[2], 0.0, 0, 0);
  ASSERT_TRUE(f.frame.depth.has_value());
  const PinholeIntrinsics& k = f.frame.depth->intrinsics;
  std::size_t valid = 0;
  for (std::size_t p = 0; p < f.exact.size(); ++p) {
    const std::uint16_t raw = f.frame.depth->depth[p];
    if (f.exact[p] <= 0) {
      EXPECT_EQ(raw, 0) << p;
      continue;
    }
    ++valid;
    // The raw value is the exact depth rounded to the millimetre, nothing else.
    ASSERT_EQ(raw, static_cast<std::uint16_t>(std::lround(f.exact[p] / k.depth_scale))) << p;
    // The exact point lies on the surface of the obstacle its ray hit (independent signed distance).
    const Eigen::Vector3d p_C = f.frame.X_CS * (pixel_ray(k, p) * f.exact[p]);
    const Obstacle& hit = scene.obstacles[static_cast<std::size_t>(f.hit[p])];
    ASSERT_NEAR(hit.signed_distance(p_C), 0.0, 1e-9) << p;
    // ... and it is the first surface: nothing solid between the sensor and it (2 cm march on every 97th
    // pixel; the thinnest obstacle is 5 cm thick).
    if (p % 97 == 0) {
      const Eigen::Vector3d d_C = (p_C - f.frame.X_CS.translation()).normalized();
      const double t_hit = (p_C - f.frame.X_CS.translation()).norm();
      for (double t = 0; t < t_hit - 0.01; t += 0.02) {
        const Eigen::Vector3d q_C = f.frame.X_CS.translation() + t * d_C;
        for (const Obstacle& o : scene.obstacles)
          ASSERT_GT(o.signed_distance(q_C), 0.0) << o.name << " " << p;
      }
    }
  }
  EXPECT_GT(valid, f.exact.size() * 9 / 10);
  // The frame's points (float, from the 16-bit image; valid pixels in row-major order) are on the true
  // surfaces within half a depth unit along their ray, plus float rounding.
  ASSERT_EQ(f.frame.points_S.size(), valid);
  std::size_t next = 0;
  for (std::size_t p = 0; p < f.exact.size(); ++p) {
    if (f.frame.depth->depth[p] == 0) continue;
    const Eigen::Vector3d p_S = f.frame.points_S[next++].getVector3fMap().cast<double>();
    const Eigen::Vector3d p_C = f.frame.X_CS * p_S;
    const double bound = kHalfUnit * p_S.norm() / p_S.z() + 1e-5;
    ASSERT_LE(std::abs(scene.obstacles[static_cast<std::size_t>(f.hit[p])].signed_distance(p_C)), bound) << p;
    if (p % 11 == 0) {
      ASSERT_LE(nearest_surface(scene, p_C), bound) << p;  // whichever obstacle is nearest
    }
    ASSERT_TRUE(scene.cell.contains(p_C));
  }
}

class NoiseBoundTest : public ::testing::TestWithParam<std::string> {};

TEST_P(NoiseBoundTest, ModelsSigmaAndBoundAreTheDocumentedOnes) {
  const Scene scene = default_scene();
  const SensorSpec& spec = scene.sensors[static_cast<std::size_t>(sensor_index(scene, GetParam()))];
  const NoiseModel model = noise_model(spec.model, spec.intrinsics);
  for (const double z : {0.3, 1.0, 2.0, 4.5}) {
    EXPECT_NEAR(model.sigma(z), documented_sigma(spec.model, spec.intrinsics, z), 1e-15) << z;
    EXPECT_NEAR(model.bound(z), documented_bound(spec.model, spec.intrinsics, z), 1e-15) << z;
  }
}

TEST_P(NoiseBoundTest, PointsAwayFromEdgesLieWithinTheModelsBound) {
  const Scene scene = default_scene();
  const Simulator simulator(scene);
  const int index = sensor_index(scene, GetParam());
  const SensorSpec& spec = scene.sensors[static_cast<std::size_t>(index)];
  const SweepPlan& plan = scene.plan_for(spec);
  const SimFrame f = simulator.render(index, plan.stops[plan.stops.size() / 2], 0.0, 0, 3);
  const NoiseModel model = noise_model(spec.model, spec.intrinsics);

  // Measured depth (cameras) or range (scanner) per pixel/beam, 0 = none.
  std::vector<double> measured(f.exact.size(), 0.0);
  std::vector<bool> near_edge(f.exact.size(), false);
  if (spec.is_camera()) {
    for (std::size_t p = 0; p < measured.size(); ++p)
      measured[p] = f.frame.depth->depth[p] * spec.intrinsics.depth_scale;
    near_edge =
        near_depth_edge(model, f.exact, spec.intrinsics.width, spec.intrinsics.height, model.edge_radius());
  } else {
    EXPECT_FALSE(f.frame.depth.has_value());
    // Re-derive each beam's range from its point (beams are in the x-y plane, in angle order).
    std::size_t next = 0;
    for (std::size_t i = 0; i < f.exact.size() && next < f.frame.points_S.size(); ++i) {
      const pcl::PointXYZ& point = f.frame.points_S[next];
      EXPECT_EQ(point.z, 0.0f);
      const double angle = -spec.scanner.fov / 2 + spec.scanner.fov * i / (spec.scanner.beams - 1);
      if (std::abs(std::atan2(point.y, point.x) - angle) < 1e-4) {
        measured[i] = std::hypot(point.x, point.y);
        ++next;
      }
    }
    EXPECT_EQ(next, f.frame.points_S.size());
  }

  std::size_t checked = 0, beyond_bound_at_edges = 0;
  double normalized_variance = 0;
  for (std::size_t p = 0; p < f.exact.size(); ++p) {
    if (f.exact[p] <= 0 || measured[p] <= 0) continue;
    const double error = measured[p] - f.exact[p];
    const double bound = documented_bound(spec.model, spec.intrinsics, f.exact[p]) + kHalfUnit + 1e-6;
    if (near_edge[p]) {
      beyond_bound_at_edges += std::abs(error) > bound;
      continue;
    }
    ASSERT_LE(std::abs(error), bound) << GetParam() << " pixel " << p << " z " << f.exact[p];
    const double sigma = documented_sigma(spec.model, spec.intrinsics, f.exact[p]);
    normalized_variance += error * error / (sigma * sigma);
    ++checked;
  }
  ASSERT_GT(checked, spec.is_camera() ? 1000u : 100u);
  normalized_variance /= checked;
  // The noise is really there, at the model's size (white σ², plus the waviness for the stereo camera).
  EXPECT_GT(normalized_variance, 0.7) << GetParam();
  EXPECT_LT(normalized_variance, 1.6) << GetParam();
  if (spec.model == SensorModel::kOs32c) {
    EXPECT_EQ(model.edge_radius(), 0);  // sharp edges: no pixel is exempt from the bound
  } else {
    EXPECT_GT(beyond_bound_at_edges, 10u) << "flying pixels / smeared edges expected at depth edges";
  }
}

INSTANTIATE_TEST_SUITE_P(Models, NoiseBoundTest, ::testing::Values("kinect_v2", "realsense_d435", "os32c"));

TEST(SimulatorTest, SameSeedSameFramesWhateverTheThreadCount) {
  const Scene scene = default_scene();
  const int cam = sensor_index(scene, "realsense_d435");
  const Eigen::VectorXd q = scene.sweep.stops[1];
  const Simulator one(scene, SimOptions{true, 1});
  const Simulator two(scene, SimOptions{true, 2});
  const SimFrame a = one.render(cam, q, 0.0, 4, 1);
  EXPECT_EQ(a.frame.depth->depth, two.render(cam, q, 0.0, 4, 1).frame.depth->depth);
  EXPECT_NE(a.frame.depth->depth,
            two.render(cam, q, 0.0, 5, 1).frame.depth->depth);  // next sweep: fresh noise
  Scene reseeded = scene;
  reseeded.sensors[static_cast<std::size_t>(cam)].seed += 1;
  EXPECT_NE(a.frame.depth->depth, Simulator(reseeded).render(cam, q, 0.0, 4, 1).frame.depth->depth);
}

TEST(SimulatorTest, EquidistantStopsMergeIntoOneCloudInsideTheCell) {
  const Scene scene = default_scene();
  const Simulator simulator(scene);
  const int cam = sensor_index(scene, "kinect_v2");
  const std::vector<SimFrame> frames = simulator.sweep(cam, 0, 10.0);
  ASSERT_EQ(frames.size(), scene.sweep.stops.size());
  std::vector<Frame> plain;
  std::size_t total = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_DOUBLE_EQ(frames[k].frame.stamp, 10.0 + k * scene.sweep.period);
    if (k >= 2) {
      const Eigen::Vector3d step1 =
          frames[k].frame.X_CS.translation() - frames[k - 1].frame.X_CS.translation();
      const Eigen::Vector3d step0 =
          frames[k - 1].frame.X_CS.translation() - frames[k - 2].frame.X_CS.translation();
      EXPECT_TRUE(step1.isApprox(step0, 1e-12));  // equidistant stops
      EXPECT_GT(step1.norm(), 0.1);
    }
    total += frames[k].frame.points_S.size();
    plain.push_back(frames[k].frame);
  }
  const Sweep sweep = merge_frames(plain);
  EXPECT_DOUBLE_EQ(sweep.stamp, frames.back().frame.stamp);
  ASSERT_EQ(sweep.scans.size(), frames.size());
  EXPECT_EQ(sweep.point_count(), total);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_TRUE(sweep.scans[k].origin_C.isApprox(frames[k].frame.X_CS.translation()));
  }
  const Cloud merged = sweep.merged();
  EXPECT_EQ(merged.size(), total);
  for (const pcl::PointXYZ& p : merged) {
    ASSERT_TRUE(scene.cell.contains(p.getVector3fMap().cast<double>(), 1e-5));
  }
  // Neighbouring frames overlap: the table top seen from two stops is the same surface (noise bound apart).
  EXPECT_GT(total, 5u * 40000u);
}

TEST(SimulatorTest, SceneEditChangesExactlyThePointsOfTheEditedObstacle) {
  const Scene scene = default_scene();
  Simulator simulator(scene);
  const int cam = sensor_index(scene, "kinect_v2");
  const NoiseModel model = noise_model(SensorModel::kKinectV2);
  const PinholeIntrinsics& k = scene.sensors[static_cast<std::size_t>(cam)].intrinsics;
  const int carton = scene.find_obstacle("carton");
  const int stack = scene.find_obstacle("stack_3");
  const std::vector<SimFrame> before = simulator.sweep(cam);

  // Move the carton 15 cm along x and raise it 5 cm; remove the top box of the stack.
  const Eigen::Vector3d moved =
      scene.obstacles[static_cast<std::size_t>(carton)].X_CO.translation() + Eigen::Vector3d(0.15, 0.0, 0.05);
  simulator.apply(transport::SceneEdit::move("carton", moved));
  simulator.apply(transport::SceneEdit::remove("stack_3"));
  const std::vector<SimFrame> after = simulator.sweep(cam);  // same seed, same sweep index
  const int carton_after = simulator.scene().find_obstacle("carton");

  std::size_t changed = 0, on_edited = 0;
  for (std::size_t f = 0; f < before.size(); ++f) {
    // The pixels whose exact surface changed, widened by the model's edge reach (flying pixels look at their
    // neighbours): only these may change.
    std::vector<double> differs(before[f].exact.size(), 0.0);
    for (std::size_t p = 0; p < differs.size(); ++p) {
      const bool edited_before = before[f].hit[p] == carton || before[f].hit[p] == stack;
      const bool edited_after = after[f].hit[p] == carton_after;
      if (before[f].exact[p] != after[f].exact[p]) {
        EXPECT_TRUE(edited_before || edited_after)
            << "pixel " << p << " changed depth but saw no edited obstacle";
        differs[p] = 1.0;
      }
      on_edited += edited_before || edited_after;
    }
    std::vector<bool> may_change(differs.size(), false);
    for (std::size_t p = 0; p < differs.size(); ++p) may_change[p] = differs[p] > 0;
    // Dilate by the edge radius + 1 (Chebyshev).
    const int r = model.edge_radius() + 1;
    std::vector<bool> wide = may_change;
    for (int v = 0; v < k.height; ++v) {
      for (int u = 0; u < k.width; ++u) {
        if (!may_change[static_cast<std::size_t>(v * k.width + u)]) continue;
        for (int dv = -r; dv <= r; ++dv) {
          for (int du = -r; du <= r; ++du) {
            const int nu = u + du, nv = v + dv;
            if (nu >= 0 && nv >= 0 && nu < k.width && nv < k.height)
              wide[static_cast<std::size_t>(nv * k.width + nu)] = true;
          }
        }
      }
    }
    // Edge pixels may keep their value (a flying pixel mixes the same neighbourhood before and after).
    const std::vector<bool> edge_before = near_depth_edge(model, before[f].exact, k.width, k.height, 1);
    const std::vector<bool> edge_after = near_depth_edge(model, after[f].exact, k.width, k.height, 1);
    for (std::size_t p = 0; p < differs.size(); ++p) {
      const std::uint16_t a = before[f].frame.depth->depth[p], b = after[f].frame.depth->depth[p];
      if (a != b) {
        ++changed;
        ASSERT_TRUE(wide[p]) << "frame " << f << " pixel " << p << " changed away from the edited obstacles";
      }
      // Where the true surface moved by much more than the noise, the measurement moved too.
      const double jump = std::abs(before[f].exact[p] - after[f].exact[p]);
      if (!edge_before[p] && !edge_after[p] && before[f].exact[p] > 0 && after[f].exact[p] > 0 &&
          jump > 2 * model.bound(2.0) + 0.002) {
        EXPECT_NE(a, b) << "frame " << f << " pixel " << p;
      }
    }
  }
  EXPECT_GT(on_edited, 1000u);
  EXPECT_GT(changed, 500u);
}

TEST(RecordingTest, FramesFileRoundTrips) {
  const Scene scene = default_scene();
  const Simulator simulator(scene);
  const int cam = sensor_index(scene, "kinect_v2");
  const std::vector<SimFrame> frames = simulator.sweep(cam, 2, 1.25);
  const std::filesystem::path dir = temp_dir("poses");
  std::vector<PoseRecord> records;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    records.push_back(PoseRecord{k, frames[k].frame.sensor, frames[k].frame.stamp,
                                 "frames/" + std::to_string(k) + ".png", frames[k].frame.X_CS, frames[k].q});
  }
  write_poses(dir / "poses.csv", records, scene.robot.joint_names());
  const std::vector<PoseRecord> read = read_poses(dir / "poses.csv");
  ASSERT_EQ(read.size(), records.size());
  for (std::size_t k = 0; k < read.size(); ++k) {
    EXPECT_EQ(read[k].frame, records[k].frame);
    EXPECT_EQ(read[k].sensor, records[k].sensor);
    EXPECT_EQ(read[k].stamp, records[k].stamp);  // 17 significant digits: the same double
    EXPECT_EQ(read[k].file, records[k].file);
    EXPECT_EQ(read[k].q, records[k].q);
    EXPECT_TRUE(read[k].X_CS.isApprox(records[k].X_CS, 1e-14));
  }

  std::string text = "frame,sensor,stamp,file,x,y,z,qw,qx,qy,qz,q:x\n0,cam,0,f.png,1,2,3,1,0,0,0,zero\n";
  write_file_atomically(dir / "bad.csv", text);
  try {
    (void)read_poses(dir / "bad.csv");
    ADD_FAILURE() << "a malformed poses file was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              (dir / "bad.csv").string() + ": line 2: q:x: 'zero' is not a finite number");
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace cellmap::sim
