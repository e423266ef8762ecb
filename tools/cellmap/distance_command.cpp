// SPDX-License-Identifier: Apache-2.0
// `cellmap distance BOX_A BOX_B`: the signed box-box distance of the collision library, as one JSON object.
#include <iostream>
#include <nlohmann/json.hpp>

#include "cellmap/collision/box_distance.hpp"
#include "cellmap/common/error.hpp"
#include "commands.hpp"
#include "parse.hpp"

namespace cellmap::cli {
namespace {

// BOX = cx,cy,cz,hx,hy,hz[,qw,qx,qy,qz] in the cell frame, metres; the quaternion must be unit (1e-6).
collision::Obb parse_box(const std::string& text, const std::string& what) {
  const std::vector<double> v = parse_numbers(text, what, {6, 10});
  Box box;
  box.center = {v[0], v[1], v[2]};
  box.half_extents = {v[3], v[4], v[5]};
  if ((box.half_extents.array() < 0.0).any()) throw Error(what + ": half extents must be >= 0");
  if (v.size() == 10) {
    box.rotation = Eigen::Quaterniond(v[6], v[7], v[8], v[9]);
    if (std::abs(box.rotation.norm() - 1.0) > 1e-6) {
      throw Error(what + ": quaternion qw,qx,qy,qz must have norm 1, got " +
                  std::to_string(box.rotation.norm()));
    }
  }
  return collision::to_obb(box);
}

nlohmann::json vector_json(const Eigen::Vector3d& v) {
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

}  // namespace

void add_distance_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "distance", "Signed distance between two boxes (negative = penetration depth), printed as JSON");
  auto box_a = std::make_shared<std::string>();
  auto box_b = std::make_shared<std::string>();
  command->add_option("BOX_A", *box_a, "cx,cy,cz,hx,hy,hz[,qw,qx,qy,qz]")->required();
  command->add_option("BOX_B", *box_b, "cx,cy,cz,hx,hy,hz[,qw,qx,qy,qz]")->required();
  command->callback([box_a, box_b] {
    const collision::Obb a = parse_box(*box_a, "BOX_A");
    const collision::Obb b = parse_box(*box_b, "BOX_B");
    const collision::SignedDistance d = collision::signed_distance(a, b);
    const nlohmann::json out = {{"distance", d.distance},
                                {"point_a", vector_json(d.point_a)},
                                {"point_b", vector_json(d.point_b)},
                                {"normal", vector_json(d.normal)}};
    std::cout << out.dump() << "\n";
  });
}

}  // namespace cellmap::cli
