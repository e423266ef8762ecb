#include "cellmap/collision/robot_boxes.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>

#include "cellmap/common/error.hpp"

namespace cellmap::collision {

RobotBoxes::RobotBoxes(Robot robot, std::vector<LinkBox> boxes)
    : robot_(std::move(robot)), boxes_(std::move(boxes)) {
  const std::vector<std::string>& links = robot_.link_names();
  for (std::size_t i = 0; i < boxes_.size(); ++i) {
    const LinkBox& box = boxes_[i];
    const std::string where = "robot box " + std::to_string(i) + " (link '" + box.link + "')";
    const auto it = std::find(links.begin(), links.end(), box.link);
    if (it == links.end()) throw Error(where + ": the robot has no such link");
    if (!box.half_extents.allFinite() || (box.half_extents.array() < 0.0).any()) {
      throw Error(where + ": half extents must be finite and >= 0");
    }
    if (!box.X_LB.matrix().allFinite()) throw Error(where + ": X_LB must be finite");
    link_index_.push_back(static_cast<int>(it - links.begin()));
  }
}

std::vector<LinkBox> link_boxes_from_urdf(const std::string& xml, const Robot& robot,
                                          const std::string& source) {
  // urdfdom reports parse problems through console_bridge on stderr; we report through Error only.
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
  if (!model) throw Error(source + ": not a valid URDF robot description");
  std::vector<LinkBox> boxes;
  for (const std::string& name : robot.link_names()) {
    const urdf::LinkConstSharedPtr link = model->getLink(name);
    if (!link) continue;  // a link the robot's chain names but this XML does not: no geometry
    for (std::size_t i = 0; i < link->collision_array.size(); ++i) {
      const urdf::CollisionSharedPtr& collision = link->collision_array[i];
      if (!collision || !collision->geometry) continue;
      const std::string where = source + ": link '" + name + "' collision " + std::to_string(i);
      if (collision->geometry->type != urdf::Geometry::BOX)
        throw Error(where + ": only box geometry is supported");
      const auto& box = static_cast<const urdf::Box&>(*collision->geometry);
      const urdf::Pose& origin = collision->origin;
      LinkBox out;
      out.link = name;
      out.X_LB.translation() = Eigen::Vector3d(origin.position.x, origin.position.y, origin.position.z);
      out.X_LB.linear() =
          Eigen::Quaterniond(origin.rotation.w, origin.rotation.x, origin.rotation.y, origin.rotation.z)
              .normalized()
              .toRotationMatrix();
      out.half_extents = 0.5 * Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z);
      boxes.push_back(out);
    }
  }
  return boxes;
}

std::vector<Obb> RobotBoxes::place(const Eigen::VectorXd& q) const {
  const std::vector<Eigen::Isometry3d> X_CL = robot_.link_poses(q);
  std::vector<Obb> out;
  out.reserve(boxes_.size());
  for (std::size_t i = 0; i < boxes_.size(); ++i) {
    const Eigen::Isometry3d X_CB = X_CL[link_index_[i]] * boxes_[i].X_LB;
    out.emplace_back(X_CB.translation(), boxes_[i].half_extents, X_CB.linear());
  }
  return out;
}

}  // namespace cellmap::collision
