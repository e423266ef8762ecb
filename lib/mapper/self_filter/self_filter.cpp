// SPDX-License-Identifier: Apache-2.0
#include "cellmap/self_filter/self_filter.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "cellmap/common/error.hpp"
#include "depth_buffer.hpp"
#include "padded_shape.hpp"

namespace cellmap {

using self_filter::DepthBuffer;
using self_filter::PaddedShape;

struct SelfFilter::Model {
  SelfFilterConfig config;
  std::size_t links = 0;
  std::vector<PaddedShape> shapes;      // in robot.shapes() order
  std::vector<int> shape_links;         // index into the link poses
  std::vector<Eigen::Isometry3d> X_LG;  // each shape's pose on its link
  std::size_t triangles = 0;
};

namespace {

// The padded shapes of one frame, their triangles' vertices in the sensor frame S.
struct PosedShapes {
  std::vector<std::vector<Eigen::Vector3f>> vertices_S;
  std::vector<const PaddedShape*> shapes;
  std::vector<Eigen::Vector3f> centres_S;
  std::size_t skipped = 0;
};

void add_posed(const PaddedShape& shape, const Eigen::Isometry3d& X_CG, const Eigen::Isometry3d& X_CS,
               PosedShapes& posed) {
  if (shape.contains(X_CG.inverse() * X_CS.translation())) {
    ++posed.skipped;
    return;
  }
  const Eigen::Isometry3f X_SG = (X_CS.inverse() * X_CG).cast<float>();
  std::vector<Eigen::Vector3f> vertices;
  vertices.reserve(shape.vertices_G.size());
  for (const Eigen::Vector3f& v : shape.vertices_G) vertices.push_back(X_SG * v);
  posed.vertices_S.push_back(std::move(vertices));
  posed.shapes.push_back(&shape);
  posed.centres_S.push_back(X_SG * shape.centre_G.cast<float>());
}

// Distance along the unit ray from the origin to its first crossing of a triangle (either side), or
// infinity (Möller–Trumbore).
float first_crossing(const Eigen::Vector3f& direction, const std::vector<Eigen::Vector3f>& vertices,
                     const std::vector<Eigen::Vector3i>& triangles) {
  float nearest = std::numeric_limits<float>::infinity();
  for (const Eigen::Vector3i& t : triangles) {
    const Eigen::Vector3f& a = vertices[std::size_t(t[0])];
    const Eigen::Vector3f e1 = vertices[std::size_t(t[1])] - a;
    const Eigen::Vector3f e2 = vertices[std::size_t(t[2])] - a;
    const Eigen::Vector3f p = direction.cross(e2);
    const float det = e1.dot(p);
    if (std::abs(det) < 1e-12f) continue;
    const float inverse_det = 1.0f / det;
    const Eigen::Vector3f s = -a;
    const float b1 = s.dot(p) * inverse_det;
    if (b1 < 0.0f || b1 > 1.0f) continue;
    const Eigen::Vector3f q = s.cross(e1);
    const float b2 = direction.dot(q) * inverse_det;
    if (b2 < 0.0f || b1 + b2 > 1.0f) continue;
    const float distance = e2.dot(q) * inverse_det;
    if (distance >= 0.0f && distance < nearest) nearest = distance;
  }
  return nearest;
}

// Classifies points: `robot_depth(p_S)` gives the distance factor f (> 0) at which the line of sight through
// p_S meets the padded robot (p_S · f is that point) or infinity; f <= 1 means p lies at or behind it.
template <class RobotDepth>
void split_points(const Frame& frame, RobotDepth&& robot_depth, SelfFilterResult& result) {
  const Eigen::Isometry3f X_CS = frame.X_CS.cast<float>();
  Cloud& kept = result.scan.points_C;
  Cloud& clear = result.scan.clear_C;
  kept.reserve(frame.points_S.size());
  for (const pcl::PointXYZ& p : frame.points_S) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const Eigen::Vector3f p_S = p.getVector3fMap();
    const float f = robot_depth(p_S);
    if (f <= 1.0f) {
      const Eigen::Vector3f end_C = X_CS * (p_S * f);
      clear.push_back(pcl::PointXYZ(end_C.x(), end_C.y(), end_C.z()));
    } else {
      const Eigen::Vector3f p_C = X_CS * p_S;
      kept.push_back(pcl::PointXYZ(p_C.x(), p_C.y(), p_C.z()));
    }
  }
  set_unorganized(kept);
  set_unorganized(clear);
  result.kept = kept.size();
  result.removed = clear.size();
}

void filter_camera(const Frame& frame, const PosedShapes& posed, SelfFilterResult& result) {
  const PinholeIntrinsics& in = frame.depth->intrinsics;
  DepthBuffer buffer(in);
  for (std::size_t i = 0; i < posed.shapes.size(); ++i)
    buffer.draw(posed.vertices_S[i], posed.shapes[i]->triangles);
  if (buffer.empty()) {
    result.scan = to_scan(frame);
    result.kept = result.scan.points_C.size();
    return;
  }
  const float fx = float(in.fx), fy = float(in.fy), cx = float(in.cx), cy = float(in.cy);
  const int width = in.width, height = in.height;
  constexpr float kNone = std::numeric_limits<float>::infinity();
  split_points(
      frame,
      [&](const Eigen::Vector3f& p) {
        if (!(p.z() > 0.0f)) return kNone;
        const long u = std::lround(fx * p.x() / p.z() + cx);
        const long v = std::lround(fy * p.y() / p.z() + cy);
        if (u < 0 || v < 0 || u >= width || v >= height) return kNone;
        const float inverse_z = buffer.inverse_depth(int(u), int(v));
        return inverse_z > 0.0f ? 1.0f / (p.z() * inverse_z) : kNone;
      },
      result);
}

void filter_rays(const Frame& frame, const PosedShapes& posed, SelfFilterResult& result) {
  constexpr float kNone = std::numeric_limits<float>::infinity();
  split_points(
      frame,
      [&](const Eigen::Vector3f& p) {
        const float length = p.norm();
        if (!(length > 0.0f)) return kNone;
        const Eigen::Vector3f direction = p / length;
        float nearest = kNone;
        for (std::size_t i = 0; i < posed.shapes.size(); ++i) {
          // Skip shapes whose bounding sphere the line of sight misses.
          const Eigen::Vector3f& c = posed.centres_S[i];
          const float along = c.dot(direction);
          const float radius = float(posed.shapes[i]->bounding_radius);
          if (along < -radius || (c - along * direction).squaredNorm() > radius * radius) continue;
          nearest =
              std::min(nearest, first_crossing(direction, posed.vertices_S[i], posed.shapes[i]->triangles));
        }
        return nearest / length;
      },
      result);
}

}  // namespace

