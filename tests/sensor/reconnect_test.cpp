// SPDX-License-Identifier: Apache-2.0
// The reconnect state machine, driven by a clock the test passes in.
#include "cellmap/sensor/reconnect.hpp"

#include <gtest/gtest.h>

#include "cellmap/common/error.hpp"
#include "support/manual_clock.hpp"

namespace cellmap {
namespace {

ReconnectParams policy() {
  ReconnectParams p;
  p.frame_timeout = 2.0;
  p.initial_backoff = 0.5;
  p.max_backoff = 4.0;
  p.factor = 2.0;
  return p;
}

TEST(ReconnectorTest, BacksOffExponentiallyUpToTheCap) {
  Reconnector r(policy());
  EXPECT_EQ(r.state(), SourceState::kClosed);
  r.lost(10.0, "no devices found");
  EXPECT_EQ(r.state(), SourceState::kDisconnected);
  EXPECT_EQ(r.reason(), "no devices found");
  EXPECT_DOUBLE_EQ(r.next_attempt(), 10.5);
  EXPECT_FALSE(r.retry_due(10.49));
  EXPECT_TRUE(r.retry_due(10.5));
  // Each failed retry doubles the wait: 1, 2, 4, then stays at 4.
  double now = 10.5;
  for (double wait : {1.0, 2.0, 4.0, 4.0, 4.0}) {
    r.lost(now, "no devices found");
    EXPECT_DOUBLE_EQ(r.next_attempt() - now, wait);
    now = r.next_attempt();
  }
}

TEST(ReconnectorTest, SilenceTurnsDisconnectedAfterTheFrameTimeout) {
  Reconnector r(policy());
  r.connected(100.0);
  EXPECT_EQ(r.state(), SourceState::kConnected);
  r.frame(100.5);
  EXPECT_FALSE(r.check(102.4));  // 1.9 s of silence
  EXPECT_EQ(r.state(), SourceState::kConnected);
  EXPECT_TRUE(r.check(102.5));  // 2 s
  EXPECT_EQ(r.state(), SourceState::kDisconnected);
  EXPECT_EQ(r.reason(), "no frames for 2 s");
  EXPECT_DOUBLE_EQ(r.next_attempt(), 103.0);
  EXPECT_FALSE(r.check(200.0));  // only a connected source times out
}

TEST(ReconnectorTest, BackoffResetsOnlyWhenFramesFlowAgain) {
  Reconnector r(policy());
  r.lost(0.0, "unplugged");   // waits 0.5, next 1
  r.lost(0.5, "unplugged");   // waits 1, next 2
  r.connected(1.5);           // opens but never streams
  EXPECT_TRUE(r.check(3.5));  // waits 2: still backing off
  EXPECT_DOUBLE_EQ(r.next_attempt(), 5.5);
  r.connected(5.5);
  r.frame(5.6);  // streaming again: back-off back to the start
  EXPECT_DOUBLE_EQ(r.backoff(), 0.5);
  r.lost(6.0, "unplugged");
  EXPECT_DOUBLE_EQ(r.next_attempt(), 6.5);
}

TEST(ReconnectorTest, ErrorIsFinalUntilClosed) {
  Reconnector r(policy());
  r.failed("no mode 640x480@30 Z16");
  EXPECT_EQ(r.state(), SourceState::kError);
  EXPECT_FALSE(r.retry_due(1e9));
  r.closed();
  EXPECT_EQ(r.state(), SourceState::kClosed);
  EXPECT_TRUE(r.reason().empty());
}

TEST(ReconnectorTest, RetryOrWaitSleepsUntilTheAttemptIsDueThenConnects) {
  // On a clock the test drives: the attempt is due 1 s after the loss; a 20 ms wait is too short, a 5 s wait
  // is cut at the attempt.
  ReconnectParams p = policy();
  p.initial_backoff = 1.0;
  test::ManualClock clock;
  const auto seconds = [&] { return std::chrono::duration<double>(clock.now().time_since_epoch()).count(); };
  Reconnector r(p, clock);
  const double lost_at = seconds();
  r.lost(lost_at, "unplugged");
  int attempts = 0;
  const auto connect = [&](double now) {
    ++attempts;
    EXPECT_DOUBLE_EQ(now, seconds());
    EXPECT_GE(now, r.next_attempt());
    r.lost(now, "still unplugged");
  };
  r.retry_or_wait(std::chrono::milliseconds(20), connect);  // not due: waits out the 20 ms, no attempt
  EXPECT_EQ(attempts, 0);
  EXPECT_NEAR(seconds() - lost_at, 0.020, 1e-6);
  r.retry_or_wait(std::chrono::milliseconds(5000), connect);  // sleeps until the attempt is due, not 5 s
  EXPECT_EQ(attempts, 0);
  EXPECT_NEAR(seconds() - lost_at, 1.0, 1e-6);
  r.retry_or_wait(std::chrono::milliseconds(5000), connect);  // due: tries at once
  EXPECT_EQ(attempts, 1);
  EXPECT_NEAR(seconds() - lost_at, 1.0, 1e-6);
  EXPECT_DOUBLE_EQ(r.backoff(), 4.0);  // 1 → 2 after the first loss, 4 (the cap) after the failed retry
}

TEST(ReconnectorTest, RefusesBadPolicies) {
  ReconnectParams p = policy();
  p.max_backoff = 0.1;
  EXPECT_THROW(Reconnector{p}, Error);
  p = policy();
  p.frame_timeout = 0;
  EXPECT_THROW(Reconnector{p}, Error);
  p = policy();
  p.factor = 0.5;
  EXPECT_THROW(Reconnector{p}, Error);
}

}  // namespace
}  // namespace cellmap
