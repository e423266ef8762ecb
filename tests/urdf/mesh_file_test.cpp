// SPDX-License-Identifier: Apache-2.0
// Mesh files through assimp and robot descriptions with mesh collision geometry: the real ABB IRB 2400 (7 STL
// collision meshes, ../shared/data/robots) checked against its files read independently, and against the
// joint origins of its URDF.
#include "cellmap/urdf/mesh_file.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <set>
#include <tuple>

#include "cellmap/common/error.hpp"
#include "cellmap/urdf/urdf_model.hpp"
#include "support/shared_data.hpp"
#include "support/test_support.hpp"

namespace cellmap {
namespace {

namespace fs = std::filesystem;

const fs::path kAbbPackage = test::shared_data_dir() / "robots" / "abb_irb2400_support";

// What a binary STL holds, read here byte by byte (not through assimp): triangles, distinct vertices, bounds.
struct StlFacts {
  std::size_t triangles = 0;
  std::size_t distinct_vertices = 0;
  Region bounds{Eigen::Vector3d::Constant(1e9), Eigen::Vector3d::Constant(-1e9)};
};

StlFacts read_binary_stl(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  StlFacts facts;
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  facts.triangles = count;
  std::set<std::tuple<float, float, float>> distinct;
  for (std::uint32_t t = 0; t < count; ++t) {
    for (int corner = 0; corner < 3; ++corner) {
      float p[3];
      std::memcpy(p, bytes.data() + 84 + 50 * t + 12 + 12 * corner, 12);
      distinct.insert({p[0], p[1], p[2]});
      const Eigen::Vector3d v(p[0], p[1], p[2]);
      facts.bounds.min = facts.bounds.min.cwiseMin(v);
      facts.bounds.max = facts.bounds.max.cwiseMax(v);
    }
  }
  facts.distinct_vertices = distinct.size();
  return facts;
}

Eigen::Isometry3d pose(const Eigen::Vector3d& p, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R;
  X.translation() = p;
  return X;
}

#define SKIP_WITHOUT_ABB() CELLMAP_SKIP_WITHOUT_DATA(kAbbPackage)

TEST(MeshFileTest, AbbIrb2400LoadsWithItsSevenStlCollisionMeshes) {
  SKIP_WITHOUT_ABB();
  const auto start = std::chrono::steady_clock::now();
  const Robot robot = UrdfModel::load((kAbbPackage / "urdf" / "irb2400.urdf").string()).robot("tool0");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "IRB 2400: URDF + 7 STL meshes loaded in " << seconds * 1e3 << " ms, "
            << robot.triangle_count() << " triangles\n";
  EXPECT_EQ(robot.link_names(), (std::vector<std::string>{"base_link", "link_1", "link_2", "link_3", "link_4",
                                                          "link_5", "link_6", "tool0"}));
  ASSERT_EQ(robot.shapes().size(), 7u);
  const char* files[] = {"base_link", "link_1", "link_2_whole", "link_3", "link_4", "link_5", "link_6"};
  std::size_t triangles = 0;
  for (std::size_t i = 0; i < 7; ++i) {
    const LinkShape& shape = robot.shapes()[i];
    EXPECT_EQ(shape.link, robot.link_names()[i]);
    ASSERT_TRUE(std::holds_alternative<MeshShape>(shape.geometry)) << shape.link;
    const TriangleMesh& mesh = *std::get<MeshShape>(shape.geometry).mesh;
    const StlFacts facts =
        read_binary_stl(kAbbPackage / "meshes" / "irb2400" / "collision" / (std::string(files[i]) + ".stl"));
    EXPECT_EQ(mesh.triangles.size(), facts.triangles) << files[i];
    EXPECT_EQ(mesh.vertices.size(), facts.distinct_vertices) << files[i];  // identical vertices joined
    const Region bounds = mesh.bounds();
    EXPECT_LT((bounds.min - facts.bounds.min).norm(), 1e-6) << files[i];
    EXPECT_LT((bounds.max - facts.bounds.max).norm(), 1e-6) << files[i];
    triangles += facts.triangles;
  }
  EXPECT_EQ(robot.triangle_count(), triangles);
  EXPECT_EQ(triangles, 1918u);
  // The tight boxes on the links are the mesh bounds (the collision origins are identity).
  const std::vector<LinkBox> boxes = robot.shape_boxes();
  const Region link_1 = std::get<MeshShape>(robot.shapes()[1].geometry).mesh->bounds();
  EXPECT_LT((boxes[1].X_LB.translation() - 0.5 * (link_1.min + link_1.max)).norm(), 1e-12);
  EXPECT_LT((boxes[1].half_extents - 0.5 * (link_1.max - link_1.min)).norm(), 1e-12);
}

TEST(MeshFileTest, AbbIrb2400ForwardKinematicsFollowsItsJointOrigins) {
  SKIP_WITHOUT_ABB();
  const Robot robot = UrdfModel::load((kAbbPackage / "urdf" / "irb2400.urdf").string()).chain("tool0");
  ASSERT_EQ(robot.dof(), 6);
  const Eigen::Matrix3d R_tool = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  // Zero pose: the joint origins add up (0.1 0 0.615), (0 0 0.705), (0.258 0 0.135), (0.497 0 0), (0.085 0
  // 0).
  std::vector<Eigen::Isometry3d> X = robot.link_poses(Eigen::VectorXd::Zero(6));
  const Eigen::Vector3d expected_zero[] = {{0, 0, 0},        {0, 0, 0},         {0.1, 0, 0.615},
                                           {0.1, 0, 1.32},   {0.358, 0, 1.455}, {0.855, 0, 1.455},
                                           {0.94, 0, 1.455}, {0.94, 0, 1.455}};
  for (std::size_t i = 0; i < X.size(); ++i)
    EXPECT_LT((X[i].translation() - expected_zero[i]).norm(), 1e-9) << i;
  EXPECT_TRUE(X.back().isApprox(pose({0.94, 0, 1.455}, R_tool), 1e-9));
  // Axis 1 at 90°: the whole arm turns to +y. Axis 2 at 90° (about y): the upper arm lies along +x.
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  q[0] = M_PI / 2;
  EXPECT_LT((robot.tool_pose(q).translation() - Eigen::Vector3d(0, 0.94, 1.455)).norm(), 1e-9);
  q.setZero();
  q[1] = M_PI / 2;
  X = robot.link_poses(q);
  EXPECT_LT((X[3].translation() - Eigen::Vector3d(0.805, 0, 0.615)).norm(), 1e-9);
  // ... and the forearm (0.258, 0, 0.135) + 0.497 + 0.085 along x then points down (-z).
  EXPECT_LT((X[7].translation() - Eigen::Vector3d(0.805 + 0.135, 0, 0.615 - 0.258 - 0.497 - 0.085)).norm(),
            1e-9);
  // Wrist: axis 5 at 90° (about y) turns the flange down.
  q.setZero();
  q[4] = M_PI / 2;
  const Eigen::Isometry3d X_CE = robot.tool_pose(q);
  EXPECT_LT((X_CE.translation() - Eigen::Vector3d(0.855, 0, 1.455 - 0.085)).norm(), 1e-9);
}

TEST(MeshFileTest, ColladaVisualMeshMatchesTheCollisionMesh) {
  SKIP_WITHOUT_ABB();
  // The visual COLLADA mesh is finer but covers the same solid: its bounds agree with the STL's within 5 cm,
  // so assimp's unit is applied and the up axis is not.
  const TriangleMesh dae = load_mesh(kAbbPackage / "meshes" / "irb2400" / "visual" / "link_1.dae");
  const Region stl = load_mesh(kAbbPackage / "meshes" / "irb2400" / "collision" / "link_1.stl").bounds();
  const Region visual = dae.bounds();
  EXPECT_LT((visual.min - stl.min).cwiseAbs().maxCoeff(), 0.05);
  EXPECT_LT((visual.max - stl.max).cwiseAbs().maxCoeff(), 0.05);
  EXPECT_GT(dae.triangles.size(), 100u);
}

TEST(MeshFileTest, ObjFileAndMeshUrisResolve) {
  const test::TempDir dir;
  fs::create_directories(dir.path() / "my_arm" / "meshes");
  fs::create_directories(dir.path() / "my_arm" / "urdf");
  // A tetrahedron with its apex 0.3 m up, scaled ×2 in x by the URDF.
  std::ofstream(dir.path() / "my_arm" / "meshes" / "tip.obj")
      << "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.3\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
  const TriangleMesh tip = load_mesh(dir.path() / "my_arm" / "meshes" / "tip.obj", {2, 1, 1});
  EXPECT_EQ(tip.triangles.size(), 4u);
  EXPECT_EQ(tip.vertices.size(), 4u);
  EXPECT_LT((tip.bounds().max - Eigen::Vector3d(0.2, 0.1, 0.3)).norm(), 1e-6);  // assimp reads floats

  const fs::path urdf_dir = dir.path() / "my_arm" / "urdf";
  const fs::path tip_file = dir.path() / "my_arm" / "meshes" / "tip.obj";
  EXPECT_EQ(resolve_mesh_uri("package://my_arm/meshes/tip.obj", urdf_dir), tip_file);  // an ancestor folder
  EXPECT_EQ(resolve_mesh_uri("package://my_arm/meshes/tip.obj", "/", {dir.path().string()}), tip_file);
  EXPECT_EQ(resolve_mesh_uri("../meshes/tip.obj", urdf_dir), urdf_dir / "../meshes/tip.obj");
  EXPECT_EQ(resolve_mesh_uri("file://" + tip_file.string(), "/"), tip_file);
  EXPECT_NE(test::error_of([&] {
              (void)resolve_mesh_uri("package://other/tip.obj", urdf_dir);
            }).find("package 'other' not found"),
            std::string::npos);
  EXPECT_NE(test::error_of([&] { (void)resolve_mesh_uri("missing.stl", urdf_dir); }).find("no file"),
            std::string::npos);

  std::ofstream(dir.path() / "empty.obj") << "# nothing\n";
  EXPECT_NE(test::error_of([&] { (void)load_mesh(dir.path() / "empty.obj"); }).find("empty.obj"),
            std::string::npos);
  std::ofstream(urdf_dir / "arm.urdf") << R"(<robot name="my_arm">
  <link name="base"><collision><origin xyz="0 0 0.5"/><geometry><cylinder radius="0.1" length="1"/></geometry></collision></link>
  <link name="hand"><collision><geometry><mesh filename="package://my_arm/meshes/tip.obj" scale="2 1 1"/></geometry></collision></link>
  <joint name="lift" type="prismatic"><parent link="base"/><child link="hand"/><origin xyz="0 0 1"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.5" effort="1" velocity="1"/></joint>
</robot>)";
  const Robot robot = UrdfModel::load((urdf_dir / "arm.urdf").string()).robot("hand");
  ASSERT_EQ(robot.shapes().size(), 2u);
  const auto& cylinder = std::get<CylinderShape>(robot.shapes()[0].geometry);
  EXPECT_DOUBLE_EQ(cylinder.half_length, 0.5);
  EXPECT_EQ(robot.triangle_count(), 4u);
  // The hand's mesh apex at lift 0.25: 1 + 0.25 + 0.3 m up.
  const std::vector<Eigen::Isometry3d> X_CG = robot.shape_poses(Eigen::VectorXd::Constant(1, 0.25));
  EXPECT_LT((X_CG[1] * Eigen::Vector3d(0, 0, 0.3) - Eigen::Vector3d(0, 0, 1.55)).norm(), 1e-12);
  EXPECT_NEAR(robot.shape_boxes()[1].half_extents.z(), 0.15, 1e-6);
}

}  // namespace
}  // namespace cellmap
