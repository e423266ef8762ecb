// Grouping frames into sweeps by their stamps as they arrive: where each frame falls, known answers.
#include "cellmap/cell/frame_grouper.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

SweepParams grouping(double period, std::size_t max_frames = 0) {
  SweepParams params;
  params.period = period;
  params.max_frames = max_frames;
  return params;
}

// The sweeps the stamps make, as frame counts, and how many were ended by the frames themselves.
std::vector<std::size_t> sweep_sizes(FrameGrouper& grouper, const std::vector<double>& stamps) {
  std::vector<std::size_t> sizes{0};
  for (const double stamp : stamps) {
    const FramePlace place = grouper.place(stamp);
    if (place.ends_open_sweep) sizes.push_back(0);
    ++sizes.back();
    if (place.completes_sweep) sizes.push_back(0);
  }
  if (sizes.back() == 0) sizes.pop_back();
  return sizes;
}

TEST(FrameGrouperTest, AFrameAtTheEndOfThePeriodEndsTheOpenSweep) {
  FrameGrouper grouper(grouping(0.5));
  // Two cameras at different rates; 0.45 (the slower camera's, late) still joins the first sweep.
  EXPECT_EQ(sweep_sizes(grouper, {0.0, 0.1, 0.2, 0.45, 0.3, 0.5, 0.6, 0.99, 1.0}),
            (std::vector<std::size_t>{5, 3, 1}));
  EXPECT_EQ(grouper.open_frames(), 1u);
  EXPECT_TRUE(grouper.flush());
  EXPECT_EQ(grouper.open_frames(), 0u);
  EXPECT_FALSE(grouper.flush()) << "nothing is open after a flush";
}

TEST(FrameGrouperTest, TheFrameThatEndsASweepOpensTheNext) {
  FrameGrouper grouper(grouping(0.5));
  EXPECT_FALSE(grouper.place(10.0).ends_open_sweep) << "the first frame has nothing to end";
  EXPECT_FALSE(grouper.place(10.49).ends_open_sweep);
  EXPECT_TRUE(grouper.place(10.5).ends_open_sweep);
  EXPECT_EQ(grouper.open_frames(), 1u);
  EXPECT_FALSE(grouper.place(10.99).ends_open_sweep) << "the period counts from the new sweep's first frame";
  EXPECT_TRUE(grouper.place(11.0).ends_open_sweep);
}

TEST(FrameGrouperTest, MaxFramesCompletesASweepWithItsLastFrame) {
  FrameGrouper grouper(grouping(10.0, 3));
  EXPECT_EQ(sweep_sizes(grouper, {0, 1, 2, 3, 4, 5, 6}), (std::vector<std::size_t>{3, 3, 1}));
  FrameGrouper both(grouping(0.5, 2));
  const FramePlace first = both.place(0.0);
  EXPECT_FALSE(first.ends_open_sweep || first.completes_sweep);
  const FramePlace late = both.place(0.7);  // past the period: a new sweep of its own
  EXPECT_TRUE(late.ends_open_sweep);
  EXPECT_FALSE(late.completes_sweep) << "it is the first frame of its sweep";
  EXPECT_TRUE(both.place(0.8).completes_sweep);
  EXPECT_FALSE(both.flush());
}

TEST(FrameGrouperTest, PeriodZeroMakesEveryFrameASweep) {
  FrameGrouper grouper(grouping(0.0));
  EXPECT_EQ(sweep_sizes(grouper, {0.0, 0.0, 0.1, 0.2}), (std::vector<std::size_t>{1, 1, 1, 1}));
}

TEST(FrameGrouperTest, AnInvalidGroupingIsRefused) {
  EXPECT_THROW(FrameGrouper(grouping(-1.0)), Error);
}

}  // namespace
}  // namespace cellmap
