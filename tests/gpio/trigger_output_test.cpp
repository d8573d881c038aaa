// TriggerOutput against the emulated GPIO chip: line requests, pulse shape, the schedule helper,
// missed slots, errors and release.

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <thread>

#include "sunvo/emulated/emulated_gpio.hpp"
#include "sunvo/gpio/trigger.hpp"
#include "sunvo/sysio/sysio.hpp"

namespace sunvo::gpio {
namespace {

const std::string kChip = "gpiochip0";
constexpr int kLine = 5;

TriggerOutputOptions options(double rate_hz = 10.0, int width_us = 2000) {
  TriggerOutputOptions o;
  o.gpio = {kChip, kLine, "sunvo-test"};
  o.rate_hz = rate_hz;
  o.pulse_width_us = width_us;
  return o;
}

class TriggerOutputTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(gpio_.addChip(kChip, 8).isOk()); }
  emulated::EmulatedGpio gpio_;
};

TEST(TriggerOutputOptions, BadKeysAreNamed) {
  EXPECT_TRUE(TriggerOutputOptions{}.validate().isOk());
  TriggerOutputOptions o;
  o.rate_hz = 0.0;
  EXPECT_NE(o.validate().message().find("trigger_output.rate_hz"), std::string::npos);
  o = TriggerOutputOptions{};
  o.rate_hz = 100.0;
  o.pulse_width_us = 5000;  // half of the 10 ms period
  EXPECT_NE(o.validate().message().find("trigger_output.pulse_width_us"), std::string::npos);
  o = TriggerOutputOptions{};
  o.gpio.line = -1;
  EXPECT_NE(o.validate().message().find("trigger_output.line"), std::string::npos);
  o = TriggerOutputOptions{};
  o.gpio.chip.clear();
  EXPECT_NE(o.validate().message().find("trigger_output.chip"), std::string::npos);
}

TEST_F(TriggerOutputTest, OpenFailuresNameChipLineAndCall) {
  TriggerOutputOptions o = options();
  o.gpio.chip = "gpiochip7";
  auto no_chip = TriggerOutput::open(o, gpio_);
  ASSERT_FALSE(no_chip.hasValue());
  EXPECT_EQ(no_chip.status().code(), StatusCode::kDeviceError);
  EXPECT_NE(no_chip.status().message().find("gpiochip7 line 5: open chip"), std::string::npos)
      << no_chip.status().message();

  o = options();
  o.gpio.line = 8;
  auto no_line = TriggerOutput::open(o, gpio_);
  ASSERT_FALSE(no_line.hasValue());
  EXPECT_NE(no_line.status().message().find("line 8: get line"), std::string::npos);
  EXPECT_EQ(gpio_.openChips(), 0);

  auto first = TriggerOutput::open(options(), gpio_);
  ASSERT_TRUE(first.hasValue());
  auto busy = TriggerOutput::open(options(), gpio_);
  ASSERT_FALSE(busy.hasValue());
  EXPECT_NE(busy.status().message().find("request output"), std::string::npos);
  EXPECT_NE(busy.status().message().find("errno " + std::to_string(EBUSY)), std::string::npos);
  EXPECT_EQ(gpio_.openChips(), 1);  // only the first holds the chip
}

TEST_F(TriggerOutputTest, PulseRaisesTheLineForThePulseWidth) {
  for (bool active_low : {false, true}) {
    TriggerOutputOptions o = options(10.0, 3000);
    o.active_low = active_low;
    const int idle = active_low ? 1 : 0;
    {
      auto out = TriggerOutput::open(o, gpio_);
      ASSERT_TRUE(out.hasValue()) << out.status().toString();
      const std::size_t before = gpio_.writes(kChip, kLine).size();
      EXPECT_EQ(gpio_.value(kChip, kLine), idle);
      ASSERT_TRUE((*out)->pulse(1000).isOk());
      const auto writes = gpio_.writes(kChip, kLine);
      ASSERT_EQ(writes.size(), before + 2);
      EXPECT_EQ(writes[before].value, 1 - idle);
      EXPECT_EQ(writes[before + 1].value, idle);
      const TimeNs width = writes[before + 1].time_ns - writes[before].time_ns;
      EXPECT_GE(width, 3'000'000);
      EXPECT_LT(width, 3'000'000 + 20'000'000);
      EXPECT_EQ((*out)->lastPulse().sequence, 0u);
      EXPECT_EQ((*out)->lastPulse().time_ns, 1000);
      EXPECT_EQ((*out)->counters().pulses, 1u);
    }  // destroyed: back to idle, released
    EXPECT_FALSE(gpio_.requested(kChip, kLine));
    EXPECT_EQ(gpio_.value(kChip, kLine), idle);
    EXPECT_EQ(gpio_.openChips(), 0);
  }
}

