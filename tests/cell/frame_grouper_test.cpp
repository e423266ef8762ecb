// SPDX-License-Identifier: Apache-2.0
// Grouping frames into sweeps by their stamps as they arrive: where each frame falls, known answers.
#include "cellmap/cell/frame_grouper.hpp"

#include <gtest/gtest.h>

#include <string>
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

struct Frame {
  std::string sensor;
  double stamp;
};

// The sweeps the frames make, as frame counts, each ended by a frame (the next or its own last).
std::vector<std::size_t> sweep_sizes(FrameGrouper& grouper, const std::vector<Frame>& frames) {
  std::vector<std::size_t> sizes{0};
  for (const Frame& frame : frames) {
    const FramePlace place = grouper.place(frame.sensor, frame.stamp);
    if (place.ends_open_sweep) sizes.push_back(0);
    ++sizes.back();
    if (place.completes_sweep) sizes.push_back(0);
  }
  if (sizes.back() == 0) sizes.pop_back();
  return sizes;
}

// Frames of one sensor at `stamps`.
std::vector<Frame> of(const std::string& sensor, const std::vector<double>& stamps) {
  std::vector<Frame> frames;
  for (const double stamp : stamps) frames.push_back({sensor, stamp});
  return frames;
}

TEST(FrameGrouperTest, AFrameAtTheEndOfThePeriodEndsTheOpenSweep) {
  FrameGrouper grouper(grouping(0.5));
  // Two cameras at uneven rates, so neither tells where its next frame falls; the slower camera's 0.45
  // (late) still joins the first sweep.
  EXPECT_EQ(sweep_sizes(grouper, {{"a", 0.0},
                                  {"a", 0.1},
                                  {"a", 0.15},
                                  {"b", 0.45},
                                  {"a", 0.3},
                                  {"a", 0.5},
                                  {"b", 0.6},
                                  {"a", 0.99},
                                  {"b", 1.0}}),
            (std::vector<std::size_t>{5, 3, 1}));
  EXPECT_EQ(grouper.open_frames(), 1u);
  EXPECT_TRUE(grouper.flush());
  EXPECT_EQ(grouper.open_frames(), 0u);
  EXPECT_FALSE(grouper.flush()) << "nothing is open after a flush";
}

TEST(FrameGrouperTest, TheFrameThatEndsASweepOpensTheNext) {
  FrameGrouper grouper(grouping(0.5));
  EXPECT_FALSE(grouper.place("a", 10.0).ends_open_sweep) << "the first frame has nothing to end";
  EXPECT_FALSE(grouper.place("a", 10.2).ends_open_sweep);
  EXPECT_TRUE(grouper.place("a", 10.5).ends_open_sweep);
  EXPECT_EQ(grouper.open_frames(), 1u);
  EXPECT_FALSE(grouper.place("a", 10.6).ends_open_sweep)
      << "the period counts from the new sweep's first frame";
  EXPECT_TRUE(grouper.place("a", 11.0).ends_open_sweep);
}

// A camera at 10 Hz completes a 0.5 s sweep with its fifth frame: its sixth would open the next anyway.
TEST(FrameGrouperTest, ASweepIsCompleteOnceItsCameraReachedTheWindowsEnd) {
  FrameGrouper grouper(grouping(0.5));
  EXPECT_EQ(sweep_sizes(grouper, of("a", {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9})),
            (std::vector<std::size_t>{5, 5}));
  EXPECT_EQ(grouper.open_frames(), 0u) << "0.9 completed the second sweep";
  EXPECT_FALSE(grouper.flush());
  // 30 Hz stamps computed as k / 30 land an ulp either side of the window's end.
  FrameGrouper at_30hz(grouping(1.0));
  std::vector<double> stamps;
  for (int k = 0; k < 90; ++k) stamps.push_back(k / 30.0);
  EXPECT_EQ(sweep_sizes(at_30hz, of("a", stamps)), (std::vector<std::size_t>{30, 30, 30}));
  EXPECT_EQ(at_30hz.open_frames(), 0u);
}

// Every camera in the sweep must have reached its end: the slower one's last frame completes it.
TEST(FrameGrouperTest, ASweepOfTwoCamerasWaitsForTheSlowerOne) {
  FrameGrouper grouper(grouping(0.5));
  const std::vector<Frame> frames{{"a", 0.0}, {"b", 0.0}, {"a", 0.1}, {"a", 0.2},
                                  {"b", 0.2}, {"a", 0.3}, {"a", 0.4}};
  for (const Frame& frame : frames) {
    EXPECT_FALSE(grouper.place(frame.sensor, frame.stamp).completes_sweep)
        << frame.sensor << " " << frame.stamp;
  }
  EXPECT_TRUE(grouper.place("b", 0.4).completes_sweep) << "b's next frame, at 0.6, lies past 0.5";
  const FramePlace next = grouper.place("a", 0.5);
  EXPECT_FALSE(next.ends_open_sweep) << "the sweep was complete already";
  EXPECT_EQ(grouper.open_frames(), 1u);
}

// A frame earlier than its camera's interval foretold (jitter) opens a sweep of its own; none is lost.
TEST(FrameGrouperTest, AFrameAfterACompletedSweepOpensTheNextWhateverItsStamp) {
  FrameGrouper grouper(grouping(0.5));
  EXPECT_EQ(sweep_sizes(grouper, of("a", {0.0, 0.25, 0.49, 0.7})), (std::vector<std::size_t>{2, 2}));
  EXPECT_EQ(grouper.open_frames(), 2u) << "0.49 opened a sweep that ends at 0.99";
  FrameGrouper late(grouping(0.5));
  EXPECT_EQ(sweep_sizes(late, of("a", {0.0, 0.25, 0.2, 0.6})), (std::vector<std::size_t>{2, 2}))
      << "0.2, out of order after 0.25 completed the first sweep, opens the second";
}

TEST(FrameGrouperTest, MaxFramesCompletesASweepWithItsLastFrame) {
  FrameGrouper grouper(grouping(10.0, 3));
  EXPECT_EQ(sweep_sizes(grouper, of("a", {0, 1, 2, 3, 4, 5, 6})), (std::vector<std::size_t>{3, 3, 1}));
  FrameGrouper both(grouping(0.5, 2));
  const FramePlace first = both.place("a", 0.0);
  EXPECT_FALSE(first.ends_open_sweep || first.completes_sweep);
  const FramePlace late = both.place("a", 0.7);  // past the period: a new sweep of its own
  EXPECT_TRUE(late.ends_open_sweep);
  EXPECT_TRUE(late.completes_sweep) << "the next frame, 0.7 later, falls past the window's end at 1.2";
  EXPECT_FALSE(both.place("a", 0.8).completes_sweep);
  EXPECT_TRUE(both.place("a", 0.85).completes_sweep) << "the second frame of its sweep";
  EXPECT_FALSE(both.flush());
}

// Period 0: one frame per sweep; from a camera's second frame on, each sweep is complete with its frame.
TEST(FrameGrouperTest, PeriodZeroMakesEveryFrameASweep) {
  FrameGrouper grouper(grouping(0.0));
  EXPECT_EQ(sweep_sizes(grouper, of("a", {0.0, 0.0, 0.1, 0.2})), (std::vector<std::size_t>{1, 1, 1, 1}));
  EXPECT_EQ(grouper.open_frames(), 0u);
}

TEST(FrameGrouperTest, AnInvalidGroupingIsRefused) {
  EXPECT_THROW(FrameGrouper(grouping(-1.0)), Error);
}

}  // namespace
}  // namespace cellmap
