#include "cellmap/self_filter/self_filter.hpp"

#include "cellmap/common/error.hpp"

namespace cellmap {

struct SelfFilter::Model {
  SelfFilterConfig config;
  std::size_t links = 0;
};

SelfFilter::SelfFilter(const Robot& robot, const SelfFilterConfig& config) {
  config.validate();
  auto model = std::make_unique<Model>();
  model->config = config;
  model->links = robot.link_names().size();
  model_ = std::move(model);
}
SelfFilter::~SelfFilter() = default;
SelfFilter::SelfFilter(SelfFilter&&) noexcept = default;
SelfFilter& SelfFilter::operator=(SelfFilter&&) noexcept = default;

const SelfFilterConfig& SelfFilter::config() const {
  return model_->config;
}
std::size_t SelfFilter::triangle_count() const {
  return 0;
}

SelfFilterResult SelfFilter::filter(const Frame& frame, const RobotAt& robot) const {
  if (robot.X_CL.size() != model_->links) throw Error("self filter: one link pose per robot link expected");
  SelfFilterResult result;
  result.scan = to_scan(frame);
  result.kept = result.scan.points_C.size();
  return result;
}

}  // namespace cellmap
