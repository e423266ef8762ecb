// cellmapd in a working cell, as a real process on loopback DDS: the simulated arm cell (the arm moving all
// the time, noise on), its frames self filtered with the robot posed from the controller's joint samples.
// Short runs here; CELLMAP_LONG_TESTS=1 runs the documented lengths (500 sweeps).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <mutex>
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

// cellmapd on `yaml` (cell "arm") until it processed `sweeps` sweeps; every version it published meanwhile.
class WorkingCellE2eTest : public ::testing::Test {
 protected:
  std::vector<Environment> run_daemon(const std::string& yaml, int domain, std::uint64_t sweeps) {
    test::use_loopback();
    const std::filesystem::path config = dir_.path() / "cellmapd.yaml";
    // The box kind and the change gathering of config/arm-cell.yaml.
    std::ofstream(config)
        << "cell: arm\nsweep_period: 0\nstatus_period: 0.5\nsegment: {boxes: {kind: aabb}}\n"
        << "change: {gather_sweeps: 2}\n"
        << yaml;
    const dds::Participant participant(static_cast<std::uint32_t>(domain));
    VersionLog log;
    transport::EnvironmentSubscriber planner(participant, "arm", std::ref(log));
    transport::StatusReader status(participant);
    test::ChildProcess daemon({CELLMAPD, "--config", config.string(), "--domain", std::to_string(domain),
                               "--state-dir", (dir_.path() / "state").string()});
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

TEST_F(WorkingCellE2eTest, ArmInViewOfTheFixedCameraMakesOneVersionAndNoBoxOnTheRobot) {
  const std::uint64_t sweeps = long_tests() ? 500 : 25;
  const sim::Scene scene = sim::load_scene(kArmScene);
  const std::vector<Environment> versions =
      run_daemon("sources: [" + kPost + "]\n", test::domain::kArmFiltered, sweeps);
  ASSERT_FALSE(versions.empty()) << "no version in " << sweeps << " sweeps";
  EXPECT_EQ(versions.back().version(), 1u) << "the moving arm made versions";
  EXPECT_GT(versions.front().boxes().size(), 5u);
  for (const Environment& env : versions) {
    EXPECT_TRUE(boxes_on_the_robot(env, scene).empty())
        << "version " << env.version() << ": a box on the robot (" << boxes_on_the_robot(env, scene)[0]
        << ")";
  }
  std::cout << "arm cell, fixed camera, self filter on: " << sweeps << " sweeps, "
            << versions.back().version() << " version(s), " << versions.back().boxes().size() << " boxes\n";
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

// The share of the surface of every obstacle of the cell (floor, table, legs, pedestal, post, the objects on
// the table; 2 cm samples) inside a box of `env`. Every obstacle: counting only the objects on the table,
// each camera's boxes alone already held all of them (1.0 each).
double surface_in_boxes(const Environment& env, const sim::Scene& scene) {
  std::size_t inside = 0, total = 0;
  for (const sim::Obstacle& obstacle : scene.obstacles) {
    for (const Eigen::Vector3d& p : obstacle.sample_surface(0.02)) {
      ++total;
      inside +=
          std::any_of(env.boxes().begin(), env.boxes().end(), [&](const Box& b) { return b.contains(p); });
    }
  }
  return static_cast<double>(inside) / static_cast<double>(total);
}

TEST_F(WorkingCellE2eTest, TwoSensorsFusedCoverMoreOfTheObstaclesThanEitherAlone) {
  if (!long_tests()) GTEST_SKIP() << "three daemons on the arm cell: CELLMAP_LONG_TESTS=1 runs it";
  const sim::Scene scene = sim::load_scene(kArmScene);
  const std::uint64_t sweeps = 20;
  const std::string settle = "change: {settle_sweeps: " + std::to_string(sweeps - 4) + "}\n";
  const auto coverage = [&](const std::string& sources, int domain) {
    const std::vector<Environment> versions =
        run_daemon(settle + "sources: [" + sources + "]\n", domain, sweeps);
    return versions.empty() ? 0.0 : surface_in_boxes(versions.back(), scene);
  };
  const double post = coverage(kPost, test::domain::kArmPostCoverage);
  const double wrist = coverage(kWrist, test::domain::kArmWristCoverage);
  const double both = coverage(kPost + ", " + kWrist, test::domain::kArmBothCoverage);
  std::cout << "share of the obstacles' surface inside boxes after " << sweeps << " sweeps: post " << post
            << ", wrist " << wrist << ", both " << both << "\n";
  EXPECT_GT(both, post);
  EXPECT_GT(both, wrist);
}

}  // namespace
}  // namespace cellmap