SelfFilter::SelfFilter(const Robot& robot, const SelfFilterConfig& config) {
  config.validate();
  auto model = std::make_unique<Model>();
  model->config = config;
  model->links = robot.link_names().size();
  for (std::size_t i = 0; i < robot.shapes().size(); ++i) {
    const LinkShape& shape = robot.shapes()[i];
    model->shapes.push_back(self_filter::pad(shape.geometry, config));
    model->shape_links.push_back(robot.shape_links()[i]);
    model->X_LG.push_back(shape.X_LG);
    model->triangles += model->shapes.back().triangles.size();
  }
  model_ = std::move(model);
}
SelfFilter::~SelfFilter() = default;
SelfFilter::SelfFilter(SelfFilter&&) noexcept = default;
SelfFilter& SelfFilter::operator=(SelfFilter&&) noexcept = default;

const SelfFilterConfig& SelfFilter::config() const {
  return model_->config;
}
std::size_t SelfFilter::triangle_count() const {
  return model_->triangles;
}

SelfFilterResult SelfFilter::filter(const Frame& frame, const RobotAt& robot) const {
  const Model& m = *model_;
  if (robot.X_CL.size() != m.links) {
    throw Error("self filter: " + std::to_string(robot.X_CL.size()) + " link poses given, the robot has " +
                std::to_string(m.links) + " links");
  }
  if (frame.depth) frame.depth->intrinsics.validate();
  SelfFilterResult result;
  if (!m.config.enabled) {
    result.scan = to_scan(frame);
    result.kept = result.scan.points_C.size();
    return result;
  }
  PosedShapes posed;
  for (std::size_t i = 0; i < m.shapes.size(); ++i) {
    add_posed(m.shapes[i], robot.X_CL[std::size_t(m.shape_links[i])] * m.X_LG[i], frame.X_CS, posed);
  }
  PaddedShape payload;  // outlives `posed`, which points to it
  if (robot.payload && !robot.X_CL.empty()) {
    payload = self_filter::pad(BoxShape{robot.payload->half_extents}, m.config);
    add_posed(payload, robot.X_CL.back() * robot.payload->X_EB, frame.X_CS, posed);
  }
  result.skipped_shapes = posed.skipped;
  if (frame.depth) {
    filter_camera(frame, posed, result);
  } else {
    filter_rays(frame, posed, result);
  }
  result.scan.origin_C = frame.X_CS.translation();
  return result;
}

}  // namespace cellmap
