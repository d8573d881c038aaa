// HealthWatch on hand-made counter samples (a stalled camera, an estimator lost on every frame or
// stalled, a replay that ended, a wall clock stepped both ways), and the start-up clock check on
// given adjtimex results.

#include "sunvo/rover/health_watch.hpp"

#include <gtest/gtest.h>
#include <sys/timex.h>

#include <cstdlib>
#include <string>

namespace sunvo::rover {
namespace {

constexpr TimeNs kMs = 1'000'000;

HealthConfig testConfig() {
  HealthConfig c;
  c.fault_exit_s = 2.0;
  c.watchdog_pose_age_s = 0.5;
  return c;
}

// Every counter advanced by `frames` since the start, all tracked, all published.
HealthSample running(TimeNs now, std::uint64_t frames) {
  HealthSample s;
  s.now_ns = now;
  s.frames_grabbed = s.frames_processed = s.poses_published = frames;
  return s;
}

TEST(HealthWatch, HealthyWhileEveryCounterAdvances) {
  HealthWatch w(testConfig(), 0, "/dev/a + /dev/b");
  for (int k = 1; k <= 100; ++k) {
    EXPECT_EQ(w.update(running(k * 50 * kMs, static_cast<std::uint64_t>(k))), HealthFault::kNone);
  }
  EXPECT_TRUE(w.healthy());
  EXPECT_FALSE(w.mustExit());
}

TEST(HealthWatch, AWallClockStepIsCountedOnceEachWayASlewAndUnreadClockAreNot) {
  HealthWatch w(testConfig(), 0, "/dev/a + /dev/b");
  constexpr TimeNs kHour = 3'600'000'000'000;
  const TimeNs utc0 = 1'700'000'000'000'000'000;  // UTC - monotonic at the start
  TimeNs step = 0;
  TimeNs slew = 0;
  for (int k = 1; k <= 120; ++k) {
    const TimeNs now = k * 50 * kMs;
    if (k == 40) step += kHour;  // forward one hour
    if (k == 80) step -= kHour;  // and back
    slew += 20'000;              // 0.4 ms/s: an NTP slew, never a jump
    HealthSample s = running(now, static_cast<std::uint64_t>(k));
    s.utc_ns = k % 10 == 5 ? 0 : utc0 + now + slew + step;  // 0: a sample without a UTC read
    EXPECT_EQ(w.update(s), HealthFault::kNone) << k;
    if (k == 40) {
      EXPECT_LT(std::llabs(w.lastClockJumpNs() - kHour), kMs);  // the step + one slew
    }
  }
  EXPECT_EQ(w.clockJumps(), 2u);
  EXPECT_LT(std::llabs(w.lastClockJumpNs() + kHour), kMs);
  EXPECT_TRUE(w.healthy());
  // Just above the threshold counts, just below does not.
  HealthWatch v(testConfig(), 0, "cam");
  HealthSample a = running(50 * kMs, 1);
  a.utc_ns = utc0;
  v.update(a);
  HealthSample b = running(100 * kMs, 2);
  b.utc_ns = utc0 + 50 * kMs + HealthWatch::kClockJumpNs - kMs;
  v.update(b);
  EXPECT_EQ(v.clockJumps(), 0u);
  HealthSample c = running(150 * kMs, 3);
  c.utc_ns = b.utc_ns + 50 * kMs - HealthWatch::kClockJumpNs - 2 * kMs;
  v.update(c);
  EXPECT_EQ(v.clockJumps(), 1u);
}

TEST(HealthWatch, SilentCameraIsAFaultNamingTheDeviceThenAnExit) {
  HealthWatch w(testConfig(), 0, "/dev/sunvo-left + /dev/sunvo-right");
  EXPECT_TRUE(w.update(running(100 * kMs, 2)) == HealthFault::kNone);
  HealthSample s = running(500 * kMs, 2);  // 0.4 s of silence: under the 0.5 s limit
  EXPECT_EQ(w.update(s), HealthFault::kNone);
  s.now_ns = 700 * kMs;
  s.grab_errors = 7;
  EXPECT_EQ(w.update(s), HealthFault::kCamera);
  EXPECT_FALSE(w.mustExit());
  EXPECT_NE(std::string(w.reason()).find("/dev/sunvo-left + /dev/sunvo-right"), std::string::npos)
      << w.reason();
  EXPECT_NE(std::string(w.reason()).find("grab errors 7"), std::string::npos) << w.reason();
  s.now_ns = 2'200 * kMs;  // 2.1 s since the last frame: past fault_exit_s
  EXPECT_EQ(w.update(s), HealthFault::kCamera);
  EXPECT_TRUE(w.mustExit());
  // Frames again: the fault clears.
  EXPECT_EQ(w.update(running(2'250 * kMs, 3)), HealthFault::kNone);
  EXPECT_FALSE(w.mustExit());
}

TEST(HealthWatch, EstimatorLostOnEveryFrame) {
  HealthWatch w(testConfig(), 0, "cam");
  EXPECT_EQ(w.update(running(100 * kMs, 2)), HealthFault::kNone);
  HealthSample s;
  for (int k = 1; k <= 20; ++k) {  // frames keep coming and are published, every one lost
    s = running((100 + 50 * k) * kMs, static_cast<std::uint64_t>(2 + k));
    s.lost_frames = static_cast<std::uint64_t>(k);
    w.update(s);
  }
  EXPECT_EQ(w.fault(), HealthFault::kLost);
  EXPECT_NE(std::string(w.reason()).find("lost"), std::string::npos);
  s.now_ns += 1'200 * kMs;
  s.frames_grabbed += 1;
  s.frames_processed += 1;
  s.lost_frames += 1;
  s.poses_published += 1;
  w.update(s);
  EXPECT_TRUE(w.mustExit());
}

TEST(HealthWatch, StalledEstimatorStopsThePosesNotTheCamera) {
  HealthWatch w(testConfig(), 0, "cam");
  HealthSample s = running(100 * kMs, 2);
  w.update(s);
  for (int k = 1; k <= 20; ++k) {  // the camera runs on, nothing is processed
    s.now_ns = (100 + 50 * k) * kMs;
    s.frames_grabbed = static_cast<std::uint64_t>(2 + k);
    w.update(s);
  }
  EXPECT_EQ(w.fault(), HealthFault::kNoPose);
  EXPECT_FALSE(w.healthy());
}

TEST(HealthWatch, EndedReplayIsIdleNotFaultyAndZeroNeverExits) {
  HealthConfig c = testConfig();
  c.fault_exit_s = 0.0;
  HealthWatch w(c, 0, "replay");
  HealthSample s = running(100 * kMs, 5);
  w.update(s);
  s.now_ns = 60'000 * kMs;
  EXPECT_EQ(w.update(s), HealthFault::kCamera);
  EXPECT_FALSE(w.mustExit());  // 0 = never
  s.source_ended = true;
  EXPECT_EQ(w.update(s), HealthFault::kNone);
}

TEST(ClockCheck, SynchronisedPasses) {
  std::string warning;
  const ClockState synced{TIME_OK, 0, 1000};
  EXPECT_FALSE(clockUnsynced(synced));
  EXPECT_TRUE(checkClock(testConfig(), synced, &warning).isOk());
  EXPECT_TRUE(warning.empty());
}

TEST(ClockCheck, UnsyncWarnsOrRefusesAsConfigured) {
  for (const ClockState& c : {ClockState{TIME_ERROR, STA_UNSYNC, 16000000},
                              ClockState{TIME_OK, STA_UNSYNC, 0}, ClockState{-1, 0, 0}}) {
    EXPECT_TRUE(clockUnsynced(c));
    HealthConfig cfg = testConfig();
    std::string warning;
    EXPECT_TRUE(checkClock(cfg, c, &warning).isOk());
    EXPECT_NE(warning.find("not synchronised"), std::string::npos);
    cfg.clock_unsynced = ClockUnsyncedAction::kRefuse;
    warning.clear();
    const Status refused = checkClock(cfg, c, &warning);
    EXPECT_FALSE(refused.isOk());
    EXPECT_NE(refused.message().find("health.clock_unsynced"), std::string::npos);
  }
}

TEST(ClockCheck, ReadsTheKernel) {
  const ClockState c = readClockState();
  EXPECT_GE(c.adjtimex_rc, 0);  // TIME_OK .. TIME_ERROR: the read-only call needs no privilege
}

}  // namespace
}  // namespace sunvo::rover
