// SPDX-License-Identifier: Apache-2.0
// The batch pipeline on real Kinect scenes (mOSD, boxes on a table and stacked boxes) with per-point labels.
// Figures are defined in bench/mosd_score.hpp; scripts/mosd_table prints them for all 25 scenes.
#include <gtest/gtest.h>
#include <pcl/filters/statistical_outlier_removal.h>

#include <filesystem>

#include "cellmap/io/cloud_file.hpp"
#include "cellmap/preprocess/outlier_removal.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "mosd_score.hpp"
#include "support/shared_data.hpp"

namespace cellmap {
namespace {

const std::string kDir = (test::shared_data_dir() / "mosd").string();

#define SKIP_WITHOUT_DATA() CELLMAP_SKIP_WITHOUT_DATA(kDir + "/learn0.pcd")

TEST(Mosd, CoverageAndPerObjectIoUOnBoxScenes) {
  SKIP_WITHOUT_DATA();
  // Boxes on a table (0, 4, 9, 13) and stacked boxes (17, 21, 24): a subset, to stay well under a minute.
  std::vector<double> iou;
  for (int n : {0, 4, 9, 13, 17, 21, 24}) {
    const CloudFile file = load_cloud_file(kDir + "/learn" + std::to_string(n) + ".pcd");
    ASSERT_EQ(file.labels.size(), file.points.size());
    const SegmentResult result = segment_cloud(file.points, SegmentConfig{});
    const mosd::Score score = mosd::score(file.points, file.labels, result.boxes.boxes);
    ASSERT_GT(score.object_points, 0u);
    EXPECT_GE(score.coverage(), 0.995) << "learn" << n;
    iou.insert(iou.end(), score.iou.begin(), score.iou.end());
    std::size_t fitted = 0;
    for (const Box& box : result.boxes.boxes) fitted += box.points;
    EXPECT_EQ(fitted + result.stats.dropped(), file.points.size()) << "learn" << n << ": a point was lost";
  }
  const double median = mosd::median(iou);
  RecordProperty("median_iou", std::to_string(median));
  std::printf("mOSD subset: %zu objects, median IoU %.3f\n", iou.size(), median);
  EXPECT_GE(median, MEDIAN_IOU_FLOOR);
}

TEST(Mosd, OneSidedOutlierRemovalAgreesWithPclOnRealData) {
  SKIP_WITHOUT_DATA();
  const CloudFile file = load_cloud_file(kDir + "/learn3.pcd");
  Cloud::Ptr cloud(new Cloud(file.points));
  pcl::StatisticalOutlierRemoval<pcl::PointXYZ> pcl_filter;
  pcl_filter.setInputCloud(cloud);
  pcl_filter.setMeanK(40);
  pcl_filter.setStddevMulThresh(1.0);
  pcl::Indices pcl_kept;
  pcl_filter.filter(pcl_kept);
  const OutlierResult ours =
      remove_outliers(compute_neighbourhoods(*cloud, 40, false), 1.0, OutlierMode::kOneSided);
  EXPECT_EQ(ours.kept, std::vector<int>(pcl_kept.begin(), pcl_kept.end()));
  const OutlierResult two =
      remove_outliers(compute_neighbourhoods(*cloud, 40, false), 1.0, OutlierMode::kTwoSided);
  EXPECT_GT(two.removed_dense, 0u);
  EXPECT_EQ(two.removed_sparse, ours.removed_sparse);
}

}  // namespace
}  // namespace cellmap
