#include <gtest/gtest.h>

#include "sunvo/rover/sources.hpp"

namespace sunvo::rover {
namespace {

constexpr TimeNs kP = 100'000'000;  // 10 Hz

TEST(TriggerMonitor, CountsMissedAndDuplicateTriggersOnFakeTimestamps) {
  TriggerMonitor m(kP);
  const TimeNs t0 = 5'000'000'000;
  m.observe(t0);
  m.observe(t0 + kP);                   // regular
  m.observe(t0 + kP + 3'000'000);       // 3 ms later: a duplicate edge
  m.observe(t0 + 2 * kP + 4'000'000);   // regular (jitter 4 ms)
  m.observe(t0 + 5 * kP);               // 3 periods: 2 missed
  m.observe(t0 + 6 * kP + 40'000'000);  // 1.4 periods: rounds to 1, none missed
  EXPECT_EQ(m.duplicates(), 1u);
  EXPECT_EQ(m.missed(), 2u);
}

std::vector<TimeNs> recording(int n) {
  std::vector<TimeNs> t;
  for (int i = 0; i < n; ++i) t.push_back(1'750'000'000'000'000'000 + i * 103'000'000LL);
  return t;
}

TEST(ReplaySchedule, StopFollowsTheRecordingAndEnds) {
  ReplaySchedule s(recording(4), 10, EndAction::kStop, 0, kP, true);
  EXPECT_TRUE(s.has(3));
  EXPECT_FALSE(s.has(4));
  EXPECT_EQ(s.recordingIndex(0), 10);
  EXPECT_EQ(s.recordingIndex(3), 13);
  EXPECT_EQ(s.offsetNs(2), 206'000'000);  // the recorded deltas
  EXPECT_EQ(s.utcNs(3), recording(4)[3]);
}

TEST(ReplaySchedule, PingPongAndLoopKeepTimeMovingForward) {
  ReplaySchedule pp(recording(4), 0, EndAction::kPingPong, 10, kP, true);
  const std::int64_t expected[] = {0, 1, 2, 3, 2, 1, 0, 1, 2, 3};
  for (std::uint64_t k = 0; k < 10; ++k) {
    EXPECT_TRUE(pp.has(k));
    EXPECT_EQ(pp.recordingIndex(k), expected[k]) << k;
    if (k > 0) {
      EXPECT_GT(pp.utcNs(k), pp.utcNs(k - 1));
    }
  }
  EXPECT_FALSE(pp.has(10));                         // total_frames
  EXPECT_EQ(pp.offsetNs(5), 309'000'000 + 2 * kP);  // the first pass, then the nominal period
  ReplaySchedule loop(recording(3), 0, EndAction::kLoop, 0, kP, false);
  EXPECT_EQ(loop.recordingIndex(3), 0);
  EXPECT_EQ(loop.recordingIndex(7), 1);
  EXPECT_EQ(loop.offsetNs(7), 7 * kP);  // fixed rate
  EXPECT_TRUE(loop.has(1'000'000));
}

TEST(SimulatedTrigger, FiresAtTheScheduleAndEnds) {
  auto schedule = std::make_shared<ReplaySchedule>(recording(3), 0, EndAction::kStop, 0, 10'000'000,
                                                   false);  // 100 Hz
  SimulatedTrigger trigger(schedule);
  TriggerEvent ev;
  std::vector<TriggerEvent> events;
  for (int i = 0; i < 3; ++i) {
    Status s = trigger.wait(1'000'000'000, &ev);
    ASSERT_TRUE(s.isOk()) << s.toString();
    events.push_back(ev);
  }
  EXPECT_EQ(events[2].sequence, 2u);
  EXPECT_EQ(events[1].mono_ns - events[0].mono_ns, 10'000'000);  // the scheduled edge times
  EXPECT_EQ(events[2].utc_ns, schedule->utcNs(2));
  EXPECT_EQ(trigger.wait(1'000'000, &ev).code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace sunvo::rover
