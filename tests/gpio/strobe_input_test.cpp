// StrobeInput against the emulated GPIO chip: rising edges with kernel timestamps, timeouts,
// errors, a strobe from another thread, and missed/duplicate strobes counted by TriggerPairer.

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <thread>

#include "sunvo/emulated/emulated_gpio.hpp"
#include "sunvo/gpio/trigger.hpp"
#include "sunvo/gpio/trigger_pairer.hpp"

namespace sunvo::gpio {
namespace {

const std::string kChip = "gpiochip1";
constexpr int kLine = 3;
constexpr TimeNs kPeriod = 50'000'000;
constexpr TimeNs kWidth = 1'000'000;

StrobeInputOptions options(int timeout_ms = 40) {
  StrobeInputOptions o;
  o.gpio = {"/dev/" + kChip, kLine, "sunvo-test"};
  o.wait_timeout_ms = timeout_ms;
  return o;
}

class StrobeInputTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(gpio_.addChip(kChip, 4).isOk()); }
  emulated::EmulatedGpio gpio_;
};

TEST(StrobeInputOptions, BadKeysAreNamed) {
  EXPECT_TRUE(StrobeInputOptions{}.validate().isOk());
  StrobeInputOptions o;
  o.wait_timeout_ms = 0;
  EXPECT_NE(o.validate().message().find("strobe_input.wait_timeout_ms"), std::string::npos);
  o = StrobeInputOptions{};
  o.gpio.consumer.clear();
  EXPECT_NE(o.validate().message().find("strobe_input.consumer"), std::string::npos);
}

TEST_F(StrobeInputTest, ReturnsRisingEdgesWithTheirKernelTimestamps) {
  auto in = StrobeInput::open(options(), gpio_);
  ASSERT_TRUE(in.hasValue()) << in.status().toString();
  EXPECT_TRUE(gpio_.requested(kChip, kLine));
  for (int k = 0; k < 3; ++k)
    ASSERT_TRUE(gpio_.strobe(kChip, kLine, 1000 + k * kPeriod, kWidth).isOk());
  for (std::uint64_t k = 0; k < 3; ++k) {
    auto e = (*in)->next();
    ASSERT_TRUE(e.hasValue()) << e.status().toString();
    EXPECT_EQ(e->sequence, k);
    EXPECT_EQ(e->time_ns, 1000 + static_cast<TimeNs>(k) * kPeriod);
  }
  EXPECT_EQ((*in)->counters().rising, 3u);
  EXPECT_EQ((*in)->counters().falling, 2u);  // the third falling edge is still unread
}

TEST_F(StrobeInputTest, TimesOutWithoutEdgesAndReportsErrors) {
  auto in = StrobeInput::open(options(30), gpio_);
  ASSERT_TRUE(in.hasValue());
  const auto start = std::chrono::steady_clock::now();
  auto e = (*in)->next();
  const auto took = std::chrono::steady_clock::now() - start;
  ASSERT_FALSE(e.hasValue());
  EXPECT_EQ(e.status().code(), StatusCode::kTimeout);
  EXPECT_GE(took, std::chrono::milliseconds(30));
  EXPECT_LT(took, std::chrono::milliseconds(30 + 500));  // loose: a shared, loaded machine
  EXPECT_EQ((*in)->counters().timeouts, 1u);

  ASSERT_TRUE(gpio_.failNextCall(kChip, kLine, ENODEV).isOk());
  e = (*in)->next();
  ASSERT_FALSE(e.hasValue());
  EXPECT_EQ(e.status().code(), StatusCode::kDeviceError);
  EXPECT_NE(e.status().message().find("/dev/gpiochip1 line 3: event wait"), std::string::npos)
      << e.status().message();
  EXPECT_EQ((*in)->counters().errors, 1u);
}

TEST_F(StrobeInputTest, WakesForAnEdgeFromAnotherThread) {
  auto in = StrobeInput::open(options(500), gpio_);
  ASSERT_TRUE(in.hasValue());
  std::thread camera([this] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_TRUE(gpio_.strobe(kChip, kLine, 777, kWidth).isOk());
  });
  const auto start = std::chrono::steady_clock::now();
  auto e = (*in)->next();
  const auto took = std::chrono::steady_clock::now() - start;
  camera.join();
  ASSERT_TRUE(e.hasValue()) << e.status().toString();
  EXPECT_EQ(e->time_ns, 777);
  EXPECT_LT(took, std::chrono::milliseconds(300));
}

TEST_F(StrobeInputTest, MissedAndDuplicateStrobesAreCountedByThePairer) {
  auto in = StrobeInput::open(options(), gpio_);
  ASSERT_TRUE(in.hasValue());
  TriggerPairerOptions po;
  po.frame_period_ns = kPeriod;
  po.expected_delay_ns = 2'000'000;  // strobe → driver timestamp
  po.match_window_ns = 1'000'000;
  auto pairer = TriggerPairer::create(po);
  ASSERT_TRUE(pairer.hasValue());

  // 10 exposures; the strobe of exposure 3 is lost, exposure 6's strobe bounces 3 ms later.
  const TimeNs t0 = 10 * kNsPerSecond;
  for (int k = 0; k < 10; ++k) {
    if (k == 3) {
      ASSERT_TRUE(gpio_.dropStrobes(kChip, kLine, 1).isOk());
    }
    if (k == 6) {
      ASSERT_TRUE(gpio_.duplicateStrobes(kChip, kLine, 1, 3'000'000).isOk());
    }
    ASSERT_TRUE(gpio_.strobe(kChip, kLine, t0 + k * kPeriod, kWidth).isOk());
  }
  for (;;) {
    auto e = (*in)->next();
    if (!e.hasValue()) break;
    pairer->addTrigger(*e);
  }
  EXPECT_EQ((*in)->counters().rising, 10u);  // 9 strobes + 1 bounce
  int matched = 0;
  for (int k = 0; k < 10; ++k) {
    auto t = pairer->matchFrame(t0 + k * kPeriod + po.expected_delay_ns + 200'000);
    if (k == 3) {
      EXPECT_FALSE(t.has_value());
      continue;
    }
    ASSERT_TRUE(t.has_value()) << "frame " << k;
    EXPECT_EQ(t->time_ns, t0 + k * kPeriod);
    ++matched;
  }
  EXPECT_EQ(matched, 9);
  EXPECT_EQ(pairer->counters().frames_without_trigger, 1u);
  EXPECT_EQ(pairer->counters().duplicate_triggers, 1u);
  EXPECT_EQ(pairer->counters().triggers_without_frame, 0u);
}

}  // namespace
}  // namespace sunvo::gpio
