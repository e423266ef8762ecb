#include "cellmap/sim/scene_edit.hpp"

#include "cellmap/common/error.hpp"

namespace cellmap::sim {

SceneEdit SceneEdit::add(Obstacle obstacle) {
  SceneEdit edit;
  edit.kind = Kind::kAdd;
  edit.obstacle = std::move(obstacle);
  return edit;
}

SceneEdit SceneEdit::remove(std::string name) {
  SceneEdit edit;
  edit.kind = Kind::kRemove;
  edit.name = std::move(name);
  return edit;
}

SceneEdit SceneEdit::move(std::string name, const Eigen::Vector3d& center,
                          std::optional<Eigen::Quaterniond> rotation) {
  SceneEdit edit;
  edit.kind = Kind::kMove;
  edit.name = std::move(name);
  edit.center = center;
  edit.rotation = rotation;
  return edit;
}

std::string apply(Scene& scene, const SceneEdit& edit) {
  switch (edit.kind) {
    case SceneEdit::Kind::kAdd: {
      Obstacle obstacle = edit.obstacle;
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
    case SceneEdit::Kind::kRemove: {
      const int index = scene.find_obstacle(edit.name);
      if (index < 0) throw Error("scene edit: remove: no obstacle named '" + edit.name + "'");
      scene.obstacles.erase(scene.obstacles.begin() + index);
      return edit.name;
    }
    case SceneEdit::Kind::kMove: {
      const int index = scene.find_obstacle(edit.name);
      if (index < 0) throw Error("scene edit: move: no obstacle named '" + edit.name + "'");
      if (!edit.center.allFinite())
        throw Error("scene edit: move '" + edit.name + "': center must be finite");
      Obstacle& obstacle = scene.obstacles[static_cast<std::size_t>(index)];
      if (edit.rotation) {
        const Eigen::Quaterniond& q = *edit.rotation;
        if (!q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-3) {
          throw Error("scene edit: move '" + edit.name + "': rotation must be a unit quaternion");
        }
        obstacle.X_CO.linear() = q.normalized().toRotationMatrix();
      }
      obstacle.X_CO.translation() = edit.center;
      return edit.name;
    }
  }
  throw Error("scene edit: unknown kind");
}

}  // namespace cellmap::sim
