// libgpiod on a real GPIO chip; skipped when the machine has none (CI machines have none).
// Opening the chip and a line's request are exercised only on a line named by the environment
// (SUNVO_HW_TRIGGER_LINE=<chip>:<line>), since driving an arbitrary pin of a real board is unsafe.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <string>

#include "sunvo/gpio/gpio_api.hpp"
#include "sunvo/gpio/trigger.hpp"

namespace sunvo::gpio {
namespace {

TEST(GpioHardware, OpensGpiochip0WhenPresent) {
  struct stat st {};
  if (::stat("/dev/gpiochip0", &st) != 0 || !S_ISCHR(st.st_mode)) {
    GTEST_SKIP() << "no /dev/gpiochip0";
  }
  GpioApi& api = libgpiodApi();
  ChipHandle chip;
  const int err = api.chipOpen("gpiochip0", chip);
  if (err != 0) GTEST_SKIP() << "/dev/gpiochip0 cannot be opened (errno " << err << ")";
  LineHandle line;
  EXPECT_EQ(api.chipGetLine(chip, 0, line), 0);
  api.chipClose(chip);
}

TEST(GpioHardware, PulsesTheLineNamedBySunvoHwTriggerLine) {
  const char* spec = std::getenv("SUNVO_HW_TRIGGER_LINE");
  if (spec == nullptr) GTEST_SKIP() << "SUNVO_HW_TRIGGER_LINE=<chip>:<line> not set";
  const std::string s(spec);
  const auto colon = s.rfind(':');
  ASSERT_NE(colon, std::string::npos) << "SUNVO_HW_TRIGGER_LINE must be <chip>:<line>";
  TriggerOutputOptions o;
  o.gpio.chip = s.substr(0, colon);
  o.gpio.line = std::atoi(s.c_str() + colon + 1);
  auto out = TriggerOutput::open(o, libgpiodApi());
  ASSERT_TRUE(out.hasValue()) << out.status().toString();
  for (int i = 0; i < 5; ++i) ASSERT_TRUE((*out)->pulse(i * (*out)->periodNs()).isOk());
  EXPECT_EQ((*out)->counters().pulses, 5u);
}

}  // namespace
}  // namespace sunvo::gpio
