// SPDX-License-Identifier: Apache-2.0
// cellmapd in a working cell, as a real process on loopback DDS: the simulated arm cell (the arm moving all
// the time, noise on), its frames self filtered with the robot posed from the controller's joint samples.
// Short runs here; CELLMAP_LONG_TESTS=1 runs the documented lengths (500 sweeps).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "cellmap/sim/scene.hpp"
#include "daemon/robot_surface.hpp"
#include "daemon/service_e2e.hpp"
#include "support/dds_domains.hpp"

namespace cellmap {
namespace {

using namespace std::chrono_literals;

const std::string kArmScene = CELLMAP_SOURCE_DIR "/config/scenes/arm_cell.yaml";
// The arm cell's sensors as config/arm-cell.yaml has them.
const std::string kPost = "{kind: sim, scene: " + kArmScene + ", sensor: post, no_return_range: 4.5}";
const std::string kWrist = "{kind: sim, scene: " + kArmScene + ", sensor: wrist}";

bool long_tests() {
  const char* value = std::getenv("CELLMAP_LONG_TESTS");
  return value != nullptr && std::string(value) == "1";
}

// Every environment a subscriber received.
class VersionLog {
 public:
  void operator()(const Environment& env, const EnvironmentDelta&) {
    std::lock_guard<std::mutex> lock(mutex_);
    versions_.push_back(env);
  }
  [[nodiscard]] std::vector<Environment> versions() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return versions_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Environment> versions_;
};

// cellmapd on `yaml` (cell "arm"; a `change` section of its own replaces the gathering below) until it
// processed `sweeps` sweeps, in a state directory of its own; every version it published meanwhile.
class WorkingCellE2eTest : public ::testing::Test {
 protected:
  std::vector<Environment> run_daemon(const std::string& yaml, int domain, std::uint64_t sweeps) {
    test::use_loopback();
    const std::filesystem::path config = dir_.path() / "cellmapd.yaml";
    // The box kind and the change gathering of config/arm-cell.yaml.
    std::ofstream(config)
        << "cell: arm\nsweep_period: 0\nstatus_period: 0.5\nsegment: {boxes: {kind: aabb}}\n"
        << (yaml.find("change:") == std::string::npos ? "change: {gather_sweeps: 2}\n" : "") << yaml;
    const dds::Participant participant(static_cast<std::uint32_t>(domain));
    VersionLog log;
    transport::EnvironmentSubscriber planner(participant, "arm", std::ref(log));
    transport::StatusReader status(participant);
    test::ChildProcess daemon({CELLMAPD, "--config", config.string(), "--domain", std::to_string(domain),
                               "--state-dir", (dir_.path() / ("state-" + std::to_string(domain))).string()});
    const auto patience = std::chrono::seconds(60 + sweeps * 2);
    const auto deadline = std::chrono::steady_clock::now() + patience;
    std::uint64_t processed = 0;
    while (processed < sweeps && std::chrono::steady_clock::now() < deadline && daemon.running()) {
      for (const transport::CellStatus& s : status.take(200ms)) {
        if (s.cell == "arm") processed = std::max(processed, s.sweeps);
      }
    }
    EXPECT_GE(processed, sweeps) << "cellmapd processed only " << processed << " sweeps";
    daemon.signal(SIGTERM);
    const int exit = daemon.wait();
    EXPECT_TRUE(WIFEXITED(exit) && WEXITSTATUS(exit) == 0) << "cellmapd did not stop cleanly";
    return log.versions();
  }

