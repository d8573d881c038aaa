// EmulatedGpio follows libgpiod v1.6's rules for the calls sunvo makes.

#include "sunvo/emulated/emulated_gpio.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <vector>

namespace sunvo::emulated {
namespace {

TEST(EmulatedGpio, FollowsLibgpiodRequestRules) {
  EmulatedGpio gpio;
  ASSERT_TRUE(gpio.addChip("gpiochip2", 4).isOk());
  gpio::ChipHandle chip;
  EXPECT_EQ(gpio.chipOpen("gpiochip9", chip), ENOENT);
  ASSERT_EQ(gpio.chipOpen("/dev/gpiochip2", chip), 0);
  gpio::LineHandle out;
  gpio::LineHandle in;
  EXPECT_EQ(gpio.chipGetLine(chip, 4, out), EINVAL);
  ASSERT_EQ(gpio.chipGetLine(chip, 0, out), 0);
  ASSERT_EQ(gpio.chipGetLine(chip, 1, in), 0);
  EXPECT_EQ(gpio.lineSetValue(out, 1), EPERM);  // not requested
  ASSERT_EQ(gpio.lineRequestOutput(out, "t", 1), 0);
  EXPECT_EQ(gpio.lineRequestOutput(out, "t", 0), EBUSY);
  EXPECT_EQ(gpio.value("gpiochip2", 0), 1);
  ASSERT_EQ(gpio.lineSetValue(out, 0), 0);
  ASSERT_EQ(gpio.writes("gpiochip2", 0).size(), 2u);

  ASSERT_EQ(gpio.lineRequestBothEdgesEvents(in, "t"), 0);
  gpio::LineEvent e;
  EXPECT_EQ(gpio.lineEventRead(in, e), EAGAIN);
  bool ready = true;
  ASSERT_EQ(gpio.lineEventWait(in, 1'000'000, ready), 0);
  EXPECT_FALSE(ready);
  ASSERT_TRUE(gpio.strobe("gpiochip2", 1, 100, 10).isOk());
  ASSERT_EQ(gpio.lineEventWait(in, 1'000'000, ready), 0);
  EXPECT_TRUE(ready);
  ASSERT_EQ(gpio.lineEventRead(in, e), 0);
  EXPECT_TRUE(e.rising);
  EXPECT_EQ(e.time_ns, 100);
  ASSERT_EQ(gpio.lineEventRead(in, e), 0);
  EXPECT_FALSE(e.rising);
  EXPECT_EQ(e.time_ns, 110);
  EXPECT_EQ(gpio.lineSetValue(in, 1), EPERM);

  // A listener sees each write with its time, after the write is recorded.
  std::vector<GpioWrite> heard;
  ASSERT_TRUE(gpio.onOutput("gpiochip2", 0,
                            [&](int v, TimeNs t) {
                              heard.push_back({v, t});
                            })
                  .isOk());
  ASSERT_EQ(gpio.lineSetValue(out, 1), 0);
  ASSERT_EQ(heard.size(), 1u);
  EXPECT_EQ(heard[0].value, 1);
  EXPECT_EQ(heard[0].time_ns, gpio.writes("gpiochip2", 0).back().time_ns);

  EXPECT_EQ(gpio.openChips(), 1);
  gpio.chipClose(chip);  // releases both lines
  EXPECT_FALSE(gpio.requested("gpiochip2", 0));
  EXPECT_FALSE(gpio.requested("gpiochip2", 1));
  EXPECT_EQ(gpio.openChips(), 0);
}

}  // namespace
}  // namespace sunvo::emulated
