// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sim/scene_edit.hpp"

#include "cellmap/common/error.hpp"

namespace cellmap::sim {

namespace {

Obstacle box_obstacle(const transport::SceneEdit& edit) {
  Obstacle obstacle;
  obstacle.name = edit.name;
  obstacle.shape = BoxShape{edit.half_extents};
  obstacle.X_CO.translation() = edit.center;
  obstacle.X_CO.linear() = Eigen::AngleAxisd(edit.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return obstacle;
}

}  // namespace

std::string apply(Scene& scene, const transport::SceneEdit& edit) {
  switch (edit.kind) {
    case transport::SceneEdit::Kind::kAddBox: {
      if (scene.obstacles.size() >= kMaxSceneObstacles) {
        throw Error("scene edit: add: the scene holds " + std::to_string(scene.obstacles.size()) +
                    " obstacles, the most a simulated cell takes");
      }
      Obstacle obstacle = box_obstacle(edit);
      if (obstacle.name.empty()) {
        for (int k = 1; obstacle.name.empty(); ++k) {
          const std::string candidate = "added_" + std::to_string(k);
          if (scene.find_obstacle(candidate) < 0) obstacle.name = candidate;
        }
      } else if (scene.find_obstacle(obstacle.name) >= 0) {
        throw Error("scene edit: add: an obstacle named '" + obstacle.name + "' already exists");
      }
      Scene edited = scene;
      edited.obstacles.push_back(obstacle);
      try {
        edited.validate();
      } catch (const Error& e) {
        throw Error(std::string("scene edit: add '") + obstacle.name + "': " + e.what());
      }
      scene = std::move(edited);
      return obstacle.name;
    }
    case transport::SceneEdit::Kind::kRemove: {
      const int index = scene.find_obstacle(edit.name);
      if (index < 0) throw Error("scene edit: remove: no obstacle named '" + edit.name + "'");
      scene.obstacles.erase(scene.obstacles.begin() + index);
      return edit.name;
    }
    case transport::SceneEdit::Kind::kMove: {
      const int index = scene.find_obstacle(edit.name);
      if (index < 0) throw Error("scene edit: move: no obstacle named '" + edit.name + "'");
      if (!edit.center.allFinite())
        throw Error("scene edit: move '" + edit.name + "': center must be finite");
      Obstacle& obstacle = scene.obstacles[static_cast<std::size_t>(index)];
      obstacle.X_CO.translation() = edit.center;
      return edit.name;
    }
  }
  throw Error("scene edit: unknown kind");
}

}  // namespace cellmap::sim
