// SPDX-License-Identifier: Apache-2.0
#include "cellmap/collision/batch.hpp"

#include <gtest/gtest.h>

#include <random>

#include "cellmap/collision/box_tree.hpp"
#include "cellmap/collision/robot_boxes.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/urdf/urdf_model.hpp"
#include "support/test_support.hpp"

namespace cellmap::collision {
namespace {

using Eigen::Vector3d;

std::vector<Obb> random_boxes(int n, double spread, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> h(0.02, 0.3);
  std::vector<Obb> boxes;
  for (int i = 0; i < n; ++i) {
    boxes.emplace_back(Vector3d(u(rng), u(rng), u(rng)) * spread, Vector3d(h(rng), h(rng), h(rng)),
                       Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix());
  }
  return boxes;
}

TEST(BoxTreeTest, QueryFindsExactlyTheBoxesWithinTheCutoff) {
  std::mt19937 rng(1);
  const std::vector<Obb> boxes = random_boxes(500, 5.0, rng);
  const BoxTree tree(boxes);
  for (const Obb& probe : random_boxes(50, 5.0, rng)) {
    for (const double cutoff : {0.0, 0.1, 1.0}) {
      std::vector<int> found;
      tree.query(probe.center, probe.aabb_half_extents(), cutoff, &found);
      std::sort(found.begin(), found.end());
      std::vector<int> expected;
      for (int i = 0; i < static_cast<int>(boxes.size()); ++i) {
        const Vector3d gap = (boxes[i].center - probe.center).cwiseAbs() - boxes[i].aabb_half_extents() -
                             probe.aabb_half_extents();
        const double g2 = gap.cwiseMax(0.0).squaredNorm();
        if (g2 == 0.0 || g2 < cutoff * cutoff) expected.push_back(i);
      }
      EXPECT_EQ(found, expected);
    }
  }
  std::vector<int> none;
  BoxTree(std::vector<Obb>{}).query(Vector3d::Zero(), Vector3d::Ones(), 1.0, &none);
  EXPECT_TRUE(none.empty());
}

TEST(BatchTest, DenseVectorHasThePaperCountAndExactEntries) {
  std::mt19937 rng(2);
  const std::vector<Obb> environment = random_boxes(7, 2.0, rng);
  std::vector<std::vector<Obb>> robot;
  for (int k = 0; k < 5; ++k) robot.push_back(random_boxes(3, 2.0, rng));
  const ConstraintSet set = constraints(robot, environment);
  EXPECT_EQ(set.n_constr(), 3u * 7u * 5u);
  ASSERT_EQ(set.entries.size(), set.n_constr());
  const Constraint& c = set.entries[2 * 21 + 1 * 7 + 4];
  EXPECT_EQ(c.checkpoint, 2);
  EXPECT_EQ(c.robot_box, 1);
  EXPECT_EQ(c.env_box, 4);
  EXPECT_EQ(c.result.distance, signed_distance(robot[2][1], environment[4]).distance);
}

TEST(BatchTest, ArraysHoldTheDenseEntriesBitForBitAndSkipNullArrays) {
  std::mt19937 rng(3);
  const std::vector<Obb> environment = random_boxes(9, 1.0, rng);
  std::vector<std::vector<Obb>> robot;
  for (int k = 0; k < 4; ++k) robot.push_back(random_boxes(3, 1.0, rng));
  const ConstraintSet set = constraints(robot, environment);
  const std::size_t n = set.n_constr();
  std::vector<double> distance(n), point_a(3 * n), point_b(3 * n, -7.0), normal(3 * n);
  constraints_into(robot, environment, {distance.data(), point_a.data(), nullptr, normal.data()});
  for (std::size_t i = 0; i < n; ++i) {
    const SignedDistance& want = set.entries[i].result;
    EXPECT_EQ(distance[i], want.distance) << i;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(point_a[3 * i + c], want.point_a[c]) << i;
      EXPECT_EQ(normal[3 * i + c], want.normal[c]) << i;
    }
  }
  EXPECT_EQ(point_b, std::vector<double>(3 * n, -7.0)) << "a null array was written";
  robot.back().pop_back();
  EXPECT_NE(
      test::error_of([&] { constraints_into(robot, environment, {distance.data()}); }).find("checkpoint 3"),
      std::string::npos);
}

TEST(BatchTest, DenseEntriesEqualSignedDistanceInEveryLane) {
  // The dense batch runs its first projections on several environment boxes at once; every entry must still
  // be exactly signed_distance's answer: separated, overlapping and touching pairs, environment sizes that do
  // and do not fill the last block.
  std::mt19937 rng(6);
  for (const int n_env : {1, 4, 11}) {
    std::vector<Obb> environment = random_boxes(n_env, 0.4, rng);
    std::vector<std::vector<Obb>> robot{random_boxes(5, 0.4, rng), random_boxes(5, 0.4, rng)};
    robot[1][0] = Obb(environment[0].center +
                          environment[0].rotation * Vector3d(environment[0].half_extents.x() + 0.3, 0, 0),
                      Vector3d(0.3, 0.1, 0.1), environment[0].rotation);  // touching a face
    const ConstraintSet set = constraints(robot, environment);
    ASSERT_EQ(set.entries.size(), set.n_constr());
    int separated = 0, overlapping = 0;
    for (const Constraint& c : set.entries) {
      const SignedDistance expected =
          signed_distance(robot[c.checkpoint][c.robot_box], environment[c.env_box]);
      EXPECT_EQ(c.result.distance, expected.distance);
      EXPECT_EQ(c.result.point_a, expected.point_a);
      EXPECT_EQ(c.result.point_b, expected.point_b);
      EXPECT_EQ(c.result.normal, expected.normal);
      (c.result.distance > 0.0 ? separated : overlapping) += 1;
    }
    if (n_env == 11) {
      EXPECT_GT(separated, 10);
      EXPECT_GT(overlapping, 10);
    }
  }
}

TEST(BatchTest, BroadPhaseKeepsEveryPairCloserThanTheCutoff) {
  std::mt19937 rng(3);
  const std::vector<Obb> environment = random_boxes(200, 6.0, rng);
  std::vector<std::vector<Obb>> robot;
  for (int k = 0; k < 10; ++k) robot.push_back(random_boxes(4, 6.0, rng));
  const ConstraintSet dense = constraints(robot, environment);
  const BoxTree tree(environment);
  const double cutoff = 0.5;
  const ConstraintSet sparse = constraints(robot, environment, tree, cutoff);
  EXPECT_EQ(sparse.n_constr(), dense.n_constr());
  EXPECT_LT(sparse.entries.size(), dense.entries.size() / 4);  // the broad phase skips most pairs here
  std::size_t near = 0;
  for (const Constraint& c : dense.entries) {
    if (c.result.distance >= cutoff) continue;
    ++near;
    const auto it = std::find_if(sparse.entries.begin(), sparse.entries.end(), [&](const Constraint& s) {
      return s.checkpoint == c.checkpoint && s.robot_box == c.robot_box && s.env_box == c.env_box;
    });
    ASSERT_NE(it, sparse.entries.end());
    EXPECT_EQ(it->result.distance, c.result.distance);
  }
  EXPECT_GT(near, 0u);
  EXPECT_EQ(sparse.min_distance(), dense.min_distance());
  EXPECT_EQ(sparse.clear(0.01), dense.clear(0.01));
  EXPECT_FALSE(sparse.clear(cutoff));  // a margin beyond the cutoff cannot be certified
}

TEST(BatchTest, MismatchedCheckpointsAreRefused) {
  std::mt19937 rng(4);
  const std::vector<std::vector<Obb>> robot{random_boxes(2, 1, rng), random_boxes(3, 1, rng)};
  EXPECT_THROW((void)constraints(robot, random_boxes(2, 1, rng)), Error);
}

TEST(RobotBoxesTest, GantryBoxesFollowTheJoints) {
  const Robot gantry = Robot::gantry(Vector3d(0, 0, 0), Vector3d(4, 3, 1));
  Eigen::Isometry3d X_LB = Eigen::Isometry3d::Identity();
  X_LB.translation() = Vector3d(0, 0, -0.2);
  const RobotBoxes robot(gantry,
                         {{"ram", X_LB, Vector3d(0.1, 0.1, 0.2)}, {"bridge", {}, Vector3d(0.1, 2, 0.1)}});
  const std::vector<Obb> at_zero = robot.place(Eigen::Vector3d(0, 0, 0));
  const std::vector<Obb> moved = robot.place(Eigen::Vector3d(1.0, 0.5, 0.25));
  EXPECT_LT((moved[0].center - at_zero[0].center - Vector3d(1.0, 0.5, 0.25)).norm(), 1e-12);
  EXPECT_LT((moved[1].center - at_zero[1].center - Vector3d(1.0, 0, 0)).norm(),
            1e-12);  // the bridge moves in x only
  EXPECT_THROW(RobotBoxes(gantry, {{"wrist", {}, Vector3d::Ones()}}), Error);
  EXPECT_THROW(RobotBoxes(gantry, {{"ram", {}, Vector3d(1, -1, 1)}}), Error);
}

// A two-link arm: shoulder revolute about z at 0.5 m height, a 0.6 m upper arm with a box along its x axis.
constexpr const char* kArm = R"(<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><collision><origin xyz="0 0 0.25"/><geometry><box size="0.4 0.4 0.5"/></geometry></collision></link>
  <link name="upper_arm">
    <collision><origin xyz="0.3 0 0" rpy="0 0 0"/><geometry><box size="0.6 0.1 0.1"/></geometry></collision>
  </link>
  <link name="flange"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper_arm"/><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="tip" type="fixed"><parent link="upper_arm"/><child link="flange"/><origin xyz="0.6 0 0"/></joint>
</robot>)";

