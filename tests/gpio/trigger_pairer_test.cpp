// TriggerPairer on synthetic timestamps: matching with delay and jitter, every miss and duplicate
// counter, ring overflow, closest-match choice, and no allocation per call.

#include "sunvo/gpio/trigger_pairer.hpp"

#include <gtest/gtest.h>

#include <random>

#if defined(SUNVO_HAVE_ALLOC_COUNTER)
#include "sunvo/runtime/alloc_counter.hpp"
#endif

namespace sunvo::gpio {
namespace {

constexpr TimeNs kPeriod = 100'000'000;
constexpr TimeNs kDelay = 7'000'000;
constexpr TimeNs kT0 = 42 * kNsPerSecond;

TriggerPairerOptions options() {
  TriggerPairerOptions o;
  o.capacity = 8;
  o.frame_period_ns = kPeriod;
  o.expected_delay_ns = kDelay;
  o.match_window_ns = 2'000'000;
  return o;
}

TriggerPairer make(const TriggerPairerOptions& o = options()) {
  auto p = TriggerPairer::create(o);
  EXPECT_TRUE(p.hasValue()) << p.status().toString();
  return std::move(p).value();
}

TEST(TriggerPairerOptions, BadKeysAreNamed) {
  EXPECT_TRUE(TriggerPairerOptions{}.validate().isOk());
  TriggerPairerOptions o = options();
  o.match_window_ns = kPeriod;  // more than half a period
  auto p = TriggerPairer::create(o);
  ASSERT_FALSE(p.hasValue());
  EXPECT_NE(p.status().message().find("trigger_pairer.match_window_ns"), std::string::npos);
  o = options();
  o.capacity = 1;
  EXPECT_NE(o.validate().message().find("trigger_pairer.capacity"), std::string::npos);
  o = options();
  o.frame_period_ns = 0;
  EXPECT_NE(o.validate().message().find("trigger_pairer.frame_period_ns"), std::string::npos);
  o = options();
  o.duplicate_fraction = 1.5;
  EXPECT_NE(o.validate().message().find("trigger_pairer.duplicate_fraction"), std::string::npos);
}

TEST(TriggerPairer, MatchesEveryFrameToItsTriggerUnderJitter) {
  TriggerPairer pairer = make();
  std::mt19937 rng(7);
  std::uniform_int_distribution<TimeNs> jitter(-1'500'000, 1'500'000);
  for (int k = 0; k < 200; ++k) {
    const TimeNs trigger = kT0 + k * kPeriod + jitter(rng) / 3;
    pairer.addTrigger({static_cast<std::uint64_t>(k), trigger});
    const auto m = pairer.matchFrame(trigger + kDelay + jitter(rng));
    ASSERT_TRUE(m.has_value()) << k;
    EXPECT_EQ(m->sequence, static_cast<std::uint64_t>(k));
    EXPECT_EQ(m->time_ns, trigger);
  }
  const auto& c = pairer.counters();
  EXPECT_EQ(c.paired, 200u);
  EXPECT_EQ(c.frames_without_trigger + c.triggers_without_frame + c.duplicate_triggers, 0u);
  EXPECT_EQ(pairer.pending(), 0);
}

TEST(TriggerPairer, TriggersMayArriveBeforeOrAfterTheirFrames) {
  TriggerPairer pairer = make();
  // The GPIO thread runs ahead: three triggers, then their frames.
  for (int k = 0; k < 3; ++k) pairer.addTrigger({static_cast<std::uint64_t>(k), kT0 + k * kPeriod});
  for (int k = 0; k < 3; ++k) {
    const auto m = pairer.matchFrame(kT0 + k * kPeriod + kDelay);
    ASSERT_TRUE(m.has_value());
    EXPECT_EQ(m->sequence, static_cast<std::uint64_t>(k));
  }
  // A frame whose trigger has not been read yet is a miss, as far as the pairer can know.
  EXPECT_FALSE(pairer.matchFrame(kT0 + 3 * kPeriod + kDelay).has_value());
  EXPECT_EQ(pairer.counters().frames_without_trigger, 1u);
}

TEST(TriggerPairer, CountsFramesWithoutTriggerAndTriggersWithoutFrame) {
  TriggerPairer pairer = make();
  // Exposure 1 has no trigger edge; exposure 3 has an edge but no frame.
  for (int k = 0; k < 6; ++k) {
    if (k != 1) pairer.addTrigger({static_cast<std::uint64_t>(k), kT0 + k * kPeriod});
  }
  int matched = 0;
  for (int k = 0; k < 6; ++k) {
    if (k == 3) continue;
    const auto m = pairer.matchFrame(kT0 + k * kPeriod + kDelay);
    if (k == 1) {
      EXPECT_FALSE(m.has_value());
    } else {
      ASSERT_TRUE(m.has_value()) << k;
      EXPECT_EQ(m->time_ns, kT0 + k * kPeriod);
      ++matched;
    }
  }
  EXPECT_EQ(matched, 4);
  EXPECT_EQ(pairer.counters().frames_without_trigger, 1u);
  EXPECT_EQ(pairer.counters().triggers_without_frame, 1u);
  EXPECT_EQ(pairer.counters().paired, 4u);
}

TEST(TriggerPairer, DropsDuplicateAndOutOfOrderTriggers) {
  TriggerPairer pairer = make();
  pairer.addTrigger({0, kT0});
  pairer.addTrigger({1, kT0 + 3'000'000});        // bounce 3 ms later
  pairer.addTrigger({2, kT0 + kPeriod / 2 - 1});  // still under half a period
  pairer.addTrigger({3, kT0 - 1});                // older than the newest
  pairer.addTrigger({4, kT0 + kPeriod});
  EXPECT_EQ(pairer.counters().triggers, 2u);
  EXPECT_EQ(pairer.counters().duplicate_triggers, 2u);
  EXPECT_EQ(pairer.counters().out_of_order_triggers, 1u);
  const auto m = pairer.matchFrame(kT0 + kDelay + 1'000'000);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->sequence, 0u);  // the first edge is kept
}

TEST(TriggerPairer, FullRingDropsTheOldestAsMissed) {
  TriggerPairerOptions o = options();
  o.capacity = 4;
  TriggerPairer pairer = make(o);
  for (int k = 0; k < 6; ++k) pairer.addTrigger({static_cast<std::uint64_t>(k), kT0 + k * kPeriod});
  EXPECT_EQ(pairer.pending(), 4);
  EXPECT_EQ(pairer.counters().triggers_without_frame, 2u);
  const auto m = pairer.matchFrame(kT0 + 5 * kPeriod + kDelay);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->sequence, 5u);
  EXPECT_EQ(pairer.counters().triggers_without_frame, 5u);  // 0..4 never got a frame
  EXPECT_EQ(pairer.pending(), 0);
}

