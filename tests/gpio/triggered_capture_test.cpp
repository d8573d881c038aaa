// The whole capture chain on emulated hardware: TriggerOutput pulses a GPIO line wired to two
// emulated cameras, V4l2StereoSource reads their frames, TriggerPairer matches each frame to the
// pulse that exposed it, and a frame lost by the cameras shows up as a trigger without a frame.

#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "sunvo/emulated/emulated_gpio.hpp"
#include "sunvo/emulated/emulated_v4l2.hpp"
#include "sunvo/gpio/trigger.hpp"
#include "sunvo/gpio/trigger_pairer.hpp"
#include "sunvo/sysio/sysio.hpp"
#include "sunvo/v4l2/stereo_source.hpp"

namespace sunvo {
namespace {

constexpr TimeNs kExposureDelay = 3'000'000;  // trigger edge → driver timestamp, ns

TEST(TriggeredCapture, EveryFrameIsMatchedToThePulseThatExposedIt) {
  emulated::EmulatedGpio gpio;
  emulated::EmulatedV4l2 cameras;
  ASSERT_TRUE(gpio.addChip("gpiochip0", 4).isOk());
  ASSERT_TRUE(cameras.addCamera({"/dev/video0", 64, 32, true, true, 0, 0, {}}).isOk());
  ASSERT_TRUE(cameras.addCamera({"/dev/video1", 64, 32, true, true, 0, 200'000, {}}).isOk());
  // The trigger line drives both cameras: each rising edge is one exposure.
  ASSERT_TRUE(gpio.onOutput("gpiochip0", 2,
                            [&](int value, TimeNs t) {
                              if (value == 1) cameras.trigger(t + kExposureDelay);
                            })
                  .isOk());

  gpio::TriggerOutputOptions to;
  to.gpio = {"gpiochip0", 2, "sunvo-test"};
  to.rate_hz = 100.0;
  to.pulse_width_us = 200;
  auto trigger = gpio::TriggerOutput::open(to, gpio);
  ASSERT_TRUE(trigger.hasValue()) << trigger.status().toString();

  v4l2::V4l2Options vo;
  vo.width = 64;
  vo.height = 32;
  vo.dequeue_timeout_ms = 50;
  vo.max_pair_skew_ns = 500'000;
  auto source = v4l2::V4l2StereoSource::open(vo, cameras);
  ASSERT_TRUE(source.hasValue()) << source.status().toString();

  gpio::TriggerPairerOptions po;
  po.frame_period_ns = (*trigger)->periodNs();
  po.expected_delay_ns = kExposureDelay;
  // The pulse's time is taken just before the line is written; on a loaded machine the write
  // (which exposes the cameras) can come milliseconds later.
  po.match_window_ns = 4'000'000;
  auto pairer = gpio::TriggerPairer::create(po);
  ASSERT_TRUE(pairer.hasValue());

  // The program's loop, run sequentially: pulse, hand the pulse to the pairer, read the frame.
  std::vector<gpio::TriggerEvent> pulses;
  int frames = 0;
  for (int k = 0; k < 30; ++k) {
    if (k == 12) {
      ASSERT_TRUE(cameras.dropFrames("/dev/video0", 1).isOk());
    }
    const TimeNs due = (*trigger)->nextPulseTime(sysio::monotonicNowNs());
    if (due > sysio::monotonicNowNs())
      std::this_thread::sleep_for(std::chrono::nanoseconds(due - sysio::monotonicNowNs()));
    ASSERT_TRUE((*trigger)->pulse(sysio::monotonicNowNs()).isOk());
    pulses.push_back((*trigger)->lastPulse());
    pairer->addTrigger((*trigger)->lastPulse());
    StereoFrame frame;
    const Status s = (*source)->next(frame);
    if (k == 12) {
      // The left camera lost this exposure: the lonely right buffer waits for its partner.
      EXPECT_EQ(s.code(), StatusCode::kTimeout) << s.toString();
      continue;
    }
    ASSERT_TRUE(s.isOk()) << k << ": " << s.toString();
    ++frames;
    const auto matched = pairer->matchFrame((*source)->lastPair().left_time_ns);
    ASSERT_TRUE(matched.has_value()) << "frame " << k;
    EXPECT_EQ(matched->sequence, static_cast<std::uint64_t>(k));
    EXPECT_EQ(matched->time_ns, pulses.back().time_ns);
  }
  EXPECT_EQ(frames, 29);
  EXPECT_EQ(pairer->counters().paired, 29u);
  EXPECT_EQ(pairer->counters().triggers_without_frame, 1u);  // pulse 12
  EXPECT_EQ(pairer->counters().frames_without_trigger, 0u);
  EXPECT_EQ((*source)->counters().sequence_gaps, 1u);
  EXPECT_EQ((*source)->counters().pairing_drops, 1u);
  EXPECT_EQ((*trigger)->counters().pulses, 30u);
}

}  // namespace
}  // namespace sunvo
