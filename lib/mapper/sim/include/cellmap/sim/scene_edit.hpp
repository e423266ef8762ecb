#pragma once
// Changes to a simulated scene between sweeps: how tests and `cellmap inject` plant synthetic changes.

#include <Eigen/Geometry>

#include <optional>
#include <string>

#include "cellmap/sim/scene.hpp"

namespace cellmap::sim {

/// Add, remove or move one obstacle. Plain value type (what the `cellmap/sim/scene_edits` topic carries).
struct SceneEdit final {
  enum class Kind { kAdd, kRemove, kMove };

  Kind kind = Kind::kAdd;
  /// kRemove/kMove: the obstacle to change. kAdd: ignored (the name is `obstacle.name`).
  std::string name;
  /// kAdd: the new obstacle; an empty name asks apply() to choose a free one ("added_1", "added_2", ...).
  Obstacle obstacle;
  /// kMove: the new centre p_CO, metres.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  /// kMove: the new orientation R_CO; absent keeps the current one.
  std::optional<Eigen::Quaterniond> rotation;

  [[nodiscard]] static SceneEdit add(Obstacle obstacle);
  [[nodiscard]] static SceneEdit remove(std::string name);
  [[nodiscard]] static SceneEdit move(std::string name, const Eigen::Vector3d& center,
                                      std::optional<Eigen::Quaterniond> rotation = std::nullopt);
};

/// Applies `edit` to `scene`; on error the scene is unchanged. Returns the name of the obstacle added,
/// removed or moved. @throws Error if the named obstacle does not exist (remove, move), the name is taken
/// (add), the added obstacle has a non-positive size or non-finite pose, or the move's values are not finite.
std::string apply(Scene& scene, const SceneEdit& edit);

}  // namespace cellmap::sim