TEST(RobotBoxesTest, UrdfGeometryFollowsTheJoints) {
  const Robot arm = UrdfModel::parse(kArm, "arm.urdf").robot("flange");
  ASSERT_EQ(arm.shapes().size(), 2u);
  const RobotBoxes robot(arm);
  // Shoulder at 90 degrees: the upper arm box points along +y, centred 0.3 m out at 0.5 m height.
  const std::vector<Obb> placed = robot.place(Eigen::VectorXd::Constant(1, M_PI / 2));
  EXPECT_LT((placed[0].center - Vector3d(0, 0, 0.25)).norm(), 1e-12);
  EXPECT_LT((placed[1].center - Vector3d(0, 0.3, 0.5)).norm(), 1e-12);
  EXPECT_LT((placed[1].aabb_half_extents() - Vector3d(0.05, 0.3, 0.05)).norm(), 1e-12);
  // An obstacle 0.2 m beyond the arm's tip along y: the constraint reports exactly that.
  const Obb obstacle(Vector3d(0, 0.9, 0.5), Vector3d(0.1, 0.1, 0.1));
  EXPECT_NEAR(signed_distance(placed[1], obstacle).distance, 0.2, 1e-12);

  // A sphere or a cylinder gets its tight box; a mesh that is not there is an error naming it.
  std::string round_arm = kArm;
  const std::string upper_box = "<box size=\"0.6 0.1 0.1\"/>";
  round_arm.replace(round_arm.find(upper_box), upper_box.size(), "<sphere radius=\"0.1\"/>");
  const RobotBoxes round(UrdfModel::parse(round_arm, "arm.urdf").robot("flange"));
  EXPECT_LT((round.boxes()[1].half_extents - Vector3d(0.1, 0.1, 0.1)).norm(), 1e-12);
  std::string mesh_arm = kArm;
  mesh_arm.replace(mesh_arm.find(upper_box), upper_box.size(),
                   "<mesh filename=\"package://nowhere/arm.stl\"/>");
  EXPECT_NE(
      test::error_of([&] {
        (void)UrdfModel::parse(mesh_arm, "arm.urdf").robot("flange");
      }).find("arm.urdf: link 'upper_arm' collision 0: mesh 'package://nowhere/arm.stl': package 'nowhere'"),
      std::string::npos);
  EXPECT_THROW((void)UrdfModel::parse("<robot", "bad.urdf"), Error);
}

}  // namespace
}  // namespace cellmap::collision