TEST(TriggerPairer, TakesTheClosestTriggerInsideTheWindow) {
  TriggerPairerOptions o = options();
  o.duplicate_fraction = 0.01;  // 1 ms: two edges 1.5 ms apart are both kept
  TriggerPairer pairer = make(o);
  pairer.addTrigger({0, kT0});
  pairer.addTrigger({1, kT0 + 1'500'000});
  const auto m = pairer.matchFrame(kT0 + kDelay + 1'200'000);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->sequence, 1u);
  EXPECT_EQ(pairer.counters().triggers_without_frame, 1u);
}

TEST(TriggerPairer, AllocatesNothingPerCall) {
#if defined(SUNVO_HAVE_ALLOC_COUNTER)
  ASSERT_TRUE(runtime::allocCounterActive());
  TriggerPairer pairer = make();
  runtime::AllocationScope scope;
  for (int k = 0; k < 1000; ++k) {
    if (k % 7 != 3) pairer.addTrigger({static_cast<std::uint64_t>(k), kT0 + k * kPeriod});
    if (k % 11 != 5) (void)pairer.matchFrame(kT0 + k * kPeriod + kDelay);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_GT(pairer.counters().frames_without_trigger, 0u);
  EXPECT_GT(pairer.counters().triggers_without_frame, 0u);
#else
  GTEST_SKIP() << "allocation counter not linked (sanitizer build)";
#endif
}

}  // namespace
}  // namespace sunvo::gpio