  test::TempDir dir_{"cellmap-working-cell"};
};

// "id: center, half extents" of each obstacle box of `env`.
std::vector<std::string> obstacle_boxes(const Environment& env) {
  std::vector<std::string> boxes;
  for (const Box& box : env.boxes()) {
    std::ostringstream out;
    out << box.id << ": " << box.center.transpose() << ", " << box.half_extents.transpose();
    if (box.space == BoxSpace::kOccupied) boxes.push_back(out.str());
  }
  return boxes;
}

// The volume of the union of the unknown boxes of `env`, in m³, from a lattice 2.5 cm apart over the arm
// cell's workspace (unknown boxes overlap where they follow a sloping edge of the sensor's view).
double unknown_volume(const Environment& env) {
  constexpr double kStep = 0.025;
  std::vector<Box> unknown;
  for (const Box& box : env.boxes()) {
    if (box.space == BoxSpace::kUnknown) unknown.push_back(box);
  }
  long long inside = 0;
  for (double z = 0.76; z < 2.0; z += kStep) {
    for (double y = -0.7; y < 2.0; y += kStep) {
      for (double x = 0.0; x < 3.0; x += kStep) {
        const Eigen::Vector3d p(x, y, z);
        inside += std::any_of(unknown.begin(), unknown.end(), [&](const Box& b) { return b.contains(p); });
      }
    }
  }
  return static_cast<double>(inside) * kStep * kStep * kStep;
}

// The boxes of `env` on a working link of the arm anywhere along one round of its motion (checked every 50
// ms against points 2 cm apart on the links' collision shapes).
std::vector<std::uint64_t> boxes_on_the_robot(const Environment& env, const sim::Scene& scene) {
  std::vector<std::uint64_t> ids;
  for (double t = 0; t < scene.motion->duration(); t += 0.05) {
    const JointState state{t, scene.motion->q_at(t), std::nullopt};
    const std::vector<Eigen::Vector3d> surface =
        test::robot_surface(scene.robot, state, 0.02, test::kArmWorkingLinks);
    for (const std::uint64_t id : test::boxes_holding_any(env.boxes(), surface)) {
      if (std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
    }
  }
  return ids;
}

TEST_F(WorkingCellE2eTest, ArmInViewOfTheFixedCameraChangesNoObstacleBoxAndPutsNoBoxOnTheRobot) {
  const std::uint64_t sweeps = long_tests() ? 500 : 25;
  const sim::Scene scene = sim::load_scene(kArmScene);
  const std::vector<Environment> versions =
      run_daemon("sources: [" + kPost + "]\n", test::domain::kArmFiltered, sweeps);
  ASSERT_FALSE(versions.empty()) << "no version in " << sweeps << " sweeps";
  EXPECT_EQ(versions.front().version(), 1u);
  EXPECT_GT(obstacle_boxes(versions.front()).size(), 5u);
  // Later versions may only shrink the unknown space (space the arm hid is seen once it moves away): the
  // moving arm changes no obstacle box.
  for (std::size_t i = 1; i < versions.size(); ++i) {
    EXPECT_EQ(obstacle_boxes(versions[i]), obstacle_boxes(versions.front()))
        << "version " << versions[i].version() << ": the moving arm changed an obstacle box";
    EXPECT_LT(unknown_volume(versions[i]), unknown_volume(versions[i - 1]))
        << "version " << versions[i].version() << " did not shrink the unknown space";
  }
  for (const Environment& env : versions) {
    EXPECT_TRUE(boxes_on_the_robot(env, scene).empty())
        << "version " << env.version() << ": a box on the robot (" << boxes_on_the_robot(env, scene)[0]
        << ")";
  }
  std::cout << "arm cell, fixed camera, self filter on: " << sweeps << " sweeps, "
            << versions.back().version() << " version(s), " << obstacle_boxes(versions.back()).size()
            << " obstacle boxes, unknown space boxed " << unknown_volume(versions.front())
            << " m³ in the first, " << unknown_volume(versions.back()) << " m³ in the last\n";
}

TEST_F(WorkingCellE2eTest, WithoutTheSelfFilterTheMovingArmMakesVersionsAndBoxesOnItself) {
  const sim::Scene scene = sim::load_scene(kArmScene);
  const std::vector<Environment> versions = run_daemon(
      "sources: [" + kPost + "]\nself_filter: {enabled: false}\n", test::domain::kArmUnfiltered, 30);
  ASSERT_FALSE(versions.empty());
  EXPECT_GT(versions.back().version(), 1u) << "the unfiltered arm made no version after the first";
  const std::size_t on_robot = boxes_on_the_robot(versions.back(), scene).size();
  EXPECT_GT(on_robot, 0u);
  std::cout << "arm cell, fixed camera, self filter off: 30 sweeps, " << versions.back().version()
            << " versions, boxes on the robot in the last: " << on_robot << "\n";
}

// Points on the surface of every obstacle of the cell (floor, table, legs, pedestal, post, the objects on the
// table), 2 cm apart: undersides and faces no sensor sees included.
std::vector<Eigen::Vector3d> obstacle_surface(const sim::Scene& scene) {
  std::vector<Eigen::Vector3d> points;
  for (const sim::Obstacle& obstacle : scene.obstacles) {
    const std::vector<Eigen::Vector3d> surface = obstacle.sample_surface(0.02);
    points.insert(points.end(), surface.begin(), surface.end());
  }
  return points;
}

// Which of `points` lie inside a box of `env`.
std::vector<bool> inside_boxes(const Environment& env, const std::vector<Eigen::Vector3d>& points) {
  std::vector<bool> inside;
  for (const Eigen::Vector3d& p : points) {
    inside.push_back(
        std::any_of(env.boxes().begin(), env.boxes().end(), [&](const Box& b) { return b.contains(p); }));
  }
  return inside;
}

std::size_t count(const std::vector<bool>& set) {
  return static_cast<std::size_t>(std::count(set.begin(), set.end(), true));
}

// The points in `a` and not in `b`, and of those, how many `fused` holds.
struct Unique {
  std::size_t points = 0;
  std::size_t fused = 0;
};
Unique unique_to(const std::vector<bool>& a, const std::vector<bool>& b, const std::vector<bool>& fused) {
  Unique u;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!a[i] || b[i]) continue;
    ++u.points;
    u.fused += fused[i] ? 1 : 0;
  }
  return u;
}

// What the three runs of one phase boxed of the obstacles' surface.
struct Boxed {
  std::vector<bool> post, wrist, both;
};

// How much of the surface `boxed` holds: of all of it, and of what some run boxed (`any`), percent.
void print_shares(const std::string& when, const Boxed& boxed, std::size_t all, std::size_t any) {
  const auto share = [&](const std::vector<bool>& set) {
    return std::to_string(100.0 * static_cast<double>(count(set)) / static_cast<double>(all)) + " / " +
           std::to_string(100.0 * static_cast<double>(count(set)) / static_cast<double>(any)) + " %";
  };
  const Unique post_only = unique_to(boxed.post, boxed.wrist, boxed.both);
  const Unique wrist_only = unique_to(boxed.wrist, boxed.post, boxed.both);
  std::cout << when << ": surface points inside boxes, of all " << all << " / of the " << any
            << " some run boxed: post " << share(boxed.post) << ", wrist " << share(boxed.wrist) << ", both "
            << share(boxed.both) << "; boxed by the post and not the wrist " << post_only.points << " (fused "
            << post_only.fused << "), by the wrist and not the post " << wrist_only.points << " (fused "
            << wrist_only.fused << ")\n";
}

// Each camera boxes a large part of the surface the other never does (the post the floor and the table's
// sides it faces, the wrist the pedestal and the floor beside it), and the fused map boxes nearly all of what
// either boxes alone: its share is above each camera's by the other's part. Shares over every obstacle's
// whole surface stay under a half: the floor's underside and the floor under the table, which no sensor sees,
// are most of it.
TEST_F(WorkingCellE2eTest, TwoSensorsFusedCoverMoreOfTheObstaclesThanEitherAlone) {
  if (!long_tests()) GTEST_SKIP() << "three daemons on the arm cell: CELLMAP_LONG_TESTS=1 runs it";
  const sim::Scene scene = sim::load_scene(kArmScene);
  const std::vector<Eigen::Vector3d> surface = obstacle_surface(scene);
  // The last version after 20 sweeps (1 s of the path each, two and a half rounds), the first after 16.
  const auto run = [&](const std::string& sources, int domain) {
    const std::vector<Environment> versions =
        run_daemon("change: {gather_sweeps: 2, settle_sweeps: 16}\nsources: [" + sources + "]\n", domain, 20);
    return versions.empty() ? std::vector<bool>(surface.size(), false)
                            : inside_boxes(versions.back(), surface);
  };
  Boxed boxed;
  boxed.post = run(kPost, test::domain::kArmPostCoverage);
  boxed.wrist = run(kWrist, test::domain::kArmWristCoverage);
  boxed.both = run(kPost + ", " + kWrist, test::domain::kArmBothCoverage);
  std::vector<bool> any(surface.size());
  for (std::size_t i = 0; i < any.size(); ++i) any[i] = boxed.post[i] || boxed.wrist[i] || boxed.both[i];
  print_shares("after 20 sweeps", boxed, surface.size(), count(any));

  const Unique post_only = unique_to(boxed.post, boxed.wrist, boxed.both);
  const Unique wrist_only = unique_to(boxed.wrist, boxed.post, boxed.both);
  EXPECT_GT(post_only.points, count(any) / 20) << "the post boxes little the wrist does not";
  EXPECT_GT(wrist_only.points, count(any) / 20) << "the wrist boxes little the post does not";
  EXPECT_GE(post_only.fused, post_only.points * 95 / 100) << "fusing lost what the post alone boxes";
  EXPECT_GE(wrist_only.fused, wrist_only.points * 95 / 100) << "fusing lost what the wrist alone boxes";
  EXPECT_GT(count(boxed.both), count(boxed.post) + wrist_only.points * 9 / 10);
  EXPECT_GT(count(boxed.both), count(boxed.wrist) + post_only.points * 9 / 10);
  // Over the whole surface: at least 3 points above the better camera (measured: 6.9).
  EXPECT_GT(count(boxed.both), std::max(count(boxed.post), count(boxed.wrist)) + surface.size() * 3 / 100);
}

}  // namespace
}  // namespace cellmap