TEST_F(TriggerOutputTest, ScheduleKeepsTheGridAndCountsMissedSlots) {
  auto opened = TriggerOutput::open(options(10.0, 10), gpio_);
  ASSERT_TRUE(opened.hasValue());
  TriggerOutput& out = **opened;
  const TimeNs p = out.periodNs();
  ASSERT_EQ(p, 100'000'000);
  const TimeNs t0 = 5'000'000'000;
  EXPECT_EQ(out.nextPulseTime(t0), t0);  // no pulse yet: now
  ASSERT_TRUE(out.pulse(t0).isOk());
  EXPECT_EQ(out.nextPulseTime(t0 + 1), t0 + p);
  ASSERT_TRUE(out.pulse(t0 + p + 300'000).isOk());  // a little late: still slot 1
  EXPECT_EQ(out.lastPulse().sequence, 1u);
  EXPECT_EQ(out.counters().missed_slots, 0u);
  EXPECT_EQ(out.nextPulseTime(t0 + p + 400'000), t0 + 2 * p);
  // The caller slept through slots 2 and 3.
  EXPECT_EQ(out.nextPulseTime(t0 + 3 * p + 1), t0 + 4 * p);
  ASSERT_TRUE(out.pulse(t0 + 4 * p).isOk());
  EXPECT_EQ(out.counters().missed_slots, 2u);
  EXPECT_EQ(out.lastPulse().sequence, 2u);
  EXPECT_EQ(out.counters().pulses, 3u);
}

TEST_F(TriggerOutputTest, PulseTrainFollowsTheScheduleInRealTime) {
  auto opened = TriggerOutput::open(options(100.0, 500), gpio_);
  ASSERT_TRUE(opened.hasValue());
  TriggerOutput& out = **opened;
  const std::size_t before = gpio_.writes(kChip, kLine).size();
  for (int i = 0; i < 20; ++i) {
    const TimeNs due = out.nextPulseTime(sysio::monotonicNowNs());
    const TimeNs wait = due - sysio::monotonicNowNs();
    if (wait > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
    ASSERT_TRUE(out.pulse(sysio::monotonicNowNs()).isOk());
  }
  const auto writes = gpio_.writes(kChip, kLine);
  ASSERT_EQ(writes.size(), before + 40);
  // Rising edges are never ahead of the grid first + i * period, and the slots the thread missed
  // on a loaded machine are counted, not lost silently.
  const TimeNs first = writes[before].time_ns;
  const TimeNs last = writes[before + 38].time_ns;
  const auto slots = static_cast<double>(last - first) / static_cast<double>(out.periodNs());
  EXPECT_NEAR(slots, 19.0 + static_cast<double>(out.counters().missed_slots), 1.0);
  for (std::size_t i = 1; i < 20; ++i) {
    const emulated::GpioWrite& rise = writes[before + 2 * i];
    EXPECT_EQ(rise.value, 1);
    EXPECT_GE(rise.time_ns - first, static_cast<TimeNs>(i) * out.periodNs() - 1'000'000) << i;
  }
}

TEST_F(TriggerOutputTest, FailedWriteIsReportedAndCounted) {
  auto opened = TriggerOutput::open(options(), gpio_);
  ASSERT_TRUE(opened.hasValue());
  ASSERT_TRUE(gpio_.failNextCall(kChip, kLine, EIO).isOk());
  const Status s = (*opened)->pulse(0);
  EXPECT_EQ(s.code(), StatusCode::kDeviceError);
  EXPECT_NE(s.message().find("gpiochip0 line 5: set value"), std::string::npos) << s.message();
  EXPECT_EQ((*opened)->counters().errors, 1u);
  EXPECT_EQ((*opened)->counters().pulses, 0u);
  EXPECT_TRUE((*opened)->pulse(0).isOk());  // the fault was one call
}

}  // namespace
}  // namespace sunvo::gpio
